// Loads the shared test characters (../shared/models, never copied into the repo) in node:
// gltf-transform strips textures (node has no image decoder), three's GLTFLoader parses the rest.
import { existsSync, readdirSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { NodeIO } from '@gltf-transform/core';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

export const MODELS_DIR = resolve(dirname(fileURLToPath(import.meta.url)), '../../../shared/models');

/** The .glb files of ../shared/models, or a reason why there are none. */
export function sharedModels(): { files: string[]; reason?: string } {
  if (!existsSync(MODELS_DIR)) return { files: [], reason: `skipped: ${MODELS_DIR} is absent (the shared test models are not on this machine)` };
  const files = readdirSync(MODELS_DIR).filter((f) => f.endsWith('.glb')).sort().map((f) => join(MODELS_DIR, f));
  return files.length ? { files } : { files, reason: `skipped: no .glb in ${MODELS_DIR}` };
}

export interface LoadedModel {
  scene: THREE.Object3D;
  skinnedMeshes: THREE.SkinnedMesh[];
  clips: THREE.AnimationClip[];
}

/** Reads a .glb in node into three.js objects (textures dropped). */
export async function loadGlb(file: string): Promise<LoadedModel> {
  const io = new NodeIO();
  const doc = await io.read(file);
  for (const texture of doc.getRoot().listTextures()) texture.dispose();
  const bytes = await io.writeBinary(doc);
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength) as ArrayBuffer;
  const gltf = await new GLTFLoader().parseAsync(buffer, '');
  const skinnedMeshes: THREE.SkinnedMesh[] = [];
  gltf.scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinnedMeshes.push(o as THREE.SkinnedMesh);
  });
  gltf.scene.updateMatrixWorld(true);
  return { scene: gltf.scene, skinnedMeshes, clips: gltf.animations };
}

/**
 * Poses `root` at time t of `clip` and returns the skin matrices of `mesh` in its own mesh space
 * (bindMatrixInverse · boneWorld · boneInverse · bindMatrix), as the deformers expect.
 */
export function skinMatricesAt(mixer: THREE.AnimationMixer, root: THREE.Object3D, mesh: THREE.SkinnedMesh, t: number, out: Float32Array): Float32Array {
  mixer.setTime(t);
  root.updateMatrixWorld(true);
  const m = new THREE.Matrix4();
  mesh.skeleton.bones.forEach((bone, j) => {
    m.multiplyMatrices(bone.matrixWorld, mesh.skeleton.boneInverses[j]);
    m.premultiply(mesh.bindMatrixInverse).multiply(mesh.bindMatrix);
    out.set(m.elements, 16 * j);
  });
  return out;
}
