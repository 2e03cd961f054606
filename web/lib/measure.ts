/**
 * gcs-skin/measure: the one place where the project measures its deformers (docs/method.md §9). Used by
 * `gcs-skin report`, `npm run metrics`, `npm run bench` and the tests.
 *
 * - Timing: `timeFrames` (median / p95 ms of a per-frame step).
 * - Fidelity: `FidelityProbe` compares a deformer's output, frame by frame, with what the rig says:
 *   rigid error (vertices bound ≥ 0.999 to one joint against S_j·x), distance from a scale-aware
 *   dual-quaternion skinning computed here in JavaScript (independently of the core), flipped and
 *   stretched triangles, normals off unit length, non-finite values and the seam gap. Distances are
 *   in % of the character's height.
 *
 * - Joints: `measureJoints` finds the knees and elbows (`findHinges`) and bends each alone
 *   (`JointProbe`): volume change, bulge and collapse, creases, new self-intersections.
 *
 * Plain TypeScript over typed arrays; no three.js.
 *
 * @module gcs-skin/measure
 */
import type { ClassicDeformer, ClassicReason, Deformer, Rig, RigInput } from './index.js';
import { GcsError } from './errors.js';
import { TriangleGrid } from './surface-distance.js';

// Knees and elbows bent one at a time (design of the figures: measure/joints.ts).
export * from './measure/hinges.js';
export * from './measure/joints.js';
export { intersectingPairs } from './measure/self-intersection.js';

// ------------------------------------------------------------------------------------ statistics

/**
 * The median (the 50th percentile, nearest rank); NaN for no values.
 * @param values The numbers (not changed).
 * @returns Their median.
 */
export function median(values: ArrayLike<number>): number {
  return percentile(values, 50);
}

/**
 * The p-th percentile (0..100, nearest rank on the sorted values, NaN sorting last); NaN for no
 * values. By selection, not a sort: the fidelity probe takes it over a million distances.
 */
export function percentile(values: ArrayLike<number>, p: number): number {
  const n = values.length;
  if (!n) return NaN;
  const rank = Math.min(n - 1, Math.max(0, Math.ceil((p / 100) * n) - 1));
  const a = new Float64Array(n);
  let m = 0;
  for (let i = 0; i < n; i++) if (!Number.isNaN(values[i])) a[m++] = values[i];
  return rank < m ? select(a, m, rank) : NaN;
}

/** The k-th smallest of a[0 … n−1] (no NaN), partly reordering a (Hoare's quickselect, median-of-three pivots). */
function select(a: Float64Array, n: number, k: number): number {
  let lo = 0, hi = n - 1;
  while (hi > lo) {
    const mid = (lo + hi) >> 1;
    const x = a[lo], y = a[mid], z = a[hi];
    const pivot = x < y ? (y < z ? y : x < z ? z : x) : (x < z ? x : y < z ? z : y);
    let i = lo, j = hi;
    while (i <= j) {
      while (a[i] < pivot) i++;
      while (a[j] > pivot) j--;
      if (i <= j) { const t = a[i]; a[i] = a[j]; a[j] = t; i++; j--; }
    }
    if (k <= j) hi = j;
    else if (k >= i) lo = i;
    else return a[k];
  }
  return a[k];
}

// ------------------------------------------------------------------------------------ timing

/** How long and how often `timeFrames` and `timeInterleaved` time. */
export interface TimingOptions {
  /** At least this many timed frames (default 200). */
  minSamples?: number;
  /** Keep timing until this much time has passed (default 150 ms)… */
  minMs?: number;
  /** …but stop after this much (default 3000 ms), whatever the sample count. */
  maxMs?: number;
  /** Frames run before timing (default: one pass over the frames). */
  warmup?: number;
  /**
   * timeInterleaved: calls per timed sample, one number for every step or one per step (default
   * 1); a sample's time is divided by it. For a coarse clock (a browser's 0.1 ms steps) a sample
   * must last many clock steps: calls of 0.05 ms are timed 20 at a time, not one by one.
   */
  repeat?: number | readonly number[];
}

/** What a timing gives: milliseconds per call. */
export interface Timing {
  /** Median time of one call, ms. */
  medianMs: number;
  /** 95th percentile of one call's time, ms. */
  p95Ms: number;
  /** Number of timed samples. */
  samples: number;
}

/**
 * Times `step(frameIndex)` once per frame, cycling over `frameCount` frames: the inputs are
 * precomputed by the caller so only the step itself is timed. Returns median and p95 in ms.
 */
export function timeFrames(frameCount: number, step: (frame: number) => void, options: TimingOptions = {}): Timing {
  const minSamples = options.minSamples ?? 200;
  const minMs = options.minMs ?? 150;
  const maxMs = options.maxMs ?? 3000;
  const warmup = options.warmup ?? frameCount;
  for (let i = 0; i < warmup; i++) step(i % frameCount);
  const samples: number[] = [];
  const start = performance.now();
  for (let i = 0; ; i++) {
    const t0 = performance.now();
    step(i % frameCount);
    const t1 = performance.now();
    samples.push(t1 - t0);
    const elapsed = t1 - start;
    if ((samples.length >= minSamples && elapsed >= minMs) || elapsed >= maxMs) break;
  }
  return { medianMs: median(samples), p95Ms: percentile(samples, 95), samples: samples.length };
}

/**
 * Times several steps in turn, one call each per round (or `repeat` calls), so that whatever else
 * the machine does lands on all of them alike: their ratios hold on a shared, noisy host where
 * timings taken one after the other do not. Each step cycles over `frameCount` frames, every step
 * on the same frames in a round. Returns one Timing per step (ms per call).
 */
export function timeInterleaved(frameCount: number, steps: ((frame: number) => void)[], options: TimingOptions = {}): Timing[] {
  const minSamples = options.minSamples ?? 200;
  const minMs = options.minMs ?? 150;
  const maxMs = options.maxMs ?? 3000;
  const warmup = options.warmup ?? frameCount;
  const repeat = steps.map((_, k) => {
    const r = typeof options.repeat === 'number' ? options.repeat : options.repeat?.[k] ?? 1;
    return Number.isInteger(r) && r >= 1 ? r : 1;
  });
  for (let i = 0; i < warmup; i++) for (const step of steps) step(i % frameCount);
  const samples: number[][] = steps.map(() => []);
  const stride = Math.max(...repeat);
  const start = performance.now();
  for (let first = 0; ; first += stride) {
    let t1 = 0;
    steps.forEach((step, k) => {
      const n = repeat[k];
      const t0 = performance.now();
      for (let r = 0; r < n; r++) step((first + r) % frameCount);
      t1 = performance.now();
      samples[k].push((t1 - t0) / n);
    });
    const elapsed = t1 - start;
    if ((samples[0].length >= minSamples && elapsed >= minMs) || elapsed >= maxMs) break;
  }
  return samples.map((s) => ({ medianMs: median(s), p95Ms: percentile(s, 95), samples: s.length }));
}

// ------------------------------------------------------------------------------------ small helpers

/** J identity matrices: the skin matrices of the bind pose. */
export function identitySkin(jointCount: number): Float32Array {
  const skin = new Float32Array(jointCount * 16);
  for (let j = 0; j < jointCount; j++) skin[16 * j] = skin[16 * j + 5] = skin[16 * j + 10] = skin[16 * j + 15] = 1;
  return skin;
}

/** Number of NaN or infinite values in the given arrays. */
export function countNonFinite(...arrays: ArrayLike<number>[]): number {
  let bad = 0;
  for (const a of arrays) for (let i = 0; i < a.length; i++) if (!Number.isFinite(a[i])) bad++;
  return bad;
}

/**
 * Groups of output vertices that coincide at rest (glTF splits vertices along UV and normal
 * seams): pairs [first of group, other member], flattened. `rest` is xyz per output vertex.
 */
export function coincidentPairs(rest: ArrayLike<number>): Uint32Array {
  const weld = weldByPosition(rest);
  const pairs: number[] = [];
  for (let v = 0; v < weld.length; v++) if (weld[v] !== v) pairs.push(weld[v], v);
  return Uint32Array.from(pairs);
}

/** For each vertex, the first vertex at exactly its rest position (itself when none comes before). */
export function weldByPosition(rest: ArrayLike<number>): Uint32Array {
  const n = Math.floor(rest.length / 3);
  const f = new Float32Array(3);
  const u = new Uint32Array(f.buffer);
  const seen = new Map<string, number>();
  const weld = new Uint32Array(n);
  for (let v = 0; v < n; v++) {
    f[0] = rest[3 * v] + 0; f[1] = rest[3 * v + 1] + 0; f[2] = rest[3 * v + 2] + 0; // +0 folds -0
    const key = `${u[0]},${u[1]},${u[2]}`;
    const at = seen.get(key);
    if (at === undefined) seen.set(key, v);
    weld[v] = at ?? v;
  }
  return weld;
}

/** Largest distance between vertices that coincide at rest (0 = no seam opens). NaN counts as infinite. */
export function seamGap(positions: ArrayLike<number>, pairs: Uint32Array): number {
  let gap = 0;
  for (let i = 0; i < pairs.length; i += 2) {
    const a = 3 * pairs[i], b = 3 * pairs[i + 1];
    const dx = positions[a] - positions[b], dy = positions[a + 1] - positions[b + 1], dz = positions[a + 2] - positions[b + 2];
    const d = Math.sqrt(dx * dx + dy * dy + dz * dz);
    if (!(d <= gap)) gap = Number.isNaN(d) ? Infinity : d;
  }
  return gap;
}

/**
 * The border of a triangle mesh (`positions` xyz per vertex) with its coincident vertices welded
 * (coincidentPairs): `open` edges used by one triangle, `overused` edges by more than two (a fold
 * or an overlap glued on). A closed manifold mesh has both 0; a closed input deformed into an
 * output with a gap or a torn seam has open > 0.
 */
export function meshBorder(positions: ArrayLike<number>, indices: ArrayLike<number>): {
  /** Edges used by one triangle. */
  open: number;
  /** Edges used by more than two triangles. */
  overused: number;
} {
  const vertexCount = Math.floor(positions.length / 3);
  const pairs = coincidentPairs(positions);
  const weld = new Uint32Array(vertexCount);
  for (let v = 0; v < vertexCount; v++) weld[v] = v;
  for (let i = 0; i < pairs.length; i += 2) weld[pairs[i + 1]] = pairs[i];
  const uses = new Map<number, number>();
  for (let t = 0; t + 2 < indices.length; t += 3)
    for (let e = 0; e < 3; e++) {
      const a = weld[indices[t + e]], b = weld[indices[t + ((e + 1) % 3)]];
      if (a === b) continue;
      const key = a < b ? a * vertexCount + b : b * vertexCount + a;
      uses.set(key, (uses.get(key) ?? 0) + 1);
    }
  let open = 0, overused = 0;
  for (const n of uses.values()) {
    if (n === 1) open++;
    else if (n > 2) overused++;
  }
  return { open, overused };
}

/**
 * The rest positions of a deformer's output vertices: the rig's bind-pose positions of their
 * source vertices where the deformer has them, else the output of a bind-pose deform.
 */
export function restOfOutput(deformer: Deformer, rigPositions: ArrayLike<number>): Float32Array {
  const source = deformer.sourceVertex;
  const nRig = Math.floor(rigPositions.length / 3);
  deformer.deform(identitySkin(deformer.jointCount));
  const out = Float32Array.from(deformer.positions);
  if (source) {
    for (let o = 0; o < source.length; o++) {
      const v = source[o];
      if (v < nRig) for (let c = 0; c < 3; c++) out[3 * o + c] = rigPositions[3 * v + c];
    }
  }
  return out;
}

/**
 * Rest error: the largest distance, over output vertices that come from a rig vertex, between the
 * bind-pose deform and that vertex's original position. null when no output vertex has a source
 * (a resampled model: see the classic detail loss instead).
 */
export function restError(deformer: Deformer, rigPositions: ArrayLike<number>): number | null {
  const source = deformer.sourceVertex;
  if (!source) return null;
  const nRig = Math.floor(rigPositions.length / 3);
  deformer.deform(identitySkin(deformer.jointCount));
  const p = deformer.positions;
  let err = 0, any = false;
  for (let o = 0; o < source.length; o++) {
    const v = source[o];
    if (v >= nRig) continue;
    any = true;
    const dx = p[3 * o] - rigPositions[3 * v], dy = p[3 * o + 1] - rigPositions[3 * v + 1], dz = p[3 * o + 2] - rigPositions[3 * v + 2];
    const d = Math.sqrt(dx * dx + dy * dy + dz * dz);
    if (!(d <= err)) err = Number.isNaN(d) ? Infinity : d;
  }
  return any ? err : null;
}

// ------------------------------------------------------------------------------------ methods

/**
 * The methods the report, metrics and tests compare: GCS with the weights criterion (the default),
 * plain (its stepped level of detail, smooth: false), the paper's Y criterion and the axial variant (influence width 1), the classic
 * cross-section model, LBS and DQS.
 */
export type MethodName = 'gcs' | 'gcs-plain' | 'gcs-y' | 'gcs-axial' | 'classic' | 'lbs' | 'dqs';
/** Every method the measures know, in the order the tables print them. */
export const METHODS: MethodName[] = ['gcs', 'gcs-plain', 'gcs-y', 'gcs-axial', 'classic', 'lbs', 'dqs'];
/** How the tables name each method. */
export const METHOD_LABELS: Record<MethodName, string> = {
  gcs: 'GCS (weights, default)', 'gcs-plain': 'GCS plain (weights, stepped)', 'gcs-y': 'GCS paper (Y)', 'gcs-axial': 'GCS paper (axial)',
  classic: 'classic', lbs: 'LBS', dqs: 'DQS',
};

/** Settings of `buildMethod`: the GCS section count and the classic model's density. */
export interface BuildSettings {
  /** GCS sections (default 6). */
  sections?: number;
  /** Classic contours per part (default 25). */
  contours?: number;
  /** Classic rays per contour (default 20). */
  rays?: number;
}

/** Builds a deformer by method name. */
export function buildMethod(rig: Rig, method: MethodName, settings: BuildSettings = {}): Deformer {
  switch (method) {
    case 'gcs': return rig.buildGcs({ sections: settings.sections });
    case 'gcs-plain': return rig.buildGcs({ sections: settings.sections, smooth: false });
    case 'gcs-y': return rig.buildGcs({ sections: settings.sections, criterion: 'y' });
    case 'gcs-axial': return rig.buildGcs({ sections: settings.sections, criterion: 'axial' });
    case 'classic': return rig.buildClassic({ contours: settings.contours, rays: settings.rays });
    case 'lbs': return rig.buildLbs();
    case 'dqs': return rig.buildDqs();
  }
}

/** A build failure as data: the GcsError code and message (e.g. a method not in this binary). */
export function errorInfo(e: unknown): {
  /** The GcsError's code, or 'ERROR' for any other exception. */
  code: string;
  /** Its sentence. */
  message: string;
} {
  if (e instanceof GcsError) return { code: e.code, message: e.message };
  return { code: 'ERROR', message: e instanceof Error ? e.message : String(e) };
}

// ------------------------------------------------------------------------------------ reference DQS

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
 */
export function splitSkinMatrix(s: ArrayLike<number>, offset = 0): SplitMatrix {
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
 */
export function referenceDqs(input: RigInput, skin: ArrayLike<number>, out: Float64Array | Float32Array): void {
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

// ------------------------------------------------------------------------------------ fidelity

/** Fidelity of one method over a set of frames (docs/method.md §9). Distances in % of `height`. */
export interface Fidelity {
  /** Frames measured. */
  frames: number;
  /** Largest distance of a vertex bound ≥ 0.999 to one joint from S_j·x; null: no such vertex or no source map. */
  rigidError: number | null;
  /** Vertices bound ≥ 0.999 to one joint (the rigid error's population). */
  rigidVertices: number;
  /** Distance from the reference DQS over every vertex and frame: 95th percentile and max; null without a source map. */
  dqsP95: number | null;
  /** Largest distance from the reference DQS; null without a source map. */
  dqsMax: number | null;
  /** Triangles whose normal turned against their rest normal carried by their dominant joint, summed over frames. */
  flipped: number;
  /**
   * Creases: interior edges (shared by exactly two triangles, vertices welded by rest position)
   * whose dihedral angle changes by more than 20° from the rest pose, summed over frames. Steps
   * between sections show here long before they flip a triangle (docs/method.md §9).
   */
  creases: number;
  /** Triangles with an edge longer than twice its rest length, summed over frames. */
  stretched: number;
  /** Largest |length − 1| of an output normal. */
  normalOffUnit: number;
  /** NaN or infinite output values (positions and normals), summed over frames. */
  nonFinite: number;
  /** Largest gap between output vertices that coincide at rest. */
  seamGap: number;
}

/** Options of `FidelityProbe` and `classicOffSurface`. */
export interface FidelityOptions {
  /**
   * The character's height in the units of the deformers' OUTPUT (posed mesh space). Default: the
   * rig's own bind-pose height, which is right only when the skin matrices carry no scale (a rig
   * whose S_j are ×100 outputs ×100 positions: pass 100 × that height).
   */
  height?: number;
}

/**
 * Measures deformers against a rig over a fixed set of frames (skin matrices J × 16 each). Build it
 * once per mesh and clip set: it computes the reference DQS of every frame once, then
 * `measure(deformer)` for each method.
 */
export class FidelityProbe {
  /** The height distances are divided by (output units). */
  readonly height: number;
  /** Vertices of the rig. */
  readonly vertexCount: number;
  private readonly reference: Float32Array[] = [];
  private readonly rigid: Int32Array; // per rig vertex: its joint when bound ≥ 0.999, else -1
  private readonly rigidCount: number;
  private readonly dominant: Int32Array; // per rig vertex: the joint of largest weight
  private readonly rotations: Float64Array[] = []; // per frame: J × 9 rotations

  /**
   * @param input The rig, as given to `createRig`.
   * @param frames Skin matrices per frame (J × 16 each).
   * @param options The character's height in output units.
   */
  constructor(readonly input: RigInput, readonly frames: readonly Float32Array[], options: FidelityOptions = {}) {
    const n = Math.floor(input.positions.length / 3);
    this.vertexCount = n;
    this.height = options.height ?? boundsHeight(input.positions);
    // Nothing to measure is an error, not NaN figures: no frames, or no height to divide by.
    if (!Array.isArray(frames) || frames.length === 0) throw new GcsError('INVALID_ARGUMENT', 'FidelityProbe needs at least one frame (skin matrices) to measure');
    if (!(this.height > 0 && this.height < Infinity)) throw new GcsError('OUT_OF_RANGE', `FidelityProbe needs a positive, finite height to give distances in % of it; got ${this.height}`);
    this.rigid = new Int32Array(n).fill(-1);
    this.dominant = new Int32Array(n);
    let rigidCount = 0;
    const K = input.influences ?? 4;
    for (let v = 0; v < n; v++) {
      let sum = 0, best = 0;
      for (let i = 0; i < K; i++) sum += Math.max(0, input.weights[K * v + i]);
      for (let i = 1; i < K; i++) if (input.weights[K * v + i] > input.weights[K * v + best]) best = i;
      this.dominant[v] = input.joints[K * v + best];
      let bound = -1;
      for (let i = 0; i < K; i++) {
        const w = input.weights[K * v + i] / sum;
        if (w >= 0.999) bound = input.joints[K * v + i];
      }
      // The same joint listed twice would sum to 1 with neither entry ≥ 0.999: merge.
      if (bound < 0) {
        const j0 = this.dominant[v];
        let w = 0;
        for (let i = 0; i < K; i++) if (input.joints[K * v + i] === j0) w += Math.max(0, input.weights[K * v + i]) / sum;
        if (w >= 0.999) bound = j0;
      }
      this.rigid[v] = bound;
      if (bound >= 0) rigidCount++;
    }
    this.rigidCount = rigidCount;
    const J = input.parents.length;
    for (const skin of frames) {
      const ref = new Float32Array(3 * n); // computed in double, stored in float (memory)
      referenceDqs(input, skin, ref);
      this.reference.push(ref);
      const rot = new Float64Array(9 * J);
      for (let j = 0; j < J; j++) rot.set(splitSkinMatrix(skin, 16 * j).r, 9 * j);
      this.rotations.push(rot);
    }
  }

  /** Deforms `deformer` through every frame and measures it. */
  measure(deformer: Deformer): Fidelity {
    const source = deformer.sourceVertex;
    const nOut = deformer.vertexCount;
    const indices = deformer.indices;
    const P0 = this.input.positions;
    // Rest geometry of the output mesh and the joint that carries each output vertex.
    deformer.deform(identitySkin(deformer.jointCount));
    const rest = Float64Array.from(deformer.positions);
    const jointOf = new Int32Array(nOut).fill(-1);
    if (source) {
      for (let o = 0; o < nOut; o++) {
        const v = source[o];
        if (!(v < this.vertexCount)) throw new GcsError('LENGTH_MISMATCH', `output vertex ${o} comes from rig vertex ${v}, but the probe's rig has ${this.vertexCount}: measure a deformer built from the same rig`);
        jointOf[o] = this.dominant[v];
        for (let c = 0; c < 3; c++) rest[3 * o + c] = P0[3 * v + c];
      }
    } else {
      const parts = (deformer as unknown as { parts?: { joint: number; firstVertex: number; vertexCount: number }[] }).parts;
      if (parts) for (const p of parts) jointOf.fill(p.joint, p.firstVertex, p.firstVertex + p.vertexCount);
    }
    const pairs = coincidentPairs(rest);
    const triCount = Math.floor(indices.length / 3);
    // Per triangle: the joint of largest summed weight over its corners (or of its first corner),
    // its rest normal, its rest edge lengths.
    const triJoint = new Int32Array(triCount).fill(-1);
    const restNormal = new Float64Array(3 * triCount);
    const restEdge = new Float64Array(3 * triCount); // squared
    for (let t = 0; t < triCount; t++) {
      const a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
      triJoint[t] = source ? triangleJoint(this.input, source[a], source[b], source[c]) : jointOf[a];
      faceNormal(rest, a, b, c, restNormal, 3 * t);
      restEdge[3 * t] = dist2(rest, a, b); restEdge[3 * t + 1] = dist2(rest, b, c); restEdge[3 * t + 2] = dist2(rest, c, a);
    }
    const edges = interiorEdges(rest, indices);
    const restCos = dihedralCosines(restNormal, edges);
    const bands = creaseBands(restCos);
    const posedNormal = new Float64Array(3 * triCount);
    const J = this.input.parents.length;
    const scales = new Float64Array(J);
    const scale = 100 / this.height;
    let rigidError = 0, flipped = 0, creases = 0, stretched = 0, normalOff = 0, nonFinite = 0, gap = 0;
    const dqsDistances = source ? new Float32Array(nOut * this.frames.length) : null;
    this.frames.forEach((skin, f) => {
      deformer.deform(skin);
      const pos = deformer.positions, nrm = deformer.normals;
      nonFinite += countNonFinite(pos, nrm);
      gap = Math.max(gap, seamGap(pos, pairs));
      for (let o = 0; o < nOut; o++) {
        const l = len3(nrm[3 * o], nrm[3 * o + 1], nrm[3 * o + 2]);
        const off = Math.abs(l - 1);
        if (!(off <= normalOff)) normalOff = Number.isNaN(off) ? Infinity : off;
      }
      if (source && dqsDistances) {
        const ref = this.reference[f];
        for (let o = 0; o < nOut; o++) {
          const v = source[o];
          const d = len3(pos[3 * o] - ref[3 * v], pos[3 * o + 1] - ref[3 * v + 1], pos[3 * o + 2] - ref[3 * v + 2]);
          dqsDistances[f * nOut + o] = Number.isNaN(d) ? Infinity : d;
          const j = this.rigid[v];
          if (j >= 0) {
            const m = 16 * j;
            const x = P0[3 * v], y = P0[3 * v + 1], z = P0[3 * v + 2];
            const ex = skin[m] * x + skin[m + 4] * y + skin[m + 8] * z + skin[m + 12];
            const ey = skin[m + 1] * x + skin[m + 5] * y + skin[m + 9] * z + skin[m + 13];
            const ez = skin[m + 2] * x + skin[m + 6] * y + skin[m + 10] * z + skin[m + 14];
            const e = len3(pos[3 * o] - ex, pos[3 * o + 1] - ey, pos[3 * o + 2] - ez);
            if (!(e <= rigidError)) rigidError = Number.isNaN(e) ? Infinity : e;
          }
        }
      }
      const rot = this.rotations[f];
      for (let j = 0; j < J; j++) scales[j] = jointScale(skin, j);
      for (let t = 0; t < triCount; t++) {
        const a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
        const j = triJoint[t];
        const rx = restNormal[3 * t], ry = restNormal[3 * t + 1], rz = restNormal[3 * t + 2];
        faceNormal(pos, a, b, c, posedNormal, 3 * t);
        if (j >= 0 && (rx !== 0 || ry !== 0 || rz !== 0)) {
          const r = 9 * j;
          const cx = rot[r] * rx + rot[r + 3] * ry + rot[r + 6] * rz;
          const cy = rot[r + 1] * rx + rot[r + 4] * ry + rot[r + 7] * rz;
          const cz = rot[r + 2] * rx + rot[r + 5] * ry + rot[r + 8] * rz;
          if (cx * posedNormal[3 * t] + cy * posedNormal[3 * t + 1] + cz * posedNormal[3 * t + 2] < 0) flipped++;
        }
        // Stretch is relative to the triangle's own scale change: compare with the rest edge carried
        // by S_j's scale (squared lengths: |e| > 2k|r| ⟺ |e|² > 4k²|r|²).
        const k = j >= 0 ? scales[j] : 1, k4 = 4 * k * k;
        if (dist2(pos, a, b) > k4 * restEdge[3 * t] || dist2(pos, b, c) > k4 * restEdge[3 * t + 1] ||
            dist2(pos, c, a) > k4 * restEdge[3 * t + 2]) stretched++;
      }
      creases += countCreases(posedNormal, edges, restCos, CREASE_DEGREES, bands);
    });
    return {
      frames: this.frames.length,
      rigidError: source && this.rigidCount ? rigidError * scale : null,
      rigidVertices: this.rigidCount,
      dqsP95: dqsDistances ? percentile(dqsDistances, 95) * scale : null,
      dqsMax: dqsDistances ? maxOf(dqsDistances) * scale : null,
      flipped, creases, stretched, normalOffUnit: normalOff, nonFinite, seamGap: gap * scale,
    };
  }
}

// ------------------------------------------------------------------------------------ creases

/** The crease threshold of docs/method.md §9: a dihedral angle change of more than 20°. */
export const CREASE_DEGREES = 20;

/**
 * The interior edges of a triangle mesh: edges shared by exactly two triangles once vertices at
 * one rest position are welded (so UV seams are not borders). `a`/`b` are the two triangles.
 * Edges of three or more triangles (non-manifold) and border edges are left out. `weld`: the
 * weldByPosition of `rest`, when the caller has it.
 */
export function interiorEdges(rest: ArrayLike<number>, indices: ArrayLike<number>,
  weld: ArrayLike<number> = weldByPosition(rest)): {
  /** Per edge, its first triangle. */
  a: Uint32Array;
  /** Per edge, its second triangle. */
  b: Uint32Array;
} {
  const n = Math.floor(rest.length / 3);
  // Edge key → first triangle, or -1 once a third triangle uses it; second triangle beside it.
  const first = new Map<number, number>();
  const second = new Map<number, number>();
  const triCount = Math.floor(indices.length / 3);
  for (let t = 0; t < triCount; t++) {
    for (let e = 0; e < 3; e++) {
      const p = weld[indices[3 * t + e]], q = weld[indices[3 * t + ((e + 1) % 3)]];
      if (p === q) continue;
      const key = Math.min(p, q) * n + Math.max(p, q);
      const t0 = first.get(key);
      if (t0 === undefined) first.set(key, t);
      else if (t0 >= 0 && !second.has(key)) second.set(key, t);
      else { first.set(key, -1); second.delete(key); }
    }
  }
  const a = new Uint32Array(second.size), b = new Uint32Array(second.size);
  let i = 0;
  for (const [key, t1] of second) { a[i] = first.get(key)!; b[i] = t1; i++; }
  return { a, b };
}

/** cos of the angle between the two face normals of each edge; NaN where a face is degenerate. */
export function dihedralCosines(faceNormals: ArrayLike<number>, edges: { a: Uint32Array; b: Uint32Array }): Float64Array {
  const out = new Float64Array(edges.a.length);
  for (let i = 0; i < out.length; i++) out[i] = normalCos(faceNormals, edges.a[i], edges.b[i]);
  return out;
}

/**
 * Interior edges whose dihedral angle differs from its rest value by more than CREASE_DEGREES.
 * Edges degenerate at rest are skipped; a face that collapses in the pose (or a non-finite one)
 * counts as a crease.
 */
export function countCreases(faceNormals: ArrayLike<number>, edges: { a: Uint32Array; b: Uint32Array },
  restCos: Float64Array, degrees = CREASE_DEGREES, bands = creaseBands(restCos, degrees)): number {
  let count = 0;
  for (let i = 0; i < restCos.length; i++) {
    if (Number.isNaN(restCos[i])) continue;
    const c = normalCos(faceNormals, edges.a[i], edges.b[i]);
    if (!(c >= bands.lo[i] && c <= bands.hi[i])) count++;
  }
  return count;
}

/**
 * Per edge, the cosines its posed dihedral may take without a crease: the angle within `degrees`
 * of its rest angle a0 is the cosine within [cos(a0 + limit), cos(a0 − limit)] (cos falls on
 * [0, π]), so a frame compares cosines instead of taking an acos per edge.
 */
export function creaseBands(restCos: Float64Array, degrees = CREASE_DEGREES): {
  /** Per edge, the lowest cosine without a crease. */
  lo: Float64Array;
  /** Per edge, the highest cosine without a crease. */
  hi: Float64Array;
} {
  const limit = degrees * Math.PI / 180;
  const lo = new Float64Array(restCos.length), hi = new Float64Array(restCos.length);
  for (let i = 0; i < restCos.length; i++) {
    const a0 = Math.acos(restCos[i]);
    lo[i] = Math.cos(Math.min(Math.PI, a0 + limit));
    hi[i] = Math.cos(Math.max(0, a0 - limit));
  }
  return { lo, hi };
}

function normalCos(nrm: ArrayLike<number>, s: number, t: number): number {
  const ax = nrm[3 * s], ay = nrm[3 * s + 1], az = nrm[3 * s + 2];
  const bx = nrm[3 * t], by = nrm[3 * t + 1], bz = nrm[3 * t + 2];
  const l = len3(ax, ay, az) * len3(bx, by, bz);
  if (!(l > 0)) return NaN;
  return Math.max(-1, Math.min(1, (ax * bx + ay * by + az * bz) / l));
}

/** Largest extent of the bounding box of xyz positions. */
export function boundsHeight(positions: ArrayLike<number>): number {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i + 2 < positions.length; i += 3)
    for (let c = 0; c < 3; c++) { lo[c] = Math.min(lo[c], positions[i + c]); hi[c] = Math.max(hi[c], positions[i + c]); }
  return Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

function triangleJoint(input: RigInput, a: number, b: number, c: number): number {
  const sum = new Map<number, number>();
  const K = input.influences ?? 4;
  for (const v of [a, b, c])
    for (let i = 0; i < K; i++) {
      const w = input.weights[K * v + i];
      if (w > 0) sum.set(input.joints[K * v + i], (sum.get(input.joints[K * v + i]) ?? 0) + w);
    }
  let best = -1, bw = -Infinity;
  for (const [j, w] of sum) if (w > bw || (w === bw && j < best)) { bw = w; best = j; }
  return best;
}

function faceNormal(p: ArrayLike<number>, a: number, b: number, c: number, out: Float64Array, o: number): void {
  const ux = p[3 * b] - p[3 * a], uy = p[3 * b + 1] - p[3 * a + 1], uz = p[3 * b + 2] - p[3 * a + 2];
  const vx = p[3 * c] - p[3 * a], vy = p[3 * c + 1] - p[3 * a + 1], vz = p[3 * c + 2] - p[3 * a + 2];
  out[o] = uy * vz - uz * vy; out[o + 1] = uz * vx - ux * vz; out[o + 2] = ux * vy - uy * vx;
}

function dist2(p: ArrayLike<number>, a: number, b: number): number {
  const x = p[3 * a] - p[3 * b], y = p[3 * a + 1] - p[3 * b + 1], z = p[3 * a + 2] - p[3 * b + 2];
  return x * x + y * y + z * z;
}

/** Mean column length of joint j's skin matrix: its scale (1 for a rigid motion). */
function jointScale(skin: ArrayLike<number>, j: number): number {
  const m = 16 * j;
  return (len3(skin[m], skin[m + 1], skin[m + 2]) + len3(skin[m + 4], skin[m + 5], skin[m + 6]) +
    len3(skin[m + 8], skin[m + 9], skin[m + 10])) / 3;
}

/**
 * The length of (x, y, z). Not Math.hypot: V8's is several times slower, and the probe takes
 * millions a frame; float32 inputs squared in double neither overflow nor underflow.
 */
function len3(x: number, y: number, z: number): number {
  return Math.sqrt(x * x + y * y + z * z);
}

function maxOf(a: ArrayLike<number>): number {
  let m = 0;
  for (let i = 0; i < a.length; i++) if (!(a[i] <= m)) m = Number.isNaN(a[i]) ? Infinity : a[i];
  return m;
}

/** What the classic model makes of a rig at one setting (the paper's Fig. 5 comparison). */
export interface ClassicFigures {
  /** Contours per part at this setting. */
  contours: number;
  /** Rays per contour at this setting. */
  rays: number;
  /** Vertices of the classic model's output mesh. */
  outputVertices: number;
  /** Parts resampled (chain parts, and trunk parts along the spine) and carried. */
  resampled: number;
  /** Trunk parts resampled along the spine. */
  trunk: number;
  /** Parts carried (their own triangles, skinned by DQS). */
  carried: number;
  /** Detail loss, % of the mesh's height (ClassicDeformer.detailLoss). */
  rms: number;
  /** Largest detail loss, % of the mesh's height. */
  max: number;
  /** Welded border edges of the output at rest (equal to the input's: no gap where tubes meet carried skin). */
  border: number;
  /** Ring vertices (contours × rays) of each resampled part, by joint. */
  points: Map<number, number>;
}

/** Builds the classic model at one setting and measures it (disposes it). */
export function classicFigures(rig: Rig, contours: number, rays: number): ClassicFigures {
  const d = rig.buildClassic({ contours, rays });
  try {
    const parts = d.parts;
    const loss = d.detailLoss;
    return {
      contours, rays, outputVertices: d.vertexCount, resampled: parts.filter((p) => p.reason === 'resampled').length,
      trunk: parts.filter((p) => p.reason === 'trunk').length, carried: parts.filter((p) => !p.resampled).length,
      rms: loss.rms, max: loss.max, border: meshBorder(d.positions, d.indices).open,
      points: new Map(parts.filter((p) => p.resampled).map((p) => [p.joint, p.vertexCount])),
    };
  } finally {
    d.dispose();
  }
}

/**
 * The classic model at the vertex budget of GCS (which keeps every input vertex): the square
 * setting (contours = rays = s) whose output vertex count is closest to the rig's, by bisection
 * over s in [3, 256] (output size grows with s).
 */
export function classicAtBudget(rig: Rig): ClassicFigures {
  let lo = 3, hi = 256;
  const size = (s: number) => {
    const d = rig.buildClassic({ contours: s, rays: s });
    const n = d.vertexCount;
    d.dispose();
    return n;
  };
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (size(mid) <= rig.vertexCount) lo = mid;
    else hi = mid;
  }
  const best = Math.abs(size(lo) - rig.vertexCount) <= Math.abs(size(hi) - rig.vertexCount) ? lo : hi;
  return classicFigures(rig, best, best);
}

/** How far one part of a classic model's output lies from the DQS-posed source surface (% of height). */
export interface OffSurfacePart {
  /** The part's joint. */
  joint: number;
  /** Whether the part is resampled (false: carried). */
  resampled: boolean;
  /** Why it is resampled or carried. */
  reason: ClassicReason;
  /** Output vertices of the part (a shared joint ring counts for both parts). */
  vertices: number;
  /** 99th percentile of its vertices' distances over the frames, % of height. */
  p99: number;
  /** Largest distance, % of height. */
  max: number;
  /** Where the max is: the frame (index into the frames given) and the output vertex. */
  worstFrame: number;
  /** The output vertex of the largest distance. */
  worstVertex: number;
}

/** The classic model against the skin it replaces (docs/method.md §9, "classic off-surface"). */
export interface ClassicOffSurface {
  /** Frames measured. */
  frames: number;
  /** Over every output vertex and frame, % of height. */
  p99: number;
  /** Largest distance over every output vertex and frame, % of height. */
  max: number;
  /** Per part, in the order of `deformer.parts`. */
  parts: OffSurfacePart[];
}

/**
 * Each classic output vertex's distance to the source surface as dual-quaternion skinning poses it
 * (point to nearest triangle of the DQS-posed input mesh), over `frames` (skin matrices J × 16
 * each), in % of `options.height` (default: the rig's bind-pose height): what resampling loses
 * (detail, bulge at the deformer's current setting) and anything that stands off the skin (flaps,
 * cuts, carried parts that do not follow it). Leaves the deformer in the last frame's pose.
 */
export function classicOffSurface(input: RigInput, deformer: ClassicDeformer, frames: readonly Float32Array[],
                                  options: FidelityOptions = {}): ClassicOffSurface {
  const height = options.height ?? boundsHeight(input.positions);
  const nOut = deformer.vertexCount;
  const parts = deformer.parts;
  // Each output vertex's part: ring and carried vertices by the parts' ranges, a cap's vertices
  // by the part of their contour's ring.
  const partOf = new Int32Array(nOut).fill(-1);
  parts.forEach((p, i) => partOf.fill(i, p.firstVertex, p.firstVertex + p.vertexCount));
  const contourOf = deformer.contourOfVertex;
  const partOfContour = new Map<number, number>();
  for (let o = 0; o < nOut; o++) if (contourOf[o] >= 0 && partOf[o] >= 0) partOfContour.set(contourOf[o], partOf[o]);
  for (let o = 0; o < nOut; o++) if (partOf[o] < 0 && contourOf[o] >= 0) partOf[o] = partOfContour.get(contourOf[o]) ?? -1;
  const posed = new Float64Array(input.positions.length);
  const grid = new TriangleGrid();
  const distances = new Float32Array(nOut * frames.length);
  frames.forEach((skin, f) => {
    referenceDqs(input, skin, posed);
    deformer.deform(skin);
    const out = deformer.positions;
    grid.build(posed, input.indices, out);
    for (let o = 0; o < nOut; o++) {
      const d = grid.distance(out[3 * o], out[3 * o + 1], out[3 * o + 2]);
      distances[f * nOut + o] = Number.isNaN(d) ? Infinity : d;
    }
  });
  const scale = 100 / height;
  const byPart = parts.map(() => [] as number[]);
  const worst = parts.map(() => ({ d: -1, frame: 0, vertex: 0 }));
  for (let f = 0; f < frames.length; f++)
    for (let o = 0; o < nOut; o++) {
      const i = partOf[o];
      if (i < 0) continue;
      const d = distances[f * nOut + o];
      byPart[i].push(d);
      if (d > worst[i].d) worst[i] = { d, frame: f, vertex: o };
    }
  return {
    frames: frames.length, p99: percentile(distances, 99) * scale, max: maxOf(distances) * scale,
    parts: parts.map((p, i) => ({
      joint: p.joint, resampled: p.resampled, reason: p.reason, vertices: p.vertexCount,
      p99: byPart[i].length ? percentile(byPart[i], 99) * scale : 0, max: byPart[i].length ? maxOf(byPart[i]) * scale : 0,
      worstFrame: worst[i].frame, worstVertex: worst[i].vertex,
    })),
  };
}

/**
 * A rig of rigid parts made from a skinned one (like Mixamo's X Bot): every vertex bound with
 * weight 1 to its dominant joint (the first of equal largest weights). The classic model's
 * decisions must hold on such a rig too: its skin tears at every joint instead of blending.
 */
export function rigidRebind(input: RigInput): RigInput {
  const n = Math.floor(input.positions.length / 3), k = input.influences ?? 4;
  const joints = new Uint32Array(4 * n), weights = new Float32Array(4 * n);
  for (let v = 0; v < n; v++) {
    let best = 0;
    for (let i = 1; i < k; i++) if (input.weights[k * v + i] > input.weights[k * v + best]) best = i;
    joints[4 * v] = input.joints[k * v + best];
    weights[4 * v] = 1;
  }
  return { ...input, joints, weights, influences: 4 };
}

/** The shape of a classic model's zip-band triangles (the bands joining tubes to carried skin). */
export interface BandQuality {
  /** Band triangles: those with both a ring vertex and a carried vertex. */
  triangles: number;
  /** Smallest interior angle (degrees): the minimum, the 1st percentile and the median over triangles. */
  minAngle: number;
  /** 1st percentile of the smallest angle, degrees. */
  minAngleP1: number;
  /** Median of the smallest angle, degrees. */
  minAngleMedian: number;
  /** Triangles with an angle under 5° and under 10°. */
  under5: number;
  /** Triangles with an angle under 10°. */
  under10: number;
  /** Aspect ratio longest edge × perimeter / (4√3 × area): 1 for an equilateral triangle; max, p99, median. */
  aspectMax: number;
  /** 99th percentile of the aspect ratio. */
  aspectP99: number;
  /** Median aspect ratio. */
  aspectMedian: number;
}

/**
 * Minimum angle and aspect ratio of the zip-band triangles of a classic model in its current pose
 * (call it after a deform with identity matrices for the bind pose): long slivers shade as streaks.
 * A band triangle is any triangle that is neither the tubes' (every corner a ring or cap vertex)
 * nor a carried triangle of `input` (every corner a copied input vertex, and the three of them one
 * of the input's triangles): it joins a ring to carried skin, touches a band's own vertices, or
 * runs along a loop.
 */
export function classicBandQuality(deformer: ClassicDeformer, input: Pick<RigInput, 'indices'>): BandQuality {
  const I = deformer.indices, X = deformer.positions, ring = deformer.contourOfVertex, source = deformer.sourceOfVertex;
  const key = (a: number, b: number, c: number) => [a, b, c].sort((x, y) => x - y).join();
  const carried = new Set<string>();
  for (let t = 0; t + 2 < input.indices.length; t += 3) carried.add(key(input.indices[t], input.indices[t + 1], input.indices[t + 2]));
  const angles: number[] = [], aspects: number[] = [];
  const at = (v: number) => [X[3 * v], X[3 * v + 1], X[3 * v + 2]];
  const dist = (p: number[], q: number[]) => Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
  for (let t = 0; t < I.length; t += 3) {
    const v = [I[t], I[t + 1], I[t + 2]];
    if (v.every((x) => ring[x] >= 0)) continue;
    if (v.every((x) => source[x] >= 0) && carried.has(key(source[v[0]], source[v[1]], source[v[2]]))) continue;
    const [a, b, c] = v.map(at);
    const la = dist(b, c), lb = dist(c, a), lc = dist(a, b);
    const s = (la + lb + lc) / 2, area = Math.sqrt(Math.max(0, s * (s - la) * (s - lb) * (s - lc)));
    const angle = (o: number, p: number, q: number) => Math.acos(Math.min(1, Math.max(-1, (p * p + q * q - o * o) / (2 * p * q)))) * 180 / Math.PI;
    angles.push(Math.min(angle(la, lb, lc), angle(lb, lc, la), angle(lc, la, lb)) || 0);
    aspects.push(area > 0 ? Math.max(la, lb, lc) * 2 * s / (4 * Math.sqrt(3) * area) : Infinity);
  }
  const sorted = (a: number[]) => [...a].sort((x, y) => x - y);
  const A = sorted(angles), R = sorted(aspects), n = A.length;
  const q = (s: number[], f: number) => (n ? s[Math.min(n - 1, Math.floor(f * (n - 1)))] : 0);
  return {
    triangles: n, minAngle: n ? A[0] : 0, minAngleP1: q(A, 0.01), minAngleMedian: q(A, 0.5),
    under5: A.filter((x) => x < 5).length, under10: A.filter((x) => x < 10).length,
    aspectMax: n ? R[n - 1] : 0, aspectP99: q(R, 0.99), aspectMedian: q(R, 0.5),
  };
}
