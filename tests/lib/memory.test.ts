// Wasm memory at its limits (issue "Reliability"): pointers above 2 GiB reach JavaScript as
// unsigned offsets, and running out of memory is a GcsError OUT_OF_MEMORY with every object still
// usable — never an abort of the module.
import { describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { makeTube, rotationAbout, tubeSkin } from '../helpers/cylinder.js';
import { gridRig } from '../helpers/grid.js';

const CHUNK = 256 * 1024 * 1024;

/** Fills wasm memory with 256 MB allocations until `stop` says enough or the core refuses. */
function fill(gcs: GcsSkin, stop: () => boolean): number[] {
  const held: number[] = [];
  while (!stop()) {
    const p = gcs.core.gcs_alloc(CHUNK);
    if (!p) break;
    held.push(p);
  }
  return held;
}

/** A flat grid rig of `side`² vertices in a unit square, two joints. */
const grid = (side: number) => gridRig(side, 1 / side);

describe('wasm memory at its limits', () => {
  test('above 2 GiB: rigs and deformers live at high addresses and give the same output', async () => {
    const gcs = await initGcsSkin();
    const tube = makeTube();
    const skin = tubeSkin(rotationAbout(tube.joint, new THREE.Vector3(0, 0, 1), 1.2));
    const low = gcs.createRig(tube.input);
    const reference = [low.buildGcs(), low.buildGcs({ smooth: true }), low.buildGcs({ criterion: 'axial' }), low.buildClassic(), low.buildLbs(), low.buildDqs()]
      .map((d) => { d.deform(skin); const out = Float32Array.from(d.positions); d.dispose(); return out; });
    const held = fill(gcs, () => gcs.memory.buffer.byteLength > 2.25 * 1024 ** 3);
    expect(gcs.memory.buffer.byteLength).toBeGreaterThan(2 ** 31);
    // Fill the holes left below too (64 KB, then 256 B blocks), so that what comes next lands
    // above 2 GiB.
    for (const block of [65536, 256])
      for (let p = 0; p < 2 ** 31 + 2 ** 24; ) {
        p = gcs.core.gcs_alloc(block);
        expect(p).not.toBe(0);
        held.push(p);
      }
    const high = gcs.createRig(tube.input);
    const deformers = [high.buildGcs(), high.buildGcs({ smooth: true }), high.buildGcs({ criterion: 'axial' }), high.buildClassic(), high.buildLbs(), high.buildDqs()];
    deformers.forEach((d, i) => {
      d.deform(skin);
      expect(d.positions.byteOffset).toBeGreaterThan(2 ** 31);
      expect(Array.from(d.positions)).toEqual(Array.from(reference[i]));
      expect(d.indices.length).toBeGreaterThan(0);
      d.dispose();
    });
    high.dispose();
    low.dispose();
    for (const p of held) gcs.core.gcs_free(p);
  }, 120000);

  test('running into the 4 GiB limit: OUT_OF_MEMORY, nothing aborts, everything stays usable', async () => {
    const gcs = await initGcsSkin();
    const big = grid(1024); // 1 M vertices: a GCS build needs about 400 MB
    const rig = gcs.createRig(big);
    const held = fill(gcs, () => false);
    expect(gcs.memory.buffer.byteLength).toBeGreaterThan(3.5 * 1024 ** 3);
    const expectOom = (f: () => unknown) => {
      let error: unknown;
      try { f(); } catch (e) { error = e; }
      expect(error).toBeInstanceOf(GcsError);
      expect((error as GcsError).code).toBe('OUT_OF_MEMORY');
      expect((error as GcsError).message).toMatch(/out of memory/);
    };
    expectOom(() => rig.buildGcs());
    expectOom(() => rig.buildClassic());
    expectOom(() => rig.buildDqs());
    expectOom(() => gcs.createRig(grid(2048))); // 4 M vertices: its copy into wasm alone does not fit
    // Free one chunk: a small rig fits, the big one still does not, and nothing leaked meanwhile
    // (the same chunk can be taken back after the failures).
    gcs.core.gcs_free(held.pop()!);
    const small = gcs.createRig(makeTube().input);
    const d = small.buildGcs();
    d.deform(tubeSkin(new THREE.Matrix4()));
    expect(Number.isFinite(d.positions[0])).toBe(true);
    d.dispose();
    small.dispose();
    expectOom(() => rig.buildGcs());
    const again = gcs.core.gcs_alloc(CHUNK);
    expect(again).not.toBe(0);
    held.push(again);
    // Everything freed: the rig that was refused builds.
    for (const p of held) gcs.core.gcs_free(p);
    const ok = rig.buildGcs();
    expect(ok.vertexCount).toBe(1024 * 1024);
    ok.dispose();
    rig.dispose();
  }, 180000);
});
