/** @module @gcs-skin/cli/report */
// `gcs-skin report <model.glb|.gltf> [--clip NAME] [--sections N] [--frames N] [--wide] [--json]`:
// builds every deformer of METHODS on each skinned mesh of any glTF character and reports, per
// method, build ms, ms per frame and the fidelity figures of docs/method.md §9 (FidelityProbe over the
// sampled frames of every clip, distances in % of the character's height), and the mesh's knees and
// elbows bent alone (measureJoints: volume change, bulge, collapse, creases, new self-intersections
// per method). Frame times come from one interleaved timing per clip (every method in turn:
// timeInterleaved, as `npm run bench`), and a method's one figure is the median of its clips'.
// Progress on stderr when it is a terminal. The JSON shape is documented in docs/report-json.md.
import type * as THREE from 'three';
import { setConsoleFunction } from 'three';
import { asGiven, GcsError, initGcsSkin, type Deformer, type GcsDeformer, type GcsSkin, type RigInput } from 'gcs-skin';
import { printable, shownName } from 'gcs-skin/gltf';
import { rigInputFromSkinnedMesh } from 'gcs-skin/three';
import { walkArguments, wholeNumber } from './args.js';
import { characterHeight, GltfError, loadGltfFile, sampleClip } from './gltf-node.js';
import {
  FidelityProbe, METHODS, buildMethod, errorInfo, identitySkin, jointMethods, jointTableRows, measureJoints, median, timeInterleaved,
  type Fidelity, type JointsMeasure, type MethodName,
} from 'gcs-skin/measure';

/** Fidelity frames in all (default --frames: this many spread over the clips, at least MIN_FRAMES_PER_CLIP each, at most 60). */
export const FRAME_BUDGET = 64;
export const MIN_FRAMES_PER_CLIP = 8;
export const DEFAULT_TIME_MS = 1200;

/**
 * Frames sampled per clip when --frames is not given: 60 for one clip, fewer for many.
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export function defaultFramesPerClip(clipCount: number): number {
  given(typeof clipCount === 'number' && Number.isInteger(clipCount) && clipCount >= 0, 'defaultFramesPerClip: the clip count must be a whole number ≥ 0', clipCount);
  return Math.max(MIN_FRAMES_PER_CLIP, Math.min(60, Math.round(FRAME_BUDGET / Math.max(1, clipCount))));
}

export const usage = `usage: gcs-skin report <model.glb|model.gltf> [--clips CLIPS.glb] [--clip NAME] [--sections N] [--frames N] [--time-ms N] [--wide] [--json]
  Builds every deformer (${METHODS.join(', ')}) on each skinned mesh of the file and prints, per
  method, build ms, ms per frame (the median of the clips', all methods timed in turn) and its
  fidelity over the sampled frames of every clip: rigid error, distance from an independent DQS
  (p95, max), flipped, creased and stretched triangles, non-finite values (distances in % of the
  character's height); then the knees and elbows (found from the skeleton) each bent alone to 45°,
  90°, 135°: volume change, bulge, collapse, creases, new self-intersections per method. Progress
  goes to stderr when it is a terminal.
  --clips FILE    also play the animations of this glTF (a character's clips shipped apart), bound
                  to the model's nodes by name as three.js's mixer does
  --clip NAME     only this animation clip (default: all clips)
  --sections N    GCS sections per part (default 6)
  --frames N      frames sampled per clip (default: 60 for one clip, fewer per clip for more
                  clips, about ${FRAME_BUDGET} in all and at least ${MIN_FRAMES_PER_CLIP} each; more frames, more time)
  --time-ms N     timing budget per mesh, shared by its clips, ms (default ${DEFAULT_TIME_MS}; fidelity is unaffected)
  --wide          every column, and per clip the frame times and adjusted sections
  --json          machine-readable output (docs/report-json.md), every detail
  Reads KHR_mesh_quantization, EXT_meshopt_compression and KHR_draco_mesh_compression files.
  exit codes: 0 ok, 1 some method produced non-finite values, 2 bad arguments or unreadable file`;

export interface ReportOptions {
  clip?: string;
  /**
   * A companion glTF whose animations are played on the model (a character and its clips shipped in
   * separate files): its clips bind to the model's nodes by name, as three.js's AnimationMixer binds.
   */
  clipsFile?: string;
  sections?: number;
  /** Frames sampled per clip (default defaultFramesPerClip). */
  frames?: number;
  /** Timing budget per mesh, shared by its clips (default DEFAULT_TIME_MS ms). */
  timeMs?: number;
  /** Called as the report goes (which mesh, method, clip), for a progress line. */
  onProgress?: (text: string) => void;
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
  /** ms per deform(): the median of the clips' medians (clips[].methods, the same timing); p95Ms the clips' largest p95. */
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
  /** `clipsFile`: the companion file the clips came from, when one was given. */
  options: { sections: number; frames: number; clip: string | null; clipsFile?: string };
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
  /**
   * @param message The one line printed on stderr.
   * @param code A GltfError or GcsError code, NO_SKINNED_MESH, NO_CLIP or USAGE (the default).
   * @param options `cause`: the error this one reports.
   * @throws ReportError `USAGE` when the message or the code is not a string or the options not an object.
   */
  constructor(message: string, code = 'USAGE', options?: { cause?: unknown }) {
    given(typeof message === 'string', 'ReportError: the message must be a string', message);
    given(typeof code === 'string' && code !== '', 'ReportError: the code must be a non-empty string', code);
    given(options === undefined || isRecord(options), 'ReportError: options must be an object', options);
    super(message, options);
    this.name = 'ReportError';
    this.code = code;
  }
}

/**
 * The argument checks of this module's functions: a ReportError 'USAGE' saying what `what` must be
 * and the value as given (asGiven) when `ok` is false.
 */
function given(ok: boolean, what: string, value: unknown): void {
  if (!ok) throw new ReportError(`${what}; got ${asGiven(value)}`, 'USAGE');
}

/** An object (not null, not an array). */
const isRecord = (value: unknown): value is Record<string, unknown> => value !== null && typeof value === 'object' && !Array.isArray(value);

/** One printable line: a message's line breaks (engine messages have some) become spaces, other controls escapes. */
const oneLine = (s: string) => printable(s.replace(/\s*\n\s*/g, ' ').trim());

const round = (x: number, digits = 4) => (Number.isFinite(x) ? Number(x.toPrecision(digits)) : x);
const roundOrNull = (x: number | null) => (x === null ? null : round(x));

/**
 * Builds the report of a file (throws ReportError for an unreadable or unskinned file).
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export async function report(file: string, options: ReportOptions = {}, gcs?: GcsSkin): Promise<Report> {
  given(typeof file === 'string', 'report: the file must be a path (a string)', file);
  given(isRecord(options), 'report: options must be an object', options);
  given(gcs === undefined || isRecord(gcs), 'report: gcs must be a GcsSkin (initGcsSkin) or absent', gcs);
  const sections = options.sections ?? 6;
  const progress = options.onProgress ?? (() => {});
  const model = await readModel(file, progress);
  if (!model.skinnedMeshes.length)
    throw new ReportError(`${file} has no skinned mesh (no skin, joints and weights): nothing to deform`, 'NO_SKINNED_MESH');
  let clips = model.clips;
  if (options.clipsFile !== undefined) clips = [...clips, ...(await companionClips(options.clipsFile, file, model.skinnedMeshes, progress))];
  if (options.clip !== undefined) {
    clips = clips.filter((c) => c.name === options.clip);
    if (!clips.length)
      throw new ReportError(`${file} has no clip named '${options.clip}' (clips: ${model.clips.map((c) => c.name).join(', ') || 'none'})`, 'NO_CLIP');
  }
  const frames = options.frames ?? defaultFramesPerClip(clips.length);
  gcs ??= await initGcsSkin();
  const height = characterHeight(model.skinnedMeshes);
  const meshes: MeshReport[] = [];
  const M = model.skinnedMeshes.length;
  model.skinnedMeshes.forEach((mesh, i) => {
    const meshProgress = (text: string) => progress(`${M > 1 ? `mesh ${i + 1}/${M} ` : ''}'${printable(mesh.name)}': ${text}`);
    meshes.push(reportMesh(gcs!, file, mesh, clips, {
      sections, frames, timeMs: options.timeMs ?? DEFAULT_TIME_MS, height: height.meshUnits[i], worldScale: height.scales[i], progress: meshProgress,
    }));
  });
  return {
    file, options: { sections, frames, clip: options.clip ?? null, ...(options.clipsFile !== undefined ? { clipsFile: options.clipsFile } : {}) },
    character: { height: round(height.world, 6), skinnedMeshes: model.skinnedMeshes.length }, meshes,
    warnings: model.warnings.map(oneLine),
  };
}

/** `file` read (loadGltfFile); a failure is a ReportError with the GltfError's code, or LOAD_FAILED. */
async function readModel(file: string, progress: (text: string) => void): ReturnType<typeof loadGltfFile> {
  progress(`reading ${file}`);
  try {
    return await loadGltfFile(file);
  } catch (e) {
    if (e instanceof GltfError) throw new ReportError(oneLine(e.message), e.code, { cause: e });
    throw new ReportError(`cannot read ${file}: ${oneLine((e as Error).message)}`, 'LOAD_FAILED', { cause: e });
  }
}

/**
 * The animations of `clipsFile` that move the model: each clip keeps the tracks whose node the
 * model has (by name, as three.js's mixer binds them); a clip that moves none of its nodes is left
 * out, and a file none of whose clips does is a ReportError (NO_CLIP) naming both files.
 */
async function companionClips(clipsFile: string, file: string, meshes: readonly THREE.SkinnedMesh[], progress: (text: string) => void): Promise<THREE.AnimationClip[]> {
  const companion = await readModel(clipsFile, progress);
  const roots = new Set(meshes.map((m) => { let root: THREE.Object3D = m; while (root.parent) root = root.parent; return root; }));
  const hasNode = (name: string) => [...roots].some((root) => !!root.getObjectByName(name));
  // GLTFLoader names a track "<node>.<property>" with the node's name sanitised (no '.'): the node is what precedes the last '.'.
  const bound = companion.clips.filter((clip) => {
    clip.tracks = clip.tracks.filter((t) => hasNode(t.name.slice(0, t.name.lastIndexOf('.'))));
    return clip.tracks.length > 0;
  });
  if (!bound.length)
    throw new ReportError(companion.clips.length
      ? `the clips of ${clipsFile} (${companion.clips.map((c) => c.name).join(', ')}) move no node of ${file}: their node names differ`
      : `${clipsFile} has no animation clip`, 'NO_CLIP');
  return bound;
}

interface MeshSettings { sections: number; frames: number; timeMs: number; height: number; worldScale: number; progress: (text: string) => void }

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
  s.progress(`reference poses (${frames.length} frames)`);
  const probe = new FidelityProbe(input, frames, { height });
  const methods = {} as Record<MethodName, MethodReport>;
  const clipMethods = clips.map(() => ({}) as Partial<Record<MethodName, ClipMethodReport>>);
  const built: { method: MethodName; d: Deformer }[] = [];
  let gcsCounts = null as { parts: number; sections: number } | null;
  try {
    // Build and measure fidelity, method by method; the deformers stay for the timing below.
    METHODS.forEach((method, k) => {
      s.progress(`${method} (${k + 1}/${METHODS.length}): build, fidelity over ${frames.length} frames`);
      let d: Deformer | undefined;
      let r: MethodReport = { available: false };
      try {
        const t0 = performance.now();
        d = buildMethod(rig!, method, { sections: s.sections });
        r.buildMs = round(performance.now() - t0);
        r.vertices = d.vertexCount;
        r.triangles = d.indices.length / 3;
        if (method !== 'lbs' && method !== 'dqs') r.sections = d.sectionCount;
        if (method === 'gcs') gcsCounts = { parts: d.partCount, sections: d.sectionCount };
        if (method === 'classic') {
          const loss = (d as unknown as { detailLoss: { rms: number; max: number } }).detailLoss;
          r.detailLoss = { rms: round(loss.rms), max: round(loss.max) };
        }
        r.fidelity = roundFidelity(probe.measure(d));
        r.available = true;
        built.push({ method, d });
      } catch (e) {
        d?.dispose();
        if (!(e instanceof GcsError)) throw e;
        r = { available: false, error: errorInfo(e), ...(r.buildMs !== undefined ? { buildMs: r.buildMs } : {}) };
      }
      methods[method] = r;
    });
    // Frame times: per clip, every method in turn (the bind pose alone when there is no clip).
    const timed = clips.length ? clipFrames : [frames];
    const budget = Math.max(20, s.timeMs / timed.length);
    const perClip = timed.map((skins, c) => {
      if (clips.length) s.progress(`timing clip '${printable(clips[c].name)}' (${c + 1}/${clips.length}), ${built.length} methods in turn`);
      const t = timeInterleaved(skins.length, built.map(({ d }) => (f: number) => d.deform(skins[f])),
        { minSamples: 30, minMs: budget / 2, maxMs: budget, warmup: Math.min(skins.length, 8) });
      built.forEach(({ method, d }, k) => {
        if (!clips.length) return;
        const x: ClipMethodReport = { medianMs: round(t[k].medianMs), p95Ms: round(t[k].p95Ms), samples: t[k].samples };
        if (method === 'gcs') {
          let adjusted = 0;
          for (const skin of skins) { d.deform(skin); adjusted += (d as GcsDeformer).adjustedShare; }
          x.adjustedShare = round(adjusted / skins.length, 3);
        }
        clipMethods[c][method] = x;
      });
      return t;
    });
    built.forEach(({ method }, k) => {
      methods[method].medianMs = round(median(perClip.map((t) => t[k].medianMs)));
      methods[method].p95Ms = round(Math.max(...perClip.map((t) => t[k].p95Ms)));
    });
    s.progress('knees and elbows, each bent alone');
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
    for (const { d } of built) d.dispose();
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

/**
 * How many vertices have more than 4 influences (weights > 0).
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export function verticesOverFourInfluences(input: RigInput): number {
  given(isRecord(input) && (Array.isArray(input.weights) || ArrayBuffer.isView(input.weights)), 'verticesOverFourInfluences: input must be a RigInput (weights an array)', input);
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

/** A Report as report() makes it: an object whose file is a string and whose meshes are an array of objects. */
function checkReport(r: unknown, fn: string): void {
  given(isRecord(r) && typeof r.file === 'string' && Array.isArray(r.meshes) && r.meshes.every(isRecord), `${fn}: the report must be one report() made`, r);
}

/**
 * The methods that produced non-finite values, per mesh (empty: none).
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export function nonFiniteMethods(r: Report): { mesh: string; method: MethodName; count: number }[] {
  checkReport(r, 'nonFiniteMethods');
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

/**
 * `text` cut to `max` columns with an ellipsis when longer.
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export function shortened(text: string, max: number): string {
  given(typeof text === 'string', 'shortened: the text must be a string', text);
  given(typeof max === 'number' && !Number.isNaN(max), 'shortened: max must be a number of columns', max);
  return text.length <= max ? text : `${text.slice(0, Math.max(0, max - 1))}…`;
}

/** Rows (the first the header) laid out with two spaces between columns; the first column and a last 'note' column left-aligned. */
function layout(rows: string[][]): string[] {
  const widths = rows[0].map((_, c) => Math.max(...rows.map((r) => r[c].length)));
  const left = (c: number) => c === 0 || rows[0][c] === 'note';
  return rows.map((r) => r.map((cell, c) => (left(c) ? cell.padEnd(widths[c]) : cell.padStart(widths[c]))).join('  ').trimEnd());
}

/**
 * A text table within `columns`: when wider, the columns named in `drop` are left out in that order
 * until it fits, then the first column's cells are shortened with an ellipsis. Returns its lines and
 * the headers left out. (No limit: every column, as they are.)
 */
function table(rows: string[][], columns = Infinity, drop: readonly string[] = []): { lines: string[]; dropped: string[] } {
  let kept = rows;
  const dropped: string[] = [];
  const widest = (lines: string[]) => Math.max(...lines.map((l) => l.length));
  let lines = layout(kept);
  for (const name of drop) {
    if (widest(lines) <= columns) break;
    const c = kept[0].indexOf(name);
    if (c < 0) continue;
    kept = kept.map((r) => r.filter((_, i) => i !== c));
    dropped.push(name);
    lines = layout(kept);
  }
  const over = widest(lines) - columns;
  if (over > 0) {
    const first = Math.max(...kept.map((r) => r[0].length));
    lines = layout(kept.map((r) => [shortened(r[0], Math.max(4, first - over)), ...r.slice(1)]));
  }
  return { lines, dropped };
}

/** `text` in lines of at most `columns`, broken at spaces; a word longer than a line is shortened with an ellipsis. */
function wrap(text: string, columns = REPORT_COLUMNS): string[] {
  const lines: string[] = [];
  let line = '';
  for (const word of text.split(' ')) {
    if (line && line.length + 1 + word.length > columns) { lines.push(line); line = `  ${word}`; }
    else line = line ? `${line} ${word}` : word;
  }
  if (line) lines.push(line);
  return lines.map((l) => shortened(l, columns));
}

/** The text report fits this many columns in a pipe or a file (on a terminal: its width, at least MIN_TERMINAL_COLUMNS). */
export const REPORT_COLUMNS = 120;
/** The narrowest layout: a terminal narrower than this still gets 80 columns. */
export const MIN_TERMINAL_COLUMNS = 80;

/**
 * The width of the text report on `stream`: REPORT_COLUMNS in a pipe or a file, the terminal's (at least 80) on a terminal.
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export function reportColumns(stream: { isTTY?: boolean; columns?: number }): number {
  given(isRecord(stream), 'reportColumns: the stream must be an object', stream);
  return stream.isTTY ? Math.max(MIN_TERMINAL_COLUMNS, stream.columns || MIN_TERMINAL_COLUMNS) : REPORT_COLUMNS;
}

/** Main table columns left out first when the report is narrower than the table, in this order (--wide and --json keep every one). */
const OPTIONAL_COLUMNS = ['stretched', 'rigid err %', 'DQS max %', 'build ms', 'flipped'];
/** The same for the joints table. */
const OPTIONAL_JOINT_COLUMNS = ['collapse p5/min', 'new self-x', 'creases'];

/**
 * Whether every method measured a joint alike (all figures equal): nothing in the joint's region
 * blends between two bones, the limb is rigid pieces, and its figures say nothing of the methods.
 */
function rigidJoint(rows: string[][]): boolean {
  const measured = rows.filter((r) => !r[2].startsWith('n/a'));
  return measured.length > 1 && measured.every((r) => r.slice(2).join('|') === measured[0].slice(2).join('|'));
}

/**
 * The human-readable report: a table per mesh within `columns` (default REPORT_COLUMNS; columns
 * left out, and long names shortened with an ellipsis, when narrower); `wide`: every column and the clips.
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export function formatReport(r: Report, options: { wide?: boolean; columns?: number } = {}): string {
  checkReport(r, 'formatReport');
  given(isRecord(options), 'formatReport: options must be an object', options);
  const wide = options.wide ?? false;
  const columns = wide ? Infinity : Math.max(MIN_TERMINAL_COLUMNS, options.columns ?? REPORT_COLUMNS);
  const out: string[] = [];
  const say = (text: string) => out.push(...(wide ? [text] : wrap(text, columns)));
  say(`gcs-skin report: ${printable(r.file)}`);
  say(`character: ${r.character.skinnedMeshes} skinned mesh(es), height ${fmt(r.character.height, 4)} world units (bind pose)`);
  for (const w of r.warnings) say(`loader warning: ${printable(w)}`);
  for (const m of r.meshes) {
    const c = m.counts;
    out.push('');
    say(`mesh '${shownName(m.name)}': ${c.vertices} vertices, ${c.triangles} triangles, ${c.joints} joints, ` +
      `${c.parts ?? 'n/a'} parts, ${c.sections ?? 'n/a'} GCS sections (${r.options.sections} per part)`);
    say(`fidelity over ${m.frames.count} frame(s) (${m.frames.source === 'clips' ? `${m.clips.length} clip(s), ${r.options.frames} each` : 'bind pose only: no clip'}); ` +
      `% of the character's height = ${fmt(m.height, 4)} mesh units (world scale ${fmt(m.worldScale, 4)})`);
    say(`influences: ${c.influences} per vertex read, ${c.moreThan4Influences} vertices with more than 4` +
      (c.moreThan4Influences ? ' (three.js\'s own skinning would drop their JOINTS_1/WEIGHTS_1)' : ''));
    const lbs = m.methods.lbs?.fidelity?.flipped;
    // Creases against the baselines: the more of LBS's and DQS's count over the same frames.
    const creaseBase = Math.max(m.methods.lbs?.fidelity?.creases ?? 0, m.methods.dqs?.fidelity?.creases ?? 0);
    const header = ['method', 'build ms', 'ms/frame', 'rigid err %', 'DQS p95 %', 'DQS max %', 'flipped', 'creases', 'stretched', 'non-finite'];
    if (wide) header.push('p95 ms', 'normal off', 'seam gap %', 'note');
    const rows = [header];
    const notes: string[] = [];
    for (const name of METHODS) {
      const x = m.methods[name];
      if (!x.available || !x.fidelity) {
        rows.push([name, fmt(x.buildMs, 2), 'n/a', ...header.slice(3).map(() => '')]);
        notes.push(`${name}: ${x.error!.code}: ${printable(x.error!.message)}`);
        continue;
      }
      const f = x.fidelity;
      const flipped = name === 'lbs' || lbs === undefined ? String(f.flipped) : wide ? `${f.flipped} (LBS ${lbs})` : `${f.flipped}`;
      const creases = name === 'lbs' || name === 'dqs' || !(creaseBase > 0) ? String(f.creases)
        : `${f.creases} (${(f.creases / creaseBase).toFixed(2)}×)`;
      // Detail loss 0: the classic model resampled nothing (every part carried), so there is no loss to report.
      const note = !x.detailLoss ? '' : x.detailLoss.rms === 0 && x.detailLoss.max === 0 ? 'nothing resampled: every part carried, its own skin moved by DQS'
        : `resampled: detail loss rms ${fmt(x.detailLoss.rms)} % max ${fmt(x.detailLoss.max)} % of its height`;
      const row = [name, fmt(x.buildMs, 2), fmt(x.medianMs, 4), fmt(f.rigidError, 4), fmt(f.dqsP95), fmt(f.dqsMax), flipped, creases, String(f.stretched),
        String(f.nonFinite)];
      if (wide) row.push(fmt(x.p95Ms, 4), fmt(f.normalOffUnit, 4), fmt(f.seamGap, 4), note);
      else if (note) notes.push(`${name}: ${note}`);
      rows.push(row);
    }
    const main = table(rows, columns, OPTIONAL_COLUMNS);
    out.push(...main.lines);
    if (main.dropped.length) say(`(${main.dropped.join(', ')}: left out at ${columns} columns; --wide or --json for every column)`);
    say(`ms/frame: median of the clips' (methods timed in turn) · creases ×: vs the more of LBS/DQS · LBS flipped ${lbs ?? 'n/a'}`);
    for (const n of notes) say(n);
    if (!m.clips.length) say('(no animation clips: the bind pose was timed)');
    else if (!wide) {
      const names = m.clips.map((clip) => shownName(clip.name)).join(', ');
      say(`${m.clips.length} clip(s)${names.length <= 70 ? `: ${names}` : ''} (per clip: --wide or --json)`);
    }
    const j = m.joints;
    out.push('');
    say(`joints, each bent alone from the bind pose: ${j.joints.length ? j.joints.map((x) => printable(x.hinge.label)).join(', ') : 'none found'}`);
    say('volume: the joint region\'s, posed against bind; bulge and collapse: distance to the nearest bone over the same at bind');
    for (const note of j.notes) say(`  note: ${printable(note)}`);
    if (j.joints.length) {
      // Each joint's name on a line of its own above its methods (a column of joint names would not
      // fit); a joint that every method moves alike (rigid pieces) gets one line instead of numbers.
      const [head, ...body] = jointTableRows(j).map((row) => row.map(printable));
      const perJoint: { label: string; rows: string[][] }[] = [];
      for (const row of body) {
        if (row[0]) perJoint.push({ label: row[0], rows: [] });
        perJoint[perJoint.length - 1].rows.push(row);
      }
      const rows = [['joint / method', ...head.slice(2)]];
      const blocks: { label: string; first: number; count: number }[] = [];
      for (const joint of perJoint) {
        const rigid = rigidJoint(joint.rows);
        blocks.push({ label: rigid ? `${joint.label}: no soft joint: the limb is rigid pieces (every method moves it alike)` : joint.label, first: rows.length, count: rigid ? 0 : joint.rows.length });
        if (!rigid) for (const row of joint.rows) rows.push([`  ${row[1]}`, ...row.slice(2)]);
      }
      const laid = table(rows, columns, OPTIONAL_JOINT_COLUMNS.map((name) => head.find((h) => h.startsWith(name)) ?? name));
      out.push(laid.lines[0]);
      for (const b of blocks) out.push(shortened(b.label, columns), ...laid.lines.slice(b.first, b.first + b.count));
      if (laid.dropped.length) say(`(${laid.dropped.join(', ')}: left out at ${columns} columns; --wide or --json for every column)`);
    }
    if (wide)
      for (const clip of m.clips) {
        out.push('', `clip '${shownName(clip.name)}' (${fmt(clip.duration, 2)} s, ${clip.frames} frames)`);
        const rows2 = [['method', 'median ms', 'p95 ms', 'samples', 'adjusted']];
        for (const name of METHODS) {
          const x = clip.methods[name];
          if (!x) { rows2.push([name, 'n/a', '', '', '']); continue; }
          rows2.push([name, fmt(x.medianMs, 4), fmt(x.p95Ms, 4), String(x.samples), x.adjustedShare !== undefined ? `${(100 * x.adjustedShare).toFixed(0)} %` : '']);
        }
        out.push(...table(rows2).lines);
      }
  }
  return out.join('\n');
}

function parseArgs(argv: string[]): { file?: string; json: boolean; wide: boolean; help: boolean; options: ReportOptions } {
  const options: ReportOptions = {};
  let file: string | undefined, json = false, wide = false, help = false;
  walkArguments(argv, (message) => new ReportError(message), (a, value) => {
    const integer = (min: number, max: number) => wholeNumber(a, value(), min, max);
    if (a === '--json') json = true;
    else if (a === '--wide') wide = true;
    else if (a === '-h' || a === '--help') help = true;
    else if (a === '--clip') options.clip = value();
    else if (a === '--clips') options.clipsFile = value();
    else if (a === '--sections') options.sections = integer(3, 256);
    else if (a === '--frames') options.frames = integer(1, 10000);
    else if (a === '--time-ms') options.timeMs = integer(1, 60000);
    else if (a.startsWith('-') && a !== '-') throw new ReportError(`unknown option '${a}'`); // '-': standard input
    else if (file === undefined) file = a;
    else throw new ReportError(`only one model file, got '${file}' and '${a}'`);
  });
  return { file, json, wide, help, options };
}

/**
 * Whether to show progress on `stream`: only on a terminal (a pipe or a file gets the report and
 * nothing else), not a dumb one, and not when GCS_SKIN_PROGRESS=0; GCS_SKIN_PROGRESS=1 forces it.
 * @throws ReportError `USAGE` when an argument is not of its kind (a string, a number, an object, a report() result where one is expected).
 */
export function wantsProgress(stream: { isTTY?: boolean }, env: Record<string, string | undefined>): boolean {
  given(isRecord(stream), 'wantsProgress: the stream must be an object', stream);
  given(isRecord(env), 'wantsProgress: env must be an object (process.env)', env);
  if (env.GCS_SKIN_PROGRESS === '1') return true;
  if (env.GCS_SKIN_PROGRESS === '0') return false;
  return stream.isTTY === true && env.TERM !== 'dumb';
}

/** One progress line on stderr, rewritten in place (cut to the terminal's width) and cleared at the end; silent when not wanted. */
function progressLine(stream: NodeJS.WriteStream, env: Record<string, string | undefined>): { show: (text: string) => void; end: () => void } {
  if (!wantsProgress(stream, env)) return { show: () => {}, end: () => {} };
  let shown = false;
  const started = performance.now();
  return {
    show: (text) => {
      const line = `gcs-skin report: ${text} (${((performance.now() - started) / 1000).toFixed(0)} s)`;
      const width = Math.max(20, (stream.columns || 80) - 1);
      stream.write(`\r\x1b[K${line.length > width ? `${line.slice(0, width - 1)}…` : line}`);
      shown = true;
    },
    end: () => {
      if (shown) stream.write('\r\x1b[K');
      shown = false;
    },
  };
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
  const progress = progressLine(process.stderr, process.env);
  try {
    r = await report(args.file, { ...args.options, onProgress: progress.show });
  } catch (e) {
    if (e instanceof ReportError) {
      progress.end();
      process.stderr.write(`gcs-skin report: ${oneLine(e.message)} [${e.code}]\n`);
      return 2;
    }
    throw e;
  } finally {
    progress.end();
  }
  console.log(args.json ? JSON.stringify(r, null, 2) : formatReport(r, { wide: args.wide, columns: reportColumns(process.stdout) }));
  const bad = nonFiniteMethods(r);
  if (bad.length) {
    process.stderr.write(`gcs-skin report: non-finite values from ${bad.map((b) => `${b.method} on '${shownName(b.mesh)}' (${b.count})`).join(', ')}\n`);
    return 1;
  }
  return 0;
}
