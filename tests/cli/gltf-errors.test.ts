// Every bad glTF file is one clear line from `gcs-skin report` (exit code 2, nothing on stdout):
// the file, what is wrong and where, and a code in brackets. Each bad file is made from the default
// human written as .glb (humanToGlb), its JSON or bytes changed. Library callers get a GltfError
// (loadGltfFile) or a ReportError (report) with the same code. The list is docs/report-json.md, "Errors".
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it, vi } from 'vitest';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { ReportError, report, run, type Report } from '../../packages/cli/src/report.js';
import { GltfError, loadGltfFile } from '../../packages/cli/src/gltf-node.js';
import { findCycle } from '../../web/lib/gltf/check-nodes.js';
import { GcsError } from '../../web/lib/errors.js';
import { initGcsSkin } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { splitGlb, writeGlbVariant, type Json } from '../helpers/glb.js';

let dir: string;
let glb: Uint8Array;
let base: { json: Json; bin: Uint8Array };

/** Writes the default human with its JSON and BIN changed by `edit`; returns the path. */
function variant(name: string, edit: (json: Json, bin: DataView) => void): string {
  return writeGlbVariant(join(dir, name), base, edit);
}

/** Byte offset in the BIN chunk of element `i` of accessor `a` (buffer view 0-based, one buffer). */
function elementOffset(json: Json, a: number, i: number): number {
  const acc = json.accessors[a];
  const bv = json.bufferViews[acc.bufferView];
  const size = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT4: 16 }[acc.type as string]! * 4;
  return (bv.byteOffset ?? 0) + (acc.byteOffset ?? 0) + i * (bv.byteStride ?? size);
}

const n = (x: number) => x.toLocaleString('en-US');

/** Runs `gcs-skin report` in-process: stdout, stderr (console.warn/error included) and the exit code. */
async function runCli(argv: string[]): Promise<{ code: number; stdout: string; stderr: string }> {
  let stdout = '', stderr = '';
  const spies = [
    vi.spyOn(process.stderr, 'write').mockImplementation((s: string | Uint8Array) => ((stderr += String(s)), true)),
    vi.spyOn(console, 'warn').mockImplementation((...a: unknown[]) => void (stderr += a.join(' ') + '\n')),
    vi.spyOn(console, 'error').mockImplementation((...a: unknown[]) => void (stderr += a.join(' ') + '\n')),
    vi.spyOn(console, 'log').mockImplementation((...a: unknown[]) => void (stdout += a.join(' ') + '\n')),
  ];
  try {
    const code = await run(argv);
    return { code, stdout, stderr };
  } finally {
    for (const s of spies) s.mockRestore();
  }
}

/** Exit code 2, nothing on stdout, exactly one line on stderr; returns that line. */
async function oneLineError(file: string, code: string): Promise<string> {
  const r = await runCli([file, '--clip', 'idle', '--frames', '1']);
  expect(r.code, r.stderr).toBe(2);
  expect(r.stdout).toBe('');
  expect(r.stderr.endsWith('\n'), JSON.stringify(r.stderr)).toBe(true);
  const line = r.stderr.slice(0, -1);
  expect(line.split('\n'), JSON.stringify(r.stderr)).toHaveLength(1);
  expect(line.startsWith('gcs-skin report: ')).toBe(true);
  expect(line).toContain(file);
  expect(line.endsWith(` [${code}]`), line).toBe(true);
  return line;
}

beforeAll(async () => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-gltf-errors-'));
  glb = await humanToGlb(createHuman({ vertices: 2000 }));
  base = splitGlb(glb);
  writeFileSync(join(dir, 'human.glb'), glb);
});
afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe('gcs-skin report on bad glTF files: one line, exit code 2', () => {
  it('a valid file still reports (exit 0, empty stderr), and so does its .gltf form with an external buffer', async () => {
    const good = await runCli([join(dir, 'human.glb'), '--json', '--clip', 'idle', '--frames', '2']);
    expect(good.stderr).toBe('');
    expect(good.code).toBe(0);
    const r = JSON.parse(good.stdout) as Report;
    expect(r.meshes).toHaveLength(1);
    expect(r.meshes[0].methods.gcs.available).toBe(true);
    expect(r.warnings).toEqual([]);
    // The same file as .gltf + .bin, and with the buffer as a data: URI.
    const json = structuredClone(base.json);
    json.buffers[0].uri = 'human.bin';
    writeFileSync(join(dir, 'human.bin'), base.bin);
    writeFileSync(join(dir, 'human.gltf'), JSON.stringify(json));
    json.buffers[0].uri = `data:application/octet-stream;base64,${Buffer.from(base.bin).toString('base64')}`;
    writeFileSync(join(dir, 'inline.gltf'), JSON.stringify(json));
    for (const f of ['human.gltf', 'inline.gltf']) {
      const m = await loadGltfFile(join(dir, f));
      expect(m.skinnedMeshes).toHaveLength(1);
      expect(m.skinnedMeshes[0].geometry.getAttribute('position').count).toBe(base.json.accessors[0].count);
    }
  });

  it('a truncated GLB: its header length against the file size', async () => {
    const file = join(dir, 'truncated.glb');
    writeFileSync(file, glb.subarray(0, 100000));
    const line = await oneLineError(file, 'TRUNCATED');
    expect(line).toBe(`gcs-skin report: ${file} is truncated: its header says ${n(glb.length)} bytes but the file has 100,000 [TRUNCATED]`);
  });

  it('a wrong magic is not read as JSON', async () => {
    const file = join(dir, 'magic.glb');
    const bytes = glb.slice();
    bytes.set(new TextEncoder().encode('gLTF'), 0);
    writeFileSync(file, bytes);
    const line = await oneLineError(file, 'NOT_GLTF');
    expect(line).toContain("is not a glTF file: it starts with 67 4c 54 46 ('gLTF'), neither the binary glTF magic 'glTF' nor a JSON object");
    expect(line).not.toMatch(/JSON at position|Unexpected token/);
  });

  it('an empty file, an unparsable JSON chunk, extra bytes after the GLB, a chunk past the end', async () => {
    const empty = join(dir, 'empty.glb');
    writeFileSync(empty, new Uint8Array(0));
    expect(await oneLineError(empty, 'NOT_GLTF')).toContain('is empty');
    const badJson = join(dir, 'bad.gltf');
    writeFileSync(badJson, '{"asset": {"version": "2.0"}, ');
    expect(await oneLineError(badJson, 'BAD_JSON')).toMatch(/is not valid JSON \(.*position 30/);
    const long = join(dir, 'long.glb');
    writeFileSync(long, new Uint8Array([...glb, 0, 0, 0, 0]));
    expect(await oneLineError(long, 'BAD_CONTAINER')).toContain(`has 4 bytes more than its header says: the header says ${n(glb.length)} bytes but the file has ${n(glb.length + 4)}`);
    const chunk = join(dir, 'chunk.glb');
    const bytes = glb.slice();
    const view = new DataView(bytes.buffer);
    const binAt = 20 + view.getUint32(12, true);
    view.setUint32(binAt, view.getUint32(binAt, true) + 1000, true);
    writeFileSync(chunk, bytes);
    expect(await oneLineError(chunk, 'BAD_CONTAINER')).toContain(`its BIN chunk (chunk 1, at byte ${n(binAt)}) says ${n(base.bin.length + 1000)} bytes but only ${n(base.bin.length)} remain`);
  });

  it('an accessor whose count is too large for its buffer view', async () => {
    const file = variant('count.glb', (json) => { json.accessors[0].count = 1000000; });
    const line = await oneLineError(file, 'OUT_OF_BOUNDS');
    const stride = base.json.bufferViews[base.json.accessors[0].bufferView].byteStride;
    expect(line).toContain(`accessor 0 (POSITION of mesh 0 'Human' primitive 0) has count 1,000,000, too many for buffer view 0`);
    expect(line).toContain(`need ${n(stride * 999999 + 12)} bytes but the view has ${n(base.json.bufferViews[0].byteLength)}`);
  });

  it('a buffer view past its buffer, a buffer longer than the BIN chunk, a missing or short external buffer', async () => {
    const view = variant('view.glb', (json) => { json.bufferViews[1].byteLength += 1000000; });
    expect(await oneLineError(view, 'OUT_OF_BOUNDS')).toContain('buffer view 1 (bytes');
    const buffer = variant('buffer.glb', (json) => { json.buffers[0].byteLength += 64; });
    expect(await oneLineError(buffer, 'TRUNCATED'))
      .toContain(`is truncated: buffer 0 says ${n(base.bin.length + 64)} bytes but the GLB's BIN chunk has ${n(base.bin.length)}`);
    const json = structuredClone(base.json);
    json.buffers[0].uri = 'absent.bin';
    const missing = join(dir, 'missing.gltf');
    writeFileSync(missing, JSON.stringify(json));
    expect(await oneLineError(missing, 'UNREADABLE')).toContain("buffer 0's file 'absent.bin' cannot be read (no such file)");
    json.buffers[0].uri = 'short.bin';
    writeFileSync(join(dir, 'short.bin'), base.bin.subarray(0, 5000));
    const short = join(dir, 'short.gltf');
    writeFileSync(short, JSON.stringify(json));
    expect(await oneLineError(short, 'TRUNCATED')).toContain(`buffer 0 says ${n(base.bin.length)} bytes but its file 'short.bin' has 5,000`);
  });

  it('a node that is its own child', async () => {
    const file = variant('self.glb', (json) => { json.nodes[0].children = [...(json.nodes[0].children ?? []), 0]; });
    const line = await oneLineError(file, 'NODE_CYCLE');
    expect(line).toContain(`node 0 '${base.json.nodes[0].name}' is its own child`);
    expect(line).not.toContain('call stack');
  });

  it('a cycle of joints (a joint made the child of its own descendant)', async () => {
    const { json } = base;
    const skinJoints: number[] = json.skins[0].joints;
    // A joint with a child that has a child: make the grandchild the joint's parent.
    const a = skinJoints.find((j) => json.nodes[j].children?.some((c: number) => json.nodes[c].children?.length))!;
    const b = json.nodes[a].children.find((c: number) => json.nodes[c].children?.length);
    const c = json.nodes[b].children[0];
    const file = variant('cycle.glb', (j) => { j.nodes[c].children = [...(j.nodes[c].children ?? []), a]; });
    const line = await oneLineError(file, 'NODE_CYCLE');
    const name = (i: number) => `node ${i} '${json.nodes[i].name}'`;
    expect(line).toContain(`the node hierarchy has a cycle: ${name(a)} → ${name(b)} → ${name(c)} → ${name(a)} (joints of skin 0`);
    // A cycle of two nodes outside the scene, both joints.
    const orphan = variant('orphan-cycle.glb', (j) => {
      const k = j.nodes.length;
      j.nodes.push({ name: 'A', children: [k + 1] }, { name: 'B', children: [k] });
      j.skins[0].joints.push(k, k + 1);
    });
    expect(await oneLineError(orphan, 'NODE_CYCLE')).toContain(`cycle: node ${json.nodes.length} 'A' → node ${json.nodes.length + 1} 'B' → node ${json.nodes.length} 'A'`);
  });

  it('a joint with two parents, a scene root that is a child: not silently re-parented', async () => {
    const { json } = base;
    const leaves = json.skins[0].joints.filter((j: number) => !json.nodes[j].children?.length);
    const [leaf, other] = leaves;
    const parentOf = (i: number) => json.nodes.findIndex((d: Json) => d.children?.includes(i));
    const file = variant('two-parents.glb', (j) => { j.nodes[other].children = [leaf]; });
    const line = await oneLineError(file, 'NODE_HIERARCHY');
    expect(line).toContain(`node ${leaf} '${json.nodes[leaf].name}' has two parents, node ${parentOf(leaf)}`);
    expect(line).toContain(`and node ${other} '${json.nodes[other].name}'`);
    const root = variant('scene-root.glb', (j) => { j.scenes[0].nodes.push(leaf); });
    expect(await oneLineError(root, 'NODE_HIERARCHY')).toContain(`lists node ${leaf} '${json.nodes[leaf].name}' as a root, but it is a child of node ${parentOf(leaf)}`);
  });

  it('all-zero skin weights on a vertex: the core says which vertex (BAD_WEIGHTS)', async () => {
    const weights = base.json.meshes[0].primitives[0].attributes.WEIGHTS_0;
    expect(base.json.accessors[weights].componentType).toBe(5126);
    const file = variant('zero-weights.glb', (json, bin) => {
      const at = elementOffset(json, weights, 7);
      for (let k = 0; k < 4; k++) bin.setFloat32(at + 4 * k, 0, true);
    });
    const line = await oneLineError(file, 'BAD_WEIGHTS');
    expect(line).toBe(`gcs-skin report: ${file}: mesh 'Human' is not a usable skin: vertex 7 has no skin weight (its weights sum to 0) [BAD_WEIGHTS]`);
    // Library callers: the loaded geometry keeps the file's zeros (three would bind it to joint 0).
    const model = await loadGltfFile(file);
    const w = model.skinnedMeshes[0].geometry.getAttribute('skinWeight');
    expect([w.getX(7), w.getY(7), w.getZ(7), w.getW(7)]).toEqual([0, 0, 0, 0]);
    expect(w.getX(8) + w.getY(8) + w.getZ(8) + w.getW(8)).toBeCloseTo(1, 5);
  });

  it("a singular inverse bind matrix: the core's code and sentence", async () => {
    const ibm = base.json.skins[0].inverseBindMatrices;
    const file = variant('singular.glb', (json, bin) => {
      const at = elementOffset(json, ibm, 3);
      for (let k = 0; k < 16; k++) bin.setFloat32(at + 4 * k, 0, true);
    });
    // What the core itself says of this rig.
    const gcs = await initGcsSkin();
    const model = await loadGltfFile(file);
    let core: GcsError | undefined;
    try {
      gcs.createRig(rigInputFromSkinnedMesh(model.skinnedMeshes[0])).dispose();
    } catch (e) {
      core = e as GcsError;
    }
    expect(core).toBeInstanceOf(GcsError);
    expect(core!.message).toContain('inverse bind matrix of joint 3');
    const line = await oneLineError(file, core!.code);
    expect(line).toBe(`gcs-skin report: ${file}: mesh 'Human' is not a usable skin: ${core!.message} [${core!.code}]`);
  });

  it('a skinned mesh with no JOINTS_0: one line (three.js no longer warns on its own line)', async () => {
    const file = variant('no-joints.glb', (json) => { for (const m of json.meshes) for (const p of m.primitives) delete p.attributes.JOINTS_0; });
    const line = await oneLineError(file, 'BAD_SKIN');
    expect(line).toMatch(/node \d+ 'Human' has skin 0 'Skin' but its mesh 0 'Human' primitive 0 has no JOINTS_0 attribute/);
  });

  it('bad references, skins and extensions', async () => {
    const ref = variant('ref.glb', (json) => { json.nodes[0].children = [9999]; });
    expect(await oneLineError(ref, 'BAD_REFERENCE')).toContain(`child 0 of node 0 '${base.json.nodes[0].name}' refers to node 9999, but the file has only ${base.json.nodes.length} nodes`);
    const ibm = variant('few-ibm.glb', (json) => { json.accessors[json.skins[0].inverseBindMatrices].count = 3; });
    expect(await oneLineError(ibm, 'BAD_SKIN')).toContain(`has ${base.json.skins[0].joints.length} joints but 3 inverse bind matrices`);
    const dup = variant('dup-joint.glb', (json) => { json.skins[0].joints[2] = json.skins[0].joints[1]; });
    expect(await oneLineError(dup, 'BAD_SKIN')).toContain('twice among its joints (joints 1 and 2)');
    const count = variant('counts.glb', (json) => { json.accessors[json.meshes[0].primitives[0].attributes.WEIGHTS_0].count = 100; });
    expect(await oneLineError(count, 'BAD_STRUCTURE')).toContain('WEIGHTS_0');
    // Only the three compression extensions and KTX2 textures are read (tests/cli/compressed.test.ts); any other required one is refused.
    const lights = variant('lights.glb', (json) => { json.extensionsRequired = ['KHR_draco_mesh_compression', 'KHR_lights_punctual']; });
    expect(await oneLineError(lights, 'UNSUPPORTED')).toContain(
      `${lights} requires the glTF extension KHR_lights_punctual, which this loader does not read (it reads quantization, meshopt, Draco, KTX2)`);
    const v1 = join(dir, 'v1.gltf');
    writeFileSync(v1, JSON.stringify({ asset: { version: '1.0' } }));
    expect(await oneLineError(v1, 'NOT_GLTF')).toContain('is glTF 1.0, not 2.0');
  });

  it('library callers tell the cases apart by code: GltfError from loadGltfFile, ReportError from report', async () => {
    const file = variant('self2.glb', (json) => { json.nodes[1].children = [1]; });
    const e = await loadGltfFile(file).then(() => null, (x: unknown) => x);
    expect(e).toBeInstanceOf(GltfError);
    expect((e as GltfError).code).toBe('NODE_CYCLE');
    expect((e as GltfError).file).toBe(file);
    expect((e as GltfError).where).toBe('/nodes/1/children/0');
    const r = await report(file).then(() => null, (x: unknown) => x);
    expect(r).toBeInstanceOf(ReportError);
    expect((r as ReportError).code).toBe('NODE_CYCLE');
    expect((r as ReportError).cause).toBeInstanceOf(GltfError);
  });

  it('findCycle is iterative: a 200,000-node chain, then closed into a cycle', () => {
    const N = 200000;
    const chain = Array.from({ length: N }, (_, i) => (i + 1 < N ? [i + 1] : []));
    expect(findCycle(chain)).toBeNull();
    chain[N - 1] = [N - 10];
    expect(findCycle(chain)).toEqual(Array.from({ length: 10 }, (_, i) => N - 10 + i));
  });
});
