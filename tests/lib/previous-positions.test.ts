// Previous positions for velocity (gcs_deformer_keep_previous_positions): after each deform,
// `previousPositions` holds the last frame's positions bit for bit, the two arrays swap (the views
// alternate between two made once: no copy, no allocation), on every deformer kind; off again, no
// second array.
import { beforeAll, expect, test } from 'vitest';
import * as THREE from 'three';
import { initGcsSkin, type Deformer, type GcsSkin, type Rig } from '../../web/lib/index.js';
import { makeTube, rotationAbout, tubeSkin } from '../helpers/cylinder.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

test('each deform keeps the last one as previousPositions, swapping two arrays (GCS, LBS, DQS, classic)', () => {
  const tube = makeTube({ band: 0.3 });
  const rig = gcs.createRig(tube.input);
  const builds: [string, (r: Rig) => Deformer][] = [
    ['gcs', (r) => r.buildGcs()], ['gcs plain', (r) => r.buildGcs({ smooth: false })], ['lbs', (r) => r.buildLbs()],
    ['dqs', (r) => r.buildDqs()], ['classic', (r) => r.buildClassic()],
  ];
  const axis = new THREE.Vector3(0, 0, 1);
  for (const [name, build] of builds) {
    const d = build(rig);
    expect(d.previousPositions, name).toBeNull();
    d.deform(tubeSkin(rotationAbout(tube.joint, axis, 0.2)));
    d.keepPreviousPositions(true);
    expect(Array.from(d.previousPositions!), name).toEqual(Array.from(d.positions));
    const views = new Set<Float32Array>([d.positions, d.previousPositions!]);
    expect(views.size).toBe(2);
    for (const angle of [0.5, 0.9, 1.3, 1.3]) {
      const last = d.positions.slice();
      const lastView = d.positions;
      d.deform(tubeSkin(rotationAbout(tube.joint, axis, angle)));
      expect(d.previousPositions, name).toBe(lastView); // swapped, not copied
      expect(Array.from(d.previousPositions!), name).toEqual(Array.from(last));
      expect(views.has(d.positions) && views.has(d.previousPositions!)).toBe(true);
    }
    // The same pose twice: previous = current (a paused character has no velocity).
    expect(Array.from(d.previousPositions!)).toEqual(Array.from(d.positions));
    d.keepPreviousPositions(false);
    expect(d.previousPositions).toBeNull();
    const at = d.positions;
    d.deform(tubeSkin(rotationAbout(tube.joint, axis, 0.1)));
    expect(d.positions).toBe(at);
    d.dispose();
  }
  rig.dispose();
});

test('off again after an odd number of deforms: positions read the array the core writes (not the one it freed)', () => {
  const tube = makeTube({ band: 0.3 });
  const rig = gcs.createRig(tube.input);
  const axis = new THREE.Vector3(0, 0, 1);
  const d = rig.buildGcs(), fresh = rig.buildGcs();
  d.keepPreviousPositions(true);
  for (const angle of [0.3, 0.6, 0.9]) d.deform(tubeSkin(rotationAbout(tube.joint, axis, angle))); // the arrays swapped three times
  d.keepPreviousPositions(false);
  for (const angle of [1.1, 0.4]) {
    const skin = tubeSkin(rotationAbout(tube.joint, axis, angle));
    d.deform(skin);
    fresh.deform(skin);
    expect(Array.from(d.positions)).toEqual(Array.from(fresh.positions));
  }
  d.dispose();
  fresh.dispose();
  rig.dispose();
});
