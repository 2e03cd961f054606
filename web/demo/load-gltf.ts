// Reads a dropped or linked glTF in the page the way `gcs-skin report` reads one in node: the
// bytes go through the shared validation (web/lib/gltf/buffers.ts, validate.ts; Draco
// headers against the accessors: web/lib/gltf/draco-check.ts) before three's GLTFLoader sees
// them, so a broken or hostile file is one sentence with a code (GltfError). Every buffer and
// image is read here, from the dropped files, this site or a data: URI only (gltf-sources.ts),
// each image's declared size checked (image-size.ts), then handed to GLTFLoader as a blob URL of
// its checked bytes; compressed data is decoded by the decoders the file needs
// (gltf-decoders.ts), and what they decode must be what the accessors declare. Vertices whose
// weights are all 0 get their zeros back (three would bind them to the first joint), so the core
// reports them as the CLI does.
import * as THREE from 'three';
import { GLTFLoader, type GLTF } from 'three/addons/loaders/GLTFLoader.js';
import { readValidatedGltf, type ValidatedGltf } from '../lib/gltf/buffers.js';
import { restoreZeroWeights, zeroWeightVertices } from '../lib/gltf/accessors.js';
import { GltfError, loaderFailure, n } from '../lib/gltf/error.js';
import type { GltfJson } from '../lib/gltf/json.js';
import { shownName } from '../lib/gltf/shown-name.js';
import { addDecoders, decoderFailure } from './gltf-decoders.js';
import { droppedReader, fetchAtMost, guardedManager, MAX_FILE_BYTES, siteReader, siteUrl, takeRefused, tooLarge, type ResourceReader } from './gltf-sources.js';
import { IMAGE_FORMATS, IMAGE_LIMITS, imageSize, imageTooLarge, MIME_TYPES, texelsOf } from './image-size.js';
import { state } from './state.js';

export { GltfError } from '../lib/gltf/error.js';

/** The last part of a path or URL, %-decoded where it decodes. */
export function basename(path: string): string {
  const last = path.split(/[\\/]/).pop() ?? path;
  try {
    return decodeURIComponent(last);
  } catch {
    return last;
  }
}

/** Characters of a file's own name the page shows (its label and menu have room for more than a message). */
export const FILE_NAME_LENGTH = 80;

/** How the page names a ?model= value: its file name, or the start of a data: URI; capped and escaped. */
export function modelName(value: string): string {
  return /^data:/i.test(value) ? shownName(value, 40) : shownName(basename(value), FILE_NAME_LENGTH);
}

/** How the page names a dropped file. */
export const fileName = (file: File): string => shownName(file.name, FILE_NAME_LENGTH);

/** A dropped .glb or .gltf with the files dropped beside it (its external buffers and images, found by name). */
export async function loadDroppedGltf(main: File, companions: readonly File[]): Promise<LoadedGltf> {
  const name = fileName(main);
  if (main.size > MAX_FILE_BYTES) throw tooLarge(name, main.size);
  return loadBytes(new Uint8Array(await main.arrayBuffer()), name, droppedReader(companions, name));
}

/** A .glb or .gltf on this site (a path relative to the page) or in a data: URI; `name` names it in messages. */
export async function loadGltfUrl(value: string, name = modelName(value)): Promise<LoadedGltf> {
  const url = siteUrl(value);
  const what = `Could not load ${name}`;
  const bytes = await fetchAtMost(url, MAX_FILE_BYTES, name, what).catch((e: unknown) => {
    throw e instanceof GltfError && /\(HTTP 404\b/.test(e.message) ? notFound(what, url, '') : e;
  });
  // A dev server (Vite's included) answers a missing file with its own HTML page, status 200.
  if (url.protocol !== 'data:' && startsLikeHtml(bytes)) throw notFound(what, url, ': the server sent its HTML page instead');
  if (bytes.byteLength >= MAX_FILE_BYTES) throw tooLarge(name, bytes.byteLength);
  return loadBytes(bytes, name, siteReader(url.protocol === 'data:' ? null : url, name));
}

/** `what`, the path asked for, and "not found (404)". */
function notFound(what: string, url: URL, how: string): GltfError {
  return new GltfError('UNREADABLE', shownName(url.pathname), '', `${what}: ${shownName(decodeURIComponent(url.pathname))} not found (404${how})`);
}

/** Whether `bytes` begin as an HTML page does (after blanks): "<!doctype" or "<html", any case. */
export function startsLikeHtml(bytes: Uint8Array): boolean {
  const head = new TextDecoder().decode(bytes.subarray(0, 64)).trimStart().toLowerCase();
  return head.startsWith('<!doctype html') || head.startsWith('<html');
}

/** What a loaded file gave the page: three's GLTF and notes to show with the character (textures skipped). */
export interface LoadedGltf extends GLTF {
  notes: string[];
}

async function loadBytes(bytes: Uint8Array, name: string, read: ResourceReader): Promise<LoadedGltf> {
  const gltf = await readValidatedGltf(bytes, name, (uri, i, maxBytes) => read(uri, 'buffer', i, maxBytes));
  const blobs: string[] = [];
  try {
    const notes = await checkImages(gltf, name, read, blobs);
    return Object.assign(await parseValidated(gltf, name, blobs), { notes });
  } finally {
    setTimeout(() => blobs.forEach((u) => URL.revokeObjectURL(u)), 10000); // textures may still be decoding
  }
}

/**
 * Reads every image (its uri's file, data: URI or buffer view) and sizes it by its own bytes
 * (image-size.ts; its declared MIME type is not trusted). One the page would not decode (a format
 * it cannot size, a side or texel count past IMAGE_LIMITS, or past the texels left of all the
 * file's images) is skipped before anything decodes it: the textures made of it are removed from
 * the materials, which then draw untextured; each skip is a note. Kept images' uris point at blob
 * URLs of the bytes read, labelled by their sniffed format.
 */
async function checkImages({ json, buffers }: ValidatedGltf, name: string, read: ResourceReader, blobs: string[]): Promise<string[]> {
  const images: GltfJson[] = Array.isArray(json.images) ? json.images : [];
  let budget = MAX_FILE_BYTES, texelsLeft: number = IMAGE_LIMITS.totalTexels;
  const skipped = new Map<number, string>();
  for (const [i, image] of images.entries()) {
    let bytes: Uint8Array | undefined;
    if (typeof image?.uri === 'string') {
      bytes = await read(image.uri, 'image', i, budget + 1);
      if (bytes.byteLength > budget) throw tooLarge(name, MAX_FILE_BYTES, `${name}'s images`);
      budget -= bytes.byteLength;
    } else if (Number.isInteger(image?.bufferView)) {
      const view = json.bufferViews?.[image.bufferView];
      const data = view && buffers[view.buffer];
      if (data) bytes = data.subarray(view.byteOffset ?? 0, (view.byteOffset ?? 0) + view.byteLength);
    }
    if (!bytes) continue;
    const size = imageSize(bytes);
    const why = !size ? `is not an image this page can size (${IMAGE_FORMATS})`
      : imageTooLarge(size) ?? (texelsOf(size) > texelsLeft ? `would take the file's images past the ${IMAGE_LIMITS.totalTexels.toLocaleString('en-US')} texels this page decodes` : null);
    if (why) {
      skipped.set(i, why);
      if (typeof image.uri === 'string') image.uri = PLACEHOLDER_PNG; // never fetched: no texture refers to it any more
      continue;
    }
    texelsLeft -= texelsOf(size!);
    if (typeof image.uri === 'string') {
      image.uri = URL.createObjectURL(new Blob([bytes as Uint8Array<ArrayBuffer>], { type: MIME_TYPES[size!.format] }));
      blobs.push(image.uri);
    } else {
      image.mimeType = MIME_TYPES[size!.format];
    }
  }
  if (!skipped.size) return [];
  dropTexturesOf(json, new Set(skipped.keys()));
  const [first, why] = [...skipped][0];
  const more = skipped.size > 1 ? ` (and ${skipped.size - 1} more image${skipped.size > 2 ? 's' : ''})` : '';
  return [`${name}: image ${first} ${why}, so it was skipped${more}: the character is drawn without those textures.`];
}

/** A 1×1 PNG: what a skipped image's uri becomes (nothing refers to it; GLTFLoader never asks for it). */
const PLACEHOLDER_PNG = 'data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAQAAAC1HAwCAAAAC0lEQVR42mNkYAAAAAYAAjCB0C8AAAAASUVORK5CYII=';

/**
 * Removes from every material each texture reference ({ index, texCoord }, in the core material
 * and in any extension) whose texture's image (its source, or an extension's: KTX2, WebP, AVIF)
 * was skipped: the material keeps its factors and draws untextured.
 */
function dropTexturesOf(json: GltfJson, images: Set<number>): void {
  const textures: GltfJson[] = Array.isArray(json.textures) ? json.textures : [];
  const sourcesOf = (t: GltfJson) => [t?.source, ...Object.values((t?.extensions ?? {}) as Record<string, GltfJson>).map((e) => e?.source)];
  const dropped = new Set(textures.flatMap((t, k) => (sourcesOf(t).some((s) => images.has(s)) ? [k] : [])));
  const strip = (node: unknown, depth: number): void => {
    if (!node || typeof node !== 'object' || depth > 8) return;
    for (const [key, value] of Object.entries(node as GltfJson)) {
      if (/Texture$/.test(key) && value && typeof value === 'object' && dropped.has((value as GltfJson).index)) delete (node as GltfJson)[key];
      else strip(value, depth + 1);
    }
  };
  for (const material of Array.isArray(json.materials) ? json.materials : []) strip(material, 0);
}

/**
 * GLTFLoader on validated JSON: each buffer's uri replaced by a blob URL of its checked bytes
 * (GLB chunk, data: URI and external files alike), images already so, so the loader reads nothing
 * the checks did not see; what it still asks for goes through the guarded manager.
 */
async function parseValidated(gltf: ValidatedGltf, name: string, blobs: string[]): Promise<GLTF> {
  const { json, buffers, data } = gltf;
  const zeroWeights = zeroWeightVertices(json, data);
  buffers.forEach((bytes, i) => {
    if (!bytes) return;
    json.buffers[i].uri = URL.createObjectURL(new Blob([bytes as Uint8Array<ArrayBuffer>]));
    blobs.push(json.buffers[i].uri);
  });
  const used: string[] = Array.isArray(json.extensionsUsed) ? json.extensionsUsed.filter((e: unknown) => typeof e === 'string') : [];
  const loader = new GLTFLoader(guardedManager);
  await addDecoders(loader, used, state.renderer, guardedManager);
  takeRefused();
  let result: GLTF;
  try {
    result = await withinTime(loader.parseAsync(JSON.stringify(json), ''), PARSE_SECONDS, () => new GltfError('LOAD_FAILED', name, '',
      `${name}: three's GLTFLoader and its decoders did not finish within ${PARSE_SECONDS} s`));
  } catch (e) {
    if (e instanceof GltfError) throw e;
    const failed = decoderFailure(used);
    if (failed) throw new GltfError('BAD_DATA', name, '', `${name}: ${failed}`);
    throw new GltfError('LOAD_FAILED', name, '', `${name} passed the checks but three's GLTFLoader could not read it: ${shownName(loaderFailure(e), 120)}`);
  }
  const refused = takeRefused();
  if (refused.length)
    throw new GltfError('OUTSIDE_FOLDER', name, '', `${name} asked the page for '${shownName(refused[0])}', on another site: this page reads only its own files`);
  checkDecodedCounts(json, result, name);
  const skinned: THREE.SkinnedMesh[] = [];
  result.scene?.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinned.push(o as THREE.SkinnedMesh); });
  restoreZeroWeights(skinned, result.parser.associations, zeroWeights);
  result.scene ??= new THREE.Group();
  return result;
}

/** A decoder whose worker dies (a crash, a refused script) never settles its promise: the page gives up after this. */
const PARSE_SECONDS = 60;

function withinTime<T>(work: Promise<T>, seconds: number, late: () => Error): Promise<T> {
  let timer = 0;
  return Promise.race([work, new Promise<never>((_, reject) => { timer = window.setTimeout(() => reject(late()), seconds * 1000); })])
    .finally(() => clearTimeout(timer));
}

/**
 * After Draco's decoder: every Draco primitive has the vertices and indices its accessors declare
 * (BAD_DATA otherwise). The other decoders cannot change a count: meshopt fills buffer views of
 * their declared length, quantized attributes are read as they are.
 */
function checkDecodedCounts(json: GltfJson, result: GLTF, name: string): void {
  result.parser.associations.forEach((ref, object) => {
    const mesh = object as THREE.Mesh;
    if (!mesh.isMesh || ref.meshes === undefined || ref.primitives === undefined) return;
    const p = json.meshes[ref.meshes].primitives[ref.primitives];
    if (!p.extensions?.KHR_draco_mesh_compression) return;
    const prim = `mesh ${ref.meshes} primitive ${ref.primitives}`;
    const declared = json.accessors[p.attributes.POSITION]?.count;
    const position = mesh.geometry.getAttribute('position');
    if (declared !== undefined && position?.count !== declared)
      throw new GltfError('BAD_DATA', name, `/meshes/${ref.meshes}/primitives/${ref.primitives}`,
        `${name}: ${prim} decodes to ${n(position?.count ?? 0)} vertices where its accessors declare ${n(declared)}`);
    const indices = p.indices === undefined ? undefined : json.accessors[p.indices].count;
    if (indices !== undefined && mesh.geometry.index?.count !== indices)
      throw new GltfError('BAD_DATA', name, `/meshes/${ref.meshes}/primitives/${ref.primitives}`,
        `${name}: ${prim} decodes to ${n(mesh.geometry.index?.count ?? 0)} indices where its accessors declare ${n(indices)}`);
  });
}
