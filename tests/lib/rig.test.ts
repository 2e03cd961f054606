// Rig building (wasm/src/rig.cpp): position welding stays fast on inputs that defeat a weak hash.
import { beforeAll, expect, test } from 'vitest';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { gridRig } from '../helpers/grid.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

// A hash of raw float bits put a power-of-two count of integer-grid positions into a few buckets:
// 262,144 vertices took 45 s to build. Welding now sorts: well under the 20 s this test allows.
test('a 262,144-vertex integer grid builds (GCS and the paper\'s criterion) within seconds', () => {
  const side = 512, n = side * side;
  const rig = gcs.createRig(gridRig(side));
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
