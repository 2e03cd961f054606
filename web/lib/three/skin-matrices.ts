// The skin matrices a deformer takes, read from a three.js skeleton as it is posed now.
import * as THREE from 'three';
import { asGiven, GcsError } from '../errors.js';

/**
 * Writes the skin matrices S_j = bindMatrixInverse · boneWorld · boneInverse · bindMatrix (mesh
 * space, J × 16 floats, what deformers take) of `source`'s skeleton as it is posed now (world
 * matrices up to date) into `out` at `offset`. No allocation when `tmp` is given.
 */
export function writeSkinMatrices(source: THREE.SkinnedMesh, out: Float32Array, offset = 0, tmp = new THREE.Matrix4()): void {
  if (!source?.isSkinnedMesh || !source.skeleton) throw new GcsError('NO_SKIN', 'writeSkinMatrices needs a THREE.SkinnedMesh with a skeleton');
  const bones = source.skeleton.bones;
  if (!(out instanceof Float32Array)) throw new GcsError('INVALID_ARGUMENT', `writeSkinMatrices writes into a Float32Array; got ${asGiven(out)}`);
  if (typeof offset !== 'number' || !Number.isInteger(offset) || offset < 0 || offset + 16 * bones.length > out.length)
    throw new GcsError('OUT_OF_RANGE', `writeSkinMatrices: ${bones.length} joints × 16 floats from offset ${asGiven(offset)} do not fit in ${out.length} floats`);
  if (!(tmp as { isMatrix4?: boolean })?.isMatrix4) throw new GcsError('INVALID_ARGUMENT', 'writeSkinMatrices: tmp must be a THREE.Matrix4 (scratch)');
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
