// `gcs-skin report` as text on a terminal and in a pipe: every line within 120 columns piped and
// within the terminal's width (80 at least), long names shortened with an ellipsis, a joint that
// every method moves alike (rigid pieces) said in words, no detail loss where nothing was
// resampled; clips from a companion file (--clips), bound by node name; KHR_materials_unlit known.
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { formatReport, report, reportColumns, ReportError, type Report } from '../../packages/cli/src/report.js';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { MODELS_DIR } from '../helpers/models.js';

const ROOT = resolve(__dirname, '../..');
const widest = (text: string) => Math.max(...text.split('\n').map((l) => l.length));
const quick = { frames: 2, timeMs: 5 };

let dir: string;
let humanFile: string;
let human: Report;

beforeAll(async () => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-report-layout-'));
  humanFile = join(dir, 'human.glb');
  writeFileSync(humanFile, await humanToGlb(createHuman({ vertices: 4000 })));
  human = await report(humanFile, quick);
}, 120000);
afterAll(() => rmSync(dir, { recursive: true, force: true }));

/** A deep copy of the human's report to edit. */
const copy = (r: Report): Report => JSON.parse(JSON.stringify(r));

describe('gcs-skin report: lines that fit', () => {
  it('the width: 120 in a pipe or a file, the terminal\'s on a terminal, never under 80', () => {
    expect(reportColumns({ isTTY: false, columns: 200 })).toBe(120);
    expect(reportColumns({})).toBe(120);
    expect(reportColumns({ isTTY: true, columns: 100 })).toBe(100);
    expect(reportColumns({ isTTY: true, columns: 60 })).toBe(80);
    expect(reportColumns({ isTTY: true })).toBe(80);
  });

  it('long names (a mesh, every joint) are shortened with an ellipsis: within 120 and 80 columns, the tables kept', () => {
    const r = copy(human);
    const long = 'mixamorig:'.repeat(15);
    r.meshes[0].name = long;
    for (const j of r.meshes[0].joints.joints) j.hinge.label = `${j.hinge.label} (${long})`;
    for (const columns of [120, 80]) {
      const text = formatReport(r, { columns });
      expect(widest(text), `${columns} columns`).toBeLessThanOrEqual(columns);
      expect(text).toContain('…');
      expect(text).toMatch(/^ {2}gcs {2,}/m); // the joints table's rows are there
      expect(text).toMatch(/^gcs {2,}[\d.]+/m); // and the main table's
    }
    // At 80 columns some columns are left out, and the report says which.
    expect(formatReport(r, { columns: 80 }).replace(/\n\s*/g, ' ')).toMatch(/left out at 80 columns; --wide or --json for every column/);
    expect(formatReport(r, { columns: 120 })).not.toMatch(/left out at/);
  });

  it('a joint every method moves alike (rigid pieces) gets one line, not six rows of the same numbers', () => {
    const r = copy(human);
    const joints = r.meshes[0].joints;
    const first = joints.joints[0];
    const figures = first.methods.gcs;
    for (const key of Object.keys(first.methods)) first.methods[key] = figures;
    const text = formatReport(r);
    const lines = text.split('\n');
    const at = lines.findIndex((l) => l.startsWith(`${first.hinge.label}:`));
    expect(lines[at]).toMatch(/no soft joint: the limb is rigid pieces/);
    expect(lines[at + 1], 'the next joint follows at once').toBe(joints.joints[1].hinge.label);
    expect(text.match(/no soft joint/g)).toHaveLength(1); // the other joints bend: their numbers stay
  });

  it('the classic model resampling nothing: no detail loss claimed', () => {
    const r = copy(human);
    r.meshes[0].methods.classic.detailLoss = { rms: 0, max: 0 };
    const text = formatReport(r);
    expect(text).toMatch(/classic: nothing resampled/);
    expect(text).not.toMatch(/classic: resampled: detail loss/);
    expect(formatReport(human)).toMatch(/classic: resampled: detail loss rms [\d.]+ %/);
  });
});

const soldierFile = join(MODELS_DIR, 'Soldier.glb');
const soldier = existsSync(soldierFile) ? soldierFile : null;
if (!soldier) console.log(`skipped: ${soldierFile} is absent`);
describe.skipIf(!soldier)('gcs-skin report on Soldier (Mixamo: long mixamorig names)', () => {
  it('≤ 120 columns piped, ≤ 80 on an 80-column terminal', async () => {
    const r = await report(soldier!, quick);
    const piped = formatReport(r, { columns: reportColumns({ isTTY: false }) });
    const terminal = formatReport(r, { columns: reportColumns({ isTTY: true, columns: 80 }) });
    console.log(`Soldier: ${r.meshes[0].counts.joints} joints; widest line ${widest(piped)} piped, ${widest(terminal)} at 80 columns`);
    expect(widest(piped)).toBeLessThanOrEqual(120);
    expect(widest(terminal)).toBeLessThanOrEqual(80);
    for (const text of [piped, terminal]) expect(text).toMatch(/^ {2}dqs {2,}/m);
  }, 120000);
});

describe('gcs-skin report --clips: animations from a companion file', () => {
  it("a character without clips measured over a companion file's clips, bound by node name", async () => {
    const { NodeIO } = await import('@gltf-transform/core');
    const io = new NodeIO();
    const doc = await io.read(humanFile);
    for (const a of doc.getRoot().listAnimations()) a.dispose();
    const bare = join(dir, 'bare.glb');
    writeFileSync(bare, await io.writeBinary(doc));
    const alone = await report(bare, quick);
    expect(alone.meshes[0].frames.source).toBe('bind pose');
    const r = await report(bare, { ...quick, clipsFile: humanFile });
    expect(r.meshes[0].frames.source).toBe('clips');
    expect(r.meshes[0].clips.map((c) => c.name).sort()).toEqual(human.meshes[0].clips.map((c) => c.name).sort());
    expect(r.options.clipsFile).toBe(humanFile);
    // The same clips played on the same skeleton: the same fidelity as the file that holds both.
    expect(r.meshes[0].methods.lbs.fidelity!.dqsP95).toBeCloseTo(human.meshes[0].methods.lbs.fidelity!.dqsP95!, 6);
  }, 120000);

  it('a companion whose clips move none of the model\'s nodes: NO_CLIP, naming both files', async () => {
    const fox = join(ROOT, 'public/Fox.glb');
    const error = await report(humanFile, { ...quick, clipsFile: fox }).catch((e: unknown) => e);
    expect(error).toBeInstanceOf(ReportError);
    expect((error as ReportError).code).toBe('NO_CLIP');
    expect((error as ReportError).message).toContain('Fox.glb');
    expect((error as ReportError).message).toContain('human.glb');
  }, 120000);
});

describe('gcs-skin report: known glTF extensions', () => {
  it('KHR_materials_unlit is known: no warning', async () => {
    const [{ NodeIO }, { KHRMaterialsUnlit }] = await Promise.all([import('@gltf-transform/core'), import('@gltf-transform/extensions')]);
    const io = new NodeIO().registerExtensions([KHRMaterialsUnlit]);
    const doc = await io.read(humanFile);
    const unlit = doc.createExtension(KHRMaterialsUnlit);
    for (const m of doc.getRoot().listMaterials()) m.setExtension('KHR_materials_unlit', unlit.createUnlit());
    const file = join(dir, 'unlit.glb');
    writeFileSync(file, await io.writeBinary(doc));
    const written = await io.readBinary(new Uint8Array(readFileSync(file)));
    expect(written.getRoot().listExtensionsUsed().map((e) => e.extensionName)).toContain('KHR_materials_unlit');
    const r = await report(file, quick);
    expect(r.warnings.filter((w) => /KHR_materials_unlit|extension/i.test(w))).toEqual([]);
  }, 120000);
});
