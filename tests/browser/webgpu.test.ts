// gcs-skin/webgpu on three.js's WebGPURenderer in headless Chromium. There is no GPU here, so
// WebGPURenderer runs its WebGL2 backend (`forceWebGL: true`, SwiftShader); real WebGPU is not
// exercised by these tests. Pictures are read back from render targets (webgpu-fixture):
//   GPU backend (TSL) vs CPU backend on CesiumMan, Soldier and the human at fixed clip times,
//   both GPU paths, plain and smooth, with and without centres of rotation: ≤ 1 % of the pixels
//   differ by more than 8/255, and the pose differs from the rest pose; GLSL (gcs-skin/three,
//   WebGLRenderer) vs TSL (gcs-skin/webgpu, WebGPURenderer) on the same pose; the node pass
//   (joint-level path) read back against the GLSL pass, run once per frame, the vertex shader free
//   of node maths; a crowd drawn and moving in one draw call; and each "never silently wrong"
//   case: it works, or runs on the CPU with a note and one warning, or throws a GcsError. With 8
//   influences per vertex (CesiumMan's weights spread onto 5–8 joints, JOINTS_1/WEIGHTS_1): the TSL
//   GPU backend and a TSL crowd = the CPU backend, and ≠ the same file read without its second set.
import { existsSync, mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { beforeAll, describe, expect, test } from 'vitest';
import { fixtureForTests, MODELS_DIR, ROOT, skipReason } from './harness.js';
import { eightInfluenceGlb } from '../helpers/influences-glb.js';

const reason = skipReason();
if (reason) console.log(reason);

/** The bound: at most 1 % of pixels differ by more than 8/255. */
const PIXEL_SHARE = 0.01;

const fixture = fixtureForTests('webgpu-fixture', '__webgpu', !!reason);

// eslint-disable-next-line @typescript-eslint/no-explicit-any
async function call<T>(fn: string, ...args: unknown[]): Promise<T> {
  return fixture.page.evaluate(([f, a]) => (window as unknown as Record<string, Record<string, (...x: unknown[]) => Promise<unknown>>>).__webgpu[f as string](...(a as unknown[])), [fn, args] as const) as Promise<T>;
}

interface Diff { image: number; covered: number }
const pct = (d: Diff) => `${(100 * d.image).toFixed(2)} % of the image (${(100 * d.covered).toFixed(2)} % of the character's pixels)`;

const SHARED = [
  { file: 'CesiumMan.glb', times: [0.5, 1.0, 1.6], clip: undefined },
  { file: 'Soldier.glb', times: [0.2, 0.55], clip: 'Run' },
];

describe.skipIf(!!reason)('gcs-skin/webgpu on WebGPURenderer (WebGL2 backend)', () => {
  for (const m of SHARED) {
    const path = join(MODELS_DIR, m.file);
    const missing = existsSync(path) ? '' : `skipped: ${path} is absent (the shared test models are not on this machine)`;
    if (missing) console.log(missing);
    for (const gpuPath of ['joints', 'sections'] as const) {
      for (const smooth of [false, true]) {
        const mode = `${smooth ? 'smooth' : 'plain'}, ${gpuPath} path`;
        test.skipIf(!!missing)(`${m.file}, ${mode}: GPU backend = CPU backend, posed`, async () => {
          const r = await call<{ backends: string[]; paths: string[]; notes: string[]; vsCpu: Diff[]; vsRest: Diff[]; coverage: number; warnings: string[] }>(
            'check', `/@fs${path}`, { smooth }, m.times, m.clip, gpuPath);
          console.log(`${m.file} ${mode}: GPU vs CPU ${r.vsCpu.map(pct).join('; ')}; vs the rest pose ${r.vsRest.map(pct).join('; ')}; coverage ${(100 * r.coverage).toFixed(1)} %`);
          expect(r.backends.every((b) => b === 'gpu'), r.notes.join('; ')).toBe(true);
          expect(r.paths.every((p) => p === gpuPath)).toBe(true);
          expect(r.warnings).toEqual([]);
          expect(r.coverage).toBeGreaterThan(0.02);
          for (const d of r.vsCpu) expect(d.image).toBeLessThanOrEqual(PIXEL_SHARE);
          for (const d of r.vsRest) expect(d.covered).toBeGreaterThan(0.05); // the pose is applied, not the rest pose
          expect(fixture.errors).toEqual([]);
        });
      }
    }
  }

  // Centres of rotation: the TSL section blend turns about each section's centre (the table's last texel).
  const cesiumFile = join(MODELS_DIR, 'CesiumMan.glb');
  test.skipIf(!existsSync(cesiumFile))('CesiumMan.glb, smooth, joints path, centres of rotation: GPU backend = CPU backend, posed', async () => {
    const r = await call<{ backends: string[]; paths: string[]; notes: string[]; vsCpu: Diff[]; vsRest: Diff[]; coverage: number; warnings: string[] }>(
      'check', `/@fs${cesiumFile}`, { smooth: true, centres: true }, [0.5, 1.0, 1.6], undefined, 'joints');
    console.log(`CesiumMan centres: GPU vs CPU ${r.vsCpu.map(pct).join('; ')}; vs the rest pose ${r.vsRest.map(pct).join('; ')}`);
    expect(r.backends.every((b) => b === 'gpu'), r.notes.join('; ')).toBe(true);
    expect(r.paths.every((p) => p === 'joints')).toBe(true);
    expect(r.warnings).toEqual([]);
    for (const d of r.vsCpu) expect(d.image).toBeLessThanOrEqual(PIXEL_SHARE);
    for (const d of r.vsRest) expect(d.covered).toBeGreaterThan(0.05);
    expect(fixture.errors).toEqual([]);
  });

  // Morph targets apply before GCS (three.js's order, the CPU's too): a swelling morph at 0.8 on the human.
  for (const gpuPath of ['joints', 'sections'] as const) {
    test(`default human with a morph target, ${gpuPath} path: GPU backend = CPU backend`, async () => {
      const r = await call<{ backends: string[]; notes: string[]; vsCpu: Diff[]; vsRest: Diff[]; coverage: number }>('check', 'human-morph', {}, [0.3, 0.7], 'walk', gpuPath);
      console.log(`human + morph ${gpuPath}: GPU vs CPU ${r.vsCpu.map(pct).join('; ')}; vs the rest pose ${r.vsRest.map(pct).join('; ')}`);
      expect(r.backends.every((b) => b === 'gpu'), r.notes.join('; ')).toBe(true);
      for (const d of r.vsCpu) expect(d.image).toBeLessThanOrEqual(PIXEL_SHARE);
      for (const d of r.vsRest) expect(d.covered).toBeGreaterThan(0.05);
      expect(fixture.errors).toEqual([]);
    });
  }

  test('default human with a morph target, joints path, centres of rotation: GPU backend = CPU backend', async () => {
    const r = await call<{ backends: string[]; notes: string[]; vsCpu: Diff[]; vsRest: Diff[]; coverage: number }>('check', 'human-morph', { smooth: true, centres: true }, [0.3, 0.7], 'walk', 'joints');
    console.log(`human + morph, centres: GPU vs CPU ${r.vsCpu.map(pct).join('; ')}; vs the rest pose ${r.vsRest.map(pct).join('; ')}`);
    expect(r.backends.every((b) => b === 'gpu'), r.notes.join('; ')).toBe(true);
    for (const d of r.vsCpu) expect(d.image).toBeLessThanOrEqual(PIXEL_SHARE);
    for (const d of r.vsRest) expect(d.covered).toBeGreaterThan(0.05);
    expect(fixture.errors).toEqual([]);
  });

  const cesium = join(MODELS_DIR, 'CesiumMan.glb');
  const soldier = join(MODELS_DIR, 'Soldier.glb');
  const noCesium = !existsSync(cesium), noSoldier = !existsSync(soldier);

  // One source of truth (docs/gpu.md): the GLSL chunk and the TSL function compute the same
  // positions and normals; MeshNormalMaterial paints the normals, so a wrong normal shows too.
  for (const [file, path, missing, time, clip] of [['CesiumMan.glb', cesium, noCesium, 1.0, undefined], ['Soldier.glb', soldier, noSoldier, 0.4, 'Run']] as const) {
    for (const gpuPath of ['joints', 'sections'] as const) {
      for (const smooth of [false, true]) {
        test.skipIf(missing)(`${file}, ${smooth ? 'smooth' : 'plain'}, ${gpuPath} path: GLSL on WebGLRenderer = TSL on WebGPURenderer`, async () => {
          const r = await call<{ diff: Diff; coverage: number; backends: string[] }>('glslVsTsl', `/@fs${path}`, { smooth }, time, clip, gpuPath);
          console.log(`${file} ${smooth ? 'smooth' : 'plain'} ${gpuPath}: GLSL vs TSL ${pct(r.diff)}; coverage ${(100 * r.coverage).toFixed(1)} %`);
          expect(r.backends).toEqual(['gpu', 'gpu']);
          expect(r.coverage).toBeGreaterThan(0.02);
          expect(r.diff.image).toBeLessThanOrEqual(PIXEL_SHARE);
          expect(fixture.errors).toEqual([]);
        });
      }
    }
  }

  test.skipIf(noSoldier)('a crowd of 16 Soldiers: one draw call for the skin, drawn and moving, joint poses uploaded', async () => {
    const r = await call<{ drawCalls: number; coverage: number; moving: number; bytesPerFrame: number; jointCount: number; path: string }>('crowd', `/@fs${soldier}`, 16, 'Run');
    console.log(`crowd of 16: ${r.drawCalls} draw call(s), coverage ${(100 * r.coverage).toFixed(1)} %, ${(100 * r.moving).toFixed(1)} % of pixels change between frames, ${r.bytesPerFrame} bytes per frame (${r.jointCount} joints, ${r.path} path)`);
    expect(r.path).toBe('joints');
    expect(r.drawCalls).toBe(1);
    expect(r.coverage).toBeGreaterThan(0.02);
    expect(r.moving).toBeGreaterThan(0.01);
    // Soldier's clips are rigid with unit scale (docs/gpu.md): the compact joint poses, 24 bytes per joint (half a texel of padding at most).
    expect(r.bytesPerFrame).toBeGreaterThanOrEqual(16 * r.jointCount * 24);
    expect(r.bytesPerFrame).toBeLessThanOrEqual(16 * r.jointCount * 24 + 16);
    expect(fixture.errors).toEqual([]);
  });

  // LBS and DQS on the GPU backend: each vertex blends its own joints in TSL, as on the CPU.
  for (const [name, model, missing, times, clip] of [
    ['the human', 'human-morph', false, [0.3, 0.7], 'walk'],
    ['CesiumMan.glb', `/@fs${cesium}`, noCesium, [0.5, 1.6], undefined],
    ['Soldier.glb', `/@fs${soldier}`, noSoldier, [0.2, 0.55], 'Run'],
  ] as const) {
    for (const method of ['lbs', 'dqs'] as const) {
      test.skipIf(missing)(`${name}, ${method.toUpperCase()} on the GPU backend = the CPU backend, posed`, async () => {
        const r = await call<{ backends: string[]; notes: string[]; vsCpu: Diff[]; vsRest: Diff[]; coverage: number; warnings: string[] }>('check', model, {}, times, clip, 'auto', method);
        console.log(`${name} ${method}: GPU vs CPU ${r.vsCpu.map(pct).join('; ')}; vs the rest pose ${r.vsRest.map(pct).join('; ')}`);
        expect(r.backends.every((b) => b === 'gpu'), r.notes.join('; ')).toBe(true);
        expect(r.notes.every((n) => !n)).toBe(true);
        expect(r.warnings).toEqual([]);
        expect(r.coverage).toBeGreaterThan(0.02);
        for (const d of r.vsCpu) expect(d.image).toBeLessThanOrEqual(PIXEL_SHARE);
        for (const d of r.vsRest) expect(d.covered).toBeGreaterThan(0.05);
        expect(fixture.errors).toEqual([]);
      });
    }
  }

  // The node pass (node-pass-tsl.ts): one fragment per node writes the four float targets; the
  // vertex stage only reads and blends. Its texels against the GLSL pass's (node-pass.ts, itself
  // checked against the CPU in tests/lib/gpu-joints.test.ts) from the same joint poses; a crowd
  // wide enough to span several rows of the targets.
  interface NodePassResult { nodes: number; rows: number; largest: number; scale: number; runs: number[]; vertexNodeMaths: boolean; vertexLoads: number; vertexSizeQueries: number; drawCalls: number; coverage: number }
  for (const [name, model, missing, count, clip, centres] of [
    ['the human', 'human-morph', false, 1, 'walk', false],
    ['the human, centres of rotation', 'human-morph', false, 1, 'walk', true],
    ['CesiumMan ×24', `/@fs${cesium}`, noCesium, 24, undefined, false],
    ['Soldier ×16, centres of rotation', `/@fs${soldier}`, noSoldier, 16, 'Run', true],
  ] as const) {
    test.skipIf(missing)(`node pass, ${name}: once per frame, TSL texels = GLSL texels, no node maths per vertex`, async () => {
      const r = await call<NodePassResult>('nodePass', model, count, { smooth: true, centres }, clip);
      console.log(`node pass ${name}: ${r.nodes} nodes in ${r.rows} row(s); TSL vs GLSL texels within ${r.largest.toExponential(2)} (translations up to ${r.scale.toFixed(3)}); runs ${r.runs.join(', ')}; vertex shader: node maths ${r.vertexNodeMaths}, ${r.vertexLoads} texel loads, ${r.vertexSizeQueries} size queries; ${r.drawCalls} draw call(s)`);
      expect(r.runs).toEqual([1, 1, 2]); // first frame, the same frame drawn again, the next frame
      expect(r.vertexNodeMaths).toBe(false);
      expect(r.vertexLoads).toBeGreaterThan(0);
      expect(r.vertexSizeQueries).toBe(0); // rows flipped once per node coordinate, not per load (texel-tsl.ts)
      expect(r.drawCalls).toBe(1);
      expect(r.coverage).toBeGreaterThan(0.01);
      expect(r.scale).toBeGreaterThan(0);
      expect(r.largest).toBeLessThanOrEqual(1e-5 * Math.max(1, r.scale));
      expect(fixture.errors).toEqual([]);
    });
  }

  // DQS's joint pass (node-pass-tsl.ts): two texels per joint (quaternion, dual part, uniform scale;
  // the scale part K), TSL against GLSL from the same joint poses; the vertex stage blends them,
  // the quaternion-only way where every joint of the vertex is a uniform scale, else with the
  // scale parts (the hips scaled non-uniformly: every joint below them).
  interface DqsPassResult { backends: string[]; joints: number; rows: number; largest: number; scale: number; rigid: number; runs: number[]; vertexJointMaths: boolean; vsCpu: Diff; vsRest: Diff; coverage: number }
  for (const [name, model, missing, times, clip, boneScale] of [
    ['the human', 'human-morph', false, [0.3, 0.7], 'walk', undefined],
    ['the human, hips scaled (1.3, 0.7, 1.1)', 'human-morph', false, [0.3, 0.7], 'walk', [1.3, 0.7, 1.1]],
    ['Soldier.glb', `/@fs${soldier}`, noSoldier, [0.2, 0.55], 'Run', undefined],
  ] as const) {
    test.skipIf(missing)(`DQS joint pass, ${name}: once per frame, TSL texels = GLSL texels, GPU = CPU`, async () => {
      const r = await call<DqsPassResult>('dqsPass', model, times, clip, boneScale);
      console.log(`DQS joint pass ${name}: ${r.joints} joints (${r.rigid} a uniform scale) in ${r.rows} row(s); TSL vs GLSL texels within ${r.largest.toExponential(2)} (translations' dual parts up to ${r.scale.toFixed(3)}); runs ${r.runs.join(', ')}; ` +
        `vertex shader joint maths ${r.vertexJointMaths}; GPU vs CPU ${pct(r.vsCpu)}; vs the rest pose ${pct(r.vsRest)}`);
      expect(r.backends).toEqual(r.backends.map(() => 'gpu'));
      expect(r.runs).toEqual([1, 2, 2, 3]); // the rest pose, a frame, the same frame drawn again, the next frame
      expect(r.vertexJointMaths).toBe(false);
      expect(r.scale).toBeGreaterThan(0);
      expect(r.largest).toBeLessThanOrEqual(1e-5 * Math.max(1, r.scale));
      if (boneScale) expect(r.rigid).toBeLessThan(r.joints / 2); // most joints take the scale blend
      else expect(r.rigid).toBe(r.joints); // a clip without scale: every joint the quaternion-only way
      expect(r.coverage).toBeGreaterThan(0.02);
      expect(r.vsCpu.image).toBeLessThanOrEqual(PIXEL_SHARE);
      expect(r.vsRest.covered).toBeGreaterThan(0.05);
      expect(fixture.errors).toEqual([]);
    });
  }

  interface Fallback { before: string; after: string; note: string; warnings: string[]; vsCpu: Diff; firstVsCpu: Diff; firstCoverage: number; error: string }
  const fallback = (which: string) => call<Fallback>('fallback', `/@fs${cesium}`, which);
  /** Ran on the CPU from the first draw on: a note, one warning, and the right picture from the second frame. */
  function expectCpuFallback(r: Fallback, note: RegExp): void {
    console.log(`  → ${r.before} then ${r.after}; note: ${r.note}; warnings: ${r.warnings.length}; second frame vs CPU ${r.vsCpu.image >= 0 ? pct(r.vsCpu) : 'not drawn'}; first frame coverage ${r.firstCoverage}`);
    expect(r.error).toBe('');
    expect(r.after).toBe('cpu');
    expect(r.note).toMatch(note);
    expect(r.warnings).toHaveLength(1);
    expect(r.warnings[0]).toMatch(note);
  }

  test.skipIf(noCesium)("gcs-skin/three's GPU backend drawn by WebGPURenderer: the CPU backend, a note naming gcs-skin/webgpu, one warning", async () => {
    const r = await fallback('three-on-webgpu');
    expectCpuFallback(r, /gcs-skin\/webgpu/);
    expect(r.before).toBe('gpu');
    // The first draw: WebGPURenderer draws the object's new (CPU) geometry: the right picture, never the bind pose.
    expect(r.firstVsCpu.image).toBeLessThanOrEqual(PIXEL_SHARE);
    expect(r.vsCpu.image).toBeLessThanOrEqual(PIXEL_SHARE);
  });

  test.skipIf(noCesium)('gcs-skin/webgpu drawn by a WebGLRenderer without nodes handler: the CPU backend, a note naming the fix, one warning', async () => {
    const r = await fallback('webgpu-on-webgl');
    expectCpuFallback(r, /setNodesHandler/);
    expect(r.before).toBe('gpu');
    expect(r.firstCoverage).toBe(0); // the first draw shows nothing rather than the bind pose
    expect(r.vsCpu.image).toBeLessThanOrEqual(PIXEL_SHARE);
  });

  test.skipIf(noCesium)('gcs-skin/webgpu drawn by a WebGLRenderer with WebGLNodesHandler: works on the GPU', async () => {
    const r = await fallback('webgpu-on-webgl-handler');
    console.log(`  → ${r.before} then ${r.after}; warnings ${r.warnings.length}; second frame vs CPU ${pct(r.vsCpu)}; error '${r.error}'`);
    expect(r.error).toBe('');
    expect(r.after).toBe('gpu');
    expect(r.warnings).toEqual([]);
    expect(r.firstCoverage).toBeGreaterThan(0.02);
    expect(r.vsCpu.image).toBeLessThanOrEqual(PIXEL_SHARE);
  });

  test.skipIf(noCesium)('gcs-skin/webgpu with a custom ShaderMaterial: the CPU backend, a note, one warning', async () => {
    const r = await fallback('webgpu-custom-shader');
    expect(r.before).toBe('cpu');
    expectCpuFallback(r, /custom shader/);
  });

  test.skipIf(noCesium)('gcs-skin/webgpu with a node material that has its own positionNode: the CPU backend, a note, one warning', async () => {
    const r = await fallback('webgpu-node-position');
    expect(r.before).toBe('cpu');
    expectCpuFallback(r, /its own positionNode/);
    expect(r.vsCpu.image).toBe(0); // both pictures are the CPU backend's
  });

  test.skipIf(noCesium)('gcs-skin/webgpu with a plain node material: extended, on the GPU, the CPU picture', async () => {
    const r = await fallback('webgpu-node-plain');
    console.log(`  → ${r.before} then ${r.after}; second frame vs CPU ${pct(r.vsCpu)}`);
    expect(r.before).toBe('gpu');
    expect(r.after).toBe('gpu');
    expect(r.warnings).toEqual([]);
    expect(r.vsCpu.image).toBeLessThanOrEqual(PIXEL_SHARE);
  });

  for (const entry of ['webgpu', 'three'] as const) {
    test.skipIf(noCesium)(`a gcs-skin/${entry} crowd drawn by the other renderer: update() throws a GcsError naming the fix`, async () => {
      const r = await call<{ error: string; code: string; warnings: string[] }>('crowdOnWrongRenderer', `/@fs${cesium}`, entry);
      console.log(`  → ${r.code}: ${r.error}`);
      expect(r.code).toBe('INVALID_ARGUMENT');
      expect(r.error).toMatch(entry === 'webgpu' ? /setNodesHandler|WebGPURenderer/ : /gcs-skin\/webgpu/);
      expect(r.warnings).toHaveLength(1);
    });
  }
});

const CESIUM_8_SOURCE = join(MODELS_DIR, 'CesiumMan.glb');
const noCesium8 = existsSync(CESIUM_8_SOURCE) ? '' : `skipped: ${CESIUM_8_SOURCE} is absent (the shared test models are not on this machine)`;
if (noCesium8) console.log(noCesium8);

/** 8 influences: at most 0.5 % of the character's pixels may differ by more than 8/255. */
const CHARACTER_PIXEL_SHARE = 0.005;

describe.skipIf(!!reason || !!noCesium8)('8 influences per vertex on WebGPURenderer (CesiumMan, weights spread onto 5–8 joints)', () => {
  const file = join(ROOT, 'build', 'test-models', 'cesium-8-webgpu.glb');
  beforeAll(async () => {
    mkdirSync(join(ROOT, 'build', 'test-models'), { recursive: true });
    await eightInfluenceGlb(CESIUM_8_SOURCE, file);
  });
  for (const gpuPath of ['joints', 'sections'] as const) {
    for (const smooth of [false, true]) {
      const mode = `${smooth ? 'smooth' : 'plain'}, ${gpuPath} path`;
      test(`${mode}: GPU backend and crowd (TSL) = CPU backend; without the second set the picture differs`, async () => {
        const r = await call<{ backends: string[]; paths: string[]; tableSlots: number[]; vsCpu: Diff; vsFour: Diff; crowdVsCpu: Diff; coverage: number }>(
          'influences', `/@fs${file}`, { smooth }, 1.0, gpuPath);
        console.log(`CesiumMan 8 influences ${mode} (table ${r.tableSlots.join(', ')}): GPU vs CPU ${pct(r.vsCpu)}; crowd vs CPU ${pct(r.crowdVsCpu)}; vs the first 4 only ${pct(r.vsFour)}`);
        expect(r.backends).toEqual(['gpu']);
        expect(r.paths).toEqual([gpuPath, gpuPath]);
        expect(r.tableSlots).toEqual(gpuPath === 'joints' ? [8, 8] : [4, 4]);
        expect(r.coverage).toBeGreaterThan(0.02);
        // Of the character's own pixels (the image-wide 1 % would not see the second set: cut to 4
        // it moves 3–4 % of the character's pixels, 0.4–0.5 % of the image).
        expect(r.vsCpu.covered).toBeLessThanOrEqual(CHARACTER_PIXEL_SHARE);
        expect(r.crowdVsCpu.covered).toBeLessThanOrEqual(CHARACTER_PIXEL_SHARE);
        expect(r.vsFour.covered).toBeGreaterThan(CHARACTER_PIXEL_SHARE); // the comparison sees the second set
        expect(fixture.errors).toEqual([]);
      });
    }
  }
});

/** Velocity: at most this share of the pixels either skin covers may differ from three.js's own skinning by more than 1 px (or 10 %). */
const VELOCITY_SHARE = 0.05;

describe.skipIf(!!reason || !!noCesium8)('velocity on WebGPURenderer: a velocity MRT pass (pass + mrt({ output, velocity }))', () => {
  // A crowd in plain mode: with velocity, three.js adds the previous instance matrices (4 vertex
  // attributes) to the crowd's 4 + 4, and the smooth mode's two section attributes would pass
  // WebGL2's 16 (docs/gpu.md).
  // The joints path, the crowd and DQS read the previous frame's nodes (or joint parts) from the node
  // pass's targets of the run before; the sections path from the previous frame's section texels.
  for (const kind of ['joints', 'sections', 'cpu', 'crowd', 'dqs'] as const) {
    const what = kind === 'crowd' ? 'a crowd of one (plain)' : kind === 'cpu' ? 'CPU backend (previous positions kept by the core)' : kind === 'dqs' ? 'GPU backend, DQS' : `GPU backend, ${kind} path`;
    test(`CesiumMan walking, ${what}: velocity as three.js's skinning writes it; paused, zero`, async () => {
      const r = await call<{ backends: string[]; vsThree: number; moving: number; largest: number; pausedLargest: number; threePausedLargest: number }>(
        'velocity', `/@fs${CESIUM_8_SOURCE}`, kind, 0.5, 1 / 30, kind === 'crowd' ? { smooth: false } : {});
      console.log(`velocity ${kind}: ${(100 * r.vsThree).toFixed(2)} % of the pixels differ from three.js's skinning (> 1 px or 10 %); ${(100 * r.moving).toFixed(1)} % of ours move > 1 px, the most ${r.largest.toFixed(2)} px; paused: ours ${r.pausedLargest.toExponential(2)} px, three's ${r.threePausedLargest.toExponential(2)} px`);
      expect(r.backends.every((b) => b === (kind === 'cpu' ? 'cpu' : 'gpu'))).toBe(true);
      expect(r.moving).toBeGreaterThan(0.2); // a walk, not a still picture
      expect(r.vsThree).toBeLessThanOrEqual(VELOCITY_SHARE);
      expect(r.pausedLargest).toBeLessThan(0.01);
      expect(fixture.errors).toEqual([]);
    });
  }
});

const TANGENT_FILE = join(ROOT, 'build', 'test-models', 'cesium-tangents.glb');

describe.skipIf(!!reason || !!noCesium8)('a normal-mapped character (CesiumMan with MikkTSpace tangents): tangents deformed in the core pass', () => {
  beforeAll(async () => {
    mkdirSync(join(ROOT, 'build', 'test-models'), { recursive: true });
    const { tangentGlb } = await import('../helpers/tangents-glb.js');
    expect(await tangentGlb(CESIUM_8_SOURCE, TANGENT_FILE)).toBeGreaterThan(0);
  });
  for (const which of ['webgl', 'webgpu'] as const) {
    test(`${which === 'webgl' ? 'WebGLRenderer (gcs-skin/three)' : 'WebGPURenderer (gcs-skin/webgpu)'}: LBS lit as three.js's skinning; GCS on the GPU (both paths) as on the CPU`, async () => {
      const r = await call<{ tangents: boolean[]; lbsVsThree: Diff; mapShows: Diff; gpuVsCpu: Diff[]; coverage: number }>('normalMapped', `/@fs${TANGENT_FILE}`, which, 1.0);
      console.log(`normal-mapped CesiumMan, ${which}: our LBS vs three.js's skinning ${pct(r.lbsVsThree)}; the normal map changes ${pct(r.mapShows)}; GCS GPU vs CPU ${r.gpuVsCpu.map(pct).join('; ')}; coverage ${(100 * r.coverage).toFixed(1)} %`);
      expect(r.tangents.every(Boolean)).toBe(true);
      expect(r.coverage).toBeGreaterThan(0.02);
      expect(r.mapShows.covered).toBeGreaterThan(0.1); // the lighting depends on the tangent frame
      expect(r.lbsVsThree.image).toBeLessThanOrEqual(PIXEL_SHARE);
      for (const d of r.gpuVsCpu) expect(d.image).toBeLessThanOrEqual(PIXEL_SHARE);
      expect(fixture.errors).toEqual([]);
    });
  }
});
