// Reads a dropped or linked glTF in the page the way `gcs-skin report` reads one in node: the
// bytes go through the shared validation (web/lib/gltf/buffers.ts, validate.ts) before
// three's GLTFLoader sees them, so a broken or hostile file is one sentence with a code
// (GltfError). GLTFLoader then parses the validated JSON with each buffer's checked bytes (blob
// URLs), and vertices whose weights are all 0 get their zeros back (three would bind them to the
// first joint), so the core reports them as the CLI does. No read is unbounded: a file or a URL's
// body is cut at MAX_FILE_BYTES, an external buffer at its declared byteLength.
import * as THREE from 'three';
import { GLTFLoader, type GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { decodeBufferPath, readValidatedGltf, type ExternalReader, type ValidatedGltf } from '../lib/gltf/buffers.js';
import { restoreZeroWeights, zeroWeightVertices } from '../lib/gltf/accessors.js';
import { GltfError, n } from '../lib/gltf/error.js';

export { GltfError } from '../lib/gltf/error.js';

/** The largest file the page reads. */
const MAX_FILE_BYTES = 512 * 2 ** 20;

/** The last part of a path or URL, %-decoded where it decodes. */
export function basename(path: string): string {
  const last = path.split(/[\\/]/).pop() ?? path;
  try {
    return decodeURIComponent(last);
  } catch {
    return last;
  }
}

/** A dropped .glb or .gltf with the files dropped beside it (its external buffers and images, found by name). */
export async function loadDroppedGltf(main: File, companions: readonly File[]): Promise<GLTF> {
  if (main.size > MAX_FILE_BYTES) throw tooLarge(main.name, main.size);
  const byName = new Map(companions.map((f) => [f.name, f]));
  const external: ExternalReader = async (uri, i, maxBytes) => {
    const file = byName.get(basename(decodeBufferPath(uri, main.name, i)));
    if (!file)
      throw new GltfError('UNREADABLE', main.name, `/buffers/${i}/uri`,
        `${main.name} keeps its data in external files (${uri}), which a dropped .gltf cannot reach: ` +
        'drop the .gltf together with those files (select them all), or use a .glb or a .gltf with embedded buffers');
    return new Uint8Array(await file.slice(0, maxBytes).arrayBuffer());
  };
  const gltf = await readValidatedGltf(new Uint8Array(await main.arrayBuffer()), main.name, external);
  const images = new Map<string, string>();
  return parseValidated(gltf, main.name, '', (url) => {
    const file = byName.get(basename(url));
    if (!file) return url;
    if (!images.has(url)) images.set(url, URL.createObjectURL(file));
    return images.get(url)!;
  }, () => images.forEach((u) => URL.revokeObjectURL(u)));
}

/** A .glb or .gltf at a URL (relative to the page), its external buffers and images beside it. */
export async function loadGltfUrl(url: string, name = url): Promise<GLTF> {
  const base = new URL(url, location.href);
  const external: ExternalReader = (uri, i, maxBytes) => fetchAtMost(new URL(decodeBufferPath(uri, name, i), base).href, maxBytes, name, i);
  const bytes = await fetchAtMost(base.href, MAX_FILE_BYTES, name, -1);
  if (bytes.byteLength >= MAX_FILE_BYTES) throw tooLarge(name, bytes.byteLength);
  const gltf = await readValidatedGltf(bytes, name, external);
  return parseValidated(gltf, name, new URL('.', base).href, (u) => u, () => {});
}

function tooLarge(name: string, bytes: number): GltfError {
  return new GltfError('TOO_LARGE', name, '', `${name} has ${n(bytes)} bytes or more, past the ${n(MAX_FILE_BYTES)} this page reads`);
}

/** The body of `url`, at most `maxBytes` of it (the rest is never downloaded); buffer `index` (-1: the file itself) in messages. */
async function fetchAtMost(url: string, maxBytes: number, name: string, index: number): Promise<Uint8Array> {
  const what = index < 0 ? `Could not load ${name}` : `${name}: buffer ${index}'s file ${url} cannot be read`;
  let response: Response;
  try {
    response = await fetch(url);
  } catch (e) {
    throw new GltfError('UNREADABLE', name, '', `${what} (${(e as Error).message})`);
  }
  if (!response.ok || !response.body) throw new GltfError('UNREADABLE', name, '', `${what} (HTTP ${response.status}${response.statusText ? ` ${response.statusText}` : ''})`);
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

/**
 * GLTFLoader on validated JSON: each buffer's uri replaced by a blob URL of its checked bytes
 * (GLB chunk, data: URI and external files alike), so the loader fetches nothing the checks did
 * not see. `imageUrl` maps the images' remaining URLs.
 */
async function parseValidated(gltf: ValidatedGltf, name: string, path: string, imageUrl: (url: string) => string, done: () => void): Promise<GLTF> {
  const { json, buffers, data } = gltf;
  const zeroWeights = zeroWeightVertices(json, data);
  const blobs: string[] = [];
  buffers.forEach((bytes, i) => {
    if (!bytes) return;
    json.buffers[i].uri = URL.createObjectURL(new Blob([bytes as Uint8Array<ArrayBuffer>]));
    blobs.push(json.buffers[i].uri);
  });
  const manager = new THREE.LoadingManager();
  manager.setURLModifier((url) => (blobs.includes(url) ? url : imageUrl(url)));
  let result: GLTF;
  try {
    result = await new GLTFLoader(manager).parseAsync(JSON.stringify(json), path);
  } catch (e) {
    throw new GltfError('LOAD_FAILED', name, '', `${name} passed the checks but three's GLTFLoader could not read it: ${(e as Error)?.message ?? e}`);
  } finally {
    blobs.forEach((u) => URL.revokeObjectURL(u));
    setTimeout(done, 10000); // images may still be decoding
  }
  const skinned: THREE.SkinnedMesh[] = [];
  result.scene?.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinned.push(o as THREE.SkinnedMesh); });
  restoreZeroWeights(skinned, result.parser.associations, zeroWeights);
  result.scene ??= new THREE.Group();
  return result;
}
