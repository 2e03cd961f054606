// Joints bent one at a time (gcs-skin/measure: findHinges, JointProbe, measureJoints): the figures
// exact on hand-made cases (a rigid-bound tube keeps its volume and its distance to the bones; a skin
// scaled by k about the bone line changes its volume by k² − 1 and its bulge to k; LBS loses volume
// where DQS keeps it), the self-intersection count (0 at rest, > 0 for LBS's collapse at 150°), and
// the knees and elbows found from the skeleton's layout alone on our human, CesiumMan (no joint
// names) and Soldier, each bending the right way: the shin back, the forearm forward; the joint
// targets' bounds as `npm run metrics -- --joint-checks` applies them.
import { beforeAll, describe, expect, test } from 'vitest';
import { initGcsSkin, type Deformer, type GcsSkin, type RigInput } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import {
  JointProbe, bendSkin, findHinges, intersectingPairs, jointCentres, measureJoints, weldByPosition, type Hinge, type JointFigures, type Vec3,
} from '../../web/lib/measure.js';
import { makeTube } from '../helpers/cylinder.js';
import { loadGlb, sharedModels } from '../helpers/models.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

/** The tube's joint 1 (at y = 1) bent about z: the tube of cylinder.ts has no limbs to find. */
const tubeHinge: Hinge = { kind: 'elbow', side: 'left', label: 'tube', joint: 1, parent: 0, centre: [0, 1, 0], end: [0, 2, 0], axis: [0, 0, 1] };

function measured(input: RigInput, build: (rig: ReturnType<GcsSkin['createRig']>) => Deformer, angles: number[]): JointFigures[] {
  const rig = gcs.createRig(input);
  const d = build(rig);
  try {
    return new JointProbe(input, tubeHinge, angles).measure(d);
  } finally {
    d.dispose();
    rig.dispose();
  }
}

describe('the joint figures on hand-made cases', () => {
  test('a rigid-bound tube bent at its joint keeps its volume and its distance to the bones (every method)', () => {
    // Every vertex bound 100 % to one bone (no ring at the joint), and the band of triangles across
    // the joint left out: two open tubes, each moved rigidly about the joint centre.
    const tube = makeTube({ rings: 40, band: 1e-6 });
    const { indices } = tube.input;
    const kept: number[] = [];
    for (let t = 0; t < indices.length; t += 3) {
      const sides = [0, 1, 2].map((k) => tube.along[indices[t + k]] > 1);
      if (sides[0] === sides[1] && sides[1] === sides[2]) kept.push(indices[t], indices[t + 1], indices[t + 2]);
    }
    tube.input.indices = Uint32Array.from(kept);
    for (const build of [(r: any) => r.buildLbs(), (r: any) => r.buildDqs(), (r: any) => r.buildGcs()]) {
      for (const f of measured(tube.input, build, [45, 90, 135])) {
        expect(Math.abs(f.volumeChange)).toBeLessThan(1e-3);
        expect(f.bulgeP95).toBeCloseTo(1, 4);
        expect(f.bulgeMax).toBeCloseTo(1, 4);
      }
    }
  });

  test('a skin scaled by k about the bone line: volume change exactly k² − 1, bulge and collapse exactly k', () => {
    const tube = makeTube({ rings: 21, segments: 16 });
    const P = tube.input.positions;
    for (const k of [0.8, 1.25]) {
      // A deformer that ignores the bones (at 0°) and scales x and z: the bone line is the y axis.
      const positions = Float32Array.from(P, (x, i) => (i % 3 === 1 ? x : k * x));
      const fake = { kind: 'lbs', vertexCount: P.length / 3, sourceVertex: null, positions, deform() {} } as unknown as Deformer;
      const [f] = new JointProbe(tube.input, tubeHinge, [0]).measure(fake);
      expect(f.volumeChange).toBeCloseTo(100 * (k * k - 1), 3);
      for (const x of [f.bulgeP95, f.bulgeMax, f.collapseP5, f.collapseMin]) expect(x).toBeCloseTo(k, 5);
      expect(f.newIntersections).toBe(0);
    }
  });

  test('LBS on a blended tube loses volume as it bends, DQS keeps it and bulges more', () => {
    const tube = makeTube({ rings: 61, segments: 16, band: 0.3 });
    const lbs = measured(tube.input, (r) => r.buildLbs(), [45, 90, 135]);
    const dqs = measured(tube.input, (r) => r.buildDqs(), [45, 90, 135]);
    expect(lbs[1].volumeChange).toBeLessThan(-2);
    expect(lbs[2].volumeChange).toBeLessThan(lbs[1].volumeChange);
    expect(lbs[1].volumeChange).toBeLessThan(lbs[0].volumeChange);
    for (let i = 0; i < 3; i++) {
      expect(Math.abs(dqs[i].volumeChange)).toBeLessThan(Math.abs(lbs[i].volumeChange) / 3);
      expect(dqs[i].bulgeMax).toBeGreaterThan(lbs[i].bulgeMax);
      expect(dqs[i].collapseMin).toBeGreaterThan(lbs[i].collapseMin);
    }
  });
});

describe('self-intersecting triangle pairs', () => {
  const tri = (a: Vec3, b: Vec3, c: Vec3) => [...a, ...b, ...c];
  test('two triangles through each other: one pair; apart, or sharing a corner: none', () => {
    const crossing = tri([0, 0, 0], [2, 0, 0], [0, 2, 0]).concat(tri([0.5, 0.5, -1], [0.5, 0.5, 1], [1.5, -0.5, 0]));
    const apart = tri([0, 0, 0], [2, 0, 0], [0, 2, 0]).concat(tri([0, 0, 1], [2, 0, 1], [0, 2, 1]));
    const fan = tri([0, 0, 0], [2, 0, 0], [0, 2, 0]).concat(tri([0, 0, 0], [1, 1, -1], [1, 1, 1]));
    const idx = [0, 1, 2, 3, 4, 5];
    const run = (p: number[]) => intersectingPairs(p, idx, weldByPosition(p)).length;
    expect(run(crossing)).toBe(1);
    expect(run(apart)).toBe(0);
    expect(run(fan)).toBe(0); // the corner at the origin is shared (welded): neighbours
  });

  test('a tube: none at rest, some once LBS folds it at 150° (and not the rigid fold at 45°)', () => {
    const tube = makeTube({ rings: 61, segments: 16, band: 0.3 });
    const { positions, indices } = tube.input;
    expect(intersectingPairs(positions, indices, weldByPosition(positions)).length).toBe(0);
    const [bent45, bent150] = measured(tube.input, (r) => r.buildLbs(), [45, 150]);
    expect(bent45.newIntersections).toBe(0);
    expect(bent150.newIntersections).toBeGreaterThan(0);
  });
});

// ------------------------------------------------------------------------------------ real skeletons

interface Expected {
  /** Mesh-space up and forward of the file (from where its head and its toes are). */
  up: Vec3;
  forward: Vec3;
  knees: [number, number];   // left, right joint ids
  elbows: [number, number];
}

async function character(name: string): Promise<{ input: RigInput; names: string[] } | null> {
  if (name === 'human') {
    const mesh = createHuman().mesh;
    return { input: rigInputFromSkinnedMesh(mesh), names: mesh.skeleton.bones.map((b) => b.name) };
  }
  const file = sharedModels().files.find((f) => f.endsWith(name));
  if (!file) return null;
  const meshes = (await loadGlb(file)).skinnedMeshes;
  const mesh = meshes.reduce((a, b) => (b.geometry.getAttribute('position').count > a.geometry.getAttribute('position').count ? b : a));
  return { input: rigInputFromSkinnedMesh(mesh), names: mesh.skeleton.bones.map((b) => b.name) };
}

const byName = (names: string[], suffix: string) => names.findIndex((n) => n.endsWith(suffix));
const dot = (a: Vec3, b: ArrayLike<number>) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

const CASES: Record<string, (names: string[]) => Expected> = {
  // Our human faces +z, y up; its bones are named.
  human: (n) => ({ up: [0, 1, 0], forward: [0, 0, 1], knees: [byName(n, 'LeftLeg'), byName(n, 'RightLeg')],
    elbows: [byName(n, 'LeftForeArm'), byName(n, 'RightForeArm')] }),
  // CesiumMan: z up, toes toward +x; no joint names. Legs 11→13→15→17 (left, +y) and 12→14→16→18;
  // arms 5→7→9 and 6→8→10 off the chest (2).
  'CesiumMan.glb': () => ({ up: [0, 0, 1], forward: [1, 0, 0], knees: [13, 14], elbows: [7, 8] }),
  // Soldier (Mixamo): z up, toes toward +y, its left on −x.
  'Soldier.glb': (n) => ({ up: [0, 0, 1], forward: [0, 1, 0], knees: [byName(n, 'LeftLeg'), byName(n, 'RightLeg')],
    elbows: [byName(n, 'LeftForeArm'), byName(n, 'RightForeArm')] }),
};

describe.each(Object.keys(CASES))('knees and elbows of %s from the skeleton alone', (name) => {
  const available = name === 'human' || sharedModels().files.some((f) => f.endsWith(name));
  test.skipIf(!available)('two knees and two elbows, the right joints on the right sides, bending the right way', async () => {
    const c = (await character(name))!;
    const want = CASES[name](c.names);
    expect([...want.knees, ...want.elbows].every((j) => j >= 0)).toBe(true);
    const found = findHinges(c.input); // no names: the layout alone
    expect(found.notes).toEqual([]);
    expect(found.hinges.map((h) => `${h.side} ${h.kind} ${h.joint}`)).toEqual([
      `left knee ${want.knees[0]}`, `right knee ${want.knees[1]}`, `left elbow ${want.elbows[0]}`, `right elbow ${want.elbows[1]}`]);
    expect(dot(want.up, found.frame!.up)).toBeGreaterThan(0.95);
    expect(dot(want.forward, found.frame!.forward)).toBeGreaterThan(0.95);
    const centres = jointCentres(c.input);
    for (const h of found.hinges) {
      // The axis is perpendicular to the bent bone and to forward.
      const bone = h.end.map((x, i) => x - h.centre[i]) as Vec3;
      const len = Math.hypot(...bone);
      expect(Math.abs(dot(h.axis, bone)) / len).toBeLessThan(1e-9);
      expect(Math.abs(dot(h.axis, want.forward))).toBeLessThan(0.2);
      // Bent 90°: the bone turns by 90°, its end toward −forward (knee) or +forward (elbow), the
      // parent and everything off the limb stay put.
      const skin = bendSkin(c.input.parents, h, 90);
      const m = 16 * h.joint;
      const posedEnd = [0, 1, 2].map((i) => skin[m + i] * h.end[0] + skin[m + 4 + i] * h.end[1] + skin[m + 8 + i] * h.end[2] + skin[m + 12 + i]) as Vec3;
      const turned = posedEnd.map((x, i) => x - h.centre[i]) as Vec3;
      expect(dot(bone, turned) / (len * len)).toBeCloseTo(0, 5);
      // (By (1 − f²)^½ − f of its length, f the bone's forward share at bind: 0.46 for CesiumMan's forearms.)
      const moved = dot(want.forward, posedEnd.map((x, i) => x - h.end[i]));
      if (h.kind === 'knee') expect(moved).toBeLessThan(-0.3 * len);
      else expect(moved).toBeGreaterThan(0.3 * len);
      for (let i = 0; i < 16; i++) expect(skin[16 * h.parent + i]).toBe(i % 5 === 0 ? 1 : 0);
      // The joint's centre stays where it is.
      for (let i = 0; i < 3; i++)
        expect(skin[m + i] * centres[h.joint][0] + skin[m + 4 + i] * centres[h.joint][1] + skin[m + 8 + i] * centres[h.joint][2] + skin[m + 12 + i])
          .toBeCloseTo(centres[h.joint][i], 4);
    }
  });
});

describe('what findHinges makes of skeletons without two pairs of limbs', () => {
  test('a tube, a skeleton collapsed to one point, a NaN centre, a cycle: no hinge, a note, no throw', () => {
    expect(findHinges(makeTube().input)).toMatchObject({ hinges: [], frame: null });
    const human = rigInputFromSkinnedMesh(createHuman({ vertices: 2000 }).mesh);
    const J = human.parents.length;
    const collapsed = { ...human, inverseBindMatrices: Float32Array.from({ length: 16 * J }, (_, i) => (i % 5 === 0 ? 1 : 0)) };
    const nan = { ...human, inverseBindMatrices: Float32Array.from(human.inverseBindMatrices, (x, i) => (i === 16 * 14 + 13 ? NaN : x)) };
    const cycle = { ...human, parents: Int32Array.from(human.parents, (p, j) => (j === 0 ? J - 1 : p)) };
    for (const input of [collapsed, nan, cycle]) {
      const found = findHinges(input);
      for (const h of found.hinges) for (const x of [...h.axis, ...h.centre]) expect(Number.isFinite(x)).toBe(true);
      if (!found.hinges.length) expect(found.notes.length).toBeGreaterThan(0);
    }
    expect(findHinges(collapsed).hinges).toEqual([]);
  });
});

describe('every method at the joints of our human', () => {
  test('LBS loses volume at 90° and 135°, DQS keeps it within 1 point and bulges more than LBS; every figure finite', () => {
    const mesh = createHuman().mesh;
    const input = rigInputFromSkinnedMesh(mesh);
    const rig = gcs.createRig(input);
    const t0 = performance.now();
    const m = measureJoints(rig, input, { names: mesh.skeleton.bones.map((b) => b.name) });
    console.log(`joints.test: measureJoints on our human (${rig.vertexCount} vertices, ${m.joints.length} joints, ${m.methods.length} methods, 3 angles): ${(performance.now() - t0).toFixed(0)} ms`);
    rig.dispose();
    expect(m.joints.map((j) => j.hinge.label)).toEqual(['left knee (LeftLeg)', 'right knee (RightLeg)', 'left elbow (LeftForeArm)', 'right elbow (RightForeArm)']);
    expect(m.methods.map((x) => x.key)).toEqual(['gcs', 'gcs-centres', 'dqs', 'lbs', 'gcs-plain', 'classic']);
    for (const j of m.joints) {
      expect(j.regionTriangles).toBeGreaterThan(500);
      const lbs = j.methods.lbs as JointFigures[], dqs = j.methods.dqs as JointFigures[];
      for (const key of Object.keys(j.methods)) {
        const figures = j.methods[key] as JointFigures[];
        expect(figures.map((f) => f.degrees)).toEqual([45, 90, 135]);
        for (const f of figures) for (const x of Object.values(f)) expect(Number.isFinite(x)).toBe(true);
      }
      for (const i of [1, 2]) {
        expect(lbs[i].volumeChange).toBeLessThan(-3);
        expect(Math.abs(dqs[i].volumeChange)).toBeLessThan(1);
        expect(dqs[i].bulgeP95).toBeGreaterThan(lbs[i].bulgeP95);
      }
    }
  });
});

describe('the joint targets as checks (npm run metrics -- --joint-checks)', () => {
  const figures = (f: Partial<JointFigures>): JointFigures => ({
    degrees: 135, volumeChange: 0, bulgeP95: 1, bulgeMax: 1, collapseP5: 1, collapseMin: 1, creases: 0, newIntersections: 0, ...f,
  });
  test('each bound as the targets state it: at the bound passes, past it fails; the volume by its size, either sign', async () => {
    const { jointChecks } = await import('../../scripts/bench/joint-checks.mjs');
    const lbs = figures({ bulgeP95: 1.04, volumeChange: -9 }), dqs = figures({ bulgeP95: 1.4, volumeChange: -3, creases: 50, newIntersections: 100 });
    const at = jointChecks(figures({ bulgeP95: 1.09, volumeChange: 5, creases: 60, newIntersections: 115 }), dqs, lbs);
    expect(at.map((c: { name: string }) => c.name)).toEqual(['bulge', 'volume', 'creases', 'self-x']);
    expect(at.map((c: { pass: boolean }) => c.pass)).toEqual([true, true, true, true]);
    const past = jointChecks(figures({ bulgeP95: 1.1, volumeChange: -5.1, creases: 61, newIntersections: 116 }), dqs, lbs);
    expect(past.map((c: { pass: boolean }) => c.pass)).toEqual([false, false, false, false]);
  });
});
