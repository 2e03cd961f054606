// `gcs-skin report`: the JSON on a shared model and on the default human written as .glb, and
// exit code 2 with one stderr line for a broken file and for an unskinned glTF.
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it, vi } from 'vitest';
import { Document, NodeIO } from '@gltf-transform/core';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { report, run, type Report } from '../../web/lib/cli/report.js';
import { sharedModels } from '../helpers/models.js';

const METHODS = ['gcs', 'gcs-smooth', 'classic', 'lbs', 'dqs'];
let dir: string;

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-report-'));
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

function checkShape(r: Report) {
  expect(r.meshes.length).toBeGreaterThan(0);
  for (const m of r.meshes) {
    expect(m.counts.vertices).toBeGreaterThan(0);
    expect(m.counts.triangles).toBeGreaterThan(0);
    expect(m.counts.joints).toBeGreaterThan(0);
    expect(m.counts.parts).toBeGreaterThan(0);
    expect(m.counts.sections).toBeGreaterThan(m.counts.parts!);
    expect(Object.keys(m.methods).sort()).toEqual([...METHODS].sort());
    for (const name of ['gcs', 'gcs-smooth', 'lbs', 'dqs']) {
      const x = m.methods[name as keyof typeof m.methods];
      expect(x.available).toBe(true);
      expect(x.buildMs).toBeGreaterThanOrEqual(0);
      expect(x.restSeamGap).toBe(0);
    }
    const c = m.methods.classic;
    if (!c.available) expect(typeof c.error!.code).toBe('string');
    // GCS reproduces the bind pose exactly.
    expect(m.methods.gcs.restError).toBeLessThanOrEqual(1e-6 * m.counts.height);
    for (const clip of m.clips) {
      expect(clip.frames).toBeGreaterThan(0);
      for (const [name, x] of Object.entries(clip.methods)) {
        expect(METHODS).toContain(name);
        expect(x!.nonFinite).toBe(0);
        expect(x!.medianMs).toBeGreaterThan(0);
        expect(x!.p95Ms).toBeGreaterThanOrEqual(x!.medianMs);
        expect(Number.isFinite(x!.seamGap)).toBe(true);
      }
      // GCS moves both sides of a shared section identically: no seam opens.
      expect(clip.methods.gcs!.seamGap).toBeLessThanOrEqual(1e-5 * m.counts.height);
      expect(clip.methods.gcs!.adjustedShare).toBeGreaterThanOrEqual(0);
      expect(clip.methods.gcs!.adjustedShare).toBeLessThanOrEqual(1);
    }
  }
}

describe('gcs-skin report', () => {
  it('reports the default human written as .glb (JSON through the subcommand)', async () => {
    const human = createHuman({ vertices: 4000 });
    const file = join(dir, 'human.glb');
    writeFileSync(file, await humanToGlb(human));
    const { code, stdout, stderr } = await runCli([file, '--json', '--frames', '8', '--sections', '5']);
    expect(stderr).toBe('');
    expect(code).toBe(0);
    const r = JSON.parse(stdout) as Report;
    expect(r.options).toEqual({ sections: 5, frames: 8, clip: null });
    checkShape(r);
    const m = r.meshes[0];
    expect(m.counts.vertices).toBe(human.mesh.geometry.getAttribute('position').count);
    expect(m.counts.joints).toBe(human.mesh.skeleton.bones.length);
    expect(m.clips.map((c) => c.name).sort()).toEqual(human.clips.map((c) => c.name).sort());
  });

  it('--clip selects one clip; the text output names the methods', async () => {
    const human = createHuman({ vertices: 3000 });
    const file = join(dir, 'human-walk.glb');
    writeFileSync(file, await humanToGlb(human));
    const { code, stdout } = await runCli([file, '--clip', 'walk', '--frames', '4']);
    expect(code).toBe(0);
    for (const name of METHODS) expect(stdout).toContain(name);
    expect(stdout).toContain("clip 'walk'");
    expect(stdout).not.toContain("clip 'run'");
    const missing = await runCli([file, '--clip', 'nope']);
    expect(missing.code).toBe(2);
    expect(missing.stderr.trim().split('\n')).toHaveLength(1);
  });

  const { files, reason } = sharedModels();
  if (reason) console.log(`report.test: ${reason}`);
  it.skipIf(files.length === 0)('reports a shared model', async () => {
    const file = files.find((f) => f.endsWith('CesiumMan.glb')) ?? files[0];
    const r = await report(file, { frames: 6, timeMs: 30 });
    checkShape(r);
    expect(JSON.parse(JSON.stringify(r))).toEqual(r);
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

  it('exits 2 with one line on stderr for a missing file', async () => {
    const { code, stderr } = await runCli([join(dir, 'absent.glb')]);
    expect(code).toBe(2);
    expect(stderr.trim().split('\n')).toHaveLength(1);
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
