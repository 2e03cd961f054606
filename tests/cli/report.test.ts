// `gcs-skin report`: the JSON shape and fidelity figures (FidelityProbe, % of the character's
// height) on the default human written as .glb and on the shared models, the height conversion
// through a mesh's world scale, exit code 1 with one stderr line for non-finite output, and exit
// code 2 with one stderr line for a broken file and for an unskinned glTF.
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it, vi } from 'vitest';
import { Document, NodeIO } from '@gltf-transform/core';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import {
  REPORT_COLUMNS, defaultFramesPerClip, formatReport, nonFiniteMethods, report, run, wantsProgress, type Report,
} from '../../packages/cli/src/report.js';
import { METHODS, median } from '../../web/lib/measure.js';
import { sharedModels } from '../helpers/models.js';

const GCS_FAMILY = ['gcs', 'gcs-plain', 'gcs-y', 'gcs-axial'] as const;
let dir: string;
let humanFile: string;
let human: ReturnType<typeof createHuman>;

beforeAll(async () => {
  // The progress line only where a test asks for it (a developer's terminal would show it otherwise).
  process.env.GCS_SKIN_PROGRESS = '0';
  dir = mkdtempSync(join(tmpdir(), 'gcs-report-'));
  human = createHuman({ vertices: 4000 });
  humanFile = join(dir, 'human.glb');
  writeFileSync(humanFile, await humanToGlb(human));
});
afterAll(() => rmSync(dir, { recursive: true, force: true }));

/** Runs the subcommand in-process and captures stdout, stderr and the exit code. */
async function runCli(argv: string[]): Promise<{ code: number; stdout: string; stderr: string }> {
  let stdout = '', stderr = '';
  const err = vi.spyOn(process.stderr, 'write').mockImplementation((s: string | Uint8Array) => ((stderr += String(s)), true));
  const log = vi.spyOn(console, 'log').mockImplementation((...a: unknown[]) => void (stdout += a.join(' ') + '\n'));
  try {
    const code = await run(argv);
    return { code, stdout, stderr };
  } finally {
    err.mockRestore();
    log.mockRestore();
  }
}

/** The shape of a report and what holds for every finite, well-formed skin. */
function checkShape(r: Report, framesPerClip: number) {
  expect(r.character.height).toBeGreaterThan(0);
  expect(r.character.skinnedMeshes).toBe(r.meshes.length);
  expect(r.meshes.length).toBeGreaterThan(0);
  for (const m of r.meshes) {
    expect(m.counts.vertices).toBeGreaterThan(0);
    expect(m.counts.triangles).toBeGreaterThan(0);
    expect(m.counts.joints).toBeGreaterThan(0);
    expect(m.counts.parts).toBeGreaterThan(0);
    expect(m.counts.sections).toBeGreaterThan(m.counts.parts!);
    // One height for the whole character, in this mesh's units.
    expect(m.worldScale).toBeGreaterThan(0);
    expect(m.height * m.worldScale).toBeCloseTo(r.character.height, 3);
    expect(m.frames.source).toBe(m.clips.length ? 'clips' : 'bind pose');
    expect(m.frames.count).toBe(m.clips.length ? framesPerClip * m.clips.length : 1);
    expect(Object.keys(m.methods)).toEqual(METHODS);
    for (const name of METHODS) {
      const x = m.methods[name];
      if (name === 'classic' && !x.available) { expect(typeof x.error!.code).toBe('string'); continue; }
      expect(x.available, `${m.name} ${name}: ${x.error?.message}`).toBe(true);
      expect(x.buildMs).toBeGreaterThanOrEqual(0);
      expect(x.medianMs).toBeGreaterThan(0);
      expect(x.p95Ms).toBeGreaterThanOrEqual(x.medianMs!);
      const f = x.fidelity!;
      expect(f.frames).toBe(m.frames.count);
      expect(f.nonFinite).toBe(0);
      for (const k of ['flipped', 'stretched', 'rigidVertices'] as const) {
        expect(Number.isInteger(f[k])).toBe(true);
        expect(f[k]).toBeGreaterThanOrEqual(0);
      }
      expect(f.normalOffUnit).toBeLessThan(1e-3);
      if (name === 'classic') {
        // Resampled: no output vertex maps back to the rig.
        expect(f.rigidError).toBeNull();
        expect(f.dqsP95).toBeNull();
        expect(x.detailLoss!.max).toBeGreaterThanOrEqual(x.detailLoss!.rms);
      } else {
        expect(f.dqsP95).toBeGreaterThanOrEqual(0);
        expect(f.dqsMax).toBeGreaterThanOrEqual(f.dqsP95!);
      }
    }
    const gcs = m.methods.gcs.fidelity!, dqs = m.methods.dqs.fidelity!, lbs = m.methods.lbs.fidelity!;
    // docs/method.md §9: the default GCS keeps rigid vertices rigid (≤ 1e-4 of height = 0.01 %) and
    // opens no seam; the core's DQS is the independent reference DQS up to float rounding.
    if (gcs.rigidVertices > 0) expect(gcs.rigidError).toBeLessThanOrEqual(0.01);
    for (const name of GCS_FAMILY) expect(m.methods[name].fidelity!.seamGap).toBeLessThanOrEqual(1e-3);
    expect(dqs.dqsMax).toBeLessThanOrEqual(0.01);
    expect(typeof lbs.flipped).toBe('number');
    for (const clip of m.clips) {
      expect(clip.frames).toBe(framesPerClip);
      expect(Object.keys(clip.methods).sort()).toEqual(METHODS.filter((k) => m.methods[k].available).sort());
      for (const x of Object.values(clip.methods)) {
        expect(x!.medianMs).toBeGreaterThan(0);
        expect(x!.p95Ms).toBeGreaterThanOrEqual(x!.medianMs);
        expect(x!.samples).toBeGreaterThan(0);
      }
      expect(clip.methods.gcs!.adjustedShare).toBeGreaterThanOrEqual(0);
      expect(clip.methods.gcs!.adjustedShare).toBeLessThanOrEqual(1);
    }
  }
  // What the JSON output carries is the object itself (no NaN or Infinity on a sound model).
  expect(JSON.parse(JSON.stringify(r))).toEqual(r);
}

describe('gcs-skin report', () => {
  it('reports the default human written as .glb (JSON through the subcommand)', async () => {
    const { code, stdout, stderr } = await runCli([humanFile, '--json', '--frames', '8', '--sections', '5']);
    expect(stderr).toBe('');
    expect(code).toBe(0);
    const r = JSON.parse(stdout) as Report;
    expect(r.options).toEqual({ sections: 5, frames: 8, clip: null });
    checkShape(r, 8);
    const m = r.meshes[0];
    expect(m.counts.vertices).toBe(human.mesh.geometry.getAttribute('position').count);
    expect(m.counts.joints).toBe(human.mesh.skeleton.bones.length);
    expect(m.clips.map((c) => c.name).sort()).toEqual(human.clips.map((c) => c.name).sort());
    // One mesh at world scale 1: the character's height is the mesh's own extent.
    expect(m.worldScale).toBe(1);
    expect(m.height).toBeCloseTo(m.counts.height, 5);
    // docs/method.md §9 targets for the default GCS on the default human.
    const gcs = m.methods.gcs.fidelity!;
    expect(gcs.dqsP95).toBeLessThanOrEqual(1);
    expect(gcs.dqsMax).toBeLessThanOrEqual(4);
    expect(gcs.seamGap).toBe(0);
  });

  it('measures in % of the character height converted through the mesh world scale', async () => {
    // The same human with its skinned mesh node scaled ×100. glTF ignores that node's transform
    // (three cancels it): the character is drawn at the same size, but the deformers' mesh space is
    // now 1/100 of the world, so the height in mesh units is 1/100 and the percentages stay.
    const io = new NodeIO();
    const doc = await io.read(humanFile);
    doc.getRoot().listNodes().find((n) => n.getSkin())!.setScale([100, 100, 100]);
    const scaledFile = join(dir, 'human-x100.glb');
    await io.write(scaledFile, doc);
    const plain = await report(humanFile, { clip: 'walk', frames: 6, timeMs: 20 });
    const scaled = await report(scaledFile, { clip: 'walk', frames: 6, timeMs: 20 });
    expect(scaled.character.height).toBeCloseTo(plain.character.height, 5);
    expect(scaled.meshes[0].worldScale).toBeCloseTo(100, 4);
    expect(scaled.meshes[0].height).toBeCloseTo(plain.meshes[0].height / 100, 7);
    // (Methods whose output follows a scale in the skin matrices; the scale is the same for every
    // joint here, so their figures must not change.)
    for (const name of ['gcs', 'gcs-plain', 'lbs'] as const) {
      const a = plain.meshes[0].methods[name].fidelity!, b = scaled.meshes[0].methods[name].fidelity!;
      expect(b.dqsP95! / a.dqsP95!).toBeCloseTo(1, 1);
      expect(b.dqsMax! / a.dqsMax!).toBeCloseTo(1, 1);
    }
    const ra = plain.meshes[0].methods.lbs.fidelity!.rigidError!, rb = scaled.meshes[0].methods.lbs.fidelity!.rigidError!;
    expect(rb / ra).toBeCloseTo(1, 1);
    expect(scaled.meshes[0].methods.dqs.fidelity!.dqsMax).toBeLessThanOrEqual(0.01);
  });

  it('--clip selects one clip; the --wide table shows every method and the LBS flip count beside the others', async () => {
    const { code, stdout } = await runCli([humanFile, '--clip', 'walk', '--frames', '4', '--wide']);
    expect(code).toBe(0);
    const lines = stdout.split('\n');
    const header = lines.findIndex((l) => l.startsWith('method') && l.includes('DQS p95 %'));
    expect(header).toBeGreaterThan(0);
    for (const l of ['rigid err %', 'DQS max %', 'flipped', 'stretched', 'normal off', 'non-finite', 'seam gap %', 'build ms', 'ms/frame', 'p95 ms'])
      expect(lines[header]).toContain(l);
    const rows = lines.slice(header + 1, header + 1 + METHODS.length);
    expect(rows.map((l) => l.split(/\s+/)[0])).toEqual(METHODS);
    const lbsFlipped = rows[METHODS.indexOf('lbs')].trim().split(/\s+/)[6];
    expect(lbsFlipped).toMatch(/^\d+$/);
    for (const name of METHODS.filter((k) => k !== 'lbs')) expect(rows[METHODS.indexOf(name)]).toContain(`(LBS ${lbsFlipped})`);
    expect(stdout).toContain("clip 'walk'");
    expect(stdout).not.toContain("clip 'run'");
    expect(stdout).toContain('fidelity over 4 frame(s)');
    const missing = await runCli([humanFile, '--clip', 'nope']);
    expect(missing.code).toBe(2);
    expect(missing.stderr.trim().split('\n')).toHaveLength(1);
  });

  it('exits 1 with one line on stderr when a method produces non-finite values', async () => {
    // A clip scaling a bone by 1e20: finite float32 skin matrices, but products past float range.
    const io = new NodeIO();
    const doc = await io.read(humanFile);
    const root = doc.getRoot();
    const buffer = root.listBuffers()[0];
    const joint = root.listSkins()[0].listJoints()[5];
    const input = doc.createAccessor().setType('SCALAR').setBuffer(buffer).setArray(new Float32Array([0, 1]));
    const output = doc.createAccessor().setType('VEC3').setBuffer(buffer).setArray(new Float32Array(6).fill(1e20));
    const sampler = doc.createAnimationSampler().setInput(input).setOutput(output).setInterpolation('LINEAR');
    const channel = doc.createAnimationChannel().setTargetNode(joint).setTargetPath('scale').setSampler(sampler);
    doc.createAnimation('huge').addSampler(sampler).addChannel(channel);
    const file = join(dir, 'huge.glb');
    await io.write(file, doc);
    const { code, stdout, stderr } = await runCli([file, '--clip', 'huge', '--frames', '2', '--json']);
    const r = JSON.parse(stdout) as Report;
    const bad = nonFiniteMethods(r);
    if (bad.length) {
      expect(code).toBe(1);
      expect(stderr.endsWith('\n')).toBe(true);
      expect(stderr.trim().split('\n')).toHaveLength(1);
      for (const b of bad) expect(stderr).toContain(`${b.method} on '${b.mesh}' (${b.count})`);
    } else {
      console.log('report.test: no method produced non-finite values under a 1e20 bone scale; exit 1 checked on a doctored report only');
      expect(code).toBe(0);
    }
    // The decision itself, on a doctored copy of a sound report.
    const sound = await report(humanFile, { clip: 'idle', frames: 2, timeMs: 10 });
    expect(nonFiniteMethods(sound)).toEqual([]);
    sound.meshes[0].methods['gcs-y'].fidelity!.nonFinite = 7;
    expect(nonFiniteMethods(sound)).toEqual([{ mesh: sound.meshes[0].name, method: 'gcs-y', count: 7 }]);
    expect(formatReport(sound)).toContain('gcs-y');
  });

  const { files, reason } = sharedModels();
  if (reason) console.log(`report.test: ${reason}`);
  const cesium = files.find((f) => f.endsWith('CesiumMan.glb'));
  it.skipIf(!cesium)('reports CesiumMan: GCS rigid, DQS = the reference, LBS flips counted', async () => {
    const r = await report(cesium!, { frames: 6, timeMs: 20 });
    checkShape(r, 6);
    const m = r.meshes[0];
    const gcs = m.methods.gcs.fidelity!;
    expect(gcs.rigidVertices).toBeGreaterThan(0);
    expect(gcs.rigidError).toBeLessThanOrEqual(0.01);
    expect(gcs.dqsP95).toBeLessThanOrEqual(1);
    expect(gcs.dqsMax).toBeLessThanOrEqual(4);
    expect(m.methods.dqs.fidelity!.dqsMax).toBeLessThanOrEqual(0.01);
    expect(Number.isInteger(m.methods.lbs.fidelity!.flipped)).toBe(true);
    // Its knees and elbows (no bone names), each bent alone: LBS loses volume where DQS keeps more; the table prints them.
    expect(m.joints.joints.map((j) => j.hinge.label)).toEqual(['left knee', 'right knee', 'left elbow', 'right elbow']);
    expect(m.joints.angles).toEqual([45, 90, 135]);
    for (const j of m.joints.joints) {
      const lbs = j.methods.lbs as { volumeChange: number }[], dqs = j.methods.dqs as { volumeChange: number }[];
      expect(lbs[2].volumeChange).toBeLessThan(dqs[2].volumeChange - 5);
    }
    const text = formatReport(r);
    expect(text).toMatch(/joints, each bent alone from the bind pose: left knee, right knee, left elbow, right elbow/);
    for (const line of text.slice(text.indexOf('joints, each bent alone')).split('\n')) expect(line.length).toBeLessThanOrEqual(120);
  });
  if (!cesium && !reason) console.log('report.test: skipped the CesiumMan test: no CesiumMan.glb in ../shared/models');

  it.skipIf(files.length === 0)('reports every shared model; a character of several meshes is measured against one height', async () => {
    for (const file of files) {
      const r = await report(file, { frames: 3, timeMs: 10 });
      checkShape(r, 3);
      const heights = r.meshes.map((m) => m.height * m.worldScale);
      for (const h of heights) expect(h).toBeCloseTo(r.character.height, 3);
      // Soldier.glb: positions in cm, an armature scaled 0.01 that its inverse binds leave out; a
      // human-sized soldier in metres, 184.8 of its mesh units (the body and the visor alike).
      if (file.endsWith('Soldier.glb')) {
        expect(r.character.height).toBeGreaterThan(1.7);
        expect(r.character.height).toBeLessThan(2);
        for (const m of r.meshes) expect(m.height).toBeCloseTo(100 * r.character.height, 0);
      }
    }
  });

  it('exits 2 with one line on stderr for a broken file', async () => {
    const file = join(dir, 'broken.glb');
    writeFileSync(file, Buffer.from('glTF this is not a binary glTF at all'));
    const { code, stdout, stderr } = await runCli([file, '--json']);
    expect(code).toBe(2);
    expect(stdout).toBe('');
    expect(stderr.endsWith('\n')).toBe(true);
    expect(stderr.trim().split('\n')).toHaveLength(1);
    expect(stderr).toContain('broken.glb');
  });

  it('exits 2 with one line on stderr for a missing file and for bad arguments', async () => {
    const { code, stderr } = await runCli([join(dir, 'absent.glb')]);
    expect(code).toBe(2);
    expect(stderr.trim().split('\n')).toHaveLength(1);
    const bad = await runCli([humanFile, '--frames', '0']);
    expect(bad.code).toBe(2);
    expect(bad.stdout).toBe('');
    expect(bad.stderr).toMatch(/--frames takes a whole number/);
  });

  it('exits 2 with one line on stderr for an unskinned glTF', async () => {
    const doc = new Document();
    const buffer = doc.createBuffer();
    const position = doc.createAccessor().setType('VEC3').setBuffer(buffer).setArray(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]));
    const prim = doc.createPrimitive().setAttribute('POSITION', position);
    const mesh = doc.createMesh('triangle').addPrimitive(prim);
    doc.createScene('scene').addChild(doc.createNode('node').setMesh(mesh));
    const file = join(dir, 'unskinned.gltf');
    await new NodeIO().write(file, doc);
    const { code, stdout, stderr } = await runCli([file]);
    expect(code).toBe(2);
    expect(stdout).toBe('');
    expect(stderr.trim().split('\n')).toHaveLength(1);
    expect(stderr).toMatch(/no skinned mesh/);
  });
});

describe('gcs-skin report: speed, progress, one median, 120 columns', () => {
  it('default frames per clip: 60 for one clip, fewer for many (about 64 in all), at least 8', () => {
    expect(defaultFramesPerClip(1)).toBe(60);
    expect(defaultFramesPerClip(3)).toBe(21);
    expect(defaultFramesPerClip(7)).toBe(9);
    expect(defaultFramesPerClip(40)).toBe(8);
    expect(defaultFramesPerClip(0)).toBe(60);
  });

  it('progress on a terminal only, never on a pipe or a file; GCS_SKIN_PROGRESS forces it either way', () => {
    expect(wantsProgress({ isTTY: true }, {})).toBe(true);
    expect(wantsProgress({ isTTY: false }, {})).toBe(false);
    expect(wantsProgress({}, {})).toBe(false);
    expect(wantsProgress({ isTTY: true }, { TERM: 'dumb' })).toBe(false);
    expect(wantsProgress({ isTTY: true }, { GCS_SKIN_PROGRESS: '0' })).toBe(false);
    expect(wantsProgress({ isTTY: false }, { GCS_SKIN_PROGRESS: '1' })).toBe(true);
  });

  it('with progress shown, it goes to stderr per method and clip, is cleared at the end, and --json stdout is the report alone', async () => {
    process.env.GCS_SKIN_PROGRESS = '1';
    try {
      const { code, stdout, stderr } = await runCli([humanFile, '--json', '--frames', '3', '--time-ms', '30']);
      expect(code).toBe(0);
      expect(() => JSON.parse(stdout)).not.toThrow();
      expect(stdout).not.toContain('\r');
      for (const name of METHODS) expect(stderr).toContain(`${name} (${METHODS.indexOf(name) + 1}/${METHODS.length})`);
      for (const clip of human.clips) expect(stderr).toContain(`timing clip '${clip.name}'`);
      expect(stderr.endsWith('\r\x1b[K')).toBe(true);
    } finally {
      process.env.GCS_SKIN_PROGRESS = '0';
    }
  });

  it('one median per method: the summary is the median of the clips\' figures from the same timing', async () => {
    const r = await report(humanFile, { frames: 4, timeMs: 60 });
    const m = r.meshes[0];
    expect(m.clips.length).toBe(3);
    for (const name of METHODS) {
      const x = m.methods[name];
      if (!x.available) continue;
      const clipMedians = m.clips.map((c) => c.methods[name]!.medianMs);
      expect(x.medianMs).toBe(Number(median(clipMedians).toPrecision(4)));
      expect(x.p95Ms).toBe(Number(Math.max(...m.clips.map((c) => c.methods[name]!.p95Ms)).toPrecision(4)));
    }
  });

  it(`the text report fits ${REPORT_COLUMNS} columns (the default human and a report of large figures); --wide carries the rest`, async () => {
    const r = await report(humanFile, { frames: 4, timeMs: 60 });
    const widest = (text: string) => Math.max(...text.split('\n').map((l) => l.length));
    expect(widest(formatReport(r))).toBeLessThanOrEqual(REPORT_COLUMNS);
    // Large counts and times in every cell: a 1 M-vertex character's figures.
    const big = structuredClone(r);
    for (const x of Object.values(big.meshes[0].methods)) {
      if (!x.fidelity) continue;
      Object.assign(x, { buildMs: 123456.7, medianMs: 1234.567 });
      Object.assign(x.fidelity, { flipped: 12345678, creases: 98765432, stretched: 1234567, nonFinite: 1234567, rigidError: 12.345678, dqsP95: 123.456, dqsMax: 1234.567 });
    }
    expect(widest(formatReport(big))).toBeLessThanOrEqual(REPORT_COLUMNS);
    const wide = formatReport(r, { wide: true });
    expect(wide).toContain('seam gap %');
    expect(wide).toContain("clip 'walk'");
    expect(formatReport(r)).not.toContain('seam gap %');
  });

  it('a 30 k-vertex character with 7 clips: every method in a bounded CPU time (figure printed; the README quotes a run)', async () => {
    const h = createHuman({ vertices: 30000 });
    const variants = [['walk', 1.25, 'stroll'], ['walk', 0.8, 'brisk'], ['run', 1.4, 'jog'], ['run', 0.8, 'sprint']] as const;
    const clips = [...h.clips, ...variants.map(([from, k, name]) => {
      const c = h.clips.find((x) => x.name === from)!.clone();
      c.name = name;
      for (const t of c.tracks) t.scale(k);
      return c.resetDuration();
    })];
    const file = join(dir, 'human-30k-7clips.glb');
    writeFileSync(file, await humanToGlb({ mesh: h.mesh, clips }));
    const cpu0 = process.cpuUsage(), t0 = performance.now();
    const r = await report(file);
    const cpu = process.cpuUsage(cpu0);
    const cpuS = (cpu.user + cpu.system) / 1e6;
    const m = r.meshes[0];
    console.log(`report, ${m.counts.vertices} vertices, ${m.clips.length} clips × ${r.options.frames} frames, ${METHODS.length} methods: ` +
      `${cpuS.toFixed(1)} s CPU, ${((performance.now() - t0) / 1000).toFixed(1)} s wall`);
    expect(m.counts.vertices).toBeGreaterThanOrEqual(29000);
    expect(m.clips).toHaveLength(7);
    expect(Object.values(m.methods).filter((x) => x.available).length).toBeGreaterThanOrEqual(METHODS.length - 1);
    // The target is 10 s on a quiet host; twice that, so a loaded shared host does not fail it.
    expect(cpuS).toBeLessThan(20);
  });
});
