// What the GCS settings cost on this machine: the deform time of the current model beside the
// plain (stepped) one at the same section count, measured in the page (not a constant that could
// go stale), so the readout can say what smooth blending and the section count cost.
import type { GcsOptions } from '../lib/index.js';
import { identitySkin } from '../lib/measure.js';
import type { SkinDeformer } from '../lib/three.js';

export interface SettingCost {
  /** ms per frame of the current GCS model, summed over the skins. */
  current: number;
  /** ms per frame of the plain (smooth: false) model at the same sections; NaN under the paper's criteria. */
  plain: number;
}

/** ms per call of each function: rounds of each taken in turn (so both see the same noise: the
 *  page renders on the same cores), each round long enough for the browser's coarse clock; medians. */
function timeInTurn(fns: readonly (() => void)[]): number[] {
  const rounds: number[][] = fns.map(() => []);
  // Warm up first: V8 runs new wasm code in its baseline tier until the code is hot, and the
  // model not on screen has not run yet.
  for (const fn of fns) for (const t0 = performance.now(); performance.now() - t0 < 30;) fn();
  for (let r = 0; r < 7; r++)
    fns.forEach((fn, k) => {
      let n = 0;
      const t0 = performance.now();
      let t = t0;
      while (t - t0 < 3 || n < 4) { fn(); n++; t = performance.now(); }
      rounds[k].push((t - t0) / n);
    });
  return rounds.map((x) => x.sort((a, b) => a - b)[x.length >> 1]);
}

/** Times the skins' current GCS models and plain ones built for the comparison (then disposed), in the bind pose. */
export function measureSettingCost(skins: readonly SkinDeformer[], options: GcsOptions): SettingCost {
  let current = 0, plain = 0;
  const byWeights = (options.criterion ?? 'weights') === 'weights';
  for (const s of skins) {
    const identity = identitySkin(s.deformer.jointCount);
    // Scratch models: timing the live one would leave the bind pose on screen.
    const same = s.rig.buildGcs(options);
    const stepped = byWeights ? s.rig.buildGcs({ ...options, smooth: false }) : null;
    try {
      const [a, b] = timeInTurn([() => same.deform(identity), ...(stepped ? [() => stepped.deform(identity)] : [])]);
      current += a;
      plain += stepped ? b : NaN;
    } finally {
      same.dispose();
      stepped?.dispose();
    }
  }
  return { current, plain };
}
