// `gcs-skin report <model.glb|.gltf> [--clip NAME] [--sections N] [--frames N] [--json]`:
// builds every deformer on any glTF skinned character and reports counts, build times, and per
// clip and method the frame time, non-finite values, seam gap (and per method the rest error).
// The JSON shape is documented in docs/report-json.md.
import * as THREE from 'three';
import { GcsError } from '../errors.js';
import { initGcsSkin, type Deformer, type GcsDeformer, type GcsSkin } from '../index.js';
import { rigInputFromSkinnedMesh } from '../three.js';
import { loadGltfFile, sampleClip } from './gltf-node.js';
import {
  METHODS, buildMethod, coincidentPairs, countNonFinite, errorInfo, identitySkin, restError, restOfOutput, seamGap, timeFrames,
  type MethodName,
} from './measure.js';

export const usage = `usage: gcs-skin report <model.glb|model.gltf> [--clip NAME] [--sections N] [--frames N] [--json]
  Builds every deformer (gcs, gcs-smooth, classic, lbs, dqs) on each skinned mesh of the file and
  prints counts, build ms, and per clip and method the median ms per frame, non-finite values,
  seam gap and rest error.
  --clip NAME     only this animation clip (default: all clips)
  --sections N    GCS sections per part (default 6)
  --frames N      frames sampled per clip (default 60)
  --json          machine-readable output (docs/report-json.md)`;

export interface ReportOptions {
  clip?: string;
  sections?: number;
  frames?: number;
  /** Timing budget per clip and method (default 300 ms). */
  timeMs?: number;
}

export interface MethodReport {
  available: boolean;
  /** Why the method could not be built (e.g. not in this binary yet); absent when available. */
  error?: { code: string; message: string };
  buildMs?: number;
  /** Output vertices and triangles (the classic model resamples, so they differ). */
  vertices?: number;
  triangles?: number;
  /** Sections (GCS) or contours (classic); absent for LBS and DQS. */
  sections?: number;
  /** Max distance of the bind-pose deform from the original vertices (model units); null if none maps back. */
  restError?: number | null;
  /** Seam gap in the bind pose. */
  restSeamGap?: number;
  /** Classic only: resampling detail loss, % of model height. */
  detailLoss?: { rms: number; max: number };
}

export interface ClipMethodReport {
  medianMs: number;
  p95Ms: number;
  samples: number;
  /** NaN or infinite values over every sampled frame (positions and normals). */
  nonFinite: number;
  /** Largest seam gap over the sampled frames (model units). */
  seamGap: number;
  /** GCS only: mean share of adjusted sections over the frames. */
  adjustedShare?: number;
}

export interface MeshReport {
  name: string;
  counts: { vertices: number; triangles: number; joints: number; parts: number | null; sections: number | null; height: number };
  methods: Record<MethodName, MethodReport>;
  clips: { name: string; duration: number; frames: number; methods: Partial<Record<MethodName, ClipMethodReport>> }[];
}

export interface Report {
  file: string;
  options: { sections: number; frames: number; clip: string | null };
  meshes: MeshReport[];
}

/** A failure the command reports as one line on stderr with exit code 2. */
export class ReportError extends Error {}

const round = (x: number, digits = 4) => (Number.isFinite(x) ? Number(x.toPrecision(digits)) : x);

/** Builds the report of a file (throws ReportError for an unreadable or unskinned file). */
export async function report(file: string, options: ReportOptions = {}, gcs?: GcsSkin): Promise<Report> {
  const sections = options.sections ?? 6;
  const frames = options.frames ?? 60;
  let model;
  try {
    model = await loadGltfFile(file);
  } catch (e) {
    throw new ReportError(`cannot read ${file}: ${(e as Error).message.replace(/\s*\n\s*/g, ' ').trim()}`);
  }
  if (!model.skinnedMeshes.length) throw new ReportError(`${file} has no skinned mesh (no skin, joints and weights): nothing to deform`);
  let clips = model.clips;
  if (options.clip !== undefined) {
    clips = clips.filter((c) => c.name === options.clip);
    if (!clips.length)
      throw new ReportError(`${file} has no clip named '${options.clip}' (clips: ${model.clips.map((c) => c.name).join(', ') || 'none'})`);
  }
  gcs ??= await initGcsSkin();
  const meshes: MeshReport[] = [];
  for (const mesh of model.skinnedMeshes) meshes.push(reportMesh(gcs, mesh, clips, sections, frames, options.timeMs ?? 300));
  return { file, options: { sections, frames, clip: options.clip ?? null }, meshes };
}

function reportMesh(gcs: GcsSkin, mesh: THREE.SkinnedMesh, clips: THREE.AnimationClip[], sections: number, frames: number, timeMs: number): MeshReport {
  let input;
  try {
    input = rigInputFromSkinnedMesh(mesh);
  } catch (e) {
    throw new ReportError(`mesh '${mesh.name}': ${(e as Error).message}`);
  }
  let rig;
  try {
    rig = gcs.createRig(input);
  } catch (e) {
    throw new ReportError(`mesh '${mesh.name}' is not a usable skin: ${(e as Error).message}`);
  }
  const deformers = new Map<MethodName, Deformer>();
  const pairs = new Map<MethodName, Uint32Array>();
  const methods = {} as Record<MethodName, MethodReport>;
  try {
    for (const method of METHODS) {
      let d: Deformer;
      const t0 = performance.now();
      try {
        d = buildMethod(rig, method, { sections });
      } catch (e) {
        if (!(e instanceof GcsError)) throw e;
        methods[method] = { available: false, error: errorInfo(e) };
        continue;
      }
      const buildMs = performance.now() - t0;
      deformers.set(method, d);
      const rest = restOfOutput(d, input.positions);
      const p = coincidentPairs(rest);
      pairs.set(method, p);
      d.deform(identitySkin(d.jointCount));
      const r: MethodReport = {
        available: true, buildMs: round(buildMs), vertices: d.vertexCount, triangles: d.indices.length / 3,
        restError: restError(d, input.positions), restSeamGap: seamGap(d.positions, p),
      };
      if (method === 'gcs' || method === 'gcs-smooth' || method === 'classic') r.sections = d.sectionCount;
      if (method === 'classic') {
        const loss = (d as unknown as { detailLoss: { rms: number; max: number } }).detailLoss;
        r.detailLoss = { rms: round(loss.rms), max: round(loss.max) };
      }
      methods[method] = r;
    }
    const gcsD = deformers.get('gcs');
    const clipReports: MeshReport['clips'] = [];
    for (const clip of clips) {
      const skins = sampleClip(mesh, clip, frames);
      const per: Partial<Record<MethodName, ClipMethodReport>> = {};
      for (const [method, d] of deformers) {
        let nonFinite = 0, gap = 0, adjusted = 0;
        const p = pairs.get(method)!;
        for (const skin of skins) {
          d.deform(skin);
          nonFinite += countNonFinite(d.positions, d.normals);
          gap = Math.max(gap, seamGap(d.positions, p));
          if (method === 'gcs') adjusted += (d as GcsDeformer).adjustedShare;
        }
        const t = timeFrames(skins.length, (f) => d.deform(skins[f]), { minSamples: 100, minMs: timeMs / 2, maxMs: timeMs });
        per[method] = { medianMs: round(t.medianMs), p95Ms: round(t.p95Ms), samples: t.samples, nonFinite, seamGap: gap };
        if (method === 'gcs') per[method]!.adjustedShare = round(adjusted / skins.length, 3);
      }
      clipReports.push({ name: clip.name, duration: round(clip.duration), frames: skins.length, methods: per });
    }
    return {
      name: mesh.name,
      counts: {
        vertices: rig.vertexCount, triangles: input.indices.length / 3, joints: rig.jointCount,
        parts: gcsD ? gcsD.partCount : null, sections: gcsD ? gcsD.sectionCount : null, height: round(rig.height, 6),
      },
      methods,
      clips: clipReports,
    };
  } finally {
    for (const d of deformers.values()) d.dispose();
    rig.dispose();
  }
}

const fmt = (x: number | null | undefined, digits = 3) =>
  x === null || x === undefined ? 'n/a' : Number.isFinite(x) ? (x === 0 ? '0' : Math.abs(x) < 1e-3 ? x.toExponential(1) : x.toFixed(digits)) : String(x);

function table(rows: string[][]): string {
  const widths = rows[0].map((_, c) => Math.max(...rows.map((r) => r[c].length)));
  return rows.map((r) => r.map((cell, c) => (c === 0 ? cell.padEnd(widths[c]) : cell.padStart(widths[c]))).join('  ')).join('\n');
}

/** The human-readable report. */
export function formatReport(r: Report): string {
  const out: string[] = [`gcs-skin report: ${r.file}`];
  for (const m of r.meshes) {
    const c = m.counts;
    out.push('', `mesh '${m.name}': ${c.vertices} vertices, ${c.triangles} triangles, ${c.joints} joints, ` +
      `${c.parts ?? 'n/a'} parts, ${c.sections ?? 'n/a'} GCS sections (${r.options.sections} per part), height ${fmt(c.height, 4)}`);
    const rows = [['method', 'build ms', 'vertices', 'rest error', 'rest seam gap', 'note']];
    for (const name of METHODS) {
      const x = m.methods[name];
      if (!x.available) { rows.push([name, 'n/a', '', '', '', `${x.error!.code}: ${x.error!.message}`]); continue; }
      const note = x.detailLoss ? `detail loss rms ${fmt(x.detailLoss.rms)} % max ${fmt(x.detailLoss.max)} % of height` : '';
      rows.push([name, fmt(x.buildMs, 2), String(x.vertices), fmt(x.restError ?? null), fmt(x.restSeamGap), note]);
    }
    out.push(table(rows));
    if (!m.clips.length) out.push('(no animation clips: per-frame numbers need a clip)');
    for (const clip of m.clips) {
      out.push('', `clip '${clip.name}' (${fmt(clip.duration, 2)} s, ${clip.frames} frames)`);
      const rows2 = [['method', 'median ms', 'p95 ms', 'non-finite', 'seam gap', 'adjusted']];
      for (const name of METHODS) {
        const x = clip.methods[name];
        if (!x) { rows2.push([name, 'n/a', '', '', '', '']); continue; }
        rows2.push([name, fmt(x.medianMs, 4), fmt(x.p95Ms, 4), String(x.nonFinite), fmt(x.seamGap),
          x.adjustedShare !== undefined ? `${(100 * x.adjustedShare).toFixed(0)} %` : '']);
      }
      out.push(table(rows2));
    }
  }
  return out.join('\n');
}

function parseArgs(argv: string[]): { file?: string; json: boolean; help: boolean; options: ReportOptions } {
  const options: ReportOptions = {};
  let file: string | undefined, json = false, help = false;
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const value = () => {
      const v = argv[++i];
      if (v === undefined) throw new ReportError(`${a} needs a value`);
      return v;
    };
    const integer = (min: number, max: number) => {
      const s = value();
      const n = Number(s);
      if (!Number.isInteger(n) || n < min || n > max) throw new ReportError(`${a} must be a whole number from ${min} to ${max}; got '${s}'`);
      return n;
    };
    if (a === '--json') json = true;
    else if (a === '-h' || a === '--help') help = true;
    else if (a === '--clip') options.clip = value();
    else if (a === '--sections') options.sections = integer(3, 256);
    else if (a === '--frames') options.frames = integer(1, 10000);
    else if (a.startsWith('-')) throw new ReportError(`unknown option '${a}'`);
    else if (file === undefined) file = a;
    else throw new ReportError(`only one model file, got '${file}' and '${a}'`);
  }
  return { file, json, help, options };
}

/** The subcommand: returns the exit code (0 ok, 2 bad arguments or an unreadable/unskinned file). */
export async function run(argv: string[]): Promise<number> {
  let args;
  try {
    args = parseArgs(argv);
  } catch (e) {
    process.stderr.write(`gcs-skin report: ${(e as Error).message}\n${usage}\n`);
    return 2;
  }
  if (args.help) {
    console.log(usage);
    return 0;
  }
  if (!args.file) {
    process.stderr.write(`gcs-skin report: missing model file\n${usage}\n`);
    return 2;
  }
  let r: Report;
  try {
    r = await report(args.file, args.options);
  } catch (e) {
    if (e instanceof ReportError) {
      process.stderr.write(`gcs-skin report: ${e.message.replace(/\s*\n\s*/g, ' ')}\n`);
      return 2;
    }
    throw e;
  }
  console.log(args.json ? JSON.stringify(r, null, 2) : formatReport(r));
  return 0;
}
