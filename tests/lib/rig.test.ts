// Rig building (wasm/src/rig.cpp): position welding stays fast on inputs that defeat a weak hash.
import { beforeAll, expect, test } from 'vitest';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

// A hash of raw float bits put a power-of-two count of integer-grid positions into a few buckets:
// 262,144 vertices took 45 s to build. Welding now sorts: well under the 20 s this test allows.
test('a 262,144-vertex integer grid builds (GCS and the paper\'s criterion) within seconds', () => {
  const side = 512, n = side * side;
  const positions = new Float32Array(3 * n), joints = new Uint32Array(4 * n), weights = new Float32Array(4 * n);
  for (let i = 0; i < side; i++)
    for (let j = 0; j < side; j++) {
      const v = i * side + j;
      positions.set([i, j, 0], 3 * v);
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
  ibm.set([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -256, 0, 0, 1]);
  const rig = gcs.createRig({ positions, indices, joints, weights, parents: [-1, 0], inverseBindMatrices: ibm });
  const t0 = performance.now();
  const weightsModel = rig.buildGcs();
  const paper = rig.buildGcs({ criterion: 'axial' });
  console.log(`262,144-vertex grid: two GCS builds in ${(performance.now() - t0).toFixed(0)} ms`);
  expect(weightsModel.sectionCount).toBe(2); // two rigid cores
  expect(paper.vertexCount).toBe(n);
  weightsModel.dispose();
  paper.dispose();
  rig.dispose();
}, 20000);
