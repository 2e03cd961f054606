// What the GCS settings cost on this machine: the deform time of the current model beside the
// plain (stepped) one at the same section count, measured in the page (not a constant that could
// go stale), so the readout can say what smooth blending and the section count cost.
import type { GcsOptions } from '../lib/index.js';
import type { SkinDeformer } from '../lib/three.js';

export interface SettingCost {
  /** ms per frame of the current GCS model, summed over the skins. */
  current: number;
  /** ms per frame of the plain (smooth: false) model at the same sections; NaN under the paper's criteria. */
  plain: number;
}

/** Median ms of `deform` over repeated rounds (each round long enough for the browser's coarse clock). */
function timeDeform(deform: () => void): number {
  const rounds: number[] = [];
  for (let r = 0; r < 5; r++) {
    let n = 0;
    const t0 = performance.now();
    let t = t0;
    while (t - t0 < 4 || n < 4) { deform(); n++; t = performance.now(); }
    rounds.push((t - t0) / n);
  }
  return rounds.sort((a, b) => a - b)[2];
}

/** Times the skins' current GCS models and plain ones built for the comparison (then disposed), in the bind pose. */
export function measureSettingCost(skins: readonly SkinDeformer[], options: GcsOptions): SettingCost {
  let current = 0, plain = 0;
  for (const s of skins) {
    const J = s.deformer.jointCount;
    const identity = new Float32Array(16 * J);
    for (let j = 0; j < J; j++) identity[16 * j] = identity[16 * j + 5] = identity[16 * j + 10] = identity[16 * j + 15] = 1;
    // A scratch model of the current settings: timing the live one would leave the bind pose on screen.
    const same = s.rig.buildGcs(options);
    try { current += timeDeform(() => same.deform(identity)); } finally { same.dispose(); }
    if ((options.criterion ?? 'weights') !== 'weights') { plain = NaN; continue; }
    const stepped = s.rig.buildGcs({ ...options, smooth: false });
    try { plain += timeDeform(() => stepped.deform(identity)); } finally { stepped.dispose(); }
  }
  return { current, plain };
}
