// Loads a glTF skinned character in node (no DOM, no image decoder). The file is first checked by
// gcs-skin/gltf: web/lib/gltf/validate.ts (GLB container, JSON structure, limits, buffer ranges, node graph, skins,
// animations): a bad file is a GltfError with a code and one sentence, before any loader sees it.
// External buffers are read only from regular files inside the glTF's folder, up to their
// declared byteLength (readBufferFile). Then @gltf-transform/core
// reads it, with the decoders of the three compression extensions the field uses
// (KHR_mesh_quantization, EXT_meshopt_compression with meshoptimizer's MeshoptDecoder,
// KHR_draco_mesh_compression with draco3dgltf's decoder), drops the textures, turns the geometry
// back into plain float attributes (JOINTS_1/WEIGHTS_1 kept: up to 8 influences per vertex; more
// than 8: the 8 largest, renormalised)
// and writes an uncompressed GLB that three's GLTFLoader parses into the same objects a browser
// gets. Used by `gcs-skin report`, `@gcs-skin/cli/gltf` (loadCharacter), the bench scripts and tests.
import { realpath } from 'node:fs/promises';
import { dirname, isAbsolute, relative, resolve, sep } from 'node:path';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import {
  decodeBufferPath, GltfError, LIMITS, loaderFailure, n, readValidatedGltf, restoreZeroWeights, shownName, sniffGltf,
  type BufferData, type GltfJson,
} from 'gcs-skin/gltf';
import { FileRefused, namesStandardInput, readRegularFile, readStandardInput, systemReason } from './read-file.js';
import { writeSkinMatrices } from 'gcs-skin/three';

export { GltfError, type GltfErrorCode } from 'gcs-skin/gltf';

export interface LoadedModel {
  scene: THREE.Object3D;
  skinnedMeshes: THREE.SkinnedMesh[];
  clips: THREE.AnimationClip[];
  /** What gltf-transform and three's GLTFLoader warned about while loading (not printed). */
  warnings: string[];
}

/** A validated glTF file: its JSON and the bytes of its buffers, keyed as gltf-transform's readJSON expects. */
export interface GltfFile {
  json: GltfJson;
  resources: Record<string, Uint8Array>;
  /** Each buffer's bytes and source, as validated. */
  data: (BufferData | undefined)[];
}

const GLB_BUFFER = '@glb.bin'; // gltf-transform's key for the GLB's BIN chunk

function reason(e: unknown): string {
  return shownName(systemReason(e), 160);
}

/** A byte budget shared by a file and its external buffers (LIMITS.fileBytes in all). */
interface Budget { left: number }

const tooMuch = (file: string, what: string, bytes: number) => new GltfError('TOO_LARGE', file, '',
  `${what} has ${n(bytes)} bytes, past the ${n(LIMITS.fileBytes)} a glTF file and its buffers may hold together`);

/**
 * The bytes of buffer `i`'s external file: only a regular file inside the glTF's folder `baseDir`
 * (after %-decoding and following links), and at most its declared `byteLength` bytes of it (a
 * shorter file is reported TRUNCATED by the validator). URLs, absolute paths, '..' out of the
 * folder, links leading out of it, devices and pipes are refused before anything is opened.
 */
async function readBufferFile(baseDir: string, uri: string, maxBytes: number, file: string, i: number, budget: Budget): Promise<Uint8Array> {
  const where = `/buffers/${i}/uri`;
  const outside = (why: string) =>
    new GltfError('OUTSIDE_FOLDER', file, where, `${file}: buffer ${i}'s uri '${shownName(uri)}' ${why}; buffers are read from the glTF's folder only`);
  const path = decodeBufferPath(uri, file, i);
  if (/^[a-z][a-z0-9+.-]+:/i.test(path)) throw outside('is a URL, not a relative path');
  if (isAbsolute(path) || /^[\\/]/.test(path)) throw outside('is an absolute path');
  const folder = resolve(baseDir);
  const within = (root: string, p: string) => { const r = relative(root, p); return r !== '..' && !r.startsWith(`..${sep}`) && !isAbsolute(r); };
  if (!within(folder, resolve(folder, path))) throw outside("leads out of the glTF's folder");
  const unreadable = (e: unknown) => new GltfError('UNREADABLE', file, where, `${file}: buffer ${i}'s file '${shownName(uri)}' cannot be read (${reason(e)})`);
  let real: string;
  try {
    real = await realpath(resolve(folder, path));
  } catch (e) {
    throw unreadable(e);
  }
  if (!within(await realpath(folder), real)) throw outside("links out of the folder");
  try {
    // No link followed at the last step: the path checked above is the one opened.
    const bytes = await readRegularFile(real, { maxBytes: budget.left, truncateAt: maxBytes, noFollow: true });
    budget.left -= bytes.byteLength;
    return bytes;
  } catch (e) {
    if (!(e instanceof FileRefused)) throw e;
    if (e.kind === 'type') throw outside(`is not a regular file (${e.message.replace(/, not a regular file$/, '')})`);
    if (e.kind === 'size') throw tooMuch(file, `${file}: buffer ${i}'s file '${shownName(uri)}'`, Math.min(maxBytes, e.size));
    throw unreadable(e.message);
  }
}

/**
 * Reads a .glb or .gltf file (a regular file, read as read-file.ts guards it) and its external
 * buffers, and validates them (gcs-skin/gltf: web/lib/gltf/validate.ts). `-` reads standard input, as bytes with
 * no folder. Throws a GltfError (code and one sentence naming the file) for anything wrong.
 */
export async function readGltfFile(file: string): Promise<GltfFile> {
  if (namesStandardInput(file)) {
    const name = 'standard input';
    try {
      return await readGltfBytes(await readStandardInput(LIMITS.fileBytes), name, null);
    } catch (e) {
      if (e instanceof FileRefused) throw tooMuch(name, name, e.size);
      throw e;
    }
  }
  let bytes: Uint8Array;
  try {
    bytes = await readRegularFile(file, { maxBytes: LIMITS.fileBytes, sniff: (head, size) => void sniffGltf(head, size, file) });
  } catch (e) {
    if (!(e instanceof FileRefused)) throw e;
    if (e.kind === 'size') throw tooMuch(file, file, e.size);
    const stdin = e.kind === 'type' && /FIFO|character device/.test(e.message) ? " (give '-' to read standard input)" : '';
    throw new GltfError('UNREADABLE', file, '', `cannot read ${file}: ${e.message}${stdin}`);
  }
  // A file named through /dev or /proc (/dev/stdin redirected from a file, /dev/fd/3) has no folder of its own.
  const folder = /^\/(dev|proc)\//.test(resolve(file)) ? null : dirname(file);
  return readGltfBytes(bytes, file, folder, { left: LIMITS.fileBytes - bytes.byteLength });
}

/**
 * Validates the bytes of a .glb or .gltf (gltf-validate.ts); `name` names it in messages. External
 * buffers are read from `baseDir` (null: bytes with no folder, so a buffer in a file of its own is
 * an UNREADABLE error). Throws a GltfError for anything wrong.
 */
export async function readGltfBytes(bytes: Uint8Array, name: string, baseDir: string | null, budget: Budget = { left: LIMITS.fileBytes }): Promise<GltfFile> {
  const external = baseDir === null ? null : (uri: string, i: number, maxBytes: number) => readBufferFile(baseDir, uri, maxBytes, name, i, budget);
  const { json, buffers, glbBin, data } = await readValidatedGltf(bytes, name, external);
  // gltf-transform reads each buffer's bytes under a key of its own (decoded once, here: data: URIs
  // included; two buffers may name one file with different byteLengths).
  const resources: Record<string, Uint8Array> = {};
  buffers.forEach((b, i) => {
    if (!b) return;
    if (glbBin[i]) { resources[GLB_BUFFER] = b; return; }
    json.buffers[i].uri = `gcs-skin-buffer-${i}.bin`;
    resources[json.buffers[i].uri] = b;
  });
  // Images are not read, nor their data: URIs decoded: textures are dropped (node has no image decoder).
  const images = Array.isArray(json.images) ? json.images : [];
  images.forEach((im, i) => {
    if (typeof im?.uri !== 'string') return;
    im.uri = `gcs-skin-image-${i}`;
    resources[im.uri] = new Uint8Array(0);
  });
  return { json, resources, data };
}

/** The compression extensions read (and removed after decoding); gltf-validate.ts rejects every other required one. */
const COMPRESSION = ['KHR_mesh_quantization', 'EXT_meshopt_compression', 'KHR_draco_mesh_compression'] as const;

// The decoders, loaded on the first file that needs them and kept (draco's takes ~100 ms to instantiate).
let meshoptDecoder: Promise<unknown> | undefined;
let dracoDecoder: Promise<unknown> | undefined;
const DRACO_MODULE = 'draco3dgltf';

/** A NodeIO that reads the compression extensions `used` by a file, with their decoders registered. */
async function decodingIO(used: readonly string[]) {
  const [{ NodeIO }, ext] = await Promise.all([import('@gltf-transform/core'), import('@gltf-transform/extensions')]);
  // Every Khronos extension is known (KHR_materials_unlit and the other material ones included: a
  // file that uses them is not warned about), and meshopt's; the compression ones are decoded.
  const io = new NodeIO().registerExtensions([...ext.KHRONOS_EXTENSIONS, ext.EXTMeshoptCompression]);
  const dependencies: Record<string, unknown> = {};
  if (used.includes('EXT_meshopt_compression')) {
    meshoptDecoder ??= import('meshoptimizer').then(async ({ MeshoptDecoder }) => {
      await MeshoptDecoder.ready;
      return MeshoptDecoder;
    });
    dependencies['meshopt.decoder'] = await meshoptDecoder;
  }
  if (used.includes('KHR_draco_mesh_compression')) {
    // draco3dgltf is CommonJS without types: its default export has createDecoderModule().
    dracoDecoder ??= import(DRACO_MODULE).then((m) => (m.default ?? m).createDecoderModule());
    dependencies['draco3d.decoder'] = await dracoDecoder;
  }
  return io.registerDependencies(dependencies);
}

type Doc = import('@gltf-transform/core').Document;
type Accessor = import('@gltf-transform/core').Accessor;

/** Semantics turned back into FLOAT when KHR_mesh_quantization stored them as integers. */
const FLOAT_SEMANTICS = /^(POSITION|NORMAL|TANGENT)$/;

/**
 * Turns decoded, possibly quantized geometry into plain glTF 2.0: POSITION, NORMAL and TANGENT
 * (and their morph targets) as FLOAT, more than 8 joint influences per vertex reduced to the 8
 * largest (renormalised, with a warning: the core takes 8), every accessor in one buffer, and the
 * compression extensions removed, so the GLB written next is uncompressed.
 */
function plainGeometry(doc: Doc, warnings: string[]): void {
  const root = doc.getRoot();
  const floats = new Map<Accessor, Accessor>();
  const toFloat = (a: Accessor): Accessor => {
    if (a.getComponentType() === 5126) return a;
    let f = floats.get(a);
    if (!f) {
      const size = a.getElementSize(), count = a.getCount();
      const out = new Float32Array(size * count), e: number[] = [];
      for (let i = 0; i < count; i++) out.set(a.getElement(i, e), i * size);
      f = doc.createAccessor(a.getName()).setType(a.getType()).setArray(out).setBuffer(a.getBuffer());
      floats.set(a, f);
    }
    return f;
  };
  root.listMeshes().forEach((mesh, mi) => mesh.listPrimitives().forEach((prim, pi) => {
    for (const semantic of prim.listSemantics())
      if (FLOAT_SEMANTICS.test(semantic)) prim.setAttribute(semantic, toFloat(prim.getAttribute(semantic)!));
    for (const target of prim.listTargets())
      for (const semantic of target.listSemantics())
        if (FLOAT_SEMANTICS.test(semantic)) target.setAttribute(semantic, toFloat(target.getAttribute(semantic)!));
    if (prim.getAttribute('JOINTS_1') && prim.getAttribute('WEIGHTS_1')) {
      const name = `mesh ${mi}${mesh.getName() ? ` '${mesh.getName()}'` : ''} primitive ${pi}`;
      const w = reduceInfluences(doc, prim, name);
      if (w) warnings.push(w);
    }
  }));
  for (const a of floats.keys()) if (!a.listParents().some((p) => p !== root)) a.dispose();
  for (const e of root.listExtensionsUsed()) if ((COMPRESSION as readonly string[]).includes(e.extensionName)) e.dispose();
  // One buffer (a GLB holds one): meshopt's decoded views and a .gltf's several buffers end up in the first.
  const [first, ...rest] = root.listBuffers();
  if (first && rest.length) {
    for (const a of root.listAccessors()) a.setBuffer(first);
    for (const b of rest) b.dispose();
  }
}

/**
 * JOINTS_0..n / WEIGHTS_0..n (n ≥ 1: more than 4 influences) → JOINTS_0..1 / WEIGHTS_0..1 with the
 * 8 largest weights of each vertex, renormalised to sum 1 (three's GLTFLoader then scales the first
 * four to sum 1 on their own, and gcs-skin/three's reader undoes that knowing the eight sum to 1).
 * Returns the warning, or null when nothing was dropped.
 */
function reduceInfluences(doc: Doc, prim: import('@gltf-transform/core').Primitive, name: string): string | null {
  const KEPT = 8;
  const pairs: [Accessor, Accessor][] = [];
  for (let k = 0; ; k++) {
    const j = prim.getAttribute(`JOINTS_${k}`), w = prim.getAttribute(`WEIGHTS_${k}`);
    if (!j || !w) break;
    pairs.push([j, w]);
  }
  const count = prim.getAttribute('POSITION')?.getCount() ?? pairs[0]?.[0].getCount() ?? 0;
  if (pairs.length < 2) return null;
  const influences = 4 * pairs.length;
  const joints = new Uint16Array(KEPT * count), weights = new Float32Array(KEPT * count);
  const jv = new Array<number>(influences), wv = new Array<number>(influences), order = new Array<number>(influences);
  const je: number[] = [], we: number[] = [];
  let cut = 0, maxDropped = 0, maxJoint = 0;
  for (let v = 0; v < count; v++) {
    pairs.forEach(([j, w], k) => {
      j.getElement(v, je);
      w.getElement(v, we);
      for (let c = 0; c < 4; c++) { jv[4 * k + c] = je[c]; wv[4 * k + c] = we[c]; order[4 * k + c] = 4 * k + c; }
    });
    order.sort((a, b) => wv[b] - wv[a] || a - b);
    let kept = 0;
    for (let c = 0; c < KEPT; c++) kept += Math.max(0, wv[order[c]]);
    const dropped = wv[order[KEPT]] > 0 ? wv[order[KEPT]] : 0;
    if (dropped > 0) { cut++; maxDropped = Math.max(maxDropped, dropped); }
    for (let c = 0; c < KEPT; c++) {
      const o = order[c];
      const weight = wv[o] > 0 ? wv[o] : 0;
      joints[KEPT * v + c] = weight > 0 ? jv[o] : 0;
      weights[KEPT * v + c] = kept > 0 ? weight / kept : 0;
      maxJoint = Math.max(maxJoint, joints[KEPT * v + c]);
    }
  }
  const buffer = pairs[0][0].getBuffer();
  for (let set = 0; set < KEPT / 4; set++) {
    const j = new Uint16Array(4 * count), w = new Float32Array(4 * count);
    for (let v = 0; v < count; v++)
      for (let c = 0; c < 4; c++) j[4 * v + c] = joints[KEPT * v + 4 * set + c], w[4 * v + c] = weights[KEPT * v + 4 * set + c];
    prim.setAttribute(`JOINTS_${set}`, doc.createAccessor().setType('VEC4').setArray(maxJoint < 256 ? Uint8Array.from(j) : j).setBuffer(buffer));
    prim.setAttribute(`WEIGHTS_${set}`, doc.createAccessor().setType('VEC4').setArray(w).setBuffer(buffer));
  }
  for (let k = KEPT / 4; k < pairs.length; k++) {
    prim.setAttribute(`JOINTS_${k}`, null);
    prim.setAttribute(`WEIGHTS_${k}`, null);
  }
  for (const [j, w] of pairs) for (const a of [j, w]) if (a.listParents().every((p) => p === doc.getRoot())) a.dispose();
  if (!cut) return null;
  return `${name} has ${influences} joint influences per vertex (JOINTS_0..${pairs.length - 1}, WEIGHTS_0..${pairs.length - 1}); ` +
    `gcs-skin takes ${KEPT}: kept the ${KEPT} largest of each vertex and renormalised them (${n(cut)} of ${n(count)} vertices lost an influence, the largest lost weight ${maxDropped.toPrecision(3)})`;
}

/** The compressed data a decoder reads, as messages name it. */
const COMPRESSED_DATA: [string, string][] = [['KHR_draco_mesh_compression', 'Draco'], ['EXT_meshopt_compression', 'meshopt']];

/** Per Draco primitive ("mesh/primitive"), the vertices and indices its accessors declare. */
function dracoCounts(json: GltfJson): Map<string, { vertices: number; indices?: number }> {
  const out = new Map<string, { vertices: number; indices?: number }>();
  (json.meshes ?? []).forEach((m: GltfJson, mi: number) => m.primitives.forEach((p: GltfJson, pi: number) => {
    if (!p.extensions?.KHR_draco_mesh_compression) return;
    out.set(`${mi}/${pi}`, { vertices: json.accessors[p.attributes.POSITION ?? Object.values(p.attributes)[0]].count, indices: p.indices === undefined ? undefined : json.accessors[p.indices].count });
  }));
  return out;
}

/**
 * After Draco's decoder: each Draco primitive decoded to the vertices and indices its accessors
 * declare (BAD_DATA otherwise; the header was checked against them before decoding, but an
 * edgebreaker stream's vertex count is known only once decoded). meshopt and quantization cannot
 * change a count.
 */
function checkDecodedCounts(doc: Doc, declared: Map<string, { vertices: number; indices?: number }>, file: string): void {
  doc.getRoot().listMeshes().forEach((mesh, mi) => mesh.listPrimitives().forEach((prim, pi) => {
    const want = declared.get(`${mi}/${pi}`);
    if (!want) return;
    const vertices = (prim.getAttribute('POSITION') ?? prim.listAttributes()[0])?.getCount() ?? 0;
    const indices = prim.getIndices()?.getCount();
    const what = vertices !== want.vertices ? `${n(vertices)} vertices where its accessors declare ${n(want.vertices)}`
      : want.indices !== undefined && indices !== want.indices ? `${n(indices ?? 0)} indices where its accessors declare ${n(want.indices)}` : null;
    if (what) throw new GltfError('BAD_DATA', file, `/meshes/${mi}/primitives/${pi}`, `${file}: the Draco data of mesh ${mi} primitive ${pi} decodes to ${what}`);
  }));
}

/**
 * Reads a .glb or .gltf file (a path, or its bytes: `name` then names it in messages) in node into
 * three.js objects: compressed geometry decoded, textures dropped. Throws a GltfError for a bad file.
 */
export async function loadGltfFile(file: string | Uint8Array, name = typeof file !== 'string' ? 'the glTF bytes' : namesStandardInput(file) ? 'standard input' : file): Promise<LoadedModel> {
  const { json, resources } = typeof file === 'string' ? await readGltfFile(file) : await readGltfBytes(file, name, null);
  file = name;
  const warnings: string[] = [];
  const logger = { debug() {}, info() {}, warn: (t: string) => void warnings.push(t), error: (t: string) => void warnings.push(t), verbosity: 2 };
  let bytes: Uint8Array;
  const zeroWeights = new Map<string, number[]>();
  const used: string[] = Array.isArray(json.extensionsUsed) ? json.extensionsUsed : [];
  const declared = dracoCounts(json);
  const io = (await decodingIO(used)).setLogger(logger as never);
  let doc: Doc;
  try {
    doc = await io.readJSON({ json, resources } as Parameters<typeof io.readJSON>[0]);
  } catch (e) {
    // The decoders' own exceptions ("Invalid typed array length", a Draco status) become ours.
    const compressed = COMPRESSED_DATA.filter(([ext]) => used.includes(ext)).map(([, what]) => what);
    if (compressed.length) throw new GltfError('BAD_DATA', file, '', `${file}: its ${compressed.join(' or ')} data does not decode`);
    throw new GltfError('LOAD_FAILED', file, '', `cannot read ${file}: ${shownName(loaderFailure(e), 160)}`);
  }
  checkDecodedCounts(doc, declared, file);
  try {
    for (const texture of doc.getRoot().listTextures()) texture.dispose();
    plainGeometry(doc, warnings);
    // three's GLTFLoader binds a vertex whose skin weights are all 0 to the first joint ("do
    // something reasonable"): note such vertices, to give them back their zeros below, so that
    // createRig reports them (BAD_WEIGHTS) instead of deforming them with a joint they do not have.
    const w = [0, 0, 0, 0];
    doc.getRoot().listMeshes().forEach((mesh, mi) => mesh.listPrimitives().forEach((prim, pi) => {
      const weights = prim.getAttribute('WEIGHTS_0');
      if (!weights) return;
      const second = prim.getAttribute('WEIGHTS_1');
      const zero: number[] = [];
      for (let v = 0, count = weights.getCount(); v < count; v++)
        if (weights.getElement(v, w).every((x) => x === 0) && (!second || second.getElement(v, w).every((x) => x === 0))) zero.push(v);
      if (zero.length) zeroWeights.set(`${mi}/${pi}`, zero);
    }));
    bytes = await io.writeBinary(doc);
  } catch (e) {
    if (e instanceof GltfError) throw e;
    throw new GltfError('LOAD_FAILED', file, '', `cannot read ${file}: ${shownName(loaderFailure(e), 160)}`);
  }
  let model: LoadedModel;
  try {
    model = await parseGlb(bytes, { warnings, zeroWeights });
  } catch (e) {
    throw new GltfError('LOAD_FAILED', file, '', `cannot read ${file}: ${shownName(loaderFailure(e), 160)}`);
  }
  return model;
}

/**
 * Parses binary glTF bytes (images must already be absent in node) with three's GLTFLoader. Its
 * console warnings are collected into `warnings`; `zeroWeights` ("mesh/primitive" → vertices) are
 * vertices whose skin weights are all 0 in the file, given back their zeros after three's repair.
 */
export async function parseGlb(
  bytes: Uint8Array | ArrayBuffer, options: { warnings?: string[]; zeroWeights?: Map<string, number[]> } = {},
): Promise<LoadedModel> {
  const u8 = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
  const buffer = u8.buffer.slice(u8.byteOffset, u8.byteOffset + u8.byteLength) as ArrayBuffer;
  const warnings = options.warnings ?? [];
  const warn = console.warn;
  console.warn = (...a: unknown[]) => void warnings.push(a.map(String).join(' '));
  let gltf;
  try {
    gltf = await new GLTFLoader().parseAsync(buffer, '');
  } finally {
    console.warn = warn;
  }
  // A file with no scene is valid glTF (a library of meshes): GLTFLoader then gives no scene.
  const scene: THREE.Object3D = gltf.scene ?? new THREE.Group();
  const skinnedMeshes: THREE.SkinnedMesh[] = [];
  scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinnedMeshes.push(o as THREE.SkinnedMesh);
  });
  if (options.zeroWeights) restoreZeroWeights(skinnedMeshes, gltf.parser.associations, options.zeroWeights);
  scene.updateMatrixWorld(true);
  return { scene, skinnedMeshes, clips: gltf.animations, warnings };
}

/** Poses `root` at time t with `mixer` (its clip actions already playing) and returns `mesh`'s skin matrices. */
export function skinMatricesAt(mixer: THREE.AnimationMixer, root: THREE.Object3D, mesh: THREE.SkinnedMesh, t: number, out: Float32Array): Float32Array {
  mixer.setTime(t);
  root.updateMatrixWorld(true);
  writeSkinMatrices(mesh, out);
  return out;
}

/** The topmost ancestor of an object. */
export function rootOf(o: THREE.Object3D): THREE.Object3D {
  while (o.parent) o = o.parent;
  return o;
}

/**
 * `frames` skin-matrix sets of `mesh` sampled evenly over `clip` (one J×16 block each), played
 * with a fresh AnimationMixer on the mesh's root; stopping it restores the bones' original pose.
 */
export function sampleClip(mesh: THREE.SkinnedMesh, clip: THREE.AnimationClip, frames: number): Float32Array[] {
  const root = rootOf(mesh);
  const mixer = new THREE.AnimationMixer(root);
  mixer.clipAction(clip).play();
  const J = mesh.skeleton.bones.length;
  const out: Float32Array[] = [];
  const duration = clip.duration > 0 ? clip.duration : 0;
  for (let f = 0; f < frames; f++) out.push(skinMatricesAt(mixer, root, mesh, (duration * f) / frames, new Float32Array(J * 16)));
  mixer.stopAllAction();
  mixer.uncacheRoot(root);
  return out;
}

/** Uniform scale of an object's world matrix: the mean length of its three axis columns. */
export function worldScaleOf(o: THREE.Object3D): number {
  o.updateWorldMatrix(true, false);
  const e = o.matrixWorld.elements;
  return (Math.hypot(e[0], e[1], e[2]) + Math.hypot(e[4], e[5], e[6]) + Math.hypot(e[8], e[9], e[10])) / 3;
}

export interface CharacterHeight {
  /** Largest extent of the world bounding box of every skinned mesh in its bind pose (world units). */
  world: number;
  /** Per mesh (the order given): its world scale, and the height in that mesh's own units (world / scale). */
  scales: number[];
  meshUnits: number[];
}

/**
 * The character's height (docs/method.md §9): the largest extent of the world bounding box of all
 * `meshes` in their bind pose, then that length in each mesh's own units through the mesh's world
 * scale (the deformers work in mesh space and their output is drawn through the mesh's world
 * matrix, so a distance d in a deformer's output is d × scale in the world).
 *
 * The bind pose in world space is `matrixWorld · C · x`, C the one skin matrix (mesh space) that
 * every joint has in the bind pose. Call it on a freshly loaded scene: when the bones' current pose
 * gives every weighted joint the same skin matrix, that is C (the file's rest pose is its bind pose
 * up to C); otherwise the rest pose is not a bind pose and C is taken as the mean scale of those
 * skin matrices. Not simply `matrixWorld · x`: glTF ignores a skinned mesh node's own transform
 * (three cancels it through bindMatrixInverse) and some files' inverse bind matrices leave out the
 * armature's scale (Soldier.glb: positions in cm under a 0.01 armature), which C carries.
 */
export function characterHeight(meshes: readonly THREE.SkinnedMesh[]): CharacterHeight {
  const box = new THREE.Box3();
  const p = new THREE.Vector3();
  const toWorld = new THREE.Matrix4();
  for (const mesh of meshes) rootOf(mesh).updateMatrixWorld(true);
  for (const mesh of meshes) {
    toWorld.copy(mesh.matrixWorld).multiply(bindPoseMatrix(mesh));
    const position = mesh.geometry.getAttribute('position');
    for (let i = 0; i < position.count; i++) box.expandByPoint(p.fromBufferAttribute(position, i).applyMatrix4(toWorld));
  }
  const size = box.isEmpty() ? new THREE.Vector3() : box.getSize(new THREE.Vector3());
  const world = Math.max(size.x, size.y, size.z);
  const scales = meshes.map(worldScaleOf);
  return { world, scales, meshUnits: scales.map((s) => world / s) };
}

/** C of characterHeight: the common skin matrix of the weighted joints, or their mean scale. */
function bindPoseMatrix(mesh: THREE.SkinnedMesh): THREE.Matrix4 {
  const J = mesh.skeleton.bones.length;
  const skin = new Float32Array(16 * J);
  writeSkinMatrices(mesh, skin);
  const used = new Set<number>();
  for (const [j, w] of [['skinIndex', 'skinWeight'], ['joints_1', 'weights_1']]) {
    const joints = mesh.geometry.getAttribute(j), weights = mesh.geometry.getAttribute(w);
    if (joints && weights)
      for (let i = 0; i < joints.count; i++) for (let k = 0; k < 4; k++) if (weights.getComponent(i, k) > 0) used.add(joints.getComponent(i, k));
  }
  const list = [...used].filter((j) => j < J);
  if (!list.length) return new THREE.Matrix4();
  const first = 16 * list[0];
  let size = 0, spread = 0;
  for (let c = 0; c < 16; c++) size = Math.max(size, Math.abs(skin[first + c]));
  for (const j of list) for (let c = 0; c < 16; c++) spread = Math.max(spread, Math.abs(skin[16 * j + c] - skin[first + c]));
  if (spread <= 1e-4 * size) return new THREE.Matrix4().fromArray(skin, first);
  let scale = 0;
  for (const j of list) for (let c = 0; c < 3; c++) scale += Math.hypot(skin[16 * j + 4 * c], skin[16 * j + 4 * c + 1], skin[16 * j + 4 * c + 2]);
  scale /= 3 * list.length;
  return new THREE.Matrix4().makeScale(scale, scale, scale);
}
