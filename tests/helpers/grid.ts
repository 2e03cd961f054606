// A flat grid rig of side² vertices (two triangles per cell), split between two joints at its
// middle row, every vertex bound 100 % to one of them. `cell` is the spacing: 1 gives an integer
// grid (the input that defeated a hash of raw float bits).
import type { RigInput } from '../../web/lib/index.js';

export function gridRig(side: number, cell = 1): RigInput {
  const n = side * side;
  const positions = new Float32Array(3 * n), joints = new Uint32Array(4 * n), weights = new Float32Array(4 * n);
  for (let i = 0; i < side; i++)
    for (let j = 0; j < side; j++) {
      const v = i * side + j;
      positions[3 * v] = i * cell;
      positions[3 * v + 1] = j * cell;
      joints[4 * v] = i < side / 2 ? 0 : 1;
      weights[4 * v] = 1;
    }
  const indices = new Uint32Array(6 * (side - 1) * (side - 1));
  let k = 0;
  for (let i = 0; i + 1 < side; i++)
    for (let j = 0; j + 1 < side; j++) {
      const a = i * side + j;
      indices.set([a, a + side, a + 1, a + 1, a + side, a + side + 1], k);
      k += 6;
    }
  const ibm = new Float32Array(32);
  ibm.set([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -(side / 2) * cell, 0, 0, 1]);
  return { positions, indices, joints, weights, parents: [-1, 0], inverseBindMatrices: ibm };
}
