// The skin matrices a deformer takes, read from a three.js skeleton as it is posed now.
import * as THREE from 'three';

/**
 * Writes the skin matrices S_j = bindMatrixInverse · boneWorld · boneInverse · bindMatrix (mesh
 * space, J × 16 floats, what deformers take) of `source`'s skeleton as it is posed now (world
 * matrices up to date) into `out` at `offset`. No allocation when `tmp` is given.
 */
export function writeSkinMatrices(source: THREE.SkinnedMesh, out: Float32Array, offset = 0, tmp = new THREE.Matrix4()): void {
  const bones = source.skeleton.bones;
  const inverses = source.skeleton.boneInverses;
  for (let j = 0; j < bones.length; j++) {
    tmp.multiplyMatrices(bones[j].matrixWorld, inverses[j]);
    tmp.premultiply(source.bindMatrixInverse);
    tmp.multiply(source.bindMatrix);
    const e = tmp.elements;
    const o = offset + 16 * j;
    for (let k = 0; k < 16; k++) out[o + k] = e[k];
  }
}
