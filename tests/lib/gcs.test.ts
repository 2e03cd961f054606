// The GCS method on analytic rigs (docs/method.md §2–4): the ω schedule, exact rest pose, seams,
// criteria, smooth mode and twist spread.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { makeTube, maxAbsDiff, rotationAbout, tubeSkin } from '../helpers/cylinder.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

const Z = new THREE.Vector3(0, 0, 1);

function expectMatrixClose(actual: ArrayLike<number>, expected: THREE.Matrix4, tol = 1e-5) {
  expect(maxAbsDiff(actual, expected.elements)).toBeLessThan(tol);
}

describe('GCS on a two-bone tube', () => {
  test('the rest pose returns the input exactly, positions and normals', () => {
    const tube = makeTube();
    const rig = gcs.createRig(tube.input);
    for (const options of [{}, { smooth: true }, { twistSpread: true }, { criterion: 'y' as const, sections: 9 }]) {
      const d = rig.buildGcs(options);
      d.deform(tubeSkin(new THREE.Matrix4()));
      const src = d.sourceVertex!;
      const pos = d.positions;
      const input = tube.input.positions as Float32Array;
      for (let o = 0; o < d.vertexCount; o++)
        for (let c = 0; c < 3; c++) expect(pos[3 * o + c]).toBe(input[3 * src[o] + c]);
      d.dispose();
    }
    rig.dispose();
  });

  test('bent 90°: each section follows the ω schedule; the SGS turns by exactly half', () => {
    const tube = makeTube();
    const rig = gcs.createRig(tube.input);
    const d = rig.buildGcs({ sections: 6, criterion: 'axial' });
    const bend = rotationAbout(tube.joint, Z, Math.PI / 2);
    d.deform(tubeSkin(bend));
    const sections = d.sections();
    const matrices = d.sectionMatrices();
    expect(sections.length).toBe(2 * 4 + 1); // 2 parts × 4 inner sections + the one SGS between them
    const shared = sections.filter((s) => s.shared);
    expect(shared.length).toBe(1);
    for (let i = 0; i < sections.length; i++) {
      const s = sections[i];
      const m = matrices.subarray(16 * i, 16 * i + 16);
      // Fraction of the joint's 90° this section turns by.
      let fraction: number;
      if (s.shared) fraction = 0.5;
      else if (s.part === 0) fraction = 0.5 * Math.min(1, Math.max(0, s.t)); // β ramp, w = 1
      else fraction = 0.5 + 0.5 * Math.min(1, Math.max(0, s.t));             // α ramp, w = 1
      if (s.shared) expect(s.alpha).toBe(0.5);
      else if (s.part === 0) expect(s.beta).toBeCloseTo(fraction, 6);
      else expect(s.alpha).toBeCloseTo(fraction, 6);
      expectMatrixClose(m, rotationAbout(tube.joint, Z, fraction * Math.PI / 2));
    }
    // The schedule is monotone along the tube: α rises away from the joint, β rises towards it.
    const part0 = sections.filter((s) => !s.shared && s.part === 0);
    const part1 = sections.filter((s) => !s.shared && s.part === 1);
    expect(part0.length).toBe(4);
    expect(part1.length).toBe(4);
    for (let i = 1; i < 4; i++) {
      expect(part0[i].beta).toBeGreaterThan(part0[i - 1].beta);
      expect(part1[i].alpha).toBeGreaterThan(part1[i - 1].alpha);
    }
    // Every vertex is its section's matrix applied to its rest position.
    const pos = d.positions, src = d.sourceVertex!, of = d.sectionOfVertex();
    const input = tube.input.positions as Float32Array;
    const v = new THREE.Vector3();
    for (let o = 0; o < d.vertexCount; o++) {
      const m = new THREE.Matrix4().fromArray(matrices, 16 * of[o]);
      v.fromArray(input, 3 * src[o]).applyMatrix4(m);
      expect(Math.abs(pos[3 * o] - v.x) + Math.abs(pos[3 * o + 1] - v.y) + Math.abs(pos[3 * o + 2] - v.z)).toBeLessThan(1e-5);
    }
    expect(d.adjustedShare).toBeGreaterThan(0.5);
    d.deform(tubeSkin(new THREE.Matrix4()));
    expect(d.adjustedShare).toBe(0);
    d.dispose();
    rig.dispose();
  });

  test('sections outside the influence width are rigid', () => {
    const tube = makeTube();
    const rig = gcs.createRig(tube.input);
    const w = 0.3;
    const d = rig.buildGcs({ sections: 12, criterion: 'axial', influenceWidth: w });
    const bend = rotationAbout(tube.joint, Z, Math.PI / 2);
    d.deform(tubeSkin(bend));
    const sections = d.sections();
    const matrices = d.sectionMatrices();
    let rigid = 0;
    sections.forEach((s, i) => {
      const m = matrices.subarray(16 * i, 16 * i + 16);
      if (s.shared) return expectMatrixClose(m, rotationAbout(tube.joint, Z, Math.PI / 4));
      if (s.part === 0 && s.t < 1 - w) { expectMatrixClose(m, new THREE.Matrix4()); rigid++; }
      if (s.part === 1 && s.t > w) { expectMatrixClose(m, bend); rigid++; }
      if (s.part === 0 && s.t > 1 - w) expect(s.beta).toBeGreaterThan(0);
      if (s.part === 1 && s.t < w) expect(s.alpha).toBeLessThan(1);
    });
    expect(rigid).toBeGreaterThan(sections.length / 2);
    d.dispose();
    rig.dispose();
  });

  test('vertices at the same position (a UV seam) never separate: seam gap is exactly 0', () => {
    const tube = makeTube({ seam: true });
    const rig = gcs.createRig(tube.input);
    for (const options of [{ sections: 5 }, { sections: 7, smooth: true }, { sections: 4, twistSpread: true }]) {
      const d = rig.buildGcs(options);
      d.deform(tubeSkin(rotationAbout(tube.joint, new THREE.Vector3(0.3, 0.2, 1), 2.0)));
      const src = d.sourceVertex!, pos = d.positions, input = tube.input.positions as Float32Array;
      const byKey = new Map<string, number[]>();
      for (let o = 0; o < d.vertexCount; o++) {
        const k = Array.from(input.subarray(3 * src[o], 3 * src[o] + 3)).join(',');
        const prev = byKey.get(k);
        if (prev) for (let c = 0; c < 3; c++) expect(pos[3 * o + c]).toBe(prev[c]);
        else byKey.set(k, [pos[3 * o], pos[3 * o + 1], pos[3 * o + 2]]);
      }
      expect(byKey.size).toBe(tube.rings * tube.segments);
      d.dispose();
    }
    rig.dispose();
  });

  test('Y criterion vs axial criterion on a horizontal limb', () => {
    const tube = makeTube({ axis: 'x' });
    const rig = gcs.createRig(tube.input);
    const extentAlong = (criterion: 'y' | 'axial') => {
      const d = rig.buildGcs({ sections: 6, criterion });
      const src = d.sourceVertex!;
      let widest = 0;
      for (const s of d.sections().filter((x) => !x.shared)) {
        let lo = Infinity, hi = -Infinity;
        for (let o = s.first; o < s.first + s.count; o++) {
          lo = Math.min(lo, tube.along[src[o]]);
          hi = Math.max(hi, tube.along[src[o]]);
        }
        widest = Math.max(widest, hi - lo);
      }
      d.dispose();
      return widest;
    };
    // Axial: each inner section is a slab of the limb (≤ a quarter of a part, plus a ring).
    expect(extentAlong('axial')).toBeLessThan(0.3);
    // Y: the bins slice the horizontal limb lengthwise, so a section runs along the whole part.
    expect(extentAlong('y')).toBeGreaterThan(0.9);
    rig.dispose();
  });

  test('smooth mode removes the banding of few sections', () => {
    const tube = makeTube({ rings: 81 });
    const rig = gcs.createRig(tube.input);
    const bend = rotationAbout(tube.joint, Z, Math.PI / 2);
    // Largest change of direction between consecutive longitudinal edges of one column.
    const maxKink = (smooth: boolean) => {
      const d = rig.buildGcs({ sections: 4, criterion: 'axial', smooth });
      d.deform(tubeSkin(bend));
      const out = new Float32Array(tube.input.positions.length);
      const src = d.sourceVertex!, pos = d.positions;
      for (let o = 0; o < d.vertexCount; o++) out.set(pos.subarray(3 * o, 3 * o + 3), 3 * src[o]);
      const segs = tube.segments;
      let worst = 0;
      const p = (ring: number) => new THREE.Vector3().fromArray(out, 3 * ring * segs);
      for (let i = 1; i + 1 < tube.rings; i++) {
        const a = p(i).sub(p(i - 1)).normalize(), b = p(i + 1).sub(p(i)).normalize();
        worst = Math.max(worst, a.angleTo(b));
      }
      d.dispose();
      return worst;
    };
    const banded = maxKink(false), smooth = maxKink(true);
    expect(banded).toBeGreaterThan(0.1);
    expect(smooth).toBeLessThan(banded * 0.5);
    rig.dispose();
  });

  test('twist spread: a 180° twist ramps along the child part and keeps the limb thick', () => {
    const tube = makeTube({ band: 0.3 });
    const rig = gcs.createRig(tube.input);
    const twist = rotationAbout(tube.joint, tube.axis, Math.PI);
    // Radius of each ring after deformation (distance of its vertices from the axis).
    const ringRadius = (positions: Float32Array, src: Uint32Array | null, ring: number) => {
      let sum = 0, n = 0;
      for (let o = 0; o < positions.length / 3; o++) {
        const v = src ? src[o] : o;
        if (tube.ringOf[v] !== ring) continue;
        sum += Math.hypot(positions[3 * o], positions[3 * o + 2]);
        n++;
      }
      return sum / n;
    };
    const jointRing = Math.round((tube.rings - 1) / 2);
    for (const twistSpread of [false, true]) {
      const d = rig.buildGcs({ sections: 8, criterion: 'axial', twistSpread });
      d.deform(tubeSkin(twist));
      const sections = d.sections();
      const m = d.sectionMatrices();
      const sgs = sections.findIndex((s) => s.shared);
      // Angle the SGS turns by: 90° (half) in the paper's scheme, 0° with the twist spread out.
      const q = new THREE.Quaternion().setFromRotationMatrix(new THREE.Matrix4().fromArray(m, 16 * sgs));
      const angle = 2 * Math.acos(Math.min(1, Math.abs(q.w)));
      expect(angle).toBeCloseTo(twistSpread ? 0 : Math.PI / 2, 4);
      if (twistSpread) {
        // Along part 1 the twist grows with t: the last section turns by close to the full 180°.
        const last = sections.reduce((best, s, i) => (s.part === 1 && !s.shared && s.t > sections[best].t ? i : best), sgs);
        const ql = new THREE.Quaternion().setFromRotationMatrix(new THREE.Matrix4().fromArray(m, 16 * last));
        expect(2 * Math.acos(Math.min(1, Math.abs(ql.w)))).toBeGreaterThan(Math.PI * sections[last].t - 1e-3);
      }
      expect(ringRadius(d.positions, d.sourceVertex, jointRing)).toBeCloseTo(0.1, 5);
      d.dispose();
    }
    // LBS collapses at the joint under the same twist (candy wrapper).
    const lbs = rig.buildLbs();
    lbs.deform(tubeSkin(twist));
    expect(ringRadius(lbs.positions, null, jointRing)).toBeLessThan(0.02);
    lbs.dispose();
    rig.dispose();
  });
});

describe('reference deformers against hand-computed values', () => {
  test('LBS blends the joint matrices; DQS blends the rotations', () => {
    const tube = makeTube({ band: 0.25 });
    const rig = gcs.createRig(tube.input);
    const lbs = rig.buildLbs();
    const dqs = rig.buildDqs();
    const angle = Math.PI / 2;
    const bend = rotationAbout(tube.joint, Z, angle);
    lbs.deform(tubeSkin(bend));
    dqs.deform(tubeSkin(bend));
    const input = tube.input.positions as Float32Array, weights = tube.input.weights as Float32Array;
    const v = new THREE.Vector3(), a = new THREE.Vector3(), b = new THREE.Vector3();
    for (let i = 0; i < lbs.vertexCount; i++) {
      const w1 = weights[4 * i + 1];
      v.fromArray(input, 3 * i);
      // LBS: (1 − w) x + w S₁ x.
      a.copy(v).multiplyScalar(1 - w1).add(b.copy(v).applyMatrix4(bend).multiplyScalar(w1));
      expect(Math.abs(lbs.positions[3 * i] - a.x) + Math.abs(lbs.positions[3 * i + 1] - a.y)).toBeLessThan(1e-5);
      // DQS of two rotations about one centre: the rotation by the blended angle about it.
      const blendedAngle = 2 * Math.atan2(w1 * Math.sin(angle / 2), (1 - w1) + w1 * Math.cos(angle / 2));
      a.copy(v).applyMatrix4(rotationAbout(tube.joint, Z, blendedAngle));
      expect(Math.abs(dqs.positions[3 * i] - a.x) + Math.abs(dqs.positions[3 * i + 1] - a.y)).toBeLessThan(1e-5);
    }
    // At the joint (w = ½) LBS pulls the surface inwards by cos 45°, DQS does not.
    lbs.dispose();
    dqs.dispose();
    rig.dispose();
  });
});

// The weights criterion (docs/method.md §2), the default: analytic cases that fail if it were wrong.
describe('GCS weights criterion (default)', () => {
  const bend = (tube: ReturnType<typeof makeTube>, deg: number) => rotationAbout(tube.joint, Z, (deg * Math.PI) / 180);
  /** Largest distance between two deformers' outputs, matched through their source vertices. */
  const distance = (a: { positions: Float32Array; sourceVertex: Uint32Array | null }, b: { positions: Float32Array; sourceVertex: Uint32Array | null }) => {
    const sa = a.sourceVertex!, sb = b.sourceVertex!;
    const inB = new Uint32Array(sb.length);
    sb.forEach((v, o) => { inB[v] = o; });
    let d = 0;
    sa.forEach((v, o) => {
      const q = inB[v];
      d = Math.max(d, Math.hypot(a.positions[3 * o] - b.positions[3 * q], a.positions[3 * o + 1] - b.positions[3 * q + 1], a.positions[3 * o + 2] - b.positions[3 * q + 2]));
    });
    return d;
  };

  test('plates bound 100 % to their bone stay exactly rigid (the paper\'s rule bends them)', () => {
    const tube = makeTube({ rings: 21 });
    const w = tube.input.weights as Float32Array, j = tube.input.joints as Uint32Array;
    for (let v = 0; v < tube.along.length; v++) {
      j[4 * v] = tube.along[v] <= 1 ? 0 : 1;
      w[4 * v] = 1; w[4 * v + 1] = 0;
    }
    const rig = gcs.createRig(tube.input);
    const m = bend(tube, 70);
    const skin = tubeSkin(m);
    const worst = (d: ReturnType<typeof rig.buildGcs>) => {
      d.deform(skin);
      let e = 0;
      d.sourceVertex!.forEach((v, o) => {
        const x = new THREE.Vector3().fromArray(tube.input.positions as Float32Array, 3 * v);
        if (j[4 * v] === 1) x.applyMatrix4(m);
        e = Math.max(e, x.distanceTo(new THREE.Vector3().fromArray(d.positions, 3 * o)));
      });
      return e;
    };
    const weights = rig.buildGcs();
    expect(weights.sections().every((s) => s.rigid)).toBe(true);
    expect(worst(weights)).toBeLessThan(1e-6);
    expect(worst(rig.buildGcs({ criterion: 'axial' }))).toBeGreaterThan(0.05); // 2.5 % of the tube's height
    rig.dispose();
  });

  test('a coarse tube whose every vertex touches the joint bends like DQS (the paper\'s SGS rule swallows it)', () => {
    const tube = makeTube({ rings: 5, band: 1 });
    const rig = gcs.createRig(tube.input);
    const skin = tubeSkin(bend(tube, 100));
    const dqs = rig.buildDqs();
    dqs.deform(skin);
    const weights = rig.buildGcs({ smooth: false });
    weights.deform(skin);
    // 5 rings, weights 0, 0.16, 0.5, 0.84, 1 on joint 1: stepped, one section per ring (its exact weights).
    expect(weights.sectionCount).toBe(5);
    expect(distance(weights, dqs)).toBeLessThan(1e-5);
    // The default (smooth) interpolates between nodes at s = 1/8 and 2/8 from each core: close, not exact.
    const byDefault = rig.buildGcs();
    byDefault.deform(skin);
    expect(byDefault.sectionCount).toBe(7);
    expect(distance(byDefault, dqs)).toBeLessThan(0.01);
    const paper = rig.buildGcs({ criterion: 'axial' });
    paper.deform(skin);
    expect(distance(paper, dqs)).toBeGreaterThan(0.05);
    rig.dispose();
  });

  test('the even-split section is one transform for both parts: half the joint\'s rotation about its centre', () => {
    const tube = makeTube(); // ring 20 sits on the joint with weights exactly 0.5 / 0.5
    const rig = gcs.createRig(tube.input);
    const d = rig.buildGcs({ sections: 6 });
    d.deform(tubeSkin(bend(tube, 90)));
    const sections = d.sections();
    const shared = sections.filter((s) => s.shared);
    expect(shared.length).toBe(1);
    expect(shared[0].alpha).toBeCloseTo(0.5, 6);
    expect(shared[0].beta).toBeCloseTo(0.5, 6);
    expect(new Set([shared[0].part, shared[0].distal])).toEqual(new Set([0, 1]));
    const i = sections.indexOf(shared[0]);
    expectMatrixClose(d.sectionMatrices().subarray(16 * i, 16 * i + 16), rotationAbout(tube.joint, Z, Math.PI / 4));
    // The rigid cores are exactly S_0 and S_1.
    const matrices = d.sectionMatrices();
    for (const [k, s] of sections.entries())
      if (s.rigid) expectMatrixClose(matrices.subarray(16 * k, 16 * k + 16), s.part === 0 ? new THREE.Matrix4() : bend(tube, 90), 1e-6);
    rig.dispose();
  });

  test('the section count is the level of detail: more sections, closer to DQS; smooth mode closer still', () => {
    const tube = makeTube({ band: 0.4 });
    const rig = gcs.createRig(tube.input);
    const skin = tubeSkin(bend(tube, 120));
    const dqs = rig.buildDqs();
    dqs.deform(skin);
    const error = (o: { sections: number; smooth?: boolean }) => {
      const d = rig.buildGcs(o);
      d.deform(skin);
      const e = distance(d, dqs);
      const n = d.sectionCount;
      d.dispose();
      return { e, n };
    };
    const coarse = error({ sections: 3, smooth: false }), mid = error({ sections: 6, smooth: false }), fine = error({ sections: 20, smooth: false });
    expect(coarse.n).toBeLessThan(mid.n);
    expect(mid.n).toBeLessThan(fine.n);
    expect(mid.e).toBeLessThan(coarse.e);
    expect(fine.e).toBeLessThan(mid.e);
    // The default (smooth nodes) at the same setting: closer still, and also finer with more sections.
    const smooth = error({ sections: 6 }), smoothCoarse = error({ sections: 3 }), smoothFine = error({ sections: 20 });
    expect(smooth.e).toBeLessThan(mid.e / 2);
    expect(smooth.e).toBeLessThan(smoothCoarse.e);
    expect(smoothFine.e).toBeLessThan(smooth.e);
    rig.dispose();
  });
});

describe('a mesh that uses a few joints of a larger skeleton', () => {
  test('joints no vertex uses change nothing, not even through a non-uniform scale (they are not decomposed)', () => {
    // The tube's joints 0 and 1 become 1 and 2 under an unused root (0); the tip (3) is unused too.
    const tube = makeTube();
    const { input } = tube;
    const joints = Array.from(input.joints, (j, i) => (input.weights[i] > 0 ? j + 1 : 0));
    const ibm = new Float32Array(64);
    ibm.set(new THREE.Matrix4().elements, 0);
    ibm.set(input.inverseBindMatrices, 16);
    const rig = gcs.createRig({ ...input, joints, parents: new Int32Array([-1, 0, 1, 2]), inverseBindMatrices: ibm });
    const plainRig = gcs.createRig(input);
    const bend = rotationAbout(tube.joint, Z, Math.PI / 3);
    const wild = new THREE.Matrix4().makeRotationX(0.7).scale(new THREE.Vector3(2, 0.5, 3)).setPosition(5, -2, 1);
    const skin = (unused: THREE.Matrix4) => {
      const s = new Float32Array(64);
      s.set(unused.elements, 0);
      s.set(tubeSkin(bend).subarray(0, 32), 16);
      s.set(unused.elements, 48);
      return s;
    };
    for (const options of [{}, { smooth: false }]) {
      const d = rig.buildGcs(options), reference = plainRig.buildGcs(options);
      d.deform(skin(new THREE.Matrix4()));
      const positions = d.positions.slice(), normals = d.normals.slice();
      d.deform(skin(wild));
      expect(d.positions).toEqual(positions);
      expect(d.normals).toEqual(normals);
      reference.deform(tubeSkin(bend));
      expect(maxAbsDiff(d.positions, reference.positions)).toBeLessThan(1e-6);
      d.dispose();
      reference.dispose();
    }
    rig.dispose();
    plainRig.dispose();
  });
});
