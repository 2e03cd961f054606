// A reference dual-quaternion skinning in double precision, computed here in JavaScript
// (independently of the core): what FidelityProbe measures every method against.
import type { RigInput } from '../index.js';
import { checkCount, checkNumbers, checkRigInput } from '../arguments.js';

/**
 * A skin matrix split as S = [R·K | t] in double precision: R a rotation (Gram–Schmidt on the
 * columns, in order of length, a right-handed frame; the identity when every column has collapsed),
 * K = Rᵀ·S₃ₓ₃ the scale, t the translation, and (R, t) as a unit dual quaternion.
 * Written apart from the core's C++ on purpose: the reference must not share its bugs.
 */
export interface SplitMatrix {
  /** R, column-major 3×3. */
  r: Float64Array;
  /** K = Rᵀ·S, column-major 3×3. */
  k: Float64Array;
  /** Dual quaternion (x, y, z, w) real then dual. */
  dq: Float64Array;
}

/**
 * Splits the skin matrix at `offset` into a rotation, a scale and a unit dual quaternion (SplitMatrix).
 * @param s Skin matrices, 16 column-major numbers each.
 * @param offset Where the matrix starts in `s`.
 * @returns Its rotation R, scale K and dual quaternion.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a count that is not a whole number, a callback that is not a function, options that are not a plain object); `OUT_OF_RANGE` for a count out of its bounds.
 */
export function splitSkinMatrix(s: ArrayLike<number>, offset = 0): SplitMatrix {
  checkNumbers(s, 's', 'splitSkinMatrix');
  checkCount(offset, 'offset', 'splitSkinMatrix', 2 ** 32);
  const col = (c: number) => [s[offset + 4 * c], s[offset + 4 * c + 1], s[offset + 4 * c + 2]];
  const cols = [col(0), col(1), col(2)];
  const len = cols.map((v) => Math.hypot(v[0], v[1], v[2]));
  const big = Math.max(...len);
  const r = new Float64Array(9);
  const axes: number[][] = [[], [], []];
  if (!(big > 1e-30)) {
    axes[0] = [1, 0, 0]; axes[1] = [0, 1, 0]; axes[2] = [0, 0, 1];
  } else {
    const order = [0, 1, 2].sort((a, b) => len[b] - len[a]);
    const [a, b, c] = order;
    const ea = cols[a].map((x) => x / len[a]);
    let vb = cols[b].map((x, i) => x - (cols[b][0] * ea[0] + cols[b][1] * ea[1] + cols[b][2] * ea[2]) * ea[i]);
    let lb = Math.hypot(vb[0], vb[1], vb[2]);
    if (!(lb > 1e-6 * big)) {
      const helper = Math.abs(ea[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
      vb = cross(ea, helper);
      lb = Math.hypot(vb[0], vb[1], vb[2]);
    }
    axes[a] = ea;
    axes[b] = vb.map((x) => x / lb);
    axes[c] = cross(axes[(c + 1) % 3], axes[(c + 2) % 3]);
  }
  for (let c = 0; c < 3; c++) for (let i = 0; i < 3; i++) r[3 * c + i] = axes[c][i];
  const k = new Float64Array(9);
  for (let c = 0; c < 3; c++) for (let i = 0; i < 3; i++) k[3 * c + i] = axes[i][0] * cols[c][0] + axes[i][1] * cols[c][1] + axes[i][2] * cols[c][2];
  const q = quatFromRotation(r);
  const t = [s[offset + 12], s[offset + 13], s[offset + 14]];
  // dual = ½ (t, 0) · q
  const d = quatMul([t[0], t[1], t[2], 0], q).map((x) => 0.5 * x);
  return { r, k, dq: Float64Array.from([...q, ...d]) };
}

function cross(a: number[], b: number[]): number[] {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}

function quatMul(a: ArrayLike<number>, b: ArrayLike<number>): number[] {
  const [ax, ay, az, aw] = [a[0], a[1], a[2], a[3]];
  const [bx, by, bz, bw] = [b[0], b[1], b[2], b[3]];
  return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
    aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz];
}

/** Unit quaternion (x, y, z, w) of a column-major rotation (Shepperd's method). */
function quatFromRotation(r: Float64Array): number[] {
  const m00 = r[0], m10 = r[1], m20 = r[2], m01 = r[3], m11 = r[4], m21 = r[5], m02 = r[6], m12 = r[7], m22 = r[8];
  const tr = m00 + m11 + m22;
  let x: number, y: number, z: number, w: number;
  if (tr > 0) {
    const s = 2 * Math.sqrt(tr + 1);
    w = 0.25 * s; x = (m21 - m12) / s; y = (m02 - m20) / s; z = (m10 - m01) / s;
  } else if (m00 > m11 && m00 > m22) {
    const s = 2 * Math.sqrt(1 + m00 - m11 - m22);
    w = (m21 - m12) / s; x = 0.25 * s; y = (m01 + m10) / s; z = (m02 + m20) / s;
  } else if (m11 > m22) {
    const s = 2 * Math.sqrt(1 + m11 - m00 - m22);
    w = (m02 - m20) / s; x = (m01 + m10) / s; y = 0.25 * s; z = (m12 + m21) / s;
  } else {
    const s = 2 * Math.sqrt(1 + m22 - m00 - m11);
    w = (m10 - m01) / s; x = (m02 + m20) / s; y = (m12 + m21) / s; z = 0.25 * s;
  }
  const n = Math.hypot(x, y, z, w);
  return [x / n, y / n, z / n, w / n];
}

/**
 * Scale-aware dual-quaternion skinning of a rig's bind-pose positions (docs/method.md §7): per vertex,
 * the normalised blend of its joints' dual quaternions (in the first influence's hemisphere) moves
 * K·x, K the blend of the joints' scale parts. Writes vertexCount × 3 positions into `out`.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function referenceDqs(input: RigInput, skin: ArrayLike<number>, out: Float64Array | Float32Array): void {
  checkRigInput(input, 'input', 'referenceDqs');
  checkNumbers(skin, 'skin', 'referenceDqs');
  checkNumbers(out, 'out', 'referenceDqs');
  const J = input.parents.length;
  const split: SplitMatrix[] = [];
  for (let j = 0; j < J; j++) split.push(splitSkinMatrix(skin, 16 * j));
  const n = Math.floor(input.positions.length / 3);
  const P = input.positions, W = input.weights, Jt = input.joints, K = input.influences ?? 4;
  const real = [0, 0, 0, 0], dual = [0, 0, 0, 0], k = new Float64Array(9);
  for (let v = 0; v < n; v++) {
    let sum = 0;
    for (let i = 0; i < K; i++) if (W[K * v + i] > 0) sum += W[K * v + i];
    real.fill(0); dual.fill(0); k.fill(0);
    let pivot: Float64Array | null = null;
    for (let i = 0; i < K; i++) {
      const w = W[K * v + i] / sum;
      if (!(w > 0)) continue;
      const sj = split[Jt[K * v + i]];
      if (!pivot) pivot = sj.dq;
      const dot = sj.dq[0] * pivot[0] + sj.dq[1] * pivot[1] + sj.dq[2] * pivot[2] + sj.dq[3] * pivot[3];
      const s = dot < 0 ? -w : w;
      for (let c = 0; c < 4; c++) { real[c] += s * sj.dq[c]; dual[c] += s * sj.dq[4 + c]; }
      for (let c = 0; c < 9; c++) k[c] += w * sj.k[c];
    }
    const len = Math.sqrt(real[0] * real[0] + real[1] * real[1] + real[2] * real[2] + real[3] * real[3]);
    for (let c = 0; c < 4; c++) { real[c] /= len; dual[c] /= len; }
    // t = 2 · dual · conj(real)
    const tq = quatMul(dual, [-real[0], -real[1], -real[2], real[3]]);
    const x = P[3 * v], y = P[3 * v + 1], z = P[3 * v + 2];
    const kx = k[0] * x + k[3] * y + k[6] * z, ky = k[1] * x + k[4] * y + k[7] * z, kz = k[2] * x + k[5] * y + k[8] * z;
    // Rotate (kx, ky, kz) by the unit quaternion: v + 2w(q×v) + 2 q×(q×v).
    const [qx, qy, qz, qw] = real;
    const cx = qy * kz - qz * ky, cy = qz * kx - qx * kz, cz = qx * ky - qy * kx;
    const rx = kx + 2 * (qw * cx + qy * cz - qz * cy);
    const ry = ky + 2 * (qw * cy + qz * cx - qx * cz);
    const rz = kz + 2 * (qw * cz + qx * cy - qy * cx);
    out[3 * v] = rx + 2 * tq[0];
    out[3 * v + 1] = ry + 2 * tq[1];
    out[3 * v + 2] = rz + 2 * tq[2];
  }
}
