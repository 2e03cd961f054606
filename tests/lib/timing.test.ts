// The timing helpers of gcs-skin/measure: what they call and how often (no wall-clock assertions:
// those flake on shared hosts; the benchmark prints the figures).
import { describe, expect, test, vi } from 'vitest';
import { percentile, timeFrames, timeInterleaved } from '../../web/lib/measure.js';

describe('timeInterleaved', () => {
  test('calls every step once per round, in turn, cycling over the frames', () => {
    const calls: string[] = [];
    const timings = timeInterleaved(3, [(f) => calls.push(`a${f}`), (f) => calls.push(`b${f}`)], { minSamples: 5, minMs: 0, warmup: 2 });
    expect(timings).toHaveLength(2);
    // Warm-up: two rounds, then the timed rounds alternate a, b on the same frame.
    expect(calls.slice(0, 4)).toEqual(['a0', 'b0', 'a1', 'b1']);
    expect(calls.slice(4, 10)).toEqual(['a0', 'b0', 'a1', 'b1', 'a2', 'b2']);
    expect(timings[0].samples).toBe(timings[1].samples);
    expect(timings[0].samples).toBeGreaterThanOrEqual(5);
    expect(calls.length).toBe(4 + 2 * timings[0].samples);
    for (const t of timings) expect(t.p95Ms).toBeGreaterThanOrEqual(t.medianMs);
  });

  test('stops at maxMs whatever the sample count', () => {
    const t = timeInterleaved(1, [() => { const end = performance.now() + 2; while (performance.now() < end); }], { minSamples: 1e9, maxMs: 30, warmup: 0 });
    expect(t[0].samples).toBeGreaterThan(0);
    expect(t[0].samples).toBeLessThan(100);
  });
});

describe('timeFrames', () => {
  test('cycles over the frames after the warm-up', () => {
    const frames: number[] = [];
    const t = timeFrames(4, (f) => frames.push(f), { minSamples: 6, minMs: 0, warmup: 4 });
    expect(frames.slice(0, 10)).toEqual([0, 1, 2, 3, 0, 1, 2, 3, 0, 1]);
    expect(t.samples).toBe(frames.length - 4);
  });
});

describe('timeInterleaved with repeat (a coarse clock)', () => {
  test('each sample times `repeat` calls of its step on the same frames, and reports ms per call', () => {
    const calls: string[] = [];
    const timings = timeInterleaved(5, [(f) => calls.push(`a${f}`), (f) => calls.push(`b${f}`)], { minSamples: 2, minMs: 0, maxMs: 1e9, warmup: 0, repeat: [3, 1] });
    // Round 1: a on frames 0-2, b on frame 0; round 2 starts 3 frames on (the longest repeat).
    expect(calls.slice(0, 8)).toEqual(['a0', 'a1', 'a2', 'b0', 'a3', 'a4', 'a0', 'b3']);
    expect(timings[0].samples).toBe(timings[1].samples);
  });

  test('a sample of n calls of a 1 ms step is 1 ms per call, not n ms (a clock the steps advance)', () => {
    let clock = 0;
    const now = vi.spyOn(performance, 'now').mockImplementation(() => clock);
    try {
      const [a, b] = timeInterleaved(1, [() => { clock += 1; }, () => { clock += 3; }], { minSamples: 3, minMs: 0, warmup: 0, repeat: [4, 2] });
      expect(a.medianMs).toBe(1);
      expect(b.medianMs).toBe(3);
    } finally {
      now.mockRestore();
    }
  });
});

describe('percentile (by selection)', () => {
  test('the nearest rank of the sorted values, NaN sorting last, as a sort gives it', () => {
    let seed = 7;
    const random = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 4294967296);
    for (const n of [1, 2, 3, 10, 101, 5000]) {
      const values = Array.from({ length: n }, () => (random() < 0.05 ? NaN : Math.round(random() * 50) / 10));
      const sorted = Float64Array.from(values).sort();
      for (const p of [0, 1, 25, 50, 95, 99, 100]) {
        const rank = Math.min(n - 1, Math.max(0, Math.ceil((p / 100) * n) - 1));
        expect(percentile(values, p), `n ${n}, p ${p}`).toBe(sorted[rank]);
      }
    }
    expect(percentile([], 50)).toBeNaN();
    expect(percentile(new Float32Array([3, 1, 2]), 50)).toBe(2);
  });
});
