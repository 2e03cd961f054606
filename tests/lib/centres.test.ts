// Centres of rotation per node (wasm/src/rotation_centres.cpp; Le & Hodgins 2016): a node of a
// bending pair (two joints, one the other's parent) turns about p*, the similarity-weighted average
// of the bind-pose surface, brought to within 1 % of the height of the pivot (the child's joint
// centre) along the line between them; every other node keeps the dual-quaternion blend. Computed
// here exactly from the formula (every triangle, no binning) and compared with the core's; a
// symmetric tube's centres lie on its axis, the even split's at the joint; rigid cores stay S_j bit
// for bit; at a bent joint the centres keep the skin nearer the bones than the dual-quaternion blend.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsDeformer, type GcsSkin, type RigInput } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { sampleClip } from '../../packages/cli/src/gltf-node.js';
import { JointProbe, identitySkin, type Hinge, type JointFigures } from '../../web/lib/measure.js';
import { jointCentres } from '../../web/lib/measure/hinges.js';
import { cleanWeights } from '../helpers/clean-weights.js';
import { makeTube, rotationAbout, tubeSkin } from '../helpers/cylinder.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

const SIGMA = 0.1;
/** The longest lever arm, pivot to centre, in units of the rig's height. */
const LEVER = 0.01;

/**
 * The centre of every section, exactly as specified: for a bending pair (two joints, one the
 * other's parent) p* = Σ_t sim(w, v_t) a_t c_t / Σ_t sim(w, v_t) a_t, brought to within LEVER ·
 * height of the child's joint centre along the line between them; null for any other section and
 * where the integral is empty.
 */
function referenceCentres(input: RigInput, d: GcsDeformer, height: number): (THREE.Vector3 | null)[] {
  const pivots = jointCentres(input).map((c) => new THREE.Vector3(...c));
  const V = input.positions.length / 3;
  const weights = Array.from({ length: V }, (_, v) => cleanWeights(input, v));
  const triangles: { v: Map<number, number>; area: number; c: THREE.Vector3 }[] = [];
  const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3();
  for (let t = 0; t < input.indices.length / 3; t++) {
    const corners = [0, 1, 2].map((i) => input.indices[3 * t + i]);
    const v = new Map<number, number>();
    for (const k of corners) for (const [j, w] of weights[k]) v.set(j, (v.get(j) ?? 0) + w / 3);
    if (v.size < 2) continue;
    a.fromArray(input.positions as number[], 3 * corners[0]);
    b.fromArray(input.positions as number[], 3 * corners[1]);
    c.fromArray(input.positions as number[], 3 * corners[2]);
    const area = b.clone().sub(a).cross(c.clone().sub(a)).length() / 2;
    if (area > 0) triangles.push({ v, area, c: a.clone().add(b).add(c).divideScalar(3) });
  }
  const table = d.sectionInfluences()!, slots = d.sectionInfluenceSlots;
  return Array.from({ length: d.sectionCount }, (_, s) => {
    const w: [number, number][] = [];
    for (let k = 0; k < slots; k++) {
      const texels = 2 * slots * s + 8 * (k >> 2);
      if (table[texels + (k & 3)] < 0) break;
      w.push([table[texels + (k & 3)], table[texels + 4 + (k & 3)]]);
    }
    if (w.length !== 2) return null;
    const child = input.parents[w[1][0]] === w[0][0] ? w[1][0] : input.parents[w[0][0]] === w[1][0] ? w[0][0] : -1;
    if (child < 0) return null;
    const sum = new THREE.Vector3();
    let mass = 0;
    for (const t of triangles) {
      let sim = 0;
      for (let i = 0; i < w.length; i++)
        for (let k = i + 1; k < w.length; k++) {
          const vj = t.v.get(w[i][0]) ?? 0, vk = t.v.get(w[k][0]) ?? 0;
          if (!vj || !vk) continue;
          const x = w[i][1] * vk - w[k][1] * vj;
          sim += w[i][1] * w[k][1] * vj * vk * Math.exp(-(x * x) / (SIGMA * SIGMA));
        }
      sum.addScaledVector(t.c, sim * t.area);
      mass += sim * t.area;
    }
    if (!(mass > 0)) return null;
    const lever = sum.divideScalar(mass).sub(pivots[child]);
    return pivots[child].clone().add(lever.clampLength(0, LEVER * height));
  });
}

function centreAt(centres: Float32Array, s: number): THREE.Vector3 | null {
  return centres[4 * s + 3] === 1 ? new THREE.Vector3(centres[4 * s], centres[4 * s + 1], centres[4 * s + 2]) : null;
}

describe('centres of rotation: the formula', () => {
  test('the default human: every bending pair\'s centre within 0.05 % of the height of the exact integral, no other node with one', () => {
    const input = rigInputFromSkinnedMesh(createHuman().mesh);
    const rig = gcs.createRig(input);
    for (const sections of [4, 6]) {
      const d = rig.buildGcs({ centres: true, sections });
      const centres = d.sectionCentres()!, reference = referenceCentres(input, d, rig.height), info = d.sections();
      let worst = 0, count = 0;
      for (let s = 0; s < d.sectionCount; s++) {
        const got = centreAt(centres, s), want = reference[s];
        expect(got === null, `section ${s}`).toBe(want === null || info[s].rigid);
        if (!got || !want) continue;
        worst = Math.max(worst, got.distanceTo(want) / rig.height);
        count++;
      }
      console.log(`human, ${sections} sections: ${count} of ${d.sectionCount} nodes turn about a centre; farthest from the exact integral ${(100 * worst).toFixed(4)} % of the height`);
      expect(count).toBeGreaterThan(d.sectionCount / 4);
      expect(worst).toBeLessThan(5e-4);
      d.dispose();
    }
    rig.dispose();
  });

  test('a symmetric tube: every centre on the axis; the even split\'s at the joint', () => {
    const tube = makeTube({ band: 0.3 });
    const rig = gcs.createRig(tube.input);
    const d = rig.buildGcs({ centres: true });
    const centres = d.sectionCentres()!, reference = referenceCentres(tube.input, d, rig.height);
    const table = d.sectionInfluences()!;
    let evenSplit = -1, turning = 0;
    for (let s = 0; s < d.sectionCount; s++) {
      const p = centreAt(centres, s);
      if (!p) continue;
      turning++;
      expect(Math.hypot(p.x, p.z), `section ${s} off the axis`).toBeLessThan(1e-6);
      expect(p.distanceTo(reference[s]!)).toBeLessThan(1e-3);
      if (table[8 * s + 4] === 0.5 && table[8 * s + 5] === 0.5) evenSplit = s;
    }
    expect(turning).toBeGreaterThan(2);
    expect(evenSplit).toBeGreaterThanOrEqual(0);
    expect(Math.abs(centres[4 * evenSplit + 1] - tube.joint.y)).toBeLessThan(1e-5);
    // Nodes weighted towards the child joint sit beyond the joint, towards the parent before it.
    for (let s = 0; s < d.sectionCount; s++) {
      const p = centreAt(centres, s);
      if (!p || s === evenSplit) continue;
      const childWeight = table[8 * s] === 1 ? table[8 * s + 4] : table[8 * s + 5];
      expect(Math.sign(p.y - tube.joint.y), `section ${s}`).toBe(Math.sign(childWeight - 0.5));
      expect(p.distanceTo(tube.joint), `section ${s}: lever arm`).toBeLessThanOrEqual(LEVER * rig.height * (1 + 1e-5));
    }
    // The hand-over: a centre at the pivot turns exactly as the dual-quaternion blend (the even
    // split's, bent 135° about the joint), so a lever arm that shrinks to 0 meets DQS with no step.
    const plain = rig.buildGcs({ centres: false });
    const skin = tubeSkin(rotationAbout(tube.joint, new THREE.Vector3(0, 0, 1), (135 * Math.PI) / 180));
    d.deform(skin);
    plain.deform(skin);
    const [a, b] = [d, plain].map((x) => x.sectionMatrices().subarray(16 * evenSplit, 16 * evenSplit + 16));
    for (let i = 0; i < 16; i++) expect(Math.abs(a[i] - b[i]), `entry ${i}`).toBeLessThan(1e-5 * rig.height);
    plain.dispose();
    d.dispose();
    rig.dispose();
  });
});

describe('centres of rotation: the motion', () => {
  test('rigid cores are S_j bit for bit; identity poses give the rest mesh exactly; blended nodes put p* where LBS does', () => {
    const human = createHuman();
    const input = rigInputFromSkinnedMesh(human.mesh);
    const rig = gcs.createRig(input);
    const d = rig.buildGcs({ centres: true });
    d.deform(identitySkin(d.jointCount));
    const source = d.sourceVertex!;
    for (let o = 0; o < d.vertexCount; o++)
      for (let c = 0; c < 3; c++) expect(d.positions[3 * o + c]).toBe(input.positions[3 * source[o] + c]);
    const frame = sampleClip(human.mesh, human.clips.find((c) => c.name === 'run')!, 4)[2];
    d.deform(frame);
    const matrices = d.sectionMatrices(), info = d.sections(), centres = d.sectionCentres()!, table = d.sectionInfluences()!;
    let rigid = 0, worst = 0;
    for (let s = 0; s < d.sectionCount; s++) {
      if (info[s].rigid) {
        rigid++;
        expect(Array.from(matrices.subarray(16 * s, 16 * s + 16))).toEqual(Array.from(frame.subarray(16 * info[s].part, 16 * info[s].part + 16)));
        continue;
      }
      const p = centreAt(centres, s);
      if (!p) continue;
      const moved = new THREE.Vector3();
      for (let k = 0; k < 4 && table[8 * s + k] >= 0; k++)
        moved.addScaledVector(p.clone().applyMatrix4(new THREE.Matrix4().fromArray(frame, 16 * table[8 * s + k])), table[8 * s + 4 + k]);
      worst = Math.max(worst, p.clone().applyMatrix4(new THREE.Matrix4().fromArray(matrices, 16 * s)).distanceTo(moved) / rig.height);
    }
    expect(rigid).toBeGreaterThan(5);
    expect(worst).toBeLessThan(1e-6);
    d.dispose();
    rig.dispose();
  });

  test('a tube bent 90° and 135°: less bulge than the dual-quaternion blend, under a quarter of LBS\'s volume loss', () => {
    const tube = makeTube({ band: 0.3, rings: 81, segments: 24 });
    const hinge: Hinge = { kind: 'elbow', side: 'left', label: 'tube', joint: 1, parent: 0, centre: [0, 1, 0], end: [0, 2, 0], axis: [0, 0, 1] };
    const probe = new JointProbe(tube.input, hinge, [90, 135]);
    const rig = gcs.createRig(tube.input);
    const [cor, dqs, lbs] = [rig.buildGcs({ centres: true }), rig.buildGcs({ centres: false }), rig.buildLbs()];
    const [c, q, l] = [cor, dqs, lbs].map((d) => probe.measure(d));
    for (let i = 0; i < 2; i++) {
      const fmt = (f: JointFigures) => `${f.bulgeP95.toFixed(3)} / ${f.bulgeMax.toFixed(3)}, ${f.volumeChange.toFixed(1)} %`;
      console.log(`tube ${c[i].degrees}°: bulge p95 / max, volume change — centres ${fmt(c[i])}; DQS-like ${fmt(q[i])}; LBS ${fmt(l[i])}`);
      expect(c[i].bulgeP95).toBeLessThan(q[i].bulgeP95);
      expect(c[i].bulgeMax).toBeLessThan(q[i].bulgeMax);
      // The centres move by LBS, which shortens the bend's axis: some of LBS's loss, not DQS's volume (README).
      expect(Math.abs(c[i].volumeChange)).toBeLessThan(0.25 * Math.abs(l[i].volumeChange));
    }
    for (const d of [cor, dqs, lbs]) d.dispose();
    rig.dispose();
  });

  test('the option is checked at the wrapper; Y and axial ignore it', () => {
    const tube = makeTube({});
    const rig = gcs.createRig(tube.input);
    for (const bad of ['yes', 1, null]) {
      try {
        rig.buildGcs({ centres: bad as unknown as boolean });
        expect.unreachable();
      } catch (e) {
        expect(e).toBeInstanceOf(GcsError);
        expect((e as GcsError).code).toBe('INVALID_ARGUMENT');
      }
    }
    const y = rig.buildGcs({ criterion: 'y', centres: true });
    expect(y.sectionCentres()).toBeNull();
    y.dispose();
    const off = rig.buildGcs({ centres: false });
    expect(off.sectionCentres()!.every((x) => x === 0)).toBe(true);
    off.dispose();
    rig.dispose();
  });
});
