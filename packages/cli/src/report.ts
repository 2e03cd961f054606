// `gcs-skin report <model.glb|.gltf> [--clip NAME] [--sections N] [--frames N] [--json]`:
// builds every deformer of METHODS on each skinned mesh of any glTF character and reports, per
// method, build ms, median ms per frame and the fidelity figures of docs/method.md §9 (FidelityProbe
// over every sampled frame of every clip, distances in % of the character's height), and per clip
// the frame time, and the mesh's knees and elbows bent alone (measureJoints: volume change, bulge,
// collapse, creases, new self-intersections per method). The JSON shape is documented in
// docs/report-json.md.
import type * as THREE from 'three';
import { setConsoleFunction } from 'three';
import { GcsError } from '../../../web/lib/errors.js';
import { initGcsSkin, type Deformer, type GcsDeformer, type GcsSkin, type RigInput } from '../../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../../web/lib/three/rig-input.js';
import { printable, shownName } from '../../../web/lib/gltf/shown-name.js';
import { wholeNumber } from './args.js';
import { characterHeight, GltfError, loadGltfFile, sampleClip } from './gltf-node.js';
import {
  FidelityProbe, METHODS, buildMethod, errorInfo, identitySkin, jointMethods, jointTableRows, measureJoints, timeFrames,
  type Fidelity, type JointsMeasure, type MethodName,
} from '../../../web/lib/measure.js';

export const usage = `usage: gcs-skin report <model.glb|model.gltf> [--clip NAME] [--sections N] [--frames N] [--time-ms N] [--json]
  Builds every deformer (${METHODS.join(', ')}) on each skinned mesh of the file and prints, per
  method, build ms, median ms per frame and its fidelity over every sampled frame of every clip:
  rigid error, distance from an independent DQS (p95, max), flipped and stretched triangles,
  normals off unit length, non-finite values, seam gap (distances in % of the character's height);
  then per clip the frame times, and the knees and elbows (found from the skeleton) each bent alone
  to 45°, 90°, 135°: volume change, bulge, collapse, creases, new self-intersections per method.
  --clip NAME     only this animation clip (default: all clips)
  --sections N    GCS sections per part (default 6)
  --frames N      frames sampled per clip (default 60)
  --time-ms N     timing budget per clip and method, ms (default 300; fidelity is unaffected)
  --json          machine-readable output (docs/report-json.md)
  Reads KHR_mesh_quantization, EXT_meshopt_compression and KHR_draco_mesh_compression files.
  exit codes: 0 ok, 1 some method produced non-finite values, 2 bad arguments or unreadable file`;

export interface ReportOptions {
  clip?: string;
  sections?: number;
  frames?: number;
  /** Timing budget per clip and method, and for all frames per method (default 300 ms). */
  timeMs?: number;
}

export interface MethodReport {
  available: boolean;
  /** Why the method could not be built or run (e.g. not in this binary yet); absent when it ran. */
  error?: { code: string; message: string };
  buildMs?: number;
  /** Output vertices and triangles (the classic model resamples, so they differ). */
  vertices?: number;
  triangles?: number;
  /** Sections (GCS) or contours (classic); absent for LBS and DQS. */
  sections?: number;
  /** ms per deform() over all the measured frames. */
  medianMs?: number;
  p95Ms?: number;
  /** FidelityProbe over all the measured frames; distances in % of the mesh's `height`. */
  fidelity?: Fidelity;
  /** Classic only: resampling detail loss, % of the mesh's own height. */
  detailLoss?: { rms: number; max: number };
}

export interface ClipMethodReport {
  medianMs: number;
  p95Ms: number;
  samples: number;
  /** GCS only: mean share of adjusted sections over the frames. */
  adjustedShare?: number;
}

export interface MeshReport {
  name: string;
  counts: {
    vertices: number; triangles: number; joints: number; parts: number | null; sections: number | null; height: number;
    /** Influences per vertex read (4, or 8 with JOINTS_1/WEIGHTS_1), and how many vertices have more than 4 (weights > 0). */
    influences: number; moreThan4Influences: number;
  };
  /** Mean column length of the mesh's world matrix. */
  worldScale: number;
  /** The character's height in this mesh's units: 100 % of every fidelity distance. */
  height: number;
  /** The frames every method was measured over: all sampled clip frames, or the bind pose when there is no clip. */
  frames: { count: number; source: 'clips' | 'bind pose' };
  methods: Record<MethodName, MethodReport>;
  clips: { name: string; duration: number; frames: number; methods: Partial<Record<MethodName, ClipMethodReport>> }[];
  /** The knees and elbows found on this mesh, each bent alone (docs/report-json.md, "Joints"). */
  joints: JointsMeasure;
}

export interface Report {
  file: string;
  options: { sections: number; frames: number; clip: string | null };
  /** The character: all skinned meshes of the scene; height in world units (bind pose, bounding box: gltf-node characterHeight). */
  character: { height: number; skinnedMeshes: number };
  meshes: MeshReport[];
  /** What the glTF loaders (gltf-transform, three's GLTFLoader) warned about; [] if nothing. */
  warnings: string[];
}

/**
 * A failure the command reports as one line on stderr (`gcs-skin report: <message> [<code>]`) with
 * exit code 2. `code`: a GltfError code for a bad file (docs/report-json.md, "Errors"), the core's
 * GcsError code for a mesh createRig rejects, or NO_SKINNED_MESH, NO_CLIP, USAGE. `cause`: the
 * GltfError or GcsError, when there is one.
 */
export class ReportError extends Error {
  readonly code: string;
  constructor(message: string, code = 'USAGE', options?: { cause?: unknown }) {
    super(message, options);
    this.name = 'ReportError';
    this.code = code;
  }
}

/** One printable line: a message's line breaks (engine messages have some) become spaces, other controls escapes. */
const oneLine = (s: string) => printable(s.replace(/\s*\n\s*/g, ' ').trim());

const round = (x: number, digits = 4) => (Number.isFinite(x) ? Number(x.toPrecision(digits)) : x);
const roundOrNull = (x: number | null) => (x === null ? null : round(x));

/** Builds the report of a file (throws ReportError for an unreadable or unskinned file). */
export async function report(file: string, options: ReportOptions = {}, gcs?: GcsSkin): Promise<Report> {
  const sections = options.sections ?? 6;
  const frames = options.frames ?? 60;
  let model;
  try {
    model = await loadGltfFile(file);
  } catch (e) {
    if (e instanceof GltfError) throw new ReportError(oneLine(e.message), e.code, { cause: e });
    throw new ReportError(`cannot read ${file}: ${oneLine((e as Error).message)}`, 'LOAD_FAILED', { cause: e });
  }
  if (!model.skinnedMeshes.length)
    throw new ReportError(`${file} has no skinned mesh (no skin, joints and weights): nothing to deform`, 'NO_SKINNED_MESH');
  let clips = model.clips;
  if (options.clip !== undefined) {
    clips = clips.filter((c) => c.name === options.clip);
    if (!clips.length)
      throw new ReportError(`${file} has no clip named '${options.clip}' (clips: ${model.clips.map((c) => c.name).join(', ') || 'none'})`, 'NO_CLIP');
  }
  gcs ??= await initGcsSkin();
  const height = characterHeight(model.skinnedMeshes);
  const meshes: MeshReport[] = [];
  model.skinnedMeshes.forEach((mesh, i) => {
    meshes.push(reportMesh(gcs!, file, mesh, clips, { sections, frames, timeMs: options.timeMs ?? 300, height: height.meshUnits[i], worldScale: height.scales[i] }));
  });
  return {
    file, options: { sections, frames, clip: options.clip ?? null },
    character: { height: round(height.world, 6), skinnedMeshes: model.skinnedMeshes.length }, meshes,
    warnings: model.warnings.map(oneLine),
  };
}

interface MeshSettings { sections: number; frames: number; timeMs: number; height: number; worldScale: number }

function roundFidelity(f: Fidelity): Fidelity {
  return {
    ...f, rigidError: roundOrNull(f.rigidError), dqsP95: roundOrNull(f.dqsP95), dqsMax: roundOrNull(f.dqsMax),
    normalOffUnit: round(f.normalOffUnit), seamGap: round(f.seamGap),
  };
}

function reportMesh(gcs: GcsSkin, file: string, mesh: THREE.SkinnedMesh, clips: THREE.AnimationClip[], s: MeshSettings): MeshReport {
  // The core's own code and sentence (GcsError), after the file and the mesh.
  const unusable = (e: unknown, what: string) => {
    if (!(e instanceof GcsError)) throw e;
    return new ReportError(`${file}: mesh '${mesh.name}' ${what}: ${oneLine(e.message)}`, e.code, { cause: e });
  };
  let input: RigInput;
  try {
    input = rigInputFromSkinnedMesh(mesh);
  } catch (e) {
    throw unusable(e, 'cannot be read as a skin');
  }
  let rig;
  try {
    rig = gcs.createRig(input);
  } catch (e) {
    throw unusable(e, 'is not a usable skin');
  }
  // The character's height in this mesh's units; the mesh's own extent if the character has none.
  const height = s.height > 0 && Number.isFinite(s.height) ? s.height : rig.height;
  const clipFrames = clips.map((clip) => sampleClip(mesh, clip, s.frames));
  const all = clipFrames.flat();
  const frames = all.length ? all : [identitySkin(rig.jointCount)];
  const probe = new FidelityProbe(input, frames, { height });
  const methods = {} as Record<MethodName, MethodReport>;
  const clipMethods = clips.map(() => ({}) as Partial<Record<MethodName, ClipMethodReport>>);
  let gcsCounts: { parts: number; sections: number } | null = null;
  try {
    for (const method of METHODS) {
      let d: Deformer | undefined;
      let r: MethodReport = { available: false };
      try {
        const t0 = performance.now();
        d = buildMethod(rig, method, { sections: s.sections });
        r.buildMs = round(performance.now() - t0);
        r.vertices = d.vertexCount;
        r.triangles = d.indices.length / 3;
        if (method !== 'lbs' && method !== 'dqs') r.sections = d.sectionCount;
        if (method === 'gcs') gcsCounts = { parts: d.partCount, sections: d.sectionCount };
        if (method === 'classic') {
          const loss = (d as unknown as { detailLoss: { rms: number; max: number } }).detailLoss;
          r.detailLoss = { rms: round(loss.rms), max: round(loss.max) };
        }
        const dd = d;
        const t = timeFrames(frames.length, (f) => dd.deform(frames[f]), { minSamples: 100, minMs: s.timeMs / 2, maxMs: s.timeMs });
        r.medianMs = round(t.medianMs);
        r.p95Ms = round(t.p95Ms);
        r.fidelity = roundFidelity(probe.measure(dd));
        clipFrames.forEach((skins, c) => {
          let adjusted = 0;
          if (method === 'gcs') for (const skin of skins) { dd.deform(skin); adjusted += (dd as GcsDeformer).adjustedShare; }
          const tc = timeFrames(skins.length, (f) => dd.deform(skins[f]), { minSamples: 100, minMs: s.timeMs / 2, maxMs: s.timeMs });
          clipMethods[c][method] = { medianMs: round(tc.medianMs), p95Ms: round(tc.p95Ms), samples: tc.samples };
          if (method === 'gcs') clipMethods[c][method]!.adjustedShare = round(adjusted / skins.length, 3);
        });
        r.available = true;
      } catch (e) {
        if (!(e instanceof GcsError)) throw e;
        r = { available: false, error: errorInfo(e), ...(r.buildMs !== undefined ? { buildMs: r.buildMs } : {}) };
      } finally {
        d?.dispose();
      }
      methods[method] = r;
    }
    const joints = roundJoints(measureJoints(rig, input, { methods: jointMethods({ sections: s.sections }), names: mesh.skeleton.bones.map((b) => b.name) }));
    return {
      name: mesh.name,
      counts: {
        vertices: rig.vertexCount, triangles: input.indices.length / 3, joints: rig.jointCount,
        parts: gcsCounts?.parts ?? null, sections: gcsCounts?.sections ?? null, height: round(rig.height, 6),
        influences: input.influences ?? 4, moreThan4Influences: verticesOverFourInfluences(input),
      },
      worldScale: round(s.worldScale, 6),
      height: round(height, 6),
      frames: { count: frames.length, source: all.length ? 'clips' : 'bind pose' },
      methods,
      clips: clips.map((clip, c) => ({ name: clip.name, duration: round(clip.duration), frames: clipFrames[c].length, methods: clipMethods[c] })),
      joints,
    };
  } finally {
    rig.dispose();
  }
}

/** The joints' figures and geometry to 4 significant digits. */
function roundJoints(m: JointsMeasure): JointsMeasure {
  const vec = (v: number[]) => v.map((x) => round(x)) as [number, number, number];
  return {
    ...m,
    frame: m.frame && { up: vec(m.frame.up), forward: vec(m.frame.forward), left: vec(m.frame.left) },
    joints: m.joints.map((j) => ({
      ...j,
      hinge: { ...j.hinge, centre: vec(j.hinge.centre), end: vec(j.hinge.end), axis: vec(j.hinge.axis) },
      methods: Object.fromEntries(Object.entries(j.methods).map(([k, r]) => [k, 'error' in r ? r : r.map((f) => ({
        ...f, volumeChange: round(f.volumeChange), bulgeP95: round(f.bulgeP95), bulgeMax: round(f.bulgeMax),
        collapseP5: round(f.collapseP5), collapseMin: round(f.collapseMin),
      }))])),
    })),
  };
}

/** How many vertices have more than 4 influences (weights > 0). */
export function verticesOverFourInfluences(input: RigInput): number {
  const K = input.influences ?? 4;
  if (K <= 4) return 0;
  let count = 0;
  for (let v = 0, n = input.weights.length / K; v < n; v++) {
    let used = 0;
    for (let k = 0; k < K; k++) if (input.weights[K * v + k] > 0) used++;
    if (used > 4) count++;
  }
  return count;
}

/** The methods that produced non-finite values, per mesh (empty: none). */
export function nonFiniteMethods(r: Report): { mesh: string; method: MethodName; count: number }[] {
  const out: { mesh: string; method: MethodName; count: number }[] = [];
  for (const m of r.meshes)
    for (const name of METHODS) {
      const f = m.methods[name]?.fidelity;
      if (f && f.nonFinite > 0) out.push({ mesh: m.name, method: name, count: f.nonFinite });
    }
  return out;
}

const fmt = (x: number | null | undefined, digits = 3) =>
  x === null || x === undefined ? 'n/a' : Number.isFinite(x) ? (x === 0 ? '0' : Math.abs(x) < 10 ** -digits ? x.toExponential(1) : x.toFixed(digits)) : String(x);

/** A text table: the first row is the header; the first column and a last 'note' column left-aligned. */
function table(rows: string[][]): string {
  const widths = rows[0].map((_, c) => Math.max(...rows.map((r) => r[c].length)));
  const left = (c: number) => c === 0 || rows[0][c] === 'note';
  return rows.map((r) => r.map((cell, c) => (left(c) ? cell.padEnd(widths[c]) : cell.padStart(widths[c]))).join('  ').trimEnd()).join('\n');
}

/** The human-readable report. */
export function formatReport(r: Report): string {
  const out: string[] = [`gcs-skin report: ${printable(r.file)}`,
    `character: ${r.character.skinnedMeshes} skinned mesh(es), height ${fmt(r.character.height, 4)} world units (bind pose)`];
  for (const w of r.warnings) out.push(`loader warning: ${printable(w)}`);
  for (const m of r.meshes) {
    const c = m.counts;
    out.push('', `mesh '${shownName(m.name)}': ${c.vertices} vertices, ${c.triangles} triangles, ${c.joints} joints, ` +
      `${c.parts ?? 'n/a'} parts, ${c.sections ?? 'n/a'} GCS sections (${r.options.sections} per part)`);
    out.push(`fidelity over ${m.frames.count} frame(s) (${m.frames.source === 'clips' ? `${m.clips.length} clip(s)` : 'bind pose only: no clip'}); ` +
      `% of the character's height = ${fmt(m.height, 4)} mesh units (world scale ${fmt(m.worldScale, 4)})`);
    out.push(`influences: ${c.influences} per vertex read, ${c.moreThan4Influences} vertices with more than 4` +
      (c.moreThan4Influences ? ' (three.js\'s own skinning would drop their JOINTS_1/WEIGHTS_1)' : ''));
    const lbs = m.methods.lbs?.fidelity?.flipped;
    // Creases against the baselines: the more of LBS's and DQS's count over the same frames.
    const creaseBase = Math.max(m.methods.lbs?.fidelity?.creases ?? 0, m.methods.dqs?.fidelity?.creases ?? 0);
    const rows = [['method', 'build ms', 'median ms', 'rigid err %', 'DQS p95 %', 'DQS max %', 'flipped', 'creases', 'stretched', 'normal off', 'non-finite', 'seam gap %', 'note']];
    for (const name of METHODS) {
      const x = m.methods[name];
      if (!x.available || !x.fidelity) { rows.push([name, fmt(x.buildMs, 2), 'n/a', '', '', '', '', '', '', '', '', '', `${x.error!.code}: ${printable(x.error!.message)}`]); continue; }
      const f = x.fidelity;
      const flipped = name === 'lbs' || lbs === undefined ? String(f.flipped) : `${f.flipped} (LBS ${lbs})`;
      const creases = name === 'lbs' || name === 'dqs' || !(creaseBase > 0) ? String(f.creases)
        : `${f.creases} (${(f.creases / creaseBase).toFixed(2)}× LBS/DQS)`;
      const note = x.detailLoss ? `resampled: detail loss rms ${fmt(x.detailLoss.rms)} % max ${fmt(x.detailLoss.max)} % of its height` : '';
      rows.push([name, fmt(x.buildMs, 2), fmt(x.medianMs, 4), fmt(f.rigidError, 4), fmt(f.dqsP95), fmt(f.dqsMax), flipped, creases, String(f.stretched),
        fmt(f.normalOffUnit, 4), String(f.nonFinite), fmt(f.seamGap, 4), note]);
    }
    out.push(table(rows));
    if (!m.clips.length) out.push('(no animation clips: per-clip timing needs a clip)');
    for (const clip of m.clips) {
      out.push('', `clip '${shownName(clip.name)}' (${fmt(clip.duration, 2)} s, ${clip.frames} frames)`);
      const rows2 = [['method', 'median ms', 'p95 ms', 'adjusted']];
      for (const name of METHODS) {
        const x = clip.methods[name];
        if (!x) { rows2.push([name, 'n/a', '', '']); continue; }
        rows2.push([name, fmt(x.medianMs, 4), fmt(x.p95Ms, 4), x.adjustedShare !== undefined ? `${(100 * x.adjustedShare).toFixed(0)} %` : '']);
      }
      out.push(table(rows2));
    }
    const j = m.joints;
    out.push('', `joints: ${j.joints.length ? j.joints.map((x) => printable(x.hinge.label)).join(', ') : 'none found'}; each bent alone from the bind pose`,
      'volume: the joint region\'s, posed against bind; bulge and collapse: distance to the nearest bone over the same at bind');
    for (const note of j.notes) out.push(`  note: ${printable(note)}`);
    if (j.joints.length) out.push(table(jointTableRows(j).map((row) => row.map(printable))));
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
    const integer = (min: number, max: number) => wholeNumber(a, value(), min, max);
    if (a === '--json') json = true;
    else if (a === '-h' || a === '--help') help = true;
    else if (a === '--clip') options.clip = value();
    else if (a === '--sections') options.sections = integer(3, 256);
    else if (a === '--frames') options.frames = integer(1, 10000);
    else if (a === '--time-ms') options.timeMs = integer(1, 60000);
    else if (a.startsWith('-') && a !== '-') throw new ReportError(`unknown option '${a}'`); // '-': standard input
    else if (file === undefined) file = a;
    else throw new ReportError(`only one model file, got '${file}' and '${a}'`);
  }
  return { file, json, help, options };
}

/**
 * The subcommand: returns the exit code (0 ok; 1 some method produced non-finite values, with the
 * report printed and one line on stderr; 2 bad arguments or an unreadable/unskinned file).
 */
export async function run(argv: string[]): Promise<number> {
  let args;
  try {
    args = parseArgs(argv);
  } catch (e) {
    process.stderr.write(`gcs-skin report: ${oneLine((e as Error).message)}\n${usage}\n`);
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
  // three's own notes (PropertyBinding: a track whose node is absent) are not the command's to
  // print: a successful run writes its report and nothing else; three's errors still reach stderr.
  setConsoleFunction((level, message, ...params) => { if (level === 'error') console.error(message, ...params); });
  let r: Report;
  try {
    r = await report(args.file, args.options);
  } catch (e) {
    if (e instanceof ReportError) {
      process.stderr.write(`gcs-skin report: ${oneLine(e.message)} [${e.code}]\n`);
      return 2;
    }
    throw e;
  }
  console.log(args.json ? JSON.stringify(r, null, 2) : formatReport(r));
  const bad = nonFiniteMethods(r);
  if (bad.length) {
    process.stderr.write(`gcs-skin report: non-finite values from ${bad.map((b) => `${b.method} on '${shownName(b.mesh)}' (${b.count})`).join(', ')}\n`);
    return 1;
  }
  return 0;
}
