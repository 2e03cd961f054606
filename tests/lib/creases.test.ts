// Steps between sections, measured by creases (docs/method.md §9; issue "No steps by default"): the
// metric itself on a hinge, then the default GCS against LBS and DQS on our human (every clip) and
// on every shared character — creases and flipped triangles no more than 1.1× the more of LBS's and
// DQS's, within 0.15 % of the height (p95) of DQS, rigid parts exact — and the stepped plain mode
// caught by the same count (so the check can fail).
import { beforeAll, describe, expect, test } from 'vitest';
import { basename } from 'node:path';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { characterHeight, sampleClip } from '../../packages/cli/src/gltf-node.js';
import { FidelityProbe, countCreases, dihedralCosines, interiorEdges, type Fidelity } from '../../web/lib/measure.js';
import { loadGlb, sharedModels } from '../helpers/models.js';
import type * as THREE from 'three';

const { files, reason } = sharedModels();
if (reason) console.log(`creases.test: ${reason}`);

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

/** Face normals (unnormalised) of a triangle list. */
function faceNormals(p: ArrayLike<number>, idx: ArrayLike<number>): Float64Array {
  const out = new Float64Array(idx.length);
  for (let t = 0; t < idx.length; t += 3) {
    const [a, b, c] = [idx[t], idx[t + 1], idx[t + 2]];
    const u = [p[3 * b] - p[3 * a], p[3 * b + 1] - p[3 * a + 1], p[3 * b + 2] - p[3 * a + 2]];
    const v = [p[3 * c] - p[3 * a], p[3 * c + 1] - p[3 * a + 1], p[3 * c + 2] - p[3 * a + 2]];
    out[t] = u[1] * v[2] - u[2] * v[1]; out[t + 1] = u[2] * v[0] - u[0] * v[2]; out[t + 2] = u[0] * v[1] - u[1] * v[0];
  }
  return out;
}

describe('the crease count', () => {
  // A hinge: two triangles sharing the edge x = 0 (its two ends duplicated, as at a UV seam), the
  // second folded up about that edge by `deg`.
  const hinge = (deg: number) => {
    const a = (deg * Math.PI) / 180;
    return new Float32Array([0, 0, 0, 0, 1, 0, -1, 0.5, 0, /* copies */ 0, 0, 0, 0, 1, 0, Math.cos(a), 0.5, Math.sin(a)]);
  };
  const indices = new Uint32Array([0, 2, 1, 3, 4, 5]);
  const edges = interiorEdges(hinge(0), indices);
  const restCos = dihedralCosines(faceNormals(hinge(0), indices), edges);

  test('the shared edge is interior once seam copies are welded; a fold over 20° is a crease, under is not', () => {
    expect(edges.a.length).toBe(1);
    expect(countCreases(faceNormals(hinge(30), indices), edges, restCos)).toBe(1);
    expect(countCreases(faceNormals(hinge(-25), indices), edges, restCos)).toBe(1);
    expect(countCreases(faceNormals(hinge(15), indices), edges, restCos)).toBe(0);
    // A face collapsed in the pose is a crease; one degenerate at rest is not counted.
    const collapsed = hinge(30);
    collapsed.set([0, 0.5, 0], 15);
    expect(countCreases(faceNormals(collapsed, indices), edges, restCos)).toBe(1);
  });

  test('border and non-manifold edges are not interior', () => {
    // A fan of three triangles on one edge: that edge belongs to none of the interior pairs.
    const p = new Float32Array([0, 0, 0, 0, 1, 0, 1, 0.5, 0, -1, 0.5, 0, 0, 0.5, 1]);
    const e = interiorEdges(p, new Uint32Array([0, 1, 2, 0, 1, 3, 0, 1, 4]));
    expect(e.a.length).toBe(0);
  });
});

type Counts = { creases: number; flipped: number; dqsP95: number; rigid: number };
const add = (a: Counts, f: Fidelity) => {
  a.creases += f.creases; a.flipped += f.flipped;
  a.dqsP95 = Math.max(a.dqsP95, f.dqsP95 ?? 0); a.rigid = Math.max(a.rigid, f.rigidError ?? 0);
};
const zero = (): Counts => ({ creases: 0, flipped: 0, dqsP95: 0, rigid: 0 });

/** Default GCS, plain GCS, LBS and DQS over 10 frames of every clip, summed over the meshes. */
function measure(meshes: THREE.SkinnedMesh[], clips: THREE.AnimationClip[]) {
  const heights = characterHeight(meshes);
  const out = { gcs: zero(), plain: zero(), lbs: zero(), dqs: zero() };
  meshes.forEach((mesh, i) => {
    const input = rigInputFromSkinnedMesh(mesh);
    const rig = gcs.createRig(input);
    const frames = clips.flatMap((c) => sampleClip(mesh, c, 10));
    const probe = new FidelityProbe(input, frames, { height: heights.meshUnits[i] > 0 ? heights.meshUnits[i] : rig.height });
    const builds = { gcs: () => rig.buildGcs(), plain: () => rig.buildGcs({ smooth: false }), lbs: () => rig.buildLbs(), dqs: () => rig.buildDqs() };
    for (const [k, build] of Object.entries(builds)) {
      const d = build();
      add(out[k as keyof typeof out], probe.measure(d));
      d.dispose();
    }
    rig.dispose();
  });
  return out;
}

function expectStepFree(name: string, m: ReturnType<typeof measure>) {
  const creaseBase = Math.max(m.lbs.creases, m.dqs.creases), flipBase = Math.max(m.lbs.flipped, m.dqs.flipped);
  console.log(`${name}: default GCS creases ${m.gcs.creases} (${(m.gcs.creases / creaseBase).toFixed(3)}× the more of LBS ${m.lbs.creases} / DQS ${m.dqs.creases}), ` +
    `flips ${m.gcs.flipped} (${(m.gcs.flipped / flipBase).toFixed(3)}×), DQS p95 ${m.gcs.dqsP95.toFixed(3)} %, rigid ${m.gcs.rigid.toExponential(1)} %; ` +
    `plain creases ${m.plain.creases} (${(m.plain.creases / creaseBase).toFixed(2)}×)`);
  expect(m.gcs.creases).toBeLessThanOrEqual(1.1 * creaseBase);
  expect(m.gcs.flipped).toBeLessThanOrEqual(1.1 * flipBase);
  expect(m.gcs.dqsP95).toBeLessThanOrEqual(0.15);
  expect(m.gcs.rigid).toBeLessThanOrEqual(0.01); // 1e-4 of the height: float rounding only
}

describe('the default GCS has no steps: creases and flips against LBS and DQS', () => {
  test('our human, each clip on its own', () => {
    const human = createHuman();
    for (const clip of human.clips) {
      const m = measure([human.mesh], [clip]);
      expectStepFree(`default human, ${clip.name}`, m);
      // The stepped plain mode folds the dense human's skin at every bin boundary once joints bend
      // (walk, run; idle barely bends): the count sees it.
      if (clip.name !== 'idle') expect(m.plain.creases).toBeGreaterThan(2 * Math.max(m.lbs.creases, m.dqs.creases));
    }
  }, 180_000);

  for (const file of files) {
    test(basename(file), async () => {
      const model = await loadGlb(file);
      expectStepFree(basename(file), measure(model.skinnedMeshes, model.clips));
    }, 120_000);
  }
});
