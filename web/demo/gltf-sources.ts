// Where the page reads a glTF's bytes from, and the one rule they all follow: the page's own
// origin, the files the user dropped, or data: URIs; never another origin. A ?model= value, a
// buffer's or an image's uri that leads anywhere else is refused (OUTSIDE_FOLDER) before any
// request; what three's loaders still ask for passes through one guarded LoadingManager that
// refuses the rest; the page's Content-Security-Policy (index.html) is the wall behind both.
// No read is unbounded: a file or a URL's body is cut at its byte limit.
import * as THREE from 'three';
import { decodeBufferPath } from '../lib/gltf/buffers.js';
import { GltfError, n } from '../lib/gltf/error.js';
import { LIMITS } from '../lib/gltf/limits.js';
import { shownName } from '../lib/gltf/shown-name.js';

/** The largest file the page reads (a glTF, one of its buffers, or its images together): the CLI's limit. */
export const MAX_FILE_BYTES = LIMITS.fileBytes;

/** Reads the file that buffer or image `index`'s `uri` names, at most `maxBytes` of it. Throws a GltfError. */
export type ResourceReader = (uri: string, kind: 'buffer' | 'image', index: number, maxBytes: number) => Promise<Uint8Array>;

/** A buffer's uri as the path it names (%-decoded, checked by decodeBufferPath); an image's as it decodes. */
function uriPath(uri: string, kind: 'buffer' | 'image', index: number, name: string): string {
  if (kind === 'buffer') return decodeBufferPath(uri, name, index);
  try {
    return decodeURIComponent(uri);
  } catch {
    return uri;
  }
}

/** Whether `uri` names a place of its own (a scheme, or //host), not a path relative to the glTF. */
const isUrl = (uri: string) => /^([a-z][a-z0-9+.-]*:|[\\/]{2})/i.test(uri);
const isData = (uri: string) => /^data:/i.test(uri);
const sameSite = (url: URL) => (url.protocol === 'http:' || url.protocol === 'https:') && url.origin === location.origin;

export function tooLarge(name: string, bytes: number, what = name): GltfError {
  return new GltfError('TOO_LARGE', name, '', `${what} has ${n(bytes)} bytes or more, past the ${n(MAX_FILE_BYTES)} this page reads`);
}

/**
 * The URL a ?model= value names: a path on this site or a data: URI. Anything else (another
 * origin, //host, javascript:, blob:) is refused in one sentence, before any request.
 */
export function siteUrl(value: string): URL {
  let url: URL | null = null;
  try {
    url = new URL(value, location.href);
  } catch { /* refused below */ }
  if (url && (sameSite(url) || url.protocol === 'data:')) return url;
  const shown = shownName(value);
  throw new GltfError('OUTSIDE_FOLDER', shown, '',
    `?model=${shown} is ${url && /^https?:$/.test(url.protocol) ? `on another site (${shownName(url.origin)})` : 'not a path of this site'}: ` +
    'this page loads only its own files (a path such as Fox.glb) and data: URIs');
}

/** The body of `url` (this site or data:), at most `maxBytes` of it: the rest is never downloaded. `what` starts the message of a failure. */
export async function fetchAtMost(url: URL, maxBytes: number, name: string, what: string): Promise<Uint8Array> {
  let response: Response;
  try {
    // 'same-origin': the browser itself refuses another origin, a redirect to one included.
    response = await fetch(url, { mode: 'same-origin', credentials: 'same-origin' });
  } catch {
    throw new GltfError('UNREADABLE', name, '', `${what} (the request failed)`);
  }
  if (!response.ok || !response.body) throw new GltfError('UNREADABLE', name, '', `${what} (HTTP ${response.status}${response.statusText ? ` ${shownName(response.statusText, 40)}` : ''})`);
  const out = new Uint8Array(Math.min(maxBytes, Number(response.headers.get('content-length')) || 2 ** 20));
  let data = out, length = 0;
  const reader = response.body.getReader();
  while (length < maxBytes) {
    const { done, value } = await reader.read();
    if (done) break;
    const take = Math.min(value.byteLength, maxBytes - length);
    if (length + take > data.length) {
      const grown = new Uint8Array(Math.min(maxBytes, Math.max(2 * data.length, length + take)));
      grown.set(data.subarray(0, length));
      data = grown;
    }
    data.set(value.subarray(0, take), length);
    length += take;
  }
  await reader.cancel().catch(() => {});
  return data.subarray(0, length);
}

/** A data: URI's bytes (fetched: the browser decodes it, nothing leaves the page). */
const dataBytes = (uri: string, maxBytes: number, name: string, what: string) =>
  fetchAtMost(new URL(uri), maxBytes, name, `${name}: ${what}'s data: URI does not decode`);

/** Resources of a file at `base` on this site (null: a data: URI, which has no folder). */
export function siteReader(base: URL | null, name: string): ResourceReader {
  return async (uri, kind, index, maxBytes) => {
    const what = `${kind} ${index}`, where = `/${kind}s/${index}/uri`;
    if (isData(uri)) return dataBytes(uri, maxBytes, name, what);
    if (!base && !isUrl(uri))
      throw new GltfError('UNREADABLE', name, where,
        `${name}: ${what} is in the file '${shownName(uri)}', which a data: URI has no folder to read from: embed it as a data: URI, or use a .glb`);
    let url: URL;
    try {
      url = new URL(uriPath(uri, kind, index, name), base ?? location.href); // no base: only //host reaches here
    } catch (e) {
      if (e instanceof GltfError) throw e;
      throw new GltfError('BAD_URI', name, where, `${name}: ${what}'s uri '${shownName(uri)}' is not a URI`);
    }
    if (!sameSite(url))
      throw new GltfError('OUTSIDE_FOLDER', name, where,
        `${name}: ${what}'s uri '${shownName(uri)}' leads to another site: this page reads a file's buffers and images only from its own site`);
    return fetchAtMost(url, maxBytes, name, `${name}: ${what}'s file '${shownName(uri)}' cannot be read`);
  };
}

/** Resources of a dropped file: only the files dropped with it (by name), or data: URIs. */
export function droppedReader(companions: readonly File[], name: string): ResourceReader {
  const byName = new Map(companions.map((f) => [f.name, f]));
  return async (uri, kind, index, maxBytes) => {
    const what = `${kind} ${index}`, where = `/${kind}s/${index}/uri`;
    if (isData(uri)) return dataBytes(uri, maxBytes, name, what);
    if (isUrl(uri))
      throw new GltfError('OUTSIDE_FOLDER', name, where,
        `${name}: ${what}'s uri '${shownName(uri)}' is a URL: a dropped file's buffers and images are read only from the files dropped with it`);
    const path = uriPath(uri, kind, index, name);
    const file = byName.get(path.split(/[\\/]/).pop() ?? path);
    if (!file)
      throw new GltfError('UNREADABLE', name, where,
        `${name} keeps ${what} in the file '${shownName(uri)}', which was not dropped with it: ` +
        'drop the .gltf together with its files (select them all), or use a .glb');
    return new Uint8Array(await file.slice(0, maxBytes).arrayBuffer());
  };
}

// Every URL three's loaders ask for, checked: blob: URLs of this page (the checked bytes), data:
// URIs and this site's own files (the decoders). The rest is refused and reported after the load.
let refused: string[] = [];

/** The one LoadingManager of the page's glTF loads and their decoders. */
export const guardedManager = new THREE.LoadingManager();
guardedManager.setURLModifier((url) => {
  let ok = isData(url) || url.startsWith(`blob:${location.origin}/`);
  if (!ok) try { ok = sameSite(new URL(url, document.baseURI)); } catch { ok = false; }
  if (ok) return url;
  refused.push(url);
  return 'data:,';
});

/** The URLs refused since the last call (a load starts and ends with it). */
export function takeRefused(): string[] {
  const out = refused;
  refused = [];
  return out;
}
