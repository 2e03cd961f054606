// Compressed glTF files read like their uncompressed original: copies of the default human
// (humanToGlb) and of CesiumMan (../shared/models, skipped with a printed reason when absent) are
// written here with @gltf-transform/functions — quantize(), meshopt() with meshoptimizer's
// encoder, draco() (sequential and edgebreaker) — and `gcs-skin report --json` must give the same
// figures, within quantisation. Then: 8 influences per vertex (JOINTS_1/WEIGHTS_1) read whole, a
// broken meshopt stream reported in one line, and other required extensions still refused.
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it, vi } from 'vitest';
import { NodeIO, type Document } from '@gltf-transform/core';
import { EXTMeshoptCompression, KHRDracoMeshCompression, KHRMeshQuantization } from '@gltf-transform/extensions';
import { draco, meshopt, quantize } from '@gltf-transform/functions';
import { MeshoptDecoder, MeshoptEncoder } from 'meshoptimizer';
// draco3dgltf (CommonJS, no types): createEncoderModule / createDecoderModule
// @ts-expect-error: the package ships no types
import draco3d from 'draco3dgltf';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { run, type Report } from '../../packages/cli/src/report.js';
import { loadCharacter } from '../../packages/cli/src/gltf.js';
import { MODELS_DIR } from '../helpers/models.js';
import { compressGlb } from '../helpers/compressed-gltf.js';

let dir: string;
let io: NodeIO;
const sources: { name: string; file: string }[] = [];
const CESIUM = join(MODELS_DIR, 'CesiumMan.glb');

/** Each compression, as a gltf-transform transform; `exactVertices`: the vertex count survives. */
const VARIANTS = [
  { name: 'quantize', transform: () => quantize(), exactVertices: true, extension: 'KHR_mesh_quantization' },
  { name: 'meshopt', transform: () => meshopt({ encoder: MeshoptEncoder }), exactVertices: true, extension: 'EXT_meshopt_compression' },
  { name: 'draco-sequential', transform: () => draco({ method: 'sequential' }), exactVertices: true, extension: 'KHR_draco_mesh_compression' },
  { name: 'draco-edgebreaker', transform: () => draco(), exactVertices: false, extension: 'KHR_draco_mesh_compression' },
] as const;

/** `gcs-skin report --json` in-process: the exit code, the parsed report and stderr. */
async function reportJson(file: string): Promise<{ code: number; report: Report; stderr: string }> {
  let stdout = '', stderr = '';
  const spies = [
    vi.spyOn(process.stderr, 'write').mockImplementation((s: string | Uint8Array) => ((stderr += String(s)), true)),
    vi.spyOn(console, 'warn').mockImplementation((...a: unknown[]) => void (stderr += a.join(' ') + '\n')),
    vi.spyOn(console, 'log').mockImplementation((...a: unknown[]) => void (stdout += a.join(' ') + '\n')),
  ];
  try {
    const code = await run([file, '--json', '--frames', '8', '--time-ms', '4']);
    return { code, report: code === 0 ? JSON.parse(stdout) : (null as never), stderr };
  } finally {
    for (const s of spies) s.mockRestore();
  }
}

async function compress(source: string, variant: (typeof VARIANTS)[number]): Promise<string> {
  const doc = await io.read(source);
  await doc.transform(variant.transform());
  const out = join(dir, `${source.split('/').pop()!.replace(/\.glb$/, '')}-${variant.name}.glb`);
  await io.write(out, doc);
  return out;
}

beforeAll(async () => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-compressed-'));
  await Promise.all([MeshoptEncoder.ready, MeshoptDecoder.ready]);
  const quiet = { debug() {}, info() {}, warn() {}, error: (t: string) => console.error(t), verbosity: 0 };
  io = new NodeIO()
    .setLogger(quiet as never)
    .registerExtensions([KHRMeshQuantization, EXTMeshoptCompression, KHRDracoMeshCompression])
    .registerDependencies({
      'meshopt.encoder': MeshoptEncoder, 'meshopt.decoder': MeshoptDecoder,
      'draco3d.encoder': await draco3d.createEncoderModule(), 'draco3d.decoder': await draco3d.createDecoderModule(),
    });
  const human = join(dir, 'human.glb');
  writeFileSync(human, await humanToGlb(createHuman({ vertices: 3000 })));
  sources.push({ name: 'the default human', file: human });
  if (existsSync(CESIUM)) sources.push({ name: 'CesiumMan', file: CESIUM });
  else console.log(`compressed CesiumMan: skipped: ${CESIUM} is absent (the shared test models are not on this machine)`);
});
afterAll(() => rmSync(dir, { recursive: true, force: true }));

/** |a − b| within `abs` or `rel` of b. */
function near(a: number | null, b: number | null, abs: number, rel: number, what: string) {
  expect(a === null, what).toBe(b === null);
  if (a === null || b === null) return;
  expect(Math.abs(a - b), `${what}: ${a} vs ${b}`).toBeLessThanOrEqual(Math.max(abs, rel * Math.abs(b)));
}

describe('compressed copies report the same figures as the original', () => {
  for (const which of ['the default human', 'CesiumMan'])
    it(which, async (ctx) => {
      const source = sources.find((s) => s.name === which);
      if (!source) return ctx.skip(); // reason printed in beforeAll
      const original = await reportJson(source.file);
      expect(original.code, original.stderr).toBe(0);
      for (const variant of VARIANTS) {
        const file = await compress(source.file, variant);
        const json = JSON.parse(readFileSync(file).subarray(20, 20 + readFileSync(file).readUInt32LE(12)).toString());
        expect(json.extensionsRequired, variant.name).toContain(variant.extension);
        const { code, report: r, stderr } = await reportJson(file);
        expect(code, `${variant.name}: ${stderr}`).toBe(0);
        expect(stderr, variant.name).toBe('');
        const a = r, b = original.report;
        expect(a.warnings, variant.name).toEqual([]);
        near(a.character.height, b.character.height, 0, 1e-3, `${variant.name} height`);
        expect(a.meshes.length).toBe(b.meshes.length);
        a.meshes.forEach((m, i) => {
          const o = b.meshes[i];
          const at = `${which} ${variant.name} '${m.name}'`;
          expect(m.counts.triangles, at).toBe(o.counts.triangles);
          expect(m.counts.joints, at).toBe(o.counts.joints);
          expect(m.counts.parts, at).toBe(o.counts.parts);
          if (variant.exactVertices) expect(m.counts.vertices, at).toBe(o.counts.vertices);
          else expect(m.counts.vertices, at).toBeGreaterThanOrEqual(o.counts.vertices);
          // Weights quantized to 8 bits fall in slightly different bins.
          near(m.counts.sections, o.counts.sections, 2, 0.05, `${at} sections`);
          near(m.height * m.worldScale, o.height * o.worldScale, 0, 1e-3, `${at} height`);
          expect(m.clips.map((c) => [c.name, c.frames]), at).toEqual(o.clips.map((c) => [c.name, c.frames]));
          for (const c of m.clips) near(c.duration, o.clips.find((x) => x.name === c.name)!.duration, 1e-3, 0, `${at} duration`);
          for (const [method, x] of Object.entries(m.methods)) {
            const y = o.methods[method as keyof typeof o.methods];
            expect(x.available, `${at} ${method}`).toBe(y.available);
            if (!x.fidelity || !y.fidelity) continue;
            const f = x.fidelity, g = y.fidelity;
            expect(f.nonFinite, `${at} ${method}`).toBe(0);
            // Distances in % of the height: positions quantized to 14 bits (~0.006 %), rotations to
            // 16, weights to 8 (quantize, meshopt) or 12 (Draco), which moves rigid vertices a little.
            near(f.rigidError, g.rigidError, 0.05, 0.02, `${at} ${method} rigidError`);
            near(f.dqsP95, g.dqsP95, 0.02, 0.1, `${at} ${method} dqsP95`);
            // The max is one vertex's figure: 8-bit weights move a vertex of the default GCS to other
            // nodes (its interpolation is exact at nodes, 1/64 of weight apart), so it moves more than the p95.
            near(f.dqsMax, g.dqsMax, 0.08, 0.1, `${at} ${method} dqsMax`);
            near(f.seamGap, g.seamGap, 0.05, 0, `${at} ${method} seamGap`);
            expect(f.normalOffUnit, `${at} ${method}`).toBeLessThan(1e-3);
          }
        });
      }
    });
});

describe('KTX2 textures (KHR_texture_basisu, required)', () => {
  it('read, the texture dropped: the same counts as the original, no warning', async () => {
    const file = join(dir, 'human-ktx2.glb');
    writeFileSync(file, await compressGlb(readFileSync(sources[0].file), 'ktx2'));
    const [a, b] = [await reportJson(file), await reportJson(sources[0].file)];
    expect(a.code, a.stderr).toBe(0);
    expect(a.stderr).toBe('');
    expect(a.report.warnings).toEqual([]);
    expect(a.report.meshes.map((m) => m.counts)).toEqual(b.report.meshes.map((m) => m.counts));
  });
});

describe('8 influences per vertex', () => {
  it('JOINTS_1/WEIGHTS_1: all eight read (rigInput.influences = 8), no warning', async () => {
    const doc: Document = await io.read(sources[0].file);
    const prim = doc.getRoot().listMeshes()[0].listPrimitives()[0];
    const J = doc.getRoot().listSkins()[0].listJoints().length;
    const j0 = prim.getAttribute('JOINTS_0')!, w0 = prim.getAttribute('WEIGHTS_0')!;
    const V = j0.getCount();
    // Eight influences: the file's four scaled by 0.9, and four more of 0.05, 0.03, 0.015, 0.005.
    const extraW = [0.05, 0.03, 0.015, 0.005];
    const joints0 = new Uint16Array(4 * V), weights0 = new Float32Array(4 * V);
    const joints1 = new Uint16Array(4 * V), weights1 = new Float32Array(4 * V);
    const expected: Map<number, number>[] = [];
    const je: number[] = [], we: number[] = [];
    for (let v = 0; v < V; v++) {
      j0.getElement(v, je);
      w0.getElement(v, we);
      const m = new Map<number, number>();
      for (let c = 0; c < 4; c++) {
        joints0[4 * v + c] = je[c];
        weights0[4 * v + c] = 0.9 * we[c];
        if (we[c] > 0) m.set(je[c], (m.get(je[c]) ?? 0) + 0.9 * we[c]);
        joints1[4 * v + c] = (v + 7 * c + 1) % J;
        weights1[4 * v + c] = extraW[c];
        m.set((v + 7 * c + 1) % J, (m.get((v + 7 * c + 1) % J) ?? 0) + extraW[c]);
      }
      expected.push(m);
    }
    const acc = (a: Uint16Array<ArrayBuffer> | Float32Array<ArrayBuffer>) => doc.createAccessor().setType('VEC4').setArray(a).setBuffer(j0.getBuffer());
    prim.setAttribute('JOINTS_0', acc(joints0)).setAttribute('WEIGHTS_0', acc(weights0));
    prim.setAttribute('JOINTS_1', acc(joints1)).setAttribute('WEIGHTS_1', acc(weights1));
    const file = join(dir, 'human-8.glb');
    await io.write(file, doc);

    const character = await loadCharacter(file);
    expect(character.warnings).toEqual([]);
    const { joints, weights, influences } = character.meshes[0].rigInput;
    expect(influences).toBe(8);
    let worst = 0;
    for (let v = 0; v < V; v++) {
      const got = new Map<number, number>();
      let sum = 0;
      for (let c = 0; c < 8; c++) {
        sum += weights[8 * v + c];
        if (weights[8 * v + c] > 0) got.set(joints[8 * v + c], (got.get(joints[8 * v + c]) ?? 0) + weights[8 * v + c]);
      }
      expect(Math.abs(sum - 1)).toBeLessThan(1e-5);
      expect([...got.keys()].sort()).toEqual([...expected[v].keys()].sort());
      for (const [j, w] of expected[v]) worst = Math.max(worst, Math.abs(got.get(j)! - w));
    }
    expect(worst).toBeLessThan(1e-5);

    // The command reads it too: every vertex has more than 4 influences.
    const { code, report: r, stderr } = await reportJson(file);
    expect(code, stderr).toBe(0);
    expect(r.warnings).toEqual([]);
    expect(r.meshes[0].counts.influences).toBe(8);
    expect(r.meshes[0].counts.moreThan4Influences).toBeGreaterThan(0.9 * V);
  });
});

describe('broken or unsupported compressed files: one line, exit code 2', () => {
  async function oneLine(file: string): Promise<string> {
    let stderr = '', stdout = '';
    const spies = [
      vi.spyOn(process.stderr, 'write').mockImplementation((s: string | Uint8Array) => ((stderr += String(s)), true)),
      vi.spyOn(console, 'warn').mockImplementation((...a: unknown[]) => void (stderr += a.join(' ') + '\n')),
      vi.spyOn(console, 'log').mockImplementation((...a: unknown[]) => void (stdout += a.join(' ') + '\n')),
    ];
    let code: number;
    try {
      code = await run([file, '--frames', '1', '--time-ms', '1']);
    } finally {
      for (const s of spies) s.mockRestore();
    }
    expect(code).toBe(2);
    expect(stdout).toBe('');
    expect(stderr.trimEnd().split('\n')).toHaveLength(1);
    return stderr.trimEnd();
  }

  /** The GLB at `file` with its JSON changed by `edit`. */
  function edited(file: string, name: string, edit: (json: Record<string, any>) => void): string {
    const bytes = readFileSync(file);
    const jsonLength = bytes.readUInt32LE(12);
    const json = JSON.parse(bytes.subarray(20, 20 + jsonLength).toString());
    edit(json);
    let text = JSON.stringify(json);
    text += ' '.repeat((4 - (Buffer.byteLength(text) % 4)) % 4);
    const head = Buffer.alloc(20), bin = bytes.subarray(20 + jsonLength);
    head.writeUInt32LE(0x46546c67, 0); head.writeUInt32LE(2, 4);
    head.writeUInt32LE(20 + Buffer.byteLength(text) + bin.length, 8);
    head.writeUInt32LE(Buffer.byteLength(text), 12); head.writeUInt32LE(0x4e4f534a, 16);
    const out = join(dir, name);
    writeFileSync(out, Buffer.concat([head, Buffer.from(text), bin]));
    return out;
  }

  it('a meshopt stream past its buffer, a Draco buffer view that does not exist, another required extension', async () => {
    const m = await compress(sources[0].file, VARIANTS[1]);
    const past = edited(m, 'meshopt-past.glb', (json) => {
      const v = json.bufferViews.find((x: any) => x.extensions?.EXT_meshopt_compression);
      v.extensions.EXT_meshopt_compression.byteLength += 1e6;
    });
    expect(await oneLine(past)).toMatch(/^gcs-skin report: .*meshopt-past\.glb: the compressed data of buffer view \d+ \(bytes [\d,]+ to [\d,]+ of buffer 0\) goes past the end of its buffer, which has [\d,]+ bytes \[OUT_OF_BOUNDS\]$/);
    const d = await compress(sources[0].file, VARIANTS[2]);
    const noView = edited(d, 'draco-view.glb', (json) => { json.meshes[0].primitives[0].extensions.KHR_draco_mesh_compression.bufferView = 999; });
    expect(await oneLine(noView)).toMatch(/the Draco data of mesh 0 'Human' primitive 0 refers to buffer view 999, but the file has only \d+ buffer views \[BAD_REFERENCE\]$/);
    const garbled = edited(m, 'meshopt-garbled.glb', (json) => {
      for (const v of json.bufferViews) if (v.extensions?.EXT_meshopt_compression) v.extensions.EXT_meshopt_compression.mode = 'TRIANGLES';
    });
    // The decoder's own exception is not the message: ours is, with BAD_DATA.
    expect(await oneLine(garbled)).toMatch(/^gcs-skin report: .*meshopt-garbled\.glb: its meshopt data does not decode \[BAD_DATA\]$/);
    const other = edited(m, 'meshopt-lights.glb', (json) => { json.extensionsRequired.push('KHR_lights_punctual'); });
    expect(await oneLine(other)).toMatch(/requires the glTF extension KHR_lights_punctual, which this loader does not read \(it reads quantization, meshopt, Draco, KTX2\) \[UNSUPPORTED\]$/);
  });
});
