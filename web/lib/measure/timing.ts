// Timing a per-frame step: median and p95 milliseconds over enough samples, alone or interleaved
// with other steps (so that they share the machine's state).
import { median, percentile } from './statistics.js';
import { checkCount, checkFunction, checkList, checkOptionsObject } from '../arguments.js';
import { asGiven, GcsError } from '../errors.js';

/** The most frames a timing cycles over, and the most samples or warm-up calls it is asked for. */
const MAX_FRAME_COUNT = 2 ** 30;

/** TimingOptions as given: a plain object, whole counts, durations that are numbers ≥ 0 (Infinity: no limit). */
function checkTimingOptions(options: unknown, fn: string): void {
  checkOptionsObject(options, 'options', fn);
  const o = options as TimingOptions;
  if (o.minSamples !== undefined) checkCount(o.minSamples, 'options.minSamples', fn, MAX_FRAME_COUNT);
  if (o.warmup !== undefined) checkCount(o.warmup, 'options.warmup', fn, MAX_FRAME_COUNT);
  for (const key of ['minMs', 'maxMs'] as const) {
    const v = o[key];
    if (v !== undefined && !(typeof v === 'number' && v >= 0))
      throw new GcsError('INVALID_ARGUMENT', `${fn}: options.${key} must be a number of milliseconds ≥ 0; got ${asGiven(v)}`);
  }
}

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
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a count that is not a whole number, a callback that is not a function, options that are not a plain object); `OUT_OF_RANGE` for a count out of its bounds.
 */
export function timeFrames(frameCount: number, step: (frame: number) => void, options: TimingOptions = {}): Timing {
  checkCount(frameCount, 'frameCount', 'timeFrames', MAX_FRAME_COUNT, 1);
  checkFunction(step, 'step', 'timeFrames');
  checkTimingOptions(options, 'timeFrames');
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
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a count that is not a whole number, a callback that is not a function, options that are not a plain object); `OUT_OF_RANGE` for a count out of its bounds.
 */
export function timeInterleaved(frameCount: number, steps: ((frame: number) => void)[], options: TimingOptions = {}): Timing[] {
  checkCount(frameCount, 'frameCount', 'timeInterleaved', MAX_FRAME_COUNT, 1);
  checkList(steps, 'steps', 'timeInterleaved');
  for (let k = 0; k < steps.length; k++) checkFunction(steps[k], `steps[${k}]`, 'timeInterleaved');
  checkTimingOptions(options, 'timeInterleaved');
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
