// A vertex's skin weights as the GCS builder reads them (wasm/src/rig.cpp, cleanWeights).
import type { RigInput } from '../../web/lib/index.js';

/** Under 0.5 % dropped (but the largest), the same joint merged, summing to 1. */
export function cleanWeights(input: RigInput, v: number): Map<number, number> {
  const slots = input.influences ?? 4;
  const raw = new Map<number, number>();
  for (let i = 0; i < slots; i++) {
    const w = input.weights[slots * v + i];
    if (w > 0) raw.set(input.joints[slots * v + i], (raw.get(input.joints[slots * v + i]) ?? 0) + w);
  }
  const biggest = Math.max(...raw.values());
  const kept = [...raw].filter(([, w]) => w >= Math.fround(0.005) || w === biggest);  // the builder compares in float32
  const sum = kept.reduce((s, [, w]) => s + w, 0);
  return new Map(kept.map(([j, w]) => [j, w / sum]));
}
