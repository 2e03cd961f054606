// Wasm memory at its limits: pointers above 2 GiB reach JavaScript as unsigned offsets, and
// running out of memory is a GcsError OUT_OF_MEMORY with every object still usable — never an
// abort of the module. And in use: the demo's sliders rebuild a model at every move; 200 rebuilds
// must not grow the heap in use or wasm memory by more than 5 % after the first 40.
import { describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { SkinDeformer } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { makeTube, rotationAbout, tubeSkin } from '../helpers/cylinder.js';
import { gridRig } from '../helpers/grid.js';
import { loadGlb, sharedModels } from '../helpers/models.js';

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

/** The section slider dragged up and back over its stops (web/demo/section-stops.ts): 20 moves a sweep. */
const SLIDER = [3, 4, 5, 6, 8, 10, 12, 16, 24, 32, 48, 32, 24, 16, 12, 10, 8, 6, 5, 4];
/** The classic model's contour slider, 20 moves a sweep. */
const CONTOURS = [8, 10, 12, 14, 16, 18, 20, 22, 24, 25, 26, 28, 26, 24, 22, 20, 18, 16, 12, 10];
const REBUILDS = 200, SETTLED = 40;

interface Growth { heap: number[]; memory: number[]; heapGrowth: number; memoryGrowth: number }

/**
 * `rebuild(i)` REBUILDS times, each followed by a frame (update); after each, the heap in use
 * (gcs_heap_in_use) and wasm memory's size. Growth: the largest of the last sweep over the
 * largest of the sweep ending at rebuild SETTLED (same settings at the same place in a sweep).
 */
function rebuildGrowth(gcs: GcsSkin, skins: SkinDeformer[], rebuild: (skin: SkinDeformer, i: number) => void): Growth {
  const heap: number[] = [], memory: number[] = [];
  for (let i = 0; i < REBUILDS; i++) {
    for (const skin of skins) { rebuild(skin, i); skin.update(); }
    heap.push(gcs.core.gcs_heap_in_use());
    memory.push(gcs.memory.buffer.byteLength);
  }
  const sweep = SLIDER.length;
  const peak = (a: number[], end: number) => Math.max(...a.slice(end - sweep, end));
  return { heap, memory, heapGrowth: peak(heap, REBUILDS) / peak(heap, SETTLED) - 1, memoryGrowth: memory[REBUILDS - 1] / memory[SETTLED - 1] - 1 };
}

const pct = (x: number) => `${(100 * x).toFixed(2)} %`;
const mb = (x: number) => `${(x / 2 ** 20).toFixed(1)} MB`;

/** The three kinds of slider rebuild of `sources` (as the demo: a SkinDeformer per skinned mesh), each on a fresh core. */
async function sliderRebuilds(name: string, sources: THREE.SkinnedMesh[]): Promise<void> {
  const kinds: { kind: string; options: object; rebuild: (skin: SkinDeformer, i: number) => void }[] = [
    { kind: 'GCS section slider (CPU backend)', options: { method: 'gcs' }, rebuild: (s, i) => s.rebuild('gcs', { gcs: { sections: SLIDER[i % SLIDER.length] } }) },
    { kind: 'GCS section slider (GPU backend)', options: { method: 'gcs', backend: 'gpu' }, rebuild: (s, i) => s.rebuild('gcs', { gcs: { sections: SLIDER[i % SLIDER.length] } }) },
    { kind: 'classic contour slider', options: { method: 'classic' }, rebuild: (s, i) => s.rebuild('classic', { classic: { contours: CONTOURS[i % CONTOURS.length] } }) },
  ];
  for (const k of kinds) {
    const gcs = await initGcsSkin();
    const skins = sources.map((source) => new SkinDeformer(gcs, source, k.options));
    const g = rebuildGrowth(gcs, skins, k.rebuild);
    console.log(`${name}, ${REBUILDS} × ${k.kind}: heap in use ${mb(g.heap[SETTLED - 1])} after ${SETTLED}, ${mb(g.heap[REBUILDS - 1])} after ${REBUILDS} ` +
      `(peak growth ${pct(g.heapGrowth)}); wasm memory ${mb(g.memory[SETTLED - 1])} → ${mb(g.memory[REBUILDS - 1])} (${pct(g.memoryGrowth)})`);
    expect(g.heap.every((b) => b > 0)).toBe(true); // the figure is read (not a platform without allocator statistics)
    expect(g.heapGrowth, `${name}, ${k.kind}: heap in use`).toBeLessThanOrEqual(0.05);
    expect(g.memoryGrowth, `${name}, ${k.kind}: wasm memory`).toBeLessThanOrEqual(0.05);
    for (const s of skins) s.dispose();
    // Everything the skins held is given back.
    expect(gcs.core.gcs_heap_in_use()).toBe(0);
  }
}

describe('slider rebuilds do not leak', () => {
  test('the heap in use counts what is held: an allocation adds its bytes, freeing it gives them back', async () => {
    const gcs = await initGcsSkin();
    const before = gcs.core.gcs_heap_in_use();
    const p = gcs.core.gcs_alloc(1 << 20);
    expect(gcs.core.gcs_heap_in_use() - before).toBeGreaterThanOrEqual(1 << 20);
    gcs.core.gcs_free(p);
    expect(gcs.core.gcs_heap_in_use()).toBe(before);
  });

  test('our human: 200 section-slider rebuilds (CPU and GPU backends) and 200 classic rebuilds', async () => {
    const human = createHuman();
    await sliderRebuilds('our human', [human.mesh]);
  }, 240000);

  const shared = sharedModels();
  const real = shared.files.find((f) => f.endsWith('CesiumMan.glb'));
  test.skipIf(!real)(`a real rig (CesiumMan): the same${real ? '' : ` (${shared.reason ?? 'skipped: no CesiumMan.glb in the shared models'})`}`, async () => {
    const model = await loadGlb(real!);
    await sliderRebuilds('CesiumMan', model.skinnedMeshes);
  }, 240000);
});
