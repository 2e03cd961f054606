// Morph targets before skinning (three.js's order: morph, then skin), on GCS, LBS and DQS.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { makeTube, rotationAbout, tubeSkin } from '../helpers/cylinder.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

describe('morph targets', () => {
  test('a morphed rest mesh deforms exactly as a rig built from the morphed positions', () => {
    const tube = makeTube({ band: 0.3 });
    const V = tube.along.length;
    const P = tube.input.positions as Float32Array;
    // Two targets: a bulge of the upper part, a shift of the tip.
    const bulge = new Float32Array(3 * V), shift = new Float32Array(3 * V);
    for (let v = 0; v < V; v++) {
      if (tube.along[v] > 1.2) { bulge[3 * v] = 0.5 * P[3 * v]; bulge[3 * v + 2] = 0.5 * P[3 * v + 2]; }
      if (tube.along[v] > 1.8) shift[3 * v] = 0.05;
    }
    const w = [0.7, 0.4];
    const morphed = Float32Array.from(P, (x, i) => x + w[0] * bulge[i] + w[1] * shift[i]);
    const skin = tubeSkin(rotationAbout(tube.joint, new THREE.Vector3(0, 0, 1), 0.9));
    const rig = gcs.createRig(tube.input);
    const reference = gcs.createRig({ ...tube.input, positions: morphed });
    for (const build of [(r: typeof rig) => r.buildGcs(), (r: typeof rig) => r.buildGcs({ smooth: true }), (r: typeof rig) => r.buildLbs(), (r: typeof rig) => r.buildDqs()]) {
      const d = build(rig), e = build(reference);
      d.setMorphTargets([bulge, shift]);
      expect(d.morphTargetCount).toBe(2);
      d.setMorphInfluences(w);
      d.deform(skin);
      e.deform(skin);
      let worst = 0;
      for (let i = 0; i < d.positions.length; i++) worst = Math.max(worst, Math.abs(d.positions[i] - e.positions[i]));
      expect(worst).toBeLessThan(1e-5);
      // Influences back to 0: the unmorphed mesh again; removing the targets restores it too.
      d.setMorphInfluences([0, 0]);
      d.deform(tubeSkin(new THREE.Matrix4()));
      const src = d.sourceVertex!;
      for (let o = 0; o < d.vertexCount; o++) expect(d.positions[3 * o]).toBeCloseTo(P[3 * src[o]], 6);
      d.setMorphInfluences([1, 0]);
      d.deform(skin);
      d.setMorphTargets([]);
      d.deform(tubeSkin(new THREE.Matrix4()));
      for (let o = 0; o < d.vertexCount; o++) expect(d.positions[3 * o + 2]).toBe(P[3 * src[o] + 2]);
      d.dispose();
      e.dispose();
    }
    rig.dispose();
    reference.dispose();
  });

  test('bad morph input is a GcsError and changes nothing', () => {
    const tube = makeTube();
    const rig = gcs.createRig(tube.input);
    const d = rig.buildGcs();
    const V = d.vertexCount;
    const codeOf = (f: () => void) => { try { f(); } catch (e) { return e instanceof GcsError ? e.code : 'not a GcsError'; } return 'no error'; };
    expect(codeOf(() => d.setMorphTargets([new Float32Array(3)]))).toBe('LENGTH_MISMATCH');
    expect(codeOf(() => d.setMorphTargets([new Float32Array(3 * V).fill(NaN)]))).toBe('NON_FINITE');
    expect(codeOf(() => d.setMorphInfluences([1]))).toBe('LENGTH_MISMATCH');
    d.setMorphTargets([new Float32Array(3 * V).fill(0.1)]);
    expect(codeOf(() => d.setMorphInfluences([Infinity]))).toBe('NON_FINITE');
    const classic = rig.buildClassic();
    expect(codeOf(() => classic.setMorphTargets([new Float32Array(3 * classic.vertexCount)]))).toBe('INVALID_ARGUMENT');
    d.setMorphInfluences([1]);
    d.deform(tubeSkin(new THREE.Matrix4()));
    const src = d.sourceVertex!;
    expect(d.positions[0]).toBeCloseTo((tube.input.positions as Float32Array)[3 * src[0]] + 0.1, 6);
    d.dispose();
    classic.dispose();
    rig.dispose();
  });
});
