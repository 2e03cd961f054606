// Loads a glTF skinned character in node (no DOM, no image decoder): @gltf-transform/core reads
// .glb or .gltf (with its external buffers) and drops the textures, three's GLTFLoader parses the
// rest into the same objects a browser gets. Used by `gcs-skin report`, the bench scripts and tests.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

export interface LoadedModel {
  scene: THREE.Object3D;
  skinnedMeshes: THREE.SkinnedMesh[];
  clips: THREE.AnimationClip[];
}

/** Reads a .glb or .gltf file in node into three.js objects (textures dropped). Throws on an unreadable file. */
export async function loadGltfFile(file: string): Promise<LoadedModel> {
  const { NodeIO } = await import('@gltf-transform/core');
  const io = new NodeIO();
  const doc = await io.read(file);
  for (const texture of doc.getRoot().listTextures()) texture.dispose();
  const bytes = await io.writeBinary(doc);
  return parseGlb(bytes);
}

/** Parses binary glTF bytes (images must already be absent in node) with three's GLTFLoader. */
export async function parseGlb(bytes: Uint8Array | ArrayBuffer): Promise<LoadedModel> {
  const u8 = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
  const buffer = u8.buffer.slice(u8.byteOffset, u8.byteOffset + u8.byteLength) as ArrayBuffer;
  const gltf = await new GLTFLoader().parseAsync(buffer, '');
  const skinnedMeshes: THREE.SkinnedMesh[] = [];
  gltf.scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinnedMeshes.push(o as THREE.SkinnedMesh);
  });
  gltf.scene.updateMatrixWorld(true);
  return { scene: gltf.scene, skinnedMeshes, clips: gltf.animations };
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
