// Measurements shared by `gcs-skin report`, `npm run bench` and `npm run metrics`: frame timing,
// rest error, seam gap, non-finite counts. Pure functions over the deformers' typed arrays.
import type { Deformer, Rig } from '../index.js';
import { GcsError } from '../errors.js';

export function median(values: ArrayLike<number>): number {
  return percentile(values, 50);
}

/** The p-th percentile (0..100, nearest rank on the sorted values); NaN for no values. */
export function percentile(values: ArrayLike<number>, p: number): number {
  const n = values.length;
  if (!n) return NaN;
  const sorted = Float64Array.from(values as ArrayLike<number>).sort();
  const rank = Math.min(n - 1, Math.max(0, Math.ceil((p / 100) * n) - 1));
  return sorted[rank];
}

export interface TimingOptions {
  /** At least this many timed frames (default 200). */
  minSamples?: number;
  /** Keep timing until this much time has passed (default 150 ms)… */
  minMs?: number;
  /** …but stop after this much (default 3000 ms), whatever the sample count. */
  maxMs?: number;
  /** Frames run before timing (default: one pass over the frames). */
  warmup?: number;
}

export interface Timing {
  medianMs: number;
  p95Ms: number;
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
  const n = Math.floor(rest.length / 3);
  const f = new Float32Array(3);
  const u = new Uint32Array(f.buffer);
  const seen = new Map<string, number>();
  const pairs: number[] = [];
  for (let v = 0; v < n; v++) {
    f[0] = rest[3 * v] + 0; f[1] = rest[3 * v + 1] + 0; f[2] = rest[3 * v + 2] + 0; // +0 folds -0
    const key = `${u[0]},${u[1]},${u[2]}`;
    const first = seen.get(key);
    if (first === undefined) seen.set(key, v);
    else pairs.push(first, v);
  }
  return Uint32Array.from(pairs);
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

export type MethodName = 'gcs' | 'gcs-smooth' | 'classic' | 'lbs' | 'dqs';
export const METHODS: MethodName[] = ['gcs', 'gcs-smooth', 'classic', 'lbs', 'dqs'];

export interface BuildSettings {
  sections?: number;
  contours?: number;
  rays?: number;
}

/** Builds a deformer by method name (GCS smooth = the GCS model with smooth mode on). */
export function buildMethod(rig: Rig, method: MethodName, settings: BuildSettings = {}): Deformer {
  switch (method) {
    case 'gcs': return rig.buildGcs({ sections: settings.sections });
    case 'gcs-smooth': return rig.buildGcs({ sections: settings.sections, smooth: true });
    case 'classic': return rig.buildClassic({ contours: settings.contours, rays: settings.rays });
    case 'lbs': return rig.buildLbs();
    case 'dqs': return rig.buildDqs();
  }
}

/** A build failure as data: the GcsError code and message (e.g. a method not in this binary). */
export function errorInfo(e: unknown): { code: string; message: string } {
  if (e instanceof GcsError) return { code: e.code, message: e.message };
  return { code: 'ERROR', message: e instanceof Error ? e.message : String(e) };
}
