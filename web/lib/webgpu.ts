/**
 * gcs-skin/webgpu: GcsCharacter and GcsCrowd for three.js's WebGPURenderer (`three/webgpu`; real
 * WebGPU, or its WebGL2 fallback). Same constructor options, properties and behaviour as
 * gcs-skin/three and gcs-skin/crowd; with `backend: 'gpu'` (and always for a crowd) GCS, LBS or
 * DQS runs on the GPU through TSL: each source material becomes its node equivalent (maps, colours
 * and flags kept) with GCS as its `positionNode`, which also turns normals and tangents; shadows
 * use the same node (`castShadowPositionNode`); morph targets apply first, as three.js orders them.
 * On the joint-level path a node pass computes every node once per frame (node-pass-tsl.ts) and
 * each vertex reads its 1–3 nodes and blends them.
 *
 *   import * as THREE from 'three/webgpu';
 *   import { GcsCharacter } from 'gcs-skin/webgpu';
 *   const renderer = new THREE.WebGPURenderer();
 *   await renderer.init();
 *   const character = new GcsCharacter(gcs, gltf.scene, { backend: 'gpu' });
 *   // each frame: mixer.update(dt); character.update(); renderer.render(scene, camera);
 *
 * Drawn by a WebGLRenderer without a nodes handler, a GPU-backend skin moves to the CPU backend
 * (`backendNote` says why, one console warning) and a crowd's update() throws GcsError naming the
 * fix; gcs-skin/three's GPU backend does the same when a WebGPURenderer draws it.
 *
 * @module gcs-skin/webgpu
 */
import type * as THREE from 'three';
import {
  GcsCharacter as WebGLCharacter, SkinDeformer as WebGLSkinDeformer,
  type GcsCharacterOptions, type SkinDeformerOptions,
} from './three.js';
import { GcsCrowd as WebGLCrowd, type GcsCrowdOptions } from './crowd.js';
import type { GcsSkin } from './index.js';
import { tslKit } from './gpu/node-materials.js';

export { bakeClip, type BakedClip, type GcsCrowdOptions } from './crowd.js';
export { rigInputFromSkinnedMesh, writeSkinMatrices, type Backend, type GcsCharacterOptions, type RebuildOptions, type SkinDeformerOptions } from './three.js';
export type { GpuPath } from './gpu/layout.js';
export { nodeMaterialSupport, toNodeMaterial } from './gpu/node-materials.js';
export { gcsPositionNode } from './gpu/tsl.js';

/** gcs-skin/three's SkinDeformer whose GPU backend runs in node materials (TSL). */
export class SkinDeformer extends WebGLSkinDeformer {
  constructor(gcs: GcsSkin, source: THREE.SkinnedMesh, options: SkinDeformerOptions = {}) {
    super(gcs, source, { ...options, gpuKit: tslKit });
  }
}

/** gcs-skin/three's GcsCharacter whose GPU backend runs in node materials (TSL). */
export class GcsCharacter extends WebGLCharacter {
  constructor(gcs: GcsSkin, root: THREE.Object3D, options: GcsCharacterOptions = {}) {
    super(gcs, root, { ...options, gpuKit: tslKit });
  }
}

/** gcs-skin/crowd's GcsCrowd drawn with node materials (TSL): one instanced draw call per skin. */
export class GcsCrowd extends WebGLCrowd {
  constructor(gcs: GcsSkin, source: THREE.SkinnedMesh, count: number, options: GcsCrowdOptions = {}) {
    super(gcs, source, count, { ...options, gpuKit: tslKit });
  }
}
