// Loads a glTF skinned character in node (no DOM, no image decoder). The file is first checked by
// gltf-validate.ts (GLB container, JSON structure, buffer ranges, node graph, skins): a bad file is
// a GltfError with a code and one sentence, before any loader sees it. Then @gltf-transform/core
// reads it and drops the textures, and three's GLTFLoader parses the rest into the same objects a
// browser gets. Used by `gcs-skin report`, the bench scripts and tests.
import { readFile } from 'node:fs/promises';
import { dirname, resolve } from 'node:path';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { GltfError, n, parseGltfContainer, validateGltfJson, type BufferData, type GltfJson } from './gltf-validate.js';

export { GltfError, type GltfErrorCode } from './gltf-validate.js';

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
}

const GLB_BUFFER = '@glb.bin'; // gltf-transform's key for the GLB's BIN chunk

function reason(e: unknown): string {
  const err = e as NodeJS.ErrnoException;
  if (err?.code === 'ENOENT') return 'no such file';
  if (err?.code === 'EISDIR') return 'it is a directory';
  if (err?.code === 'EACCES') return 'permission denied';
  return String(err?.message ?? e).replace(/\s*\n\s*/g, ' ');
}

/** The bytes of a data: URI (base64 or percent-encoded), or null if it is not one. */
function dataUri(uri: string): Uint8Array | null {
  const m = /^data:[^,]*?(;base64)?,(.*)$/s.exec(uri);
  if (!m) return null;
  return m[1] ? new Uint8Array(Buffer.from(m[2], 'base64')) : new TextEncoder().encode(decodeURIComponent(m[2]));
}

/**
 * Reads a .glb or .gltf file and its external buffers and validates them (gltf-validate.ts).
 * Throws a GltfError (code and one sentence naming the file) for anything wrong.
 */
export async function readGltfFile(file: string): Promise<GltfFile> {
  let bytes: Uint8Array;
  try {
    bytes = await readFile(file);
  } catch (e) {
    throw new GltfError('UNREADABLE', file, '', `cannot read ${file}: ${reason(e)}`);
  }
  const { json, bin, glb } = parseGltfContainer(bytes, file);
  const resources: Record<string, Uint8Array> = {};
  const data: (BufferData | undefined)[] = [];
  const buffers = Array.isArray(json.buffers) ? json.buffers : [];
  for (let i = 0; i < buffers.length; i++) {
    const b = buffers[i];
    if (!b || typeof b !== 'object') continue; // validateGltfJson reports it
    const uri = b.uri;
    if (uri === undefined) {
      if (glb && i === 0 && bin) {
        resources[GLB_BUFFER] = bin;
        data.push({ byteLength: bin.byteLength, source: "the GLB's BIN chunk" });
      } else if (b.extensions) {
        data.push(undefined); // an extension's buffer (e.g. a meshopt fallback): no data to check
      } else {
        throw new GltfError('BAD_REFERENCE', file, `/buffers/${i}`,
          glb && i === 0 ? `${file}: buffer 0 has no uri and the file has no BIN chunk: its ${n(b.byteLength ?? 0)} bytes are nowhere`
            : `${file}: buffer ${i} has no uri${glb ? ' and only buffer 0 can be the GLB\'s BIN chunk' : ''}: its data is nowhere`);
      }
      continue;
    }
    if (typeof uri !== 'string') throw new GltfError('BAD_STRUCTURE', file, `/buffers/${i}/uri`, `${file}: buffer ${i}'s uri is not a string`);
    const inline = dataUri(uri);
    if (inline) {
      data.push({ byteLength: inline.byteLength, source: 'its data: URI' });
      continue;
    }
    let path: string;
    try {
      path = resolve(dirname(file), decodeURIComponent(uri));
    } catch {
      path = resolve(dirname(file), uri);
    }
    try {
      resources[uri] = await readFile(path);
    } catch (e) {
      throw new GltfError('UNREADABLE', file, `/buffers/${i}/uri`, `${file}: buffer ${i}'s file '${uri}' cannot be read (${reason(e)})`);
    }
    data.push({ byteLength: resources[uri].byteLength, source: `its file '${uri}'` });
  }
  validateGltfJson(json, file, data);
  // External images are not read: textures are dropped (node has no image decoder).
  const images = Array.isArray(json.images) ? json.images : [];
  for (const im of images) if (typeof im.uri === 'string' && !im.uri.startsWith('data:')) resources[im.uri] = new Uint8Array(0);
  return { json, resources };
}

/** Reads a .glb or .gltf file in node into three.js objects (textures dropped). Throws a GltfError for a bad file. */
export async function loadGltfFile(file: string): Promise<LoadedModel> {
  const { json, resources } = await readGltfFile(file);
  const { NodeIO } = await import('@gltf-transform/core');
  const warnings: string[] = [];
  const logger = { debug() {}, info() {}, warn: (t: string) => void warnings.push(t), error: (t: string) => void warnings.push(t), verbosity: 2 };
  const io = new NodeIO().setLogger(logger as never);
  let bytes: Uint8Array;
  const zeroWeights = new Map<string, number[]>();
  try {
    const doc = await io.readJSON({ json, resources } as Parameters<typeof io.readJSON>[0]);
    for (const texture of doc.getRoot().listTextures()) texture.dispose();
    // three's GLTFLoader binds a vertex whose skin weights are all 0 to the first joint ("do
    // something reasonable"): note such vertices, to give them back their zeros below, so that
    // createRig reports them (BAD_WEIGHTS) instead of deforming them with a joint they do not have.
    const w = [0, 0, 0, 0];
    doc.getRoot().listMeshes().forEach((mesh, mi) => mesh.listPrimitives().forEach((prim, pi) => {
      const weights = prim.getAttribute('WEIGHTS_0');
      if (!weights) return;
      const zero: number[] = [];
      for (let v = 0, count = weights.getCount(); v < count; v++)
        if (weights.getElement(v, w).every((x) => x === 0)) zero.push(v);
      if (zero.length) zeroWeights.set(`${mi}/${pi}`, zero);
    }));
    bytes = await io.writeBinary(doc);
  } catch (e) {
    if (e instanceof GltfError) throw e;
    throw new GltfError('LOAD_FAILED', file, '', `cannot read ${file}: ${reason(e)}`);
  }
  let model: LoadedModel;
  try {
    model = await parseGlb(bytes, { warnings, zeroWeights });
  } catch (e) {
    throw new GltfError('LOAD_FAILED', file, '', `cannot read ${file}: ${reason(e)}`);
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
  const skinnedMeshes: THREE.SkinnedMesh[] = [];
  gltf.scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinnedMeshes.push(o as THREE.SkinnedMesh);
  });
  if (options.zeroWeights?.size)
    for (const mesh of skinnedMeshes) {
      const at = gltf.parser.associations.get(mesh);
      const zero = at && options.zeroWeights.get(`${at.meshes}/${at.primitives ?? 0}`);
      const weights = mesh.geometry.getAttribute('skinWeight');
      if (zero && weights) for (const v of zero) weights.setXYZW(v, 0, 0, 0, 0);
    }
  gltf.scene.updateMatrixWorld(true);
  return { scene: gltf.scene, skinnedMeshes, clips: gltf.animations, warnings };
}

/**
 * Skin matrices of `mesh` in its own mesh space (bindMatrixInverse · boneWorld · boneInverse ·
 * bindMatrix), as the deformers expect, from the bones' current world matrices.
 */
export function skinMatricesOf(mesh: THREE.SkinnedMesh, out: Float32Array, tmp = new THREE.Matrix4()): Float32Array {
  const bones = mesh.skeleton.bones;
  const inverses = mesh.skeleton.boneInverses;
  for (let j = 0; j < bones.length; j++) {
    tmp.multiplyMatrices(bones[j].matrixWorld, inverses[j]);
    tmp.premultiply(mesh.bindMatrixInverse).multiply(mesh.bindMatrix);
    out.set(tmp.elements, 16 * j);
  }
  return out;
}

/** Poses `root` at time t with `mixer` (its clip actions already playing) and returns `mesh`'s skin matrices. */
export function skinMatricesAt(mixer: THREE.AnimationMixer, root: THREE.Object3D, mesh: THREE.SkinnedMesh, t: number, out: Float32Array): Float32Array {
  mixer.setTime(t);
  root.updateMatrixWorld(true);
  return skinMatricesOf(mesh, out);
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
 * The character's height (design.md §7): the largest extent of the world bounding box of all
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
  const skin = skinMatricesOf(mesh, new Float32Array(16 * J));
  const joints = mesh.geometry.getAttribute('skinIndex'), weights = mesh.geometry.getAttribute('skinWeight');
  const used = new Set<number>();
  if (joints && weights)
    for (let i = 0; i < joints.count; i++) for (let k = 0; k < 4; k++) if (weights.getComponent(i, k) > 0) used.add(joints.getComponent(i, k));
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
