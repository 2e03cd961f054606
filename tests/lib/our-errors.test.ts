// Only our errors, case by case where a rule has a reason of its own: sizes bounded before anything
// is allocated (bakeClip), sources checked by type (loadCharacter, initGcsSkin), a module's exports
// checked before use, decoder input checked before the decoder runs (a Draco attribute without
// its id), integers where the data is indices (parents).
import { describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin } from '../../web/lib/index.js';
import { GltfError, loaderFailure } from '../../web/lib/gltf/error.js';
import { bakeClip, GcsCrowd } from '../../web/lib/crowd.js';
import { CORE_FUNCTIONS } from '../../web/lib/core-check.js';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { loadCharacter } from '../../packages/cli/src/gltf.js';
import { compressGlb } from '../helpers/compressed-gltf.js';
import { splitGlb, packGlb } from '../helpers/glb.js';
import { makeTube } from '../helpers/cylinder.js';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

const human = createHuman({ vertices: 2000 });

/** Runs `f` (sync or async) and returns what it threw. */
async function thrown(f: () => unknown): Promise<unknown> {
  try {
    await f();
  } catch (e) {
    return e;
  }
  throw new Error('expected a throw');
}

describe('sizes and durations bounded before allocating', () => {
  test('bakeClip: a clip of a million seconds, of NaN or infinite seconds, a non-clip', async () => {
    const long = new THREE.AnimationClip('long', 1e6, []);
    const e = await thrown(() => bakeClip(human.mesh, long));
    expect(e).toBeInstanceOf(GcsError);
    expect(e).toMatchObject({ code: 'OUT_OF_RANGE', message: expect.stringMatching(/needs 60000000 frames .*lower fps/) });
    for (const duration of [NaN, Infinity, -1]) {
      const clip = new THREE.AnimationClip('odd', 1, []);
      clip.duration = duration;
      expect(await thrown(() => bakeClip(human.mesh, clip))).toMatchObject({ code: 'OUT_OF_RANGE', message: expect.stringMatching(/finite, non-negative time/) });
    }
    expect(await thrown(() => bakeClip(human.mesh, {} as THREE.AnimationClip))).toMatchObject({ code: 'INVALID_ARGUMENT', message: expect.stringMatching(/AnimationClip/) });
    expect(await thrown(() => bakeClip(human.mesh, human.clips[0], '60' as unknown as number))).toMatchObject({ code: 'OUT_OF_RANGE' });
    // A clip that fits still bakes.
    const baked = bakeClip(human.mesh, human.clips[0], 10);
    expect(baked.frames).toBe(Math.max(1, Math.round(human.clips[0].duration * 10)));
    expect(baked.data.every(Number.isFinite)).toBe(true);
  });

  test('createRig: arrays that cannot fit in wasm memory are refused before any loop', async () => {
    const gcs = await initGcsSkin();
    const input = { ...makeTube().input, indices: { length: 2 ** 40 } as ArrayLike<number> };
    const started = performance.now();
    expect(await thrown(() => gcs.createRig(input))).toMatchObject({ code: 'OUT_OF_MEMORY', message: expect.stringMatching(/more than wasm memory/) });
    expect(performance.now() - started).toBeLessThan(1000);
  });

  test('createRig: a parent of 1.5 is refused, not truncated to 1', async () => {
    const gcs = await initGcsSkin();
    const input = makeTube().input;
    input.parents = [-1, 0, 1.5];
    expect(await thrown(() => gcs.createRig(input))).toMatchObject({ code: 'JOINT_OUT_OF_RANGE', message: 'joint 2 has parent 1.5: a parent is a joint index (a whole number) or -1 for a root' });
  });

  test('GcsCrowd without a count: one instance, count 1', async () => {
    const gcs = await initGcsSkin();
    const crowd = new (GcsCrowd as unknown as new (g: unknown, m: THREE.SkinnedMesh) => GcsCrowd)(gcs, human.mesh);
    expect(crowd.count).toBe(1);
    expect(crowd.mesh.count).toBe(1);
    expect(crowd.offsetOf(0)).toBe(0);
    crowd.dispose();
  });
});

describe('sources checked by type, modules by their exports', () => {
  test('loadCharacter of an http: URL, of a number: GltfError in our words', async () => {
    const e = await thrown(() => loadCharacter(new URL('http://example.invalid/a.glb')));
    expect(e).toBeInstanceOf(GltfError);
    expect(e).toMatchObject({ code: 'UNREADABLE', message: expect.stringMatching(/^http:\/\/example\.invalid\/a\.glb is not a file: URL: .*pass its bytes$/) });
    expect(await thrown(() => loadCharacter(42 as unknown as string))).toMatchObject({ code: 'UNREADABLE', message: expect.stringMatching(/got 42$/) });
  });

  test('initGcsSkin with a module lacking our exports names the missing export', async () => {
    // A hand-made module: memory and _initialize only (as a wasm built from other sources has).
    const name = (s: string) => [s.length, ...Buffer.from(s)];
    const exports = [2, ...name('_initialize'), 0, 0, ...name('memory'), 2, 0];
    const bytes = new Uint8Array([
      0x00, 0x61, 0x73, 0x6d, 0x01, 0x00, 0x00, 0x00,
      0x01, 0x04, 0x01, 0x60, 0x00, 0x00, // type () → ()
      0x03, 0x02, 0x01, 0x00, // one function
      0x05, 0x03, 0x01, 0x00, 0x01, // one page of memory
      0x07, exports.length, ...exports,
      0x0a, 0x04, 0x01, 0x02, 0x00, 0x0b,
    ]);
    const e = await thrown(() => initGcsSkin({ wasm: bytes }));
    expect(e).toBeInstanceOf(GcsError);
    expect(e).toMatchObject({ code: 'WASM_LOAD', message: `could not load gcs-skin.wasm: the module lacks ${CORE_FUNCTIONS.length} exports, first 'gcs_alloc': it is not gcs-skin.wasm (or from a version with other functions)` });
    expect(await thrown(() => initGcsSkin({ wasm: new Uint8Array([1, 2, 3]) }))).toMatchObject({ code: 'WASM_LOAD', message: 'could not load gcs-skin.wasm: the bytes are not a WebAssembly module (they do not compile)' });
    expect(await thrown(() => initGcsSkin({ wasm: 5 as unknown as string }))).toMatchObject({ code: 'WASM_LOAD', message: expect.stringMatching(/wasm must be a URL, a path/) });
  });

  test('the list of core functions is the header\'s', () => {
    const header = readFileSync(fileURLToPath(new URL('../../wasm/include/gcs_skin.h', import.meta.url)), 'utf8').replace(/\/\*[\s\S]*?\*\//g, '');
    const declared = [...header.matchAll(/^(?:const\s+)?[A-Za-z_]\w*\s*\**\s*(gcs_\w+)\s*\(/gm)].map((m) => m[1]);
    expect([...CORE_FUNCTIONS].sort()).toEqual([...new Set(declared)].sort());
  });
});

describe('decoder input checked before the decoder runs', () => {
  test('a loader\'s engine error is never the LOAD_FAILED sentence; its own message is', () => {
    expect(loaderFailure(new RangeError('Invalid typed array length: 50008'))).toBe('the loader failed inside on data the checks let through (please report the file)');
    expect(loaderFailure(new TypeError("Cannot read properties of undefined (reading 'count')"))).not.toMatch(/Cannot read/);
    expect(loaderFailure(new Error('THREE.GLTFLoader: Unsupported asset.\nglTF versions >=2.0 are supported.'))).toBe('THREE.GLTFLoader: Unsupported asset. glTF versions >=2.0 are supported.');
  });

  test('a Draco primitive whose JOINTS_0 has no Draco attribute id (nor a buffer view): BAD_STRUCTURE, no engine text', async () => {
    const glb = await compressGlb(await humanToGlb(human), 'draco');
    const { json, bin } = splitGlb(glb);
    const prim = (json.meshes as { primitives: { extensions: { KHR_draco_mesh_compression: { attributes: Record<string, number> } } }[] }[])[0].primitives[0];
    delete prim.extensions.KHR_draco_mesh_compression.attributes.JOINTS_0;
    const e = await thrown(() => loadCharacter(packGlb(json, bin), { name: 'no-id.glb' }));
    expect(e).toBeInstanceOf(GltfError);
    expect(e).toMatchObject({ code: 'BAD_STRUCTURE', message: expect.stringMatching(/JOINTS_0 has neither a buffer view nor a Draco attribute id: its data is nowhere/) });
  });
});

describe('one validation for one input, wherever it is read', () => {
  /** The human's GLB with one morph target on its mesh whose delta at vertex 5 is NaN. */
  async function nanMorphGlb(): Promise<Uint8Array> {
    const { json, bin } = splitGlb(await humanToGlb(human));
    const prim = json.meshes[0].primitives[0];
    const count = json.accessors[prim.attributes.POSITION].count as number;
    const deltas = new Float32Array(3 * count);
    deltas[16] = NaN;
    const offset = bin.length;
    json.buffers[0].byteLength = offset + deltas.byteLength;
    json.bufferViews.push({ buffer: 0, byteOffset: offset, byteLength: deltas.byteLength });
    json.accessors.push({ bufferView: json.bufferViews.length - 1, componentType: 5126, count, type: 'VEC3' });
    prim.targets = [{ POSITION: json.accessors.length - 1 }];
    json.meshes[0].weights = [0];
    const joined = new Uint8Array(offset + deltas.byteLength);
    joined.set(bin);
    joined.set(new Uint8Array(deltas.buffer), offset);
    return packGlb(json, joined);
  }

  test('a NaN morph delta: NON_FINITE with one sentence from the library, loadCharacter and the report alike', async () => {
    const glb = await nanMorphGlb();
    const sentence = /^morph target 0 has a NaN or infinite position delta at vertex 5$/;
    const gcs = await initGcsSkin();
    const { loadGltfFile } = await import('../../packages/cli/src/gltf-node.js');
    const model = await loadGltfFile(glb, 'nan-morph.glb');
    const { SkinDeformer } = await import('../../web/lib/three.js');
    expect(await thrown(() => new SkinDeformer(gcs, model.skinnedMeshes[0]))).toMatchObject({ code: 'NON_FINITE', message: expect.stringMatching(sentence) });
    expect(await thrown(() => loadCharacter(glb, { name: 'nan-morph.glb' }))).toMatchObject({ code: 'NON_FINITE', message: expect.stringMatching(sentence) });
    const { mkdtempSync, writeFileSync } = await import('node:fs');
    const { tmpdir } = await import('node:os');
    const file = `${mkdtempSync(`${tmpdir()}/gcs-morph-`)}/nan-morph.glb`;
    writeFileSync(file, glb);
    const { report } = await import('../../packages/cli/src/report.js');
    expect(await thrown(() => report(file, { frames: 1, timeMs: 1 }, gcs))).toMatchObject({ code: 'NON_FINITE', message: expect.stringMatching(/morph target 0 has a NaN or infinite position delta at vertex 5$/) });
  });
});
