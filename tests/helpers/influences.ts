// Characters with more than 4 influences per vertex, made from a shared one, and the 8-influence
// references they are checked against, in plain JavaScript (float64), written here from the
// definitions and not from the core:
//   spreadInfluences  each influence (j, w) of a vertex that already blends joints spread onto j (55 %),
//                     j's parent (30 %) and j's first child (15 %) — what an artist's smooth weight
//                     painting across a joint does — merged, the 8 largest kept, renormalised: 5 to 8
//                     joints on many vertices; a vertex bound to one joint stays bound (a rigid plate);
//   referenceLbs      x' = Σ w_j S_j x;
//   referenceDqs      Kavan et al.'s dual quaternions of the rigid parts (R_j, t_j) of S_j = [R_j K_j | t_j]
//                     (R_j by polar decomposition), each in the hemisphere of the first influence's,
//                     blended and normalised; the scale parts K_j blended linearly and applied first;
// (influences-glb.ts writes such a character as a .glb.) Browser-safe: the GPU fixtures use it too.
import type { RigInput } from '../../web/lib/index.js';

/** Slots per vertex of a spread rig. */
export const SPREAD_INFLUENCES = 8;

/**
 * Spreads a rig's weights (K per vertex) onto parent and child joints; returns 8 per vertex, each
 * vertex's sorted by weight (largest first) and summing to 1.
 */
export function spreadWeights(joints: ArrayLike<number>, weights: ArrayLike<number>, parents: ArrayLike<number>, vertexCount: number, K = 4): { joints: Uint32Array; weights: Float32Array } {
  const J = parents.length;
  const firstChild = new Int32Array(J).fill(-1);
  for (let j = J - 1; j >= 0; j--) if (parents[j] >= 0) firstChild[parents[j]] = j;
  const outJ = new Uint32Array(SPREAD_INFLUENCES * vertexCount), outW = new Float32Array(SPREAD_INFLUENCES * vertexCount);
  const sum = new Map<number, number>();
  for (let v = 0; v < vertexCount; v++) {
    sum.clear();
    const add = (j: number, w: number) => sum.set(j, (sum.get(j) ?? 0) + w);
    let used = 0;
    for (let k = 0; k < K; k++) if (weights[K * v + k] > 0) used++;
    for (let k = 0; k < K; k++) {
      const j = joints[K * v + k], w = weights[K * v + k];
      if (!(w > 0)) continue;
      if (used === 1) { add(j, w); continue; }
      add(j, 0.55 * w);
      add(parents[j] >= 0 ? parents[j] : j, 0.3 * w);
      add(firstChild[j] >= 0 ? firstChild[j] : j, 0.15 * w);
    }
    const kept = [...sum].sort((a, b) => b[1] - a[1] || a[0] - b[0]).slice(0, SPREAD_INFLUENCES);
    const total = kept.reduce((s, [, w]) => s + w, 0);
    kept.forEach(([j, w], k) => { outJ[SPREAD_INFLUENCES * v + k] = j; outW[SPREAD_INFLUENCES * v + k] = w / total; });
  }
  return { joints: outJ, weights: outW };
}

/** A rig with its weights spread onto 5–8 joints (spreadWeights), `influences: 8`. */
export function spreadInfluences(input: RigInput): RigInput {
  const n = input.positions.length / 3, K = input.influences ?? 4;
  return { ...input, ...spreadWeights(input.joints, input.weights, input.parents, n, K), influences: SPREAD_INFLUENCES };
}

/** The same rig with only its first 4 influences per vertex: what a reader of JOINTS_0/WEIGHTS_0 alone sees. */
export function firstFour(input: RigInput): RigInput {
  const K = input.influences ?? 4, n = input.positions.length / 3;
  const joints = new Uint32Array(4 * n), weights = new Float32Array(4 * n);
  for (let v = 0; v < n; v++) for (let k = 0; k < 4; k++) { joints[4 * v + k] = input.joints[K * v + k]; weights[4 * v + k] = input.weights[K * v + k]; }
  return { ...input, joints, weights, influences: 4 };
}

/** Vertices with more than 4 weights above 0. */
export function overFour(input: RigInput): number {
  const K = input.influences ?? 4, n = input.positions.length / 3;
  let count = 0;
  for (let v = 0; v < n; v++) {
    let used = 0;
    for (let k = 0; k < K; k++) if (input.weights[K * v + k] > 0) used++;
    if (used > 4) count++;
  }
  return count;
}

/** Each vertex's weights over all of its slots, normalised: [joint, weight][] with weight > 0. */
function influencesOf(input: RigInput, v: number): [number, number][] {
  const K = input.influences ?? 4;
  const out: [number, number][] = [];
  let total = 0;
  for (let k = 0; k < K; k++) {
    const w = input.weights[K * v + k];
    if (w > 0) { out.push([input.joints[K * v + k], w]); total += w; }
  }
  for (const x of out) x[1] /= total;
  return out;
}

/** Linear blend skinning, float64: vertexCount × 3 positions. */
export function referenceLbs(input: RigInput, skin: ArrayLike<number>): Float64Array {
  const n = input.positions.length / 3, P = input.positions, out = new Float64Array(3 * n);
  for (let v = 0; v < n; v++) {
    const x = P[3 * v], y = P[3 * v + 1], z = P[3 * v + 2];
    for (const [j, w] of influencesOf(input, v)) {
      const m = 16 * j;
      for (let r = 0; r < 3; r++) out[3 * v + r] += w * (skin[m + r] * x + skin[m + 4 + r] * y + skin[m + 8 + r] * z + skin[m + 12 + r]);
    }
  }
  return out;
}

type M3 = number[]; // column-major 3×3
const col = (m: ArrayLike<number>, o: number): M3 => [m[o], m[o + 1], m[o + 2], m[o + 4], m[o + 5], m[o + 6], m[o + 8], m[o + 9], m[o + 10]];
const det3 = (a: M3) => a[0] * (a[4] * a[8] - a[7] * a[5]) - a[3] * (a[1] * a[8] - a[7] * a[2]) + a[6] * (a[1] * a[5] - a[4] * a[2]);
/** The inverse transpose of a 3×3. */
function invT(a: M3): M3 {
  const d = det3(a);
  return [
    (a[4] * a[8] - a[5] * a[7]) / d, (a[5] * a[6] - a[3] * a[8]) / d, (a[3] * a[7] - a[4] * a[6]) / d,
    (a[2] * a[7] - a[1] * a[8]) / d, (a[0] * a[8] - a[2] * a[6]) / d, (a[1] * a[6] - a[0] * a[7]) / d,
    (a[1] * a[5] - a[2] * a[4]) / d, (a[2] * a[3] - a[0] * a[5]) / d, (a[0] * a[4] - a[1] * a[3]) / d,
  ];
}
/** The rotation of a 3×3 (polar decomposition by Newton's iteration R ← (R + R⁻ᵀ) / 2; a mirror keeps its sign out). */
function polarRotation(m: M3): M3 {
  let r = m.map((x) => x * (det3(m) < 0 ? -1 : 1));
  for (let i = 0; i < 30; i++) { const t = invT(r); r = r.map((x, k) => 0.5 * (x + t[k])); }
  return r;
}
/** Unit quaternion (x, y, z, w) of a rotation matrix (column-major). */
function quatOf(r: M3): number[] {
  const [m00, m10, m20, m01, m11, m21, m02, m12, m22] = r;
  const tr = m00 + m11 + m22;
  let q: number[];
  if (tr > 0) { const s = 2 * Math.sqrt(tr + 1); q = [(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s]; }
  else if (m00 > m11 && m00 > m22) { const s = 2 * Math.sqrt(1 + m00 - m11 - m22); q = [0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s]; }
  else if (m11 > m22) { const s = 2 * Math.sqrt(1 + m11 - m00 - m22); q = [(m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s]; }
  else { const s = 2 * Math.sqrt(1 + m22 - m00 - m11); q = [(m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s]; }
  return q;
}
const qmul = (a: number[], b: number[]) => [
  a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
  a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
  a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
  a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
];
const rotate = (q: number[], v: number[]) => qmul(qmul(q, [v[0], v[1], v[2], 0]), [-q[0], -q[1], -q[2], q[3]]).slice(0, 3);

/** Dual-quaternion skinning with the scale parts blended linearly and applied first, float64. */
export function referenceDqs(input: RigInput, skin: ArrayLike<number>): Float64Array {
  const J = input.parents.length;
  const poses = Array.from({ length: J }, (_, j) => {
    const m = col(skin, 16 * j), r = polarRotation(m);
    const k = [0, 1, 2].flatMap((c) => [0, 1, 2].map((i) => r[3 * i] * m[3 * c] + r[3 * i + 1] * m[3 * c + 1] + r[3 * i + 2] * m[3 * c + 2])); // Rᵀ·M
    const q = quatOf(r), t = [skin[16 * j + 12], skin[16 * j + 13], skin[16 * j + 14]];
    const d = qmul([t[0], t[1], t[2], 0], q).map((x) => 0.5 * x);
    return { q, d, k };
  });
  const n = input.positions.length / 3, P = input.positions, out = new Float64Array(3 * n);
  for (let v = 0; v < n; v++) {
    const inf = influencesOf(input, v);
    const pivot = poses[inf[0][0]].q;
    const br = [0, 0, 0, 0], bd = [0, 0, 0, 0], k = new Array(9).fill(0);
    for (const [j, w] of inf) {
      const p = poses[j];
      const s = p.q[0] * pivot[0] + p.q[1] * pivot[1] + p.q[2] * pivot[2] + p.q[3] * pivot[3] < 0 ? -w : w;
      for (let c = 0; c < 4; c++) { br[c] += s * p.q[c]; bd[c] += s * p.d[c]; }
      for (let c = 0; c < 9; c++) k[c] += w * p.k[c];
    }
    const len = Math.hypot(...br);
    const q = br.map((x) => x / len), d = bd.map((x) => x / len);
    const t = qmul(d, [-q[0], -q[1], -q[2], q[3]]).slice(0, 3).map((x) => 2 * x);
    const x = [P[3 * v], P[3 * v + 1], P[3 * v + 2]];
    const kx = [0, 1, 2].map((r) => k[r] * x[0] + k[3 + r] * x[1] + k[6 + r] * x[2]);
    const y = rotate(q, kx);
    for (let c = 0; c < 3; c++) out[3 * v + c] = y[c] + t[c];
  }
  return out;
}

/** Largest and 95th-percentile distance between `got` (vertex `map[o]` of the reference at output o, or o) and `want`, divided by `height`. */
export function distances(got: ArrayLike<number>, want: ArrayLike<number>, height: number, map?: ArrayLike<number>): { max: number; p95: number } {
  const n = got.length / 3, d = new Float64Array(n);
  for (let o = 0; o < n; o++) {
    const v = map ? map[o] : o;
    d[o] = Math.hypot(got[3 * o] - want[3 * v], got[3 * o + 1] - want[3 * v + 1], got[3 * o + 2] - want[3 * v + 2]) / height;
    if (Number.isNaN(d[o])) d[o] = Infinity;
  }
  d.sort();
  return { max: d[n - 1], p95: d[Math.min(n - 1, Math.ceil(0.95 * n) - 1)] };
}
