// The classic cross-section model (docs/method.md §6): analytic tubes (radius, joint contour on the
// bisector plane, rings moving as their skin, bulge formula, winding, errors, fallbacks), the default human (which parts
// resample, points per limb, detail loss, rebuild time) and the shared real characters.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { basename } from 'node:path';
import { initGcsSkin, GcsError, type GcsSkin, type RigInput, type ClassicDeformer } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { coincidentPairs, meshBorder, seamGap } from '../../web/lib/measure.js';
import { createHuman } from '../../web/lib/human/index.js';
import { loadGlb, sharedModels, skinMatricesAt } from '../helpers/models.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

interface Tube3 { input: RigInput; radius: number; }

/**
 * A tube of radius r along +Y from 0 to 3 with three bones (joints at y = 0, 1, 2; joint 2 owns the
 * last third, a leaf): parts 0 and 1 are chain parts (resampled), part 2 is a leaf (rigid).
 * `drop` removes the triangles of part 1 whose first vertex has z < 0 (an open half-pipe);
 * `joint2` moves joint 2's centre (its weights stay on y ≥ 2); `closed` closes both ends with a fan;
 * `patch` binds a small patch on the side of part 1 (y in [1.4, 1.6], a few segments) to joint 2.
 */
function tube3(o: { radius?: number; segments?: number; rings?: number; drop?: boolean; joint2?: number; closed?: boolean; patch?: boolean } = {}): Tube3 {
  const r = o.radius ?? 0.1, segs = o.segments ?? 48, rings = o.rings ?? 121, j2 = o.joint2 ?? 2;
  const positions: number[] = [], joints: number[] = [], weights: number[] = [];
  for (let i = 0; i < rings; i++) {
    const y = (3 * i) / (rings - 1);
    for (let k = 0; k < segs; k++) {
      const a = (2 * Math.PI * k) / segs;
      positions.push(r * Math.cos(a), y, r * Math.sin(a));
      const patched = o.patch && y >= 1.4 && y <= 1.6 && k < 4;
      joints.push(y < 1 ? 0 : y < 2 && !patched ? 1 : 2, 0, 0, 0);
      weights.push(1, 0, 0, 0);
    }
  }
  const indices: number[] = [];
  for (let i = 0; i + 1 < rings; i++)
    for (let k = 0; k < segs; k++) {
      const a = i * segs + k, b = i * segs + ((k + 1) % segs);
      const y = (3 * i) / (rings - 1);
      if (o.drop && y >= 1 && y < 2 && positions[3 * a + 2] < 0) continue;
      indices.push(a, b + segs, b, a, a + segs, b + segs);
    }
  if (o.closed) { // a centre vertex at each end, fans wound against the tube's use of the end rings
    const bottom = rings * segs, top = bottom + 1, last = (rings - 1) * segs;
    positions.push(0, 0, 0, 0, 3, 0);
    joints.push(0, 0, 0, 0, 2, 0, 0, 0);
    weights.push(1, 0, 0, 0, 1, 0, 0, 0);
    for (let k = 0; k < segs; k++) {
      const k1 = (k + 1) % segs;
      indices.push(bottom, k, k1, top, last + k1, last + k);
    }
  }
  const ibm = new Float32Array(48);
  [0, 1, j2].forEach((y, j) => ibm.set(new THREE.Matrix4().makeTranslation(0, -y, 0).elements, 16 * j));
  return {
    radius: r,
    input: { positions: new Float32Array(positions), indices: new Uint32Array(indices), joints: new Uint32Array(joints),
      weights: new Float32Array(weights), parents: new Int32Array([-1, 0, 1]), inverseBindMatrices: ibm },
  };
}

/** Skin matrices: joint 0 still, joints 1 and 2 rotated by `angle` about Z through (0, 1, 0). */
function bendSkin(angle: number): Float32Array {
  const m = new THREE.Matrix4().makeTranslation(0, 1, 0)
    .multiply(new THREE.Matrix4().makeRotationZ(angle)).multiply(new THREE.Matrix4().makeTranslation(0, -1, 0));
  const out = new Float32Array(48);
  out.set(new THREE.Matrix4().elements, 0);
  out.set(m.elements, 16);
  out.set(m.elements, 32);
  return out;
}

function allFinite(a: ArrayLike<number>): boolean {
  for (let i = 0; i < a.length; i++) if (!Number.isFinite(a[i])) return false;
  return true;
}

const vec = (a: ArrayLike<number>, i: number) => new THREE.Vector3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);

describe('classic cross-sections on analytic tubes', () => {
  test('parts: two chain parts resample, the leaf is carried rigidly', () => {
    const rig = gcs.createRig(tube3().input);
    const d = rig.buildClassic({ contours: 25, rays: 40, bulge: 0 });
    const parts = d.parts;
    expect(parts.map((p) => [p.joint, p.resampled])).toEqual([[0, true], [1, true], [2, false]]);
    // Contours scale with bone length: both bones are 1 long, so 25 contours × 40 rays each.
    expect(parts[0].vertexCount).toBe(25 * 40);
    expect(parts[1].vertexCount).toBe(25 * 40);
    // The joint contour is stored once: the last ring of part 0 is the first ring of part 1.
    expect(parts[1].firstVertex).toBe(parts[0].firstVertex + parts[0].vertexCount - 40);
    expect(d.sectionCount).toBe(49);
    d.dispose();
    rig.dispose();
  });

  test('a cylinder resamples to its true radius (within 1 %), outward winding, small detail loss', () => {
    const t = tube3({ segments: 48 });
    const rig = gcs.createRig(t.input);
    const d = rig.buildClassic({ contours: 25, rays: 40, bulge: 0 });
    const pos = d.positions;
    let worst = 0;
    for (const p of d.parts.filter((q) => q.resampled))
      for (let v = p.firstVertex; v < p.firstVertex + p.vertexCount; v++)
        worst = Math.max(worst, Math.abs(Math.hypot(pos[3 * v], pos[3 * v + 2]) - t.radius) / t.radius);
    // A 48-gon's chord is at cos(π/48) = 0.9979 of the radius: rays between its corners see that.
    expect(worst).toBeLessThan(0.01);
    // Tube and band triangles (a band zips part 1's end ring to the carried leaf's border) face away
    // from the axis; carried triangles are the input's (also outward).
    const idx = d.indices;
    let inward = 0, tube = 0;
    const tubeEnd = d.parts[1].firstVertex + d.parts[1].vertexCount;
    for (let i = 0; i < idx.length; i += 3) {
      if (idx[i] >= tubeEnd) continue;
      const a = vec(pos, idx[i]), b = vec(pos, idx[i + 1]), c = vec(pos, idx[i + 2]);
      const n = b.clone().sub(a).cross(c.clone().sub(a));
      const centre = a.clone().add(b).add(c).divideScalar(3);
      const out = new THREE.Vector3(centre.x, 0, centre.z);
      if (out.length() < 1e-6) continue; // cap triangles touch the axis
      tube++;
      if (n.dot(out) <= 0) inward++;
    }
    expect(tube).toBeGreaterThan(0);
    expect(inward).toBe(0);
    const loss = d.detailLoss;
    console.log(`classic tube: radius error ${(worst * 100).toFixed(3)} %, detail loss RMS ${loss.rms.toFixed(4)} % / max ${loss.max.toFixed(4)} % of height`);
    expect(loss.rms).toBeGreaterThanOrEqual(0);
    expect(loss.max).toBeLessThan(0.1); // % of height (3): < 3 mm on a 0.1 tube
    d.dispose();
    rig.dispose();
  });

  test('bent 90°: the joint contour lies on the bisector plane (hard weights), rings move as the skin they resample, every value finite', () => {
    const rig = gcs.createRig(tube3().input);
    const d = rig.buildClassic({ contours: 25, rays: 40, bulge: 0 });
    const bind = Float64Array.from(d.positions);
    const angle = Math.PI / 2;
    d.deform(bendSkin(angle));
    const pos = d.positions;
    expect(allFinite(pos)).toBe(true);
    expect(allFinite(d.normals)).toBe(true);
    const joint = new THREE.Vector3(0, 1, 0);
    // Upper bone +Y, lower bone turned 90° about Z: −X. Each side bound 100 % to its bone, so the
    // shared ring takes half of each: the bisector N_o = normalize(+Y − X), radius kept.
    const bis = new THREE.Vector3(-1, 1, 0).normalize();
    const first = d.parts[1].firstVertex;
    let off = 0, rad = 0;
    for (let v = first; v < first + 40; v++) {
      const p = vec(pos, v).sub(joint);
      off = Math.max(off, Math.abs(p.dot(bis)));
      rad = Math.max(rad, Math.abs(p.length() - 0.1));
    }
    expect(off).toBeLessThan(1e-5);
    expect(rad).toBeLessThan(0.002);
    // Every other ring of the lower part resamples skin bound to joint 1 only: it is its bind ring
    // moved by joint 1's motion (what dual-quaternion skinning does to that skin).
    const turn = new THREE.Matrix4().fromArray(bendSkin(angle), 16);
    let drift = 0;
    for (let v = first + 40; v < first + d.parts[1].vertexCount; v++)
      drift = Math.max(drift, vec(bind, v).applyMatrix4(turn).distanceTo(vec(pos, v)));
    expect(drift).toBeLessThan(1e-5);
    d.dispose();
    rig.dispose();
  });

  test('bulge: radii scale by 1 + b · flex · sin(π t), flex = bend / π; setBulge changes it live', () => {
    const rig = gcs.createRig(tube3().input);
    const b = 0.8;
    const d = rig.buildClassic({ contours: 25, rays: 40, bulge: b });
    const bindY = Array.from({ length: d.vertexCount }, (_, v) => d.positions[3 * v + 1]);
    const angle = Math.PI / 2;
    d.deform(bendSkin(angle));
    const flex = angle / Math.PI;
    const pos = d.positions;
    const p0 = d.parts[0];
    const radiusOf = (i: number) => {
      // part 0 does not move: contour i's centre is (0, t, 0)
      const t = i / 24;
      let sum = 0;
      for (let r = 0; r < 40; r++) sum += vec(pos, p0.firstVertex + 40 * i + r).sub(new THREE.Vector3(0, t, 0)).length();
      return sum / 40;
    };
    for (const i of [3, 6, 12, 18]) {
      const t = i / 24;
      const expected = 0.1 * Math.cos(Math.PI / 48) ** 0 * (1 + b * flex * Math.sin(Math.PI * t));
      expect(Math.abs(radiusOf(i) / expected - 1)).toBeLessThan(0.01);
    }
    d.setBulge(0);
    d.deform(bendSkin(angle));
    expect(Math.abs(radiusOf(12) / 0.1 - 1)).toBeLessThan(0.01);
    // Part 1's distal joint (2) does not bend: no bulge there whatever b is.
    d.setBulge(4);
    d.deform(bendSkin(angle));
    const p1 = d.parts[1];
    let worst = 0;
    const c1 = new THREE.Vector3(-(bindY[p1.firstVertex + 40 * 12] - 1), 1, 0); // its centre on the bent lower bone
    for (let r = 0; r < 40; r++) worst = Math.max(worst, Math.abs(vec(pos, p1.firstVertex + 40 * 12 + r).sub(c1).length() - 0.1));
    expect(worst).toBeLessThan(0.002);
    d.dispose();
    rig.dispose();
  });

  test('out-of-range counts and bulge: OUT_OF_RANGE with the limits, from the wrapper and the core', () => {
    const rig = gcs.createRig(tube3().input);
    for (const o of [{ contours: 1 }, { contours: 257 }, { rays: 2 }, { rays: 1000 }, { bulge: -0.1 }, { bulge: 4.5 }, { bulge: NaN }]) {
      let err: unknown;
      try { rig.buildClassic(o); } catch (e) { err = e; }
      expect(err).toBeInstanceOf(GcsError);
      expect((err as GcsError).code).toBe('OUT_OF_RANGE');
    }
    // The core itself (the wrapper checks first): 0 and a sentence naming the limits.
    const core = gcs.core;
    const handle = (rig as unknown as { handle: number }).handle;
    const readMessage = () => {
      const ptr = core.gcs_last_error_message();
      const bytes = new Uint8Array((core.memory as WebAssembly.Memory).buffer, ptr, 400);
      return new TextDecoder().decode(bytes.subarray(0, bytes.indexOf(0)));
    };
    expect(core.gcs_build_classic(handle, 1, 20, 0)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(9);
    expect(readMessage()).toMatch(/between 2 and 256; got 1/);
    expect(core.gcs_build_classic(handle, 25, 300, 0)).toBe(0);
    expect(readMessage()).toMatch(/between 3 and 256; got 300/);
    expect(core.gcs_build_classic(handle, 25, 20, 5)).toBe(0);
    expect(readMessage()).toMatch(/between 0 and 4/);
    const d = rig.buildClassic({ contours: 10, rays: 12 });
    expect(() => d.setBulge(9)).toThrow(GcsError);
    d.dispose();
    rig.dispose();
  });

  test('an open mesh (half-pipe part) still builds: that part falls back to rigid and is reported', () => {
    const rig = gcs.createRig(tube3({ drop: true }).input);
    const d = rig.buildClassic({ contours: 25, rays: 40, bulge: 0.5 });
    expect(d.parts.map((p) => p.resampled)).toEqual([true, false, false]);
    d.deform(bendSkin(1));
    expect(allFinite(d.positions)).toBe(true);
    expect(allFinite(d.normals)).toBe(true);
    // Part 0 now ends at a carried neighbour: a band zips its end ring to the half-pipe's border.
    expect(d.parts[0].vertexCount).toBe(25 * 40);
    d.dispose();
    rig.dispose();
  });

  test('where tubes meet carried skin nothing opens: a closed tube stays closed, an open one keeps only its two end rims', () => {
    for (const closed of [true, false]) {
      const t = tube3({ closed });
      const rig = gcs.createRig(t.input);
      const inputBorder = meshBorder(t.input.positions, t.input.indices);
      expect(inputBorder).toEqual({ open: closed ? 0 : 2 * 48, overused: 0 });
      for (const [contours, rays] of [[25, 40], [4, 3], [60, 64]]) {
        const d = rig.buildClassic({ contours, rays, bulge: 1 });
        expect(d.parts.map((p) => p.reason)).toEqual(['resampled', 'resampled', 'leaf']);
        const pairs = coincidentPairs(d.positions.slice());
        // Closed: nothing open. Open: the resampled bottom rim (rays edges) and the leaf's own top rim.
        expect(meshBorder(d.positions, d.indices)).toEqual({ open: closed ? 0 : rays + 48, overused: 0 });
        // Part 1's tube ends inside the leaf's border loop, which the band shares with the carried
        // triangles: bent, the ring, the band and the leaf stay joined (no coincident pair opens).
        for (const angle of [0.5, Math.PI / 2, 2.5]) {
          d.deform(bendSkin(angle));
          expect(seamGap(d.positions, pairs)).toBe(0);
          expect(allFinite(d.positions) && allFinite(d.normals)).toBe(true);
        }
        d.dispose();
      }
      rig.dispose();
    }
  });

  test('a patch bound to another bone on the side of a tube is absorbed by the tube at build, then found off the skin: carried, closed', () => {
    const t = tube3({ patch: true, closed: true });
    const rig = gcs.createRig(t.input);
    const d = rig.buildClassic({ contours: 25, rays: 40, bulge: 0 });
    // The patch (y in [1.4, 1.6], bound to joint 2) would be absorbed by part 1's tube (no side
    // loop), but the skin there follows joint 2 while the tube follows joint 1: at the probe poses
    // the tube stands off it, so part 1 is carried and its skin keeps its own triangles.
    expect(d.parts.map((p) => p.reason)).toEqual(['resampled', 'off-surface', 'leaf']);
    expect(meshBorder(d.positions, d.indices)).toEqual({ open: 0, overused: 0 });
    // Without the patch the same tube is resampled.
    const plain = gcs.createRig(tube3({ closed: true }).input);
    const p = plain.buildClassic({ contours: 25, rays: 40, bulge: 0 });
    expect(p.parts.map((q) => q.reason)).toEqual(['resampled', 'resampled', 'leaf']);
    p.dispose();
    plain.dispose();
    d.dispose();
    rig.dispose();
  });

  test('a zero-length part is carried rigidly; no resampleable part at all still builds', () => {
    // Joint 2 at the same point as joint 1: part 1 (y in [1, 2)) has a zero-length bone.
    const rig = gcs.createRig(tube3({ joint2: 1 }).input);
    const d = rig.buildClassic();
    expect(d.parts.map((p) => [p.resampled, p.reason])).toEqual([[true, 'resampled'], [false, 'too-short'], [false, 'leaf']]);
    d.deform(bendSkin(0.7));
    expect(allFinite(d.positions)).toBe(true);
    d.dispose();
    rig.dispose();
    // A single bone: one leaf part, nothing to resample. Output = the input, rigidly skinned.
    const one = tube3();
    const input = { ...one.input, joints: new Uint32Array(one.input.joints.length), parents: new Int32Array([-1]),
      inverseBindMatrices: new Float32Array(new THREE.Matrix4().elements) };
    const rig1 = gcs.createRig(input);
    const d1 = rig1.buildClassic();
    expect(d1.parts).toEqual([{ joint: 0, resampled: false, reason: 'leaf', firstVertex: 0, vertexCount: rig1.vertexCount }]);
    expect(d1.indices.length).toBe(input.indices.length);
    expect(d1.sectionCount).toBe(0);
    d1.deform(new Float32Array(new THREE.Matrix4().makeTranslation(1, 2, 3).elements));
    expect(d1.positions[1]).toBeCloseTo(input.positions[1] + 2, 5);
    expect(d1.detailLoss).toEqual({ rms: 0, max: 0 });
    d1.dispose();
    rig1.dispose();
  });
});
