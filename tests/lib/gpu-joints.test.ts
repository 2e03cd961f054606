// The joint-level GPU path's math, pinned in node (weights criterion): the per-frame joint poses
// (gcs_gcs_compute_joint_poses, JointPoses: the rows of S_j and its rotation quaternion) and the
// static per-section table (gcs_gcs_section_influences), evaluated in plain JavaScript exactly as
// the node pass and the vertex stage do it (web/lib/gpu/glsl.ts: each node's dual-quaternion blend of its joints'
// parts, M = s·R where every joint is a uniform scale, else the scale parts blended linearly and applied first, written to float32 texels with
// its normal texel; per vertex, the normal matrix N = cof(M·x)·y and the smooth-mode length fix), give gcs_deformer_deform's positions (within 1e-6 of the height)
// and normals (within 1e-5, not renormalised) — on the default human's walk and run and on
// CesiumMan and Soldier (../shared/models, skipped with the reason printed when absent), plain and
// smooth, with the skin matrices as they are, ×100 (Mixamo's centimetre rigs) and under a
// non-uniform scale. Also: a crowd in one call, the texel layout, bad input as GcsError.
import { beforeAll, describe, expect, test } from 'vitest';
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { GcsError, GPU_TEXELS_PER_JOINT, initGcsSkin, JointPoses, type GcsDeformer, type GcsSkin, type Rig } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { sampleClip } from '../../packages/cli/src/gltf-node.js';
import { identitySkin } from '../../web/lib/measure.js';
import { sectionTable } from '../../web/lib/gpu/sections.js';
import { RIGID_JOINT_TOLERANCE } from '../../web/lib/gpu/layout.js';
import { loadGlb, MODELS_DIR } from '../helpers/models.js';
import { maxDistance, scaledSkin as scaled } from '../helpers/skins.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

/** A section's transform as the shader computes it: the affine 3×4 (rows), the normal matrix (rows) and whether normals are renormalised. */
interface Blend { p: Float64Array; n: Float64Array; renorm: boolean }

/** Rows of the rotation matrix of the unit quaternion (x, y, z, w). */
function quatRows(x: number, y: number, z: number, w: number): number[] {
  return [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)];
}

/** The cofactor matrix of a row-major 3×3 (cof(A) = det(A)·A⁻ᵀ: what turns normals). */
function cofactor(a: ArrayLike<number>): number[] {
  const cof = new Array<number>(9);
  for (let i = 0; i < 3; i++)
    for (let j = 0; j < 3; j++) {
      const i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      cof[3 * i + j] = a[3 * i1 + j1] * a[3 * i2 + j2] - a[3 * i1 + j2] * a[3 * i2 + j1];
    }
  return cof;
}

/**
 * The node pass's normal texel (glsl.ts gcsNormalTexel) for scale part k (row-major): (x, y) with
 * N = cof(M·x)·y, and whether normals renormalise — the CPU's normalMatrix (transform.h): R where k
 * is a positive uniform scale s (x = 1/s, y = 1), else R·cof(k/kbig)/big (x = 1/kbig, y = 1/big).
 */
function normalTexel(k: number[]): { x: number; y: number; renorm: boolean } {
  const s = (k[0] + k[4] + k[8]) / 3;
  let uniform = s > 0;
  for (let i = 0; i < 9 && uniform; i++) if (Math.abs(k[i] - (i % 4 === 0 ? s : 0)) > 1e-4 * s) uniform = false;
  if (uniform) return { x: 1 / s, y: 1, renorm: false };
  let kbig = 0;
  for (const v of k) kbig = Math.max(kbig, Math.abs(v));
  if (!(kbig > 1e-30)) return { x: 0, y: 0, renorm: true };
  let big = 0;
  for (const v of cofactor(k.map((v) => v / kbig))) big = Math.max(big, Math.abs(v));
  if (!(big > 1e-30)) return { x: 0, y: 0, renorm: true };
  return { x: 1 / kbig, y: 1 / big, renorm: true };
}

/**
 * A node as the vertex stage reads it back from the node pass's float targets: [M | T] and the
 * normal texel rounded to float32, then N = cof(M·x)·y.
 */
function nodeAsRead(p: Float64Array, k: number[]): Blend {
  const rows = Float32Array.from(p), t = normalTexel(k), x = Math.fround(t.x), y = Math.fround(t.y);
  const a = [0, 1, 2, 4, 5, 6, 8, 9, 10].map((i) => rows[i] * x);
  return { p: Float64Array.from(rows), n: Float64Array.from(cofactor(a).map((v) => v * y)), renorm: t.renorm };
}

/** The joint pass's u_j: s where K_j is a positive uniform scale s·I within RIGID_JOINT_TOLERANCE × s (the diagonal itself where its entries are equal), else 0. */
function rigidScale(k: number[]): number {
  const s = (k[0] + k[4] + k[8]) / 3;
  let e = 0;
  for (let c = 0; c < 9; c++) e = Math.max(e, Math.abs(k[c] - (c % 4 === 0 ? s : 0)));
  if (!(s > 0 && e <= RIGID_JOINT_TOLERANCE * s)) return 0;
  return k[0] === k[4] && k[4] === k[8] ? k[0] : s;
}

/** The node pass's section blend from the joint texels of one instance (at texel `base`) and the static table, as the vertex stage reads it. */
function sectionBlend(poses: Float32Array, base: number, table: Float32Array, s: number): Blend {
  const at = (j: number) => (base + j * GPU_TEXELS_PER_JOINT) * 4;
  const joint = (i: number) => table[12 * s + i], weight = (i: number) => table[12 * s + 4 + i];
  const centre = table.subarray(12 * s + 8, 12 * s + 12);  // (x, y, z, 1), or w = 0: no centre of rotation
  /** K_j = R_jᵀ·S_j (row-major). */
  const scaleOf = (o: number, r: number[]) => {
    const k = new Array<number>(9).fill(0);
    for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) for (let m = 0; m < 3; m++) k[3 * i + j] += r[3 * m + i] * poses[o + 4 * m + j];
    return k;
  };
  if (joint(1) < 0) { // a rigid core: S_j itself
    const o = at(joint(0));
    const r = quatRows(poses[o + 12], poses[o + 13], poses[o + 14], poses[o + 15]);
    return nodeAsRead(Float64Array.from(poses.subarray(o, o + 12)), scaleOf(o, r));
  }
  const o0 = at(joint(0));
  const pivot = [poses[o0 + 12], poses[o0 + 13], poses[o0 + 14], poses[o0 + 15]];
  const br = [0, 0, 0, 0], bd = [0, 0, 0, 0], k = new Array<number>(9).fill(0), moved = [0, 0, 0];
  let scale = 0, rigid = true; // Σ w u_j, and whether every joint's K_j is a uniform scale (the joint pass's u_j > 0)
  for (let i = 0; i < 4 && joint(i) >= 0; i++) {
    const o = at(joint(i)), w = weight(i);
    // Σ w_i (S_i p − p): where linear blend skinning moves the centre p.
    for (let r = 0; r < 3; r++)
      moved[r] += w * (poses[o + 4 * r] * centre[0] + poses[o + 4 * r + 1] * centre[1] + poses[o + 4 * r + 2] * centre[2] + poses[o + 4 * r + 3] - centre[r]);
    const q = [poses[o + 12], poses[o + 13], poses[o + 14], poses[o + 15]];
    const t = [poses[o + 3], poses[o + 7], poses[o + 11]];
    // dual = ½ (0, t)·q
    const d = [0.5 * (q[3] * t[0] + t[1] * q[2] - t[2] * q[1]), 0.5 * (q[3] * t[1] + t[2] * q[0] - t[0] * q[2]),
      0.5 * (q[3] * t[2] + t[0] * q[1] - t[1] * q[0]), -0.5 * (t[0] * q[0] + t[1] * q[1] + t[2] * q[2])];
    const sw = q[0] * pivot[0] + q[1] * pivot[1] + q[2] * pivot[2] + q[3] * pivot[3] < 0 ? -w : w;
    for (let c = 0; c < 4; c++) { br[c] += sw * q[c]; bd[c] += sw * d[c]; }
    const kj = scaleOf(o, quatRows(q[0], q[1], q[2], q[3]));
    for (let c = 0; c < 9; c++) k[c] += w * kj[c];
    const u = rigidScale(kj);
    scale += w * u;
    rigid &&= u > 0;
  }
  // Every joint a uniform scale: M = s·R (and K = s·I for the normal texel), as the node pass takes it from the joint pass's parts.
  if (rigid) for (let c = 0; c < 9; c++) k[c] = c % 4 === 0 ? scale : 0;
  const inv2 = 1 / (br[0] ** 2 + br[1] ** 2 + br[2] ** 2 + br[3] ** 2);
  // t = 2·(br.w·dv − bd.w·rv − dv × rv)/|br|²
  const cx = bd[1] * br[2] - bd[2] * br[1], cy = bd[2] * br[0] - bd[0] * br[2], cz = bd[0] * br[1] - bd[1] * br[0];
  const tv = [0, 1, 2].map((c) => 2 * inv2 * (br[3] * bd[c] - bd[3] * br[c] - [cx, cy, cz][c]));
  const k2 = 2 * inv2, [x, y, z, w] = br;
  const rot = [1 - k2 * (y * y + z * z), k2 * (x * y - w * z), k2 * (x * z + w * y),
    k2 * (x * y + w * z), 1 - k2 * (x * x + z * z), k2 * (y * z - w * x),
    k2 * (x * z - w * y), k2 * (y * z + w * x), 1 - k2 * (x * x + y * y)];
  const p = new Float64Array(12);
  for (let i = 0; i < 3; i++) {
    for (let j = 0; j < 3; j++) for (let m = 0; m < 3; m++) p[4 * i + j] += rot[3 * i + m] * k[3 * m + j];
    // With a centre: M p + T = Σ w_i S_i p (the blend's rotation about p, p moved by LBS).
    p[4 * i + 3] = centre[3] > 0.5 ? moved[i] - (p[4 * i] * centre[0] + p[4 * i + 1] * centre[1] + p[4 * i + 2] * centre[2] - centre[i]) : tv[i];
  }
  return nodeAsRead(p, k);
}

/** Every vertex as the shader moves it: plain, or smooth (lerp of two sections, the CPU's normal length fix: none
 * for rotations under 2.8° apart, the cubic under 35°, else exact). */
function shade(d: GcsDeformer, poses: Float32Array, base: number, rest: { p: Float32Array; n: Float32Array }, outP: Float64Array, outN: Float64Array): void {
  const table = sectionTable(d);
  const sectionOf = d.sectionOfVertex(), other = d.blendOther(), factor = d.blendFactor();
  const third = d.blendThird(), thirdFactor = d.blendThirdFactor();
  const blends = Array.from({ length: d.sectionCount }, (_, s) => sectionBlend(poses, base, table, s));
  const M = new Float64Array(12), N = new Float64Array(9);
  const traceOf = (x: { n: Float64Array }, y: { n: Float64Array }) => { let t = 0; for (let i = 0; i < 9; i++) t += x.n[i] * y.n[i]; return t; };
  for (let v = 0; v < sectionOf.length; v++) {
    const a = blends[sectionOf[v]], b = other ? blends[other[v]] : a, c = third ? blends[third[v]] : a;
    const f = factor ? factor[v] : 0, g = thirdFactor ? thirdFactor[v] : 0;
    const blending = a !== b, three = c !== a;
    for (let i = 0; i < 12; i++) M[i] = a.p[i] + f * (b.p[i] - a.p[i]) + g * (c.p[i] - a.p[i]);
    for (let i = 0; i < 9; i++) N[i] = a.n[i] + f * (b.n[i] - a.n[i]) + g * (c.n[i] - a.n[i]);
    const x = rest.p[3 * v], y = rest.p[3 * v + 1], z = rest.p[3 * v + 2];
    const nx = rest.n[3 * v], ny = rest.n[3 * v + 1], nz = rest.n[3 * v + 2];
    let len2 = 0;
    for (let r = 0; r < 3; r++) {
      outP[3 * v + r] = M[4 * r] * x + M[4 * r + 1] * y + M[4 * r + 2] * z + M[4 * r + 3];
      const n = N[3 * r] * nx + N[3 * r + 1] * ny + N[3 * r + 2] * nz;
      outN[3 * v + r] = n;
      len2 += n * n;
    }
    let near = false, almostEqual = false;
    if (three && !a.renorm && !b.renorm && !c.renorm) {
      // A three-joint lattice cell: the least pairwise trace, the three-node thresholds (25°, 2.4°).
      const least = Math.min(traceOf(a, b), traceOf(a, c), traceOf(b, c));
      near = least > 1 + 2 * 0.9063;
      almostEqual = least > 1 + 2 * 0.9991;
    } else if (!three && blending && !a.renorm && !b.renorm) {
      const trace = traceOf(a, b);
      near = trace > 1 + 2 * 0.82;
      almostEqual = trace > 1 + 2 * 0.9988;
    }
    let scale = 1;
    if (almostEqual) scale = 1;
    else if (near) { const e = len2 - 1; scale = 1 + e * (-0.5 + 0.375 * e); }
    else if (blending || a.renorm) scale = len2 > 0 ? 1 / Math.sqrt(len2) : 0;
    for (let r = 0; r < 3; r++) outN[3 * v + r] = scale === 0 ? rest.n[3 * v + r] : outN[3 * v + r] * scale;
  }
}

const SCALES: { name: string; s: [number, number, number] }[] = [
  { name: 'as is', s: [1, 1, 1] },
  { name: '×100', s: [100, 100, 100] },
  { name: 'non-uniform (1.3, 0.7, 1.1)', s: [1.3, 0.7, 1.1] },
];

/**
 * Joint-level shading = deform on every frame and scale. `height`: the character's (a model's
 * largest skin): a small skin far from the origin (Soldier's visor, 12 of 185 cm, at head height)
 * is measured against the character it belongs to, as float32 rounding at its distance is.
 */
function compare(rig: Rig, frames: Float32Array[], smooth: boolean, label: string, height = rig.height, centres = false): void {
  const d = rig.buildGcs({ smooth, centres });
  if (centres) expect(d.sectionCentres()!.some((x, i) => i % 4 === 3 && x === 1)).toBe(true);
  expect(d.jointLevel).toBe(true);
  d.deform(identitySkin(d.jointCount));
  const rest = { p: Float32Array.from(d.positions), n: Float32Array.from(d.normals) };
  const poses = new JointPoses(d, 1);
  const V = d.vertexCount;
  const outP = new Float64Array(3 * V), outN = new Float64Array(3 * V);
  const report: string[] = [];
  let moved = 0;
  for (const { name, s } of SCALES) {
    let worstP = 0, worstN = 0;
    for (const frame of frames) {
      const skin = scaled(frame, ...s);
      poses.skins.set(skin);
      poses.compute();
      d.deform(skin);
      shade(d, poses.texels, 0, rest, outP, outN);
      const H = height * Math.max(...s);
      worstP = Math.max(worstP, maxDistance(outP, d.positions) / H);
      worstN = Math.max(worstN, maxDistance(outN, d.normals));
      if (name === 'as is') moved = Math.max(moved, maxDistance(rest.p, d.positions) / H);
    }
    report.push(`${name}: positions ${worstP.toExponential(1)} of the height, normals ${worstN.toExponential(1)}`);
    expect(worstP, `${label} ${name} positions`).toBeLessThan(1e-6);
    expect(worstN, `${label} ${name} normals`).toBeLessThan(1e-5);
  }
  console.log(`${label} (${d.sectionCount} sections, ${d.jointCount} joints, ${frames.length} frames, moving the skin up to ${moved.toFixed(2)} of the height): ${report.join('; ')}`);
  expect(moved).toBeGreaterThan(0.05); // the frames bend the character: equal in the bind pose would prove little
  poses.dispose();
  d.dispose();
}

describe('joint poses + static section table, shaded in JS = gcs_deformer_deform', () => {
  for (const smooth of [false, true]) {
    test(`default human, walk and run, ${smooth ? 'smooth' : 'plain'}`, () => {
      const human = createHuman();
      const rig = gcs.createRig(rigInputFromSkinnedMesh(human.mesh));
      const frames = ['walk', 'run'].flatMap((n) => sampleClip(human.mesh, human.clips.find((c) => c.name === n)!, 5));
      for (const centres of [false, true]) compare(rig, frames, smooth, `human ${smooth ? 'smooth' : 'plain'}${centres ? ', centres' : ''}`, rig.height, centres);
      rig.dispose();
    });
  }
  for (const file of ['CesiumMan.glb', 'Soldier.glb']) {
    const path = join(MODELS_DIR, file);
    const missing = existsSync(path) ? '' : `skipped: ${path} is absent (the shared test models are not on this machine)`;
    if (missing) console.log(missing);
    test.skipIf(!!missing)(`${file}, plain and smooth`, async () => {
      const model = await loadGlb(path);
      const rigs = model.skinnedMeshes.map((mesh) => gcs.createRig(rigInputFromSkinnedMesh(mesh)));
      const height = Math.max(...rigs.map((r) => r.height));
      for (const [i, mesh] of model.skinnedMeshes.entries()) {
        const rig = rigs[i];
        const clip = model.clips.find((c) => c.name === 'Run') ?? model.clips[0];
        const frames = sampleClip(mesh, clip, 5);
        for (const smooth of [false, true])
          for (const centres of [false, true]) compare(rig, frames, smooth, `${file} ${mesh.name} ${smooth ? 'smooth' : 'plain'}${centres ? ', centres' : ''}`, height, centres);
        rig.dispose();
      }
    }, 60000);
  }
});

describe('JointPoses', () => {
  let rig: Rig;
  let frames: Float32Array[];
  beforeAll(() => {
    const human = createHuman();
    rig = gcs.createRig(rigInputFromSkinnedMesh(human.mesh));
    frames = sampleClip(human.mesh, human.clips.find((c) => c.name === 'walk')!, 8);
  });

  test('texels: the rows of S_j bit for bit, then a unit quaternion that rotates like S_j; the table: the blends', () => {
    const d = rig.buildGcs({});
    const poses = new JointPoses(d, 1);
    const J = d.jointCount;
    expect(poses.width * poses.height).toBeGreaterThanOrEqual(J * GPU_TEXELS_PER_JOINT);
    expect(poses.bytesFor(1)).toBe(J * 64);
    const skin = scaled(frames[3], 100, 100, 100);
    poses.skins.set(skin);
    poses.compute();
    const t = poses.texels;
    for (let j = 0; j < J; j++) {
      for (let r = 0; r < 3; r++) for (let c = 0; c < 4; c++) expect(t[16 * j + 4 * r + c]).toBe(skin[16 * j + 4 * c + r]);
      const [x, y, z, w] = t.subarray(16 * j + 12, 16 * j + 16);
      expect(Math.abs(Math.hypot(x, y, z, w) - 1)).toBeLessThan(1e-6);
      // S_j's columns divided by 100 are the rotation's (the frame is rigid × 100).
      const r = quatRows(x, y, z, w);
      for (let i = 0; i < 3; i++) for (let c = 0; c < 3; c++) expect(Math.abs(r[3 * i + c] - skin[16 * j + 4 * c + i] / 100)).toBeLessThan(1e-5);
    }
    const table = d.sectionInfluences()!;
    const info = d.sections();
    expect(table.length).toBe(8 * d.sectionCount);
    for (let s = 0; s < d.sectionCount; s++) {
      const joints = Array.from(table.subarray(8 * s, 8 * s + 4)), weights = Array.from(table.subarray(8 * s + 4, 8 * s + 8));
      const n = joints.filter((j) => j >= 0).length;
      expect(joints.slice(0, n).every((j) => Number.isInteger(j) && j < J)).toBe(true);
      expect(joints.slice(n).every((j) => j === -1) && weights.slice(n).every((w) => w === 0)).toBe(true);
      expect(n === 1).toBe(info[s].rigid);
      expect(Math.abs(weights.reduce((a, b) => a + b, 0) - 1)).toBeLessThan(1e-5);
      expect(joints.slice(0, n)).toContain(info[s].part);
    }
    poses.dispose();
    d.dispose();
  });

  test('a crowd: every instance in one call equals that instance alone; compute(n) leaves the rest', () => {
    const d = rig.buildGcs({ smooth: true });
    const N = 9, J = d.jointCount;
    const all = new JointPoses(d, N, 64);
    expect(all.width).toBe(64);
    for (let k = 0; k < N; k++) all.skins.set(frames[k % frames.length], k * J * 16);
    all.compute();
    const packed = Float32Array.from(all.texels);
    const one = new JointPoses(d, 1);
    const per = J * GPU_TEXELS_PER_JOINT * 4;
    for (let k = 0; k < N; k++) {
      one.skins.set(frames[k % frames.length]);
      one.compute();
      expect(Array.from(packed.subarray(k * per, (k + 1) * per))).toEqual(Array.from(one.texels.subarray(0, per)));
    }
    all.skins.set(identitySkin(J), (N - 1) * J * 16);
    all.compute(1);
    expect(Array.from(all.texels.subarray((N - 1) * per, N * per))).toEqual(Array.from(packed.subarray((N - 1) * per, N * per)));
    one.dispose();
    all.dispose();
    d.dispose();
  });

  test('bad input is a GcsError and writes nothing; the Y and axial criteria have no joint-level path', () => {
    const code = (f: () => void) => { try { f(); } catch (e) { expect(e).toBeInstanceOf(GcsError); return (e as GcsError).code; } return 'none'; };
    const d = rig.buildGcs({});
    const poses = new JointPoses(d, 2);
    const J = d.jointCount;
    poses.skins.set(frames[1], 0);
    poses.skins.set(frames[2], J * 16);
    poses.compute();
    const before = Float32Array.from(poses.texels);
    poses.skins.set(frames[4], 0);
    poses.skins[J * 16 + 16 * (J - 1) + 2] = Infinity; // instance 1, last joint
    expect(code(() => poses.compute())).toBe('NON_FINITE');
    expect(Array.from(poses.texels)).toEqual(Array.from(before));
    expect(code(() => poses.compute(3))).toBe('OUT_OF_RANGE');
    expect(code(() => new JointPoses(d, 0))).toBe('OUT_OF_RANGE');
    expect(code(() => new JointPoses(d, 1, 3))).toBe('OUT_OF_RANGE');
    const core = gcs.core;
    expect(core.gcs_gcs_compute_joint_poses(0, 8, J, 1, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    const handle = (x: unknown) => (x as { handle: number }).handle;
    expect(core.gcs_gcs_compute_joint_poses(handle(d), 8, J + 1, 1, 8)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(2); // LENGTH_MISMATCH
    for (const criterion of ['y', 'axial'] as const) {
      const paper = rig.buildGcs({ criterion });
      expect(paper.jointLevel).toBe(false);
      expect(paper.sectionInfluences()).toBeNull();
      expect(code(() => new JointPoses(paper, 1))).toBe('INVALID_ARGUMENT');
      expect(core.gcs_gcs_compute_joint_poses(handle(paper), poses.texels.byteOffset, J, 1, poses.texels.byteOffset)).toBe(0);
      expect(core.gcs_last_error_code()).toBe(1);
      paper.dispose();
    }
    const lbs = rig.buildLbs();
    expect(core.gcs_gcs_section_influences(handle(lbs))).toBe(0);
    expect(core.gcs_gcs_compute_joint_poses(handle(lbs), 8, J, 1, 8)).toBe(0);
    lbs.dispose();
    expect(Array.from(poses.texels)).toEqual(Array.from(before));
    poses.dispose();
    expect(code(() => poses.compute())).toBe('DISPOSED');
    d.dispose();
    expect(code(() => new JointPoses(d, 1))).toBe('DISPOSED');
  });
});
