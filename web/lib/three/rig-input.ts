// A SkinnedMesh (as GLTFLoader gives it) read into the core's RigInput: positions, normals,
// indices, up to 8 influences per vertex, the skeleton's parents and mesh-space inverse binds.
import * as THREE from 'three';
import { GcsError } from '../errors.js';
import type { RigInput } from '../index.js';
import { checkMorphTargets } from './morph-data.js';

export type AnyAttribute = THREE.BufferAttribute | THREE.InterleavedBufferAttribute;

/** Geometries already warned about (a rebuild with other options reads the same geometry again). */
const warnedInfluences = new WeakSet<THREE.BufferGeometry>();

/** Whether any vertex of a skin weight attribute has a weight above 0. */
function anyWeight(weights: AnyAttribute): boolean {
  for (let i = 0; i < weights.count; i++)
    for (let k = 0; k < weights.itemSize; k++) if (weights.getComponent(i, k) > 0) return true;
  return false;
}

/**
 * The second set of influences, as GLTFLoader keeps JOINTS_1/WEIGHTS_1 (`joints_1`/`weights_1`;
 * three's own skinning ignores them), or null when absent or all zero (the rig then costs what a
 * 4-influence one does). Where the first four sum to 1 (as GLTFLoader leaves them) and the second
 * set holds weight, the first four are scaled by 1 − Σ(second): a glTF's eight sum to 1. A third set (more than 8 influences) is beyond the core: said once per geometry.
 */
function secondInfluences(geometry: THREE.BufferGeometry): { joints: AnyAttribute; weights: AnyAttribute } | null {
  const extra = geometry.getAttribute('weights_2');
  if (extra && !warnedInfluences.has(geometry) && anyWeight(extra)) {
    warnedInfluences.add(geometry);
    console.warn('gcs-skin: the skinned mesh has more than 8 joint influences per vertex (joints_2/weights_2); only the first 8 are used ' +
      '(gcs-skin/gltf keeps the 8 largest and renormalises)');
  }
  const joints = geometry.getAttribute('joints_1'), weights = geometry.getAttribute('weights_1');
  if (!joints || !weights || joints.itemSize !== 4 || weights.itemSize !== 4 || !anyWeight(weights)) return null;
  return { joints, weights };
}

/** Reads the rig (bind-pose mesh, skin, skeleton) out of a SkinnedMesh as GLTFLoader gives it. */
export function rigInputFromSkinnedMesh(source: THREE.SkinnedMesh): RigInput {
  if (!source || !(source as THREE.SkinnedMesh).isSkinnedMesh || !source.skeleton)
    throw new GcsError('NO_SKIN', 'the object is not a skinned mesh (no skeleton): gcs-skin needs a THREE.SkinnedMesh');
  const geometry = source.geometry;
  const position = geometry.getAttribute('position');
  const skinIndex = geometry.getAttribute('skinIndex');
  const skinWeight = geometry.getAttribute('skinWeight');
  if (!position) throw new GcsError('NO_SKIN', 'the skinned mesh has no position attribute');
  if (!skinIndex || !skinWeight)
    throw new GcsError('NO_SKIN', 'the mesh has no skin weights (skinIndex/skinWeight attributes): it cannot be deformed by bones');
  const second = secondInfluences(geometry);
  const influences = second ? 8 : 4;
  const n = position.count;
  const positions = new Float32Array(n * 3);
  const joints = new Uint32Array(n * influences);
  const weights = new Float32Array(n * influences);
  // Build-time only: getX/getY… handle interleaved and normalised attributes uniformly.
  for (let i = 0; i < n; i++) {
    positions[3 * i] = position.getX(i);
    positions[3 * i + 1] = position.getY(i);
    positions[3 * i + 2] = position.getZ(i);
    for (let k = 0; k < 4; k++) {
      joints[influences * i + k] = skinIndex.getComponent(i, k);
      weights[influences * i + k] = skinWeight.getComponent(i, k);
    }
    if (second) {
      let first = 0, rest = 0;
      for (let k = 0; k < 4; k++) {
        joints[influences * i + 4 + k] = second.joints.getComponent(i, k);
        weights[influences * i + 4 + k] = second.weights.getComponent(i, k);
        first += weights[influences * i + k];
        rest += Math.max(0, weights[influences * i + 4 + k]);
      }
      // GLTFLoader scales the first four to sum 1 (SkinnedMesh.normalizeSkinWeights) and leaves the
      // second set alone; a glTF's eight sum to 1, so the first four had 1 − Σ(second) between them.
      if (Math.abs(first - 1) < 1e-3) for (let k = 0; k < 4; k++) weights[influences * i + k] *= Math.max(0, 1 - rest);
    }
  }
  const normalAttr = geometry.getAttribute('normal');
  let normals: Float32Array | null = null;
  if (normalAttr) {
    normals = new Float32Array(n * 3);
    for (let i = 0; i < n; i++) {
      normals[3 * i] = normalAttr.getX(i);
      normals[3 * i + 1] = normalAttr.getY(i);
      normals[3 * i + 2] = normalAttr.getZ(i);
    }
  }
  let indices: Uint32Array;
  if (geometry.index) {
    indices = Uint32Array.from(geometry.index.array as ArrayLike<number>);
  } else {
    indices = new Uint32Array(n - (n % 3));
    for (let i = 0; i < indices.length; i++) indices[i] = i;
  }
  const bones = source.skeleton.bones;
  const boneIndex = new Map<THREE.Object3D, number>();
  bones.forEach((b, i) => boneIndex.set(b, i));
  const parents = new Int32Array(bones.length);
  bones.forEach((bone, i) => {
    let p: THREE.Object3D | null = bone.parent;
    while (p && !boneIndex.has(p)) p = p.parent;
    parents[i] = p ? boneIndex.get(p)! : -1;
  });
  // Mesh-space inverse binds: three skins bindMatrixInverse · bone · boneInverse · bindMatrix.
  const inverseBindMatrices = new Float32Array(bones.length * 16);
  const m = new THREE.Matrix4();
  source.skeleton.boneInverses.forEach((inv, i) => {
    m.multiplyMatrices(inv, source.bindMatrix);
    inverseBindMatrices.set(m.elements, 16 * i);
  });
  checkMorphTargets(geometry); // one rule for morph deltas, however the mesh is read
  return { positions, normals, indices, joints, weights, influences, parents, inverseBindMatrices };
}
