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
  for (let j = 0; j < bones.length; j++) writeSkinMatrix(source, j, out, offset + 16 * j, tmp);
}

/** Joint j's skin matrix by Matrix4's full products, into `out` at `o` (checked by the callers). */
function writeSkinMatrix(source: THREE.SkinnedMesh, j: number, out: Float32Array, o: number, tmp: THREE.Matrix4): void {
  tmp.multiplyMatrices(source.skeleton.bones[j].matrixWorld, source.skeleton.boneInverses[j]);
  tmp.premultiply(source.bindMatrixInverse);
  tmp.multiply(source.bindMatrix);
  const e = tmp.elements;
  for (let k = 0; k < 16; k++) out[o + k] = e[k];
}

/** Whether a column-major 4×4 matrix is affine (last row 0, 0, 0, 1). */
function affine(e: ArrayLike<number>, o = 0): boolean {
  return e[o + 3] === 0 && e[o + 7] === 0 && e[o + 11] === 0 && e[o + 15] === 1;
}

/**
 * The constant right-hand factor of each skin matrix, T_j = boneInverse_j · bindMatrix, as 16
 * floats per joint (float64): a skeleton posed every frame then costs one affine product per
 * joint less. Null when a factor is not affine (writeSkinMatrices then does the whole product).
 */
export function skinTails(source: THREE.SkinnedMesh): Float64Array | null {
  const inverses = source.skeleton.boneInverses;
  const tails = new Float64Array(16 * inverses.length);
  const m = new THREE.Matrix4();
  for (let j = 0; j < inverses.length; j++) {
    m.multiplyMatrices(inverses[j], source.bindMatrix);
    if (!affine(m.elements)) return null;
    tails.set(m.elements, 16 * j);
  }
  return tails;
}

/**
 * writeSkinMatrices with the tails of skinTails(source) (made from the same boneInverses and
 * bindMatrix): S_j = bindMatrixInverse · boneWorld_j · T_j as two affine products written out on
 * the arrays. A bone or bind inverse that is not affine takes Matrix4's full product.
 */
export function writeSkinMatricesWithTails(source: THREE.SkinnedMesh, tails: Float64Array, out: Float32Array, tmp: THREE.Matrix4): void {
  const bones = source.skeleton.bones, L = source.bindMatrixInverse.elements;
  if (!affine(L)) {
    writeSkinMatrices(source, out, 0, tmp);
    return;
  }
  const l0 = L[0], l1 = L[1], l2 = L[2], l4 = L[4], l5 = L[5], l6 = L[6], l8 = L[8], l9 = L[9], l10 = L[10], l12 = L[12], l13 = L[13], l14 = L[14];
  for (let j = 0; j < bones.length; j++) {
    const w = bones[j].matrixWorld.elements, o = 16 * j;
    if (!affine(w)) {
      writeSkinMatrix(source, j, out, o, tmp);
      continue;
    }
    // A = L · W (3 × 4)
    const a0 = l0 * w[0] + l4 * w[1] + l8 * w[2], a1 = l1 * w[0] + l5 * w[1] + l9 * w[2], a2 = l2 * w[0] + l6 * w[1] + l10 * w[2];
    const a4 = l0 * w[4] + l4 * w[5] + l8 * w[6], a5 = l1 * w[4] + l5 * w[5] + l9 * w[6], a6 = l2 * w[4] + l6 * w[5] + l10 * w[6];
    const a8 = l0 * w[8] + l4 * w[9] + l8 * w[10], a9 = l1 * w[8] + l5 * w[9] + l9 * w[10], a10 = l2 * w[8] + l6 * w[9] + l10 * w[10];
    const a12 = l0 * w[12] + l4 * w[13] + l8 * w[14] + l12, a13 = l1 * w[12] + l5 * w[13] + l9 * w[14] + l13, a14 = l2 * w[12] + l6 * w[13] + l10 * w[14] + l14;
    // S = A · T_j
    const t0 = tails[o], t1 = tails[o + 1], t2 = tails[o + 2], t4 = tails[o + 4], t5 = tails[o + 5], t6 = tails[o + 6];
    const t8 = tails[o + 8], t9 = tails[o + 9], t10 = tails[o + 10], t12 = tails[o + 12], t13 = tails[o + 13], t14 = tails[o + 14];
    out[o] = a0 * t0 + a4 * t1 + a8 * t2; out[o + 1] = a1 * t0 + a5 * t1 + a9 * t2; out[o + 2] = a2 * t0 + a6 * t1 + a10 * t2; out[o + 3] = 0;
    out[o + 4] = a0 * t4 + a4 * t5 + a8 * t6; out[o + 5] = a1 * t4 + a5 * t5 + a9 * t6; out[o + 6] = a2 * t4 + a6 * t5 + a10 * t6; out[o + 7] = 0;
    out[o + 8] = a0 * t8 + a4 * t9 + a8 * t10; out[o + 9] = a1 * t8 + a5 * t9 + a9 * t10; out[o + 10] = a2 * t8 + a6 * t9 + a10 * t10; out[o + 11] = 0;
    out[o + 12] = a0 * t12 + a4 * t13 + a8 * t14 + a12; out[o + 13] = a1 * t12 + a5 * t13 + a9 * t14 + a13; out[o + 14] = a2 * t12 + a6 * t13 + a10 * t14 + a14; out[o + 15] = 1;
  }
}
