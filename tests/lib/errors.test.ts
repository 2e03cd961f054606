// Bad input gets a typed GcsError with a code and a readable sentence; nothing crashes, and
// the objects stay usable after a rejected call.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsSkin, type RigInput } from '../../web/lib/index.js';
import { GcsSettingsBytes, writeGcsSettings } from '../../web/lib/boundary.generated.js';
import { makeTube, rotationAbout, tubeSkin } from '../helpers/cylinder.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

function expectGcsError(fn: () => unknown, code: string, words: RegExp) {
  try {
    fn();
  } catch (e) {
    expect(e).toBeInstanceOf(GcsError);
    expect((e as GcsError).code).toBe(code);
    expect((e as GcsError).message).toMatch(words);
    return;
  }
  throw new Error(`expected a GcsError ${code}`);
}

function tubeWith(change: (input: RigInput) => void): RigInput {
  const input = makeTube().input;
  change(input);
  return input;
}

describe('rig input', () => {
  test('no skin: no joints, no vertices, no triangles, zero weights', () => {
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.parents = []; i.inverseBindMatrices = []; })), 'NO_SKIN', /no joints/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.positions = []; i.joints = []; i.weights = []; })), 'NO_SKIN', /no vertices/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.indices = []; })), 'NO_SKIN', /no triangles/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.weights as Float32Array).fill(0, 0, 4); })), 'BAD_WEIGHTS', /vertex 0 has no skin weight/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.weights as Float32Array)[5] = -1; })), 'BAD_WEIGHTS', /negative/);
    expectGcsError(() => gcs.createRig(undefined as unknown as RigInput), 'INVALID_ARGUMENT', /expects an object/);
  });

  test('mismatched array lengths', () => {
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.positions = (i.positions as Float32Array).slice(1); })), 'LENGTH_MISMATCH', /multiple of 3/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.weights = (i.weights as Float32Array).slice(4); })), 'LENGTH_MISMATCH', /weights/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.joints = (i.joints as Uint32Array).slice(4); })), 'LENGTH_MISMATCH', /joints/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.normals = new Float32Array(3); })), 'LENGTH_MISMATCH', /normals/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.inverseBindMatrices = new Float32Array(32); })), 'LENGTH_MISMATCH', /16 per joint/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.indices = (i.indices as Uint32Array).slice(1); })), 'LENGTH_MISMATCH', /multiple of 3/);
  });

  test('indices and joint ids out of range, parent cycles', () => {
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.indices as Uint32Array)[7] = 1e6; })), 'INDEX_OUT_OF_RANGE', /1000000 .*out of range/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.indices = Array.from(i.indices as Uint32Array, (v, k) => (k === 2 ? -1 : v)); })), 'INDEX_OUT_OF_RANGE', /-1/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.joints as Uint32Array)[0] = 3; })), 'JOINT_OUT_OF_RANGE', /joint 3.*3 joints/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.joints = Array.from(i.joints as Uint32Array, (v, k) => (k === 0 ? -2 : v)); })), 'JOINT_OUT_OF_RANGE', /vertex 0/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.parents = [2, 0, 1]; })), 'JOINT_OUT_OF_RANGE', /cycle/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.parents = [-1, 7, 1]; })), 'JOINT_OUT_OF_RANGE', /parent 7/);
  });

  test('non-finite positions, normals, weights and matrices', () => {
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.positions as Float32Array)[10] = NaN; })), 'NON_FINITE', /position/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.normals = new Float32Array(i.positions.length).fill(Infinity); })), 'NON_FINITE', /normal/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.weights as Float32Array)[1] = NaN; })), 'NON_FINITE', /weights/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.inverseBindMatrices as Float32Array)[20] = NaN; })), 'NON_FINITE', /inverse bind/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { (i.inverseBindMatrices as Float32Array).fill(0, 0, 16); })), 'DEGENERATE', /singular \(not invertible\)/);
  });
});

describe('model settings', () => {
  test('section count below 3 or absurdly large; bad width or criterion; zero-length bones', () => {
    const rig = gcs.createRig(makeTube().input);
    expectGcsError(() => rig.buildGcs({ sections: 2 }), 'SECTION_COUNT', /between 3 and 256/);
    expectGcsError(() => rig.buildGcs({ sections: 1e6 }), 'SECTION_COUNT', /between 3 and 256/);
    expectGcsError(() => rig.buildGcs({ sections: 4.5 }), 'SECTION_COUNT', /whole number/);
    expectGcsError(() => rig.buildGcs({ influenceWidth: 0 }), 'OUT_OF_RANGE', /\(0, 1\]/);
    expectGcsError(() => rig.buildGcs({ influenceWidth: NaN }), 'OUT_OF_RANGE', /\(0, 1\]/);
    expectGcsError(() => rig.buildGcs({ criterion: 'z' as 'y' }), 'INVALID_ARGUMENT', /'weights', 'y' or 'axial'/);
    expectGcsError(() => rig.build('nope' as 'gcs'), 'INVALID_ARGUMENT', /unknown deformer kind/);
    // The rig is still usable after every rejection.
    const d = rig.buildGcs({ sections: 5 });
    expect(d.sectionCount).toBeGreaterThan(0);
    d.dispose();
    rig.dispose();

    // Joint 1 moved onto joint 0: the part's bone has no length.
    const input = makeTube().input;
    (input.inverseBindMatrices as Float32Array).set(new THREE.Matrix4().elements, 16);
    const flat = gcs.createRig(input);
    // The paper's rule needs bone axes; the weights criterion (the default) does not.
    expectGcsError(() => flat.buildGcs({ criterion: 'axial' }), 'ZERO_LENGTH_BONE', /zero-length bone/);
    expectGcsError(() => flat.buildGcs({ criterion: 'y' }), 'ZERO_LENGTH_BONE', /zero-length bone/);
    const weights = flat.buildGcs();
    expect(weights.sectionCount).toBeGreaterThan(0);
    weights.dispose();
    flat.dispose();
  });

  test('options of the wrong type are refused, quoting the value as given (a string is not read as a number or a flag)', () => {
    const rig = gcs.createRig(makeTube().input);
    type Loose = Record<string, unknown>;
    const gcsWith = (o: Loose) => () => rig.buildGcs(o as never);
    const classicWith = (o: Loose) => () => rig.buildClassic(o as never);
    expectGcsError(gcsWith({ smooth: 'no' }), 'INVALID_ARGUMENT', /smooth must be true or false; got 'no'$/);
    expectGcsError(gcsWith({ smooth: 1 }), 'INVALID_ARGUMENT', /smooth must be true or false; got 1$/);
    expectGcsError(gcsWith({ twistSpread: 'false' }), 'INVALID_ARGUMENT', /twistSpread must be true or false; got 'false'$/);
    expectGcsError(gcsWith({ influenceWidth: '0.5' }), 'INVALID_ARGUMENT', /influence width must be a number in \(0, 1\]; got '0.5'$/);
    expectGcsError(gcsWith({ sections: '6' }), 'SECTION_COUNT', /got '6'$/);
    expectGcsError(gcsWith({ sections: 4.5 }), 'SECTION_COUNT', /got 4.5$/);
    expectGcsError(gcsWith({ criterion: 7 }), 'INVALID_ARGUMENT', /got 7$/);
    expectGcsError(() => rig.buildGcs('smooth' as never), 'INVALID_ARGUMENT', /buildGcs takes an options object; got 'smooth'$/);
    expectGcsError(classicWith({ contours: '12' }), 'OUT_OF_RANGE', /contours .*; got '12'$/);
    expectGcsError(classicWith({ bulge: '0.5' }), 'INVALID_ARGUMENT', /bulge must be a number .*; got '0.5'$/);
    // Booleans and numbers as documented still build.
    const d = rig.buildGcs({ smooth: false, twistSpread: false, influenceWidth: 0.5, sections: 6 });
    expect(d.sectionCount).toBeGreaterThan(0);
    d.dispose();
    rig.dispose();
  });

  test('fractional or negative joint ids are reported as given, not as their u32 wrap (4294967295)', () => {
    const withJoint = (value: number) => tubeWith((i) => { i.joints = Array.from(i.joints as Uint32Array, (v, k) => (k === 9 ? value : v)); });
    expectGcsError(() => gcs.createRig(withJoint(-1)), 'JOINT_OUT_OF_RANGE', /^vertex 2 has joint id -1 \(joints\[9\]\): joint ids are whole numbers from 0 to 2$/);
    expectGcsError(() => gcs.createRig(withJoint(1.5)), 'JOINT_OUT_OF_RANGE', /joint id 1.5 \(joints\[9\]\)/);
    expectGcsError(() => gcs.createRig(tubeWith((i) => { i.joints = Float32Array.from(i.joints as Uint32Array, (v, k) => (k === 9 ? -0.5 : v)); })), 'JOINT_OUT_OF_RANGE', /joint id -0.5/);
  });

  test('the core also rejects what bypasses the TypeScript checks', () => {
    const rig = gcs.createRig(makeTube().input);
    const core = gcs.core;
    const handle = (rig as unknown as { handle: number }).handle;
    const settings = core.gcs_alloc(GcsSettingsBytes);
    const withSettings = (sections: number, criterion: number) => {
      writeGcsSettings(gcs.memory.buffer, settings, { sections, criterion, influenceWidth: 1, smooth: 0, twistSpread: 0, centres: 0 });
      return settings;
    };
    expect(core.gcs_build_gcs(handle, withSettings(2, 1))).toBe(0);
    expect(core.gcs_last_error_code()).toBe(7);
    expect(core.gcs_build_gcs(handle, withSettings(6, 9))).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    expect(core.gcs_build_gcs(0, withSettings(6, 1))).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    core.gcs_free(settings);
    rig.dispose();
  });
});

describe('per-frame input', () => {
  test('wrong matrix count or non-finite matrices are rejected and the last frame is kept', () => {
    const tube = makeTube();
    const rig = gcs.createRig(tube.input);
    for (const d of [rig.buildGcs(), rig.buildLbs(), rig.buildDqs()]) {
      const bend = tubeSkin(rotationAbout(tube.joint, new THREE.Vector3(0, 0, 1), 1));
      d.deform(bend);
      const before = d.positions.slice();
      expectGcsError(() => d.deform(new Float32Array(16)), 'LENGTH_MISMATCH', /48 numbers/);
      const bad = bend.slice();
      bad[20] = NaN;
      expectGcsError(() => d.deform(bad), 'NON_FINITE', /joint 1/);
      expect(d.positions).toEqual(before);
      d.deform(bend); // still usable
      expect(d.positions).toEqual(before);
      d.dispose();
      expectGcsError(() => d.deform(bend), 'DISPOSED', /disposed/);
      expectGcsError(() => d.positions, 'DISPOSED', /disposed/);
    }
    rig.dispose();
    expectGcsError(() => rig.buildGcs(), 'DISPOSED', /disposed/);
  });
});

describe('vertex data gathered into the output order (what the adapters carry: uv, colours…)', () => {
  test('a source shorter than the rig, or a deformer without source vertices, is refused; the deformer stays usable', () => {
    const tube = makeTube();
    const rig = gcs.createRig(tube.input);
    const d = rig.buildGcs({});
    const V = tube.input.positions.length / 3;
    const ids = new Float32Array(V).map((_, i) => i);
    const bytes = (a: Float32Array) => new Uint8Array(a.buffer);
    const gathered = new Float32Array(d.gather(bytes(ids), V, 4, 4).buffer);
    expect(Array.from(gathered)).toEqual(Array.from(d.sourceVertex!)); // item o is source item sourceVertex[o]
    expectGcsError(() => d.gather(bytes(ids.subarray(0, V - 1).slice()), V - 1, 4, 4), 'INVALID_ARGUMENT', /past the/);
    expectGcsError(() => d.gather(bytes(ids), V, 4, 8), 'INVALID_ARGUMENT', /itemBytes/);
    d.deform(tubeSkin(new THREE.Matrix4()));
    const classic = rig.buildClassic({});
    expectGcsError(() => classic.gather(bytes(ids), V, 4, 4), 'INVALID_ARGUMENT', /source vertices/);
    classic.dispose();
    d.dispose();
    rig.dispose();
  });
});
