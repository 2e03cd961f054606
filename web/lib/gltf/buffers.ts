// The bytes of a glTF's buffers, gathered and validated the same way in node (packages/cli/src/gltf-node.ts: files
// beside the .gltf) and in the browser (the demo: dropped files, URLs): the GLB's BIN chunk,
// data: URIs decoded here (a malformed one is a BAD_URI GltfError, not the engine's URIError), and
// external files through a reader the caller gives, asked for at most the declared byteLength.
// Then the whole file goes through validateGltfJson. Browser-safe: no node module.
import { parseGltfContainer } from './container.js';
import { checkDracoCounts } from './draco-check.js';
import { shownName } from './shown-name.js';
import { GltfError, n } from './error.js';
import type { BufferData, GltfJson } from './json.js';
import { validateGltfJson } from './validate.js';

/**
 * Reads buffer `index`'s external file `uri`: at most `maxBytes` of it (its declared byteLength),
 * or throws a GltfError (UNREADABLE, OUTSIDE_FOLDER, BAD_URI, …).
 */
export type ExternalReader = (uri: string, index: number, maxBytes: number) => Promise<Uint8Array>;

/** A validated glTF: its JSON and, per buffer, its bytes (undefined: an extension's buffer with no data). */
export interface ValidatedGltf {
  /** The glTF JSON, validated against the reader's limits. */
  json: GltfJson;
  /** Buffer i's bytes, at most its byteLength. */
  buffers: (Uint8Array | undefined)[];
  /** Whether buffer i is the GLB's BIN chunk. */
  glbBin: boolean[];
  /** What validateGltfJson was given (the bytes and their sources), for the checks that read values later. */
  data: (BufferData | undefined)[];
}

/** The bytes of a data: URI (base64 or percent-encoded), or null if `uri` is not one. */
export function decodeDataUri(uri: string, file: string, i: number): Uint8Array | null {
  if (!/^data:/i.test(uri)) return null;
  const where = `/buffers/${i}/uri`;
  const comma = uri.indexOf(',');
  if (comma < 0) throw new GltfError('BAD_URI', file, where, `${file}: buffer ${i}'s data: URI has no comma before its data`);
  const body = uri.slice(comma + 1);
  if (/;base64$/i.test(uri.slice(0, comma))) {
    const base64 = body.replace(/\s+/g, '');
    if (!/^[A-Za-z0-9+/]*={0,2}$/.test(base64) || base64.length % 4 === 1)
      throw new GltfError('BAD_URI', file, where, `${file}: buffer ${i}'s data: URI says base64 but its data is not base64`);
    const text = atob(base64.replace(/=+$/, '').padEnd(Math.ceil(base64.replace(/=+$/, '').length / 4) * 4, '='));
    const out = new Uint8Array(text.length);
    for (let k = 0; k < text.length; k++) out[k] = text.charCodeAt(k);
    return out;
  }
  const bad = /%(?![0-9a-fA-F]{2})/.exec(body);
  if (bad) throw new GltfError('BAD_URI', file, where, `${file}: buffer ${i}'s data: URI has a bad %-escape at character ${comma + 1 + bad.index}`);
  // Percent-decoding to bytes (not to text: decodeURIComponent refuses bytes that are not UTF-8).
  const text = new TextEncoder().encode(body);
  const out = new Uint8Array(text.length);
  let length = 0;
  for (let k = 0; k < text.length; k++) {
    if (text[k] === 0x25) { out[length++] = parseInt(String.fromCharCode(text[k + 1], text[k + 2]), 16); k += 2; }
    else out[length++] = text[k];
  }
  return out.slice(0, length);
}

/** A buffer uri %-decoded into the relative path it names (BAD_URI if it does not decode, or holds a NUL). */
export function decodeBufferPath(uri: string, file: string, i: number): string {
  let path: string;
  try {
    path = decodeURIComponent(uri);
  } catch {
    throw new GltfError('BAD_URI', file, `/buffers/${i}/uri`, `${file}: buffer ${i}'s uri '${shownName(uri)}' has a bad %-escape`);
  }
  if (path.includes('\0')) throw new GltfError('BAD_URI', file, `/buffers/${i}/uri`, `${file}: buffer ${i}'s uri has a NUL character`);
  return path;
}

/**
 * Splits and validates the bytes of a .glb or .gltf (`file` names it in messages), reading its
 * external buffers through `external` (null: bytes with no folder, so a buffer in a file of its
 * own is an UNREADABLE error). Throws a GltfError for anything wrong.
 */
export async function readValidatedGltf(bytes: Uint8Array, file: string, external: ExternalReader | null): Promise<ValidatedGltf> {
  const { json, bin, glb } = parseGltfContainer(bytes, file);
  const buffers: (Uint8Array | undefined)[] = [];
  const glbBin: boolean[] = [];
  const data: (BufferData | undefined)[] = [];
  const defs = Array.isArray(json.buffers) ? json.buffers : [];
  for (let i = 0; i < defs.length; i++) {
    const b = defs[i];
    const keep = (bytes: Uint8Array | undefined, source: string, isBin = false) => {
      buffers[i] = bytes;
      glbBin[i] = isBin;
      data[i] = bytes && { byteLength: bytes.byteLength, bytes, source };
    };
    if (!b || typeof b !== 'object') { keep(undefined, ''); continue; } // validateGltfJson reports it
    const uri = b.uri;
    if (uri === undefined) {
      if (glb && i === 0 && bin) keep(bin, "the GLB's BIN chunk", true);
      else if (b.extensions) keep(undefined, ''); // an extension's buffer (e.g. a meshopt fallback): no data to check
      else
        throw new GltfError('BAD_REFERENCE', file, `/buffers/${i}`,
          glb && i === 0 ? `${file}: buffer 0 has no uri and the file has no BIN chunk: its ${n(b.byteLength ?? 0)} bytes are nowhere`
            : `${file}: buffer ${i} has no uri${glb ? ' and only buffer 0 can be the GLB\'s BIN chunk' : ''}: its data is nowhere`);
      continue;
    }
    if (typeof uri !== 'string') throw new GltfError('BAD_STRUCTURE', file, `/buffers/${i}/uri`, `${file}: buffer ${i}'s uri is not a string`);
    const inline = decodeDataUri(uri, file, i);
    if (inline) { keep(inline, 'its data: URI'); continue; }
    if (!external)
      throw new GltfError('UNREADABLE', file, `/buffers/${i}/uri`,
        `${file}: buffer ${i} is in the file '${shownName(uri)}', which cannot be resolved without the .gltf's folder: give the .gltf's path, or a .glb`);
    const maxBytes = Number.isInteger(b.byteLength) && b.byteLength >= 0 ? b.byteLength : 0; // a bad byteLength is reported next
    keep(await external(uri, i, maxBytes), `its file '${shownName(uri)}'`);
  }
  validateGltfJson(json, file, data);
  checkDracoCounts(json, data, file);
  return { json, buffers, glbBin, data };
}
