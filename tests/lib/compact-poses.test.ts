// The joint poses' compact format (gcs_gcs_compute_joint_poses_compact, JointPoses with `compact`):
// per joint the "smallest three" of its rotation quaternion and its translation, 6 floats, the
// dropped component's index in the lowest mantissa bits of the first two. Decoded here in plain
// JavaScript as the GPU passes decode it (glsl.ts gcsJoint, node-pass-tsl.ts jointPose): the
// rotation within float bounds of S_j at every angle (180° about each axis included), the
// translation bit for bit; the full format wherever a joint scales, shears or mirrors; the
// measured data of the real characters (../shared/models, skipped with the reason printed when
// absent); bad input as GcsError with nothing written.
import { beforeAll, describe, expect, test } from 'vitest';
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import * as THREE from 'three';
import { COMPACT_FLOATS_PER_JOINT, GcsError, initGcsSkin, JointPoses, type GcsSkin, type Rig } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { sampleClip } from '../../packages/cli/src/gltf-node.js';
import { loadGlb, MODELS_DIR } from '../helpers/models.js';
import { scaledSkin } from '../helpers/skins.js';

const FLT_MIN = 2 ** -126;

let gcs: GcsSkin;
let rig: Rig;
let J: number;
beforeAll(async () => {
  gcs = await initGcsSkin();
  rig = gcs.createRig(rigInputFromSkinnedMesh(createHuman().mesh));
  J = rig.jointCount;
});

/** Joint g's pose from compact floats, as the shaders decode it: the quaternion (x, y, z, w), its rotation's rows, the translation, the dropped index. */
function decode(f: Float32Array, g: number): { q: number[]; rows: number[]; t: number[]; dropped: number } {
  const bits = new Uint32Array(f.buffer, f.byteOffset, f.length);
  const o = g * COMPACT_FLOATS_PER_JOINT;
  const dropped = (bits[o] & 1) | ((bits[o + 1] & 1) << 1);
  const c = [f[o], f[o + 1], f[o + 2]];
  const d = Math.sqrt(Math.max(0, 1 - (c[0] * c[0] + c[1] * c[1] + c[2] * c[2])));
  const q = [...c];
  q.splice(dropped, 0, d);
  const [x, y, z, w] = q;
  const rows = [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)];
  return { q, rows, t: [f[o + 3], f[o + 4], f[o + 5]], dropped };
}

/** The largest |R(q̂) − S| entry over joints 0..count−1 of `skin` (column-major 4×4s); also checks the translations bit for bit. */
function worstRoundTrip(f: Float32Array, skin: Float32Array, count: number, first = 0): number {
  let worst = 0;
  for (let j = 0; j < count; j++) {
    const { rows, t } = decode(f, first + j);
    for (let r = 0; r < 3; r++) {
      for (let c = 0; c < 3; c++) worst = Math.max(worst, Math.abs(rows[3 * r + c] - skin[16 * j + 4 * c + r]));
      expect(t[r], `joint ${j} translation`).toBe(skin[16 * j + 12 + r]);
    }
  }
  return worst;
}

/** A frame of J rigid skin matrices: joint j turned by `angles[j]` about `axes[j]`, moved by a translation of up to 2. */
function rigidFrame(axes: THREE.Vector3[], angles: number[]): Float32Array {
  const skin = new Float32Array(J * 16), m = new THREE.Matrix4();
  for (let j = 0; j < J; j++) {
    m.makeRotationAxis(axes[j % axes.length].clone().normalize(), angles[j % angles.length]);
    m.setPosition(Math.sin(3 * j) * 2, Math.cos(5 * j) * 2, j % 3 === 0 ? 0 : 0.25 * j);
    skin.set(m.elements, 16 * j);
  }
  return skin;
}

describe('compact joint poses', () => {
  test('round trip S_j → 6 floats → R(q)·x + t within float bounds, at every angle and near 180° about each axis', () => {
    const d = rig.buildGcs({});
    const poses = new JointPoses(d, 1, 2048, true);
    expect(poses.compactFormat).toBe(true); // the bind pose: identities
    const axes = [new THREE.Vector3(1, 0, 0), new THREE.Vector3(0, 1, 0), new THREE.Vector3(0, 0, 1), new THREE.Vector3(1, -2, 0.5), new THREE.Vector3(-0.3, 0.2, 1)];
    const near180 = [Math.PI, -Math.PI, Math.PI - 1e-7, Math.PI - 1e-4, Math.PI - 1e-2, -(Math.PI - 3e-6)];
    const other = [0, 1e-6, 0.3, -1.2, 2.0, 2.9, -2.5];
    let worst = 0;
    const seen = new Set<number>();
    for (const angles of [near180, other]) {
      for (let shift = 0; shift < axes.length; shift++) {
        const skin = rigidFrame([...axes.slice(shift), ...axes.slice(0, shift)], angles);
        poses.skins.set(skin);
        poses.compute();
        expect(poses.compactFormat).toBe(true);
        const f = poses.texels;
        worst = Math.max(worst, worstRoundTrip(f, skin, J));
        for (let j = 0; j < J; j++) {
          const { q, dropped } = decode(f, j);
          seen.add(dropped);
          const o = j * COMPACT_FLOATS_PER_JOINT;
          // Stored: the three smallest (≤ 1/√2), the dropped one ≥ ½, the quaternion unit; the index bits on normal floats.
          for (let c = 0; c < 3; c++) expect(Math.abs(f[o + c])).toBeLessThanOrEqual(Math.SQRT1_2 + 1e-6);
          expect(q[dropped]).toBeGreaterThanOrEqual(0.5 - 1e-6);
          expect(Math.abs(Math.hypot(...q) - 1)).toBeLessThan(1e-6);
          expect(Math.abs(f[o])).toBeGreaterThanOrEqual(FLT_MIN);
          expect(Math.abs(f[o + 1])).toBeGreaterThanOrEqual(FLT_MIN);
        }
      }
    }
    console.log(`compact round trip: worst |R(q) − S| entry ${worst.toExponential(2)} over rotations near 180° about x, y, z and two oblique axes`);
    expect([...seen].sort()).toEqual([0, 1, 2, 3]); // every index was written and read back
    expect(worst).toBeLessThan(1e-6);
    // A plain (x, y, z) with w = sqrt(1 − |v|²) would lose the rotation's axis near 180°; here q is exact there too.
    const skin = rigidFrame([new THREE.Vector3(1, 0, 0)], [Math.PI - 1e-4]);
    poses.skins.set(skin);
    poses.compute();
    const { q } = decode(poses.texels, 0);
    expect(Math.abs(q[0])).toBeGreaterThan(0.999999);
    expect(Math.abs(Math.abs(q[3]) - Math.sin(0.5e-4))).toBeLessThan(1e-7);
    poses.dispose();
    d.dispose();
  });

  test('a crowd in one call: instance k joint j at float (k·J + j)·6; one scaled joint of one instance makes the whole call full', () => {
    const d = rig.buildGcs({});
    const crowd = new JointPoses(d, 3, 2048, true), full = new JointPoses(d, 3);
    const frames = sampleClip(createHuman().mesh, createHuman().clips.find((c) => c.name === 'run')!, 3);
    frames.forEach((f, k) => { crowd.skins.set(f, k * J * 16); full.skins.set(f, k * J * 16); });
    crowd.compute();
    expect(crowd.compactFormat).toBe(true);
    for (let k = 0; k < 3; k++) expect(worstRoundTrip(crowd.texels, frames[k], J, k * J)).toBeLessThan(1e-6);
    // A scale, a shear, a mirror, a uniform ×100 (not a unit scale) on one joint of the last instance: the full format, equal to gcs_gcs_compute_joint_poses's.
    const cases: [string, THREE.Matrix4][] = [
      ['scale 1.001', new THREE.Matrix4().makeScale(1.001, 1, 1)],
      ['uniform ×100', new THREE.Matrix4().makeScale(100, 100, 100)],
      ['uniform ×1.00001', new THREE.Matrix4().makeScale(1.00001, 1.00001, 1.00001)],
      ['shear', new THREE.Matrix4().makeShear(0, 0, 1e-5, 0, 0, 0)],
      ['mirror', new THREE.Matrix4().makeScale(-1, 1, 1)],
      ['collapse', new THREE.Matrix4().makeScale(0, 0, 0)],
    ];
    for (const [name, s] of cases) {
      const skin = Float32Array.from(frames[2]);
      skin.set(new THREE.Matrix4().fromArray(skin, 16 * 7).premultiply(s).elements, 16 * 7);
      crowd.skins.set(skin, 2 * J * 16);
      full.skins.set(skin, 2 * J * 16);
      crowd.compute();
      full.compute();
      expect(crowd.compactFormat, name).toBe(false);
      expect(Array.from(crowd.texels), name).toEqual(Array.from(full.texels));
    }
    // Within the tolerance (a float32 product's rounding): still compact.
    const skin = Float32Array.from(frames[2]);
    skin.set(new THREE.Matrix4().fromArray(skin, 16 * 7).premultiply(new THREE.Matrix4().makeScale(1 + 5e-7, 1, 1)).elements, 16 * 7);
    crowd.skins.set(skin, 2 * J * 16);
    crowd.compute();
    expect(crowd.compactFormat).toBe(true);
    crowd.dispose();
    full.dispose();
    d.dispose();
  });

  test('real characters: rigid with unit scale in mesh space where their clips are (compact), the full format where a clip scales', async () => {
    const human = createHuman();
    const cases: { name: string; mesh: THREE.SkinnedMesh; clips: THREE.AnimationClip[]; compact: boolean }[] = [
      { name: 'human', mesh: human.mesh, clips: human.clips, compact: true },
    ];
    // Measured over every clip (200 frames each): every frame compact on the human, Fox and Soldier's body, 199 of 200 on CesiumMan
    // (its worst joint 2.0e-6 from its rotation); none on RobotExpressive, whose clips scale and shear (up to 1.1e-5) on every frame.
    // Soldier's visor (12 cm tall, 1.7 m from the origin: a tolerance 15× tighter) is compact on 51 of 800.
    for (const [file, compact] of [['CesiumMan.glb', true], ['Fox.glb', true], ['Soldier.glb', true], ['RobotExpressive.glb', false]] as const) {
      const path = join(MODELS_DIR, file);
      if (!existsSync(path)) { console.log(`skipped ${file}: ${path} is absent (the shared test models are not on this machine)`); continue; }
      const model = await loadGlb(path);
      cases.push({ name: file, mesh: model.skinnedMeshes[0], clips: model.clips, compact });
    }
    for (const { name, mesh, clips, compact } of cases) {
      const r = gcs.createRig(rigInputFromSkinnedMesh(mesh));
      const d = r.buildGcs({});
      const poses = new JointPoses(d, 1, 2048, true);
      let frames = 0, compactFrames = 0, worst = 0;
      for (const clip of clips)
        for (const skin of sampleClip(mesh, clip, 10)) {
          poses.skins.set(skin);
          poses.compute();
          frames++;
          if (!poses.compactFormat) continue;
          compactFrames++;
          // Where R(q)·x + t puts a point at the height's distance from the origin, against S·x + t.
          worst = Math.max(worst, worstRoundTrip(poses.texels, skin, d.jointCount));
        }
      console.log(`${name}: ${compactFrames}/${frames} frames compact; worst |R(q) − S| entry ${worst.toExponential(2)}`);
      expect(compactFrames, name).toBe(compact ? frames : 0);
      expect(worst, name).toBeLessThanOrEqual(2e-6 + 1e-6);
      poses.dispose();
      d.dispose();
      r.dispose();
    }
  }, 120000);

  test('bad input is a GcsError and writes nothing; the wasm call refuses what the full one refuses', () => {
    const code = (f: () => void) => { try { f(); } catch (e) { expect(e).toBeInstanceOf(GcsError); return (e as GcsError).code; } return 'none'; };
    const d = rig.buildGcs({});
    const poses = new JointPoses(d, 2, 2048, true);
    poses.skins.set(scaledSkin(poses.skins.slice(0, J * 16), 1, 1, 1));
    poses.compute();
    const before = Float32Array.from(poses.texels);
    poses.skins[J * 16 + 16 * (J - 1) + 13] = NaN; // instance 1, last joint's translation
    expect(code(() => poses.compute())).toBe('NON_FINITE');
    expect(Array.from(poses.texels)).toEqual(Array.from(before));
    poses.skins[J * 16 + 16 * (J - 1) + 13] = 0;
    poses.skins[5] = Infinity; // the first joint's 3×3 part
    expect(code(() => poses.compute())).toBe('NON_FINITE');
    expect(Array.from(poses.texels)).toEqual(Array.from(before));
    expect(code(() => poses.compute(3))).toBe('OUT_OF_RANGE');
    const core = gcs.core, handle = (x: unknown) => (x as { handle: number }).handle;
    expect(core.gcs_gcs_compute_joint_poses_compact(0, 8, J, 1, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1); // INVALID_ARGUMENT
    expect(core.gcs_gcs_compute_joint_poses_compact(handle(d), 8, J + 1, 1, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(2); // LENGTH_MISMATCH
    expect(core.gcs_gcs_compute_joint_poses_compact(handle(d), 8, J, 0, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(9); // OUT_OF_RANGE
    expect(core.gcs_gcs_compute_joint_poses_compact(handle(d), 0, J, 1, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    expect(core.gcs_gcs_compute_joint_poses_compact(handle(d), 8, J, 1, 0)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    const y = rig.buildGcs({ criterion: 'y' });
    expect(core.gcs_gcs_compute_joint_poses_compact(handle(y), 8, J, 1, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    const lbs = rig.buildLbs();
    expect(core.gcs_gcs_compute_joint_poses_compact(handle(lbs), 8, J, 1, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    expect(code(() => new JointPoses(y, 1, 2048, true))).toBe('INVALID_ARGUMENT');
    poses.dispose();
    d.dispose();
    y.dispose();
    lbs.dispose();
  });
});
