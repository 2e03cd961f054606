// Finite in, finite out, whatever the scale: a legal skinned tube far from unit size (×1e37, near
// float's largest; ×1e-30, near its smallest) with no normals given: every method's positions and
// normals are finite and the normals unit; and figures with nothing to measure are our error,
// never NaN.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { FidelityProbe, countNonFinite, identitySkin } from '../../web/lib/measure.js';
import { makeTube, rotationAbout, tubeSkin } from '../helpers/cylinder.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

const METHODS = [
  ['gcs', { sections: 6 }], ['gcs-plain', { smooth: false }], ['gcs-y', { criterion: 'y' }], ['gcs-centres', { centres: true }],
  ['classic', {}], ['lbs', {}], ['dqs', {}],
] as const;

describe('finite in, finite out', () => {
  for (const scale of [1e37, 1e-30]) {
    test(`a tube ×${scale} without normals: every method finite, normals unit`, () => {
      const tube = makeTube({ length: scale, radius: 0.1 * scale });
      expect(tube.input.normals).toBeUndefined();
      expect(countNonFinite(tube.input.positions as Float32Array)).toBe(0);
      const rig = gcs.createRig(tube.input);
      const bent = tubeSkin(rotationAbout(tube.joint, new THREE.Vector3(0, 0, 1), 1.2));
      const worst: Record<string, { nonFinite: number; offUnit: number }> = {};
      for (const [name, options] of METHODS) {
        const d = name === 'classic' ? rig.buildClassic() : name === 'lbs' ? rig.buildLbs() : name === 'dqs' ? rig.buildDqs() : rig.buildGcs(options);
        let nonFinite = 0, offUnit = 0;
        for (const skin of [identitySkin(rig.jointCount), bent]) {
          d.deform(skin);
          nonFinite += countNonFinite(d.positions, d.normals);
          const n = d.normals;
          for (let i = 0; i < n.length; i += 3) offUnit = Math.max(offUnit, Math.abs(Math.hypot(n[i], n[i + 1], n[i + 2]) - 1));
        }
        worst[name] = { nonFinite, offUnit: Number.isNaN(offUnit) ? Infinity : offUnit };
        d.dispose();
      }
      rig.dispose();
      for (const [name] of METHODS) {
        expect(worst[name].nonFinite, `${name}: non-finite values`).toBe(0);
        expect(worst[name].offUnit, `${name}: normal length off 1`).toBeLessThan(1e-3);
      }
    });
  }

  test('FidelityProbe with no frames, or a height of 0: our error, not NaN figures', () => {
    const tube = makeTube();
    expect(() => new FidelityProbe(tube.input, [])).toThrow(GcsError);
    expect(() => new FidelityProbe(tube.input, [identitySkin(3)], { height: 0 })).toThrow(/positive, finite height/);
    expect(() => new FidelityProbe(tube.input, [identitySkin(3)], { height: NaN })).toThrow(GcsError);
  });
});
