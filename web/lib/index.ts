/**
 * gcs-skin: skin deformation by generalized cross-sections, in WebAssembly.
 *
 *   const gcs = await initGcsSkin();
 *   const rig = gcs.createRig({ positions, indices, joints, weights, parents, inverseBindMatrices });
 *   const deformer = rig.buildGcs({ sections: 8 });
 *   deformer.deform(skinMatrices);          // every frame: J × 16 floats
 *   deformer.positions / deformer.normals   // Float32Array views on wasm memory
 *   deformer.dispose(); rig.dispose();
 *
 * Every object that owns wasm memory has `dispose()`; using it afterwards throws GcsError
 * 'DISPOSED'. Every failure is a GcsError with a `code`.
 *
 * One file for the core's API, over 700 lines on purpose: GcsSkin, Rig, the deformers and the pose
 * buffers share internal state (handles, views on wasm memory, raise()) that a split would have to
 * export; the boundary itself is boundary.generated.ts, the measures measure/, the adapters three/.
 *
 * @module gcs-skin
 */
import {
  GCS_CLASSIC_DEFAULT_BULGE, GCS_CLASSIC_DEFAULT_CONTOURS, GCS_CLASSIC_DEFAULT_RAYS, GCS_CLASSIC_MAX_BULGE, GCS_CLASSIC_MAX_CONTOURS,
  GCS_CLASSIC_MAX_RAYS, GCS_CLASSIC_MIN_CONTOURS, GCS_CLASSIC_MIN_RAYS, GCS_CLASSIC_PART_INTS, GCS_DEFAULT_CENTRES, GCS_DEFAULT_CRITERION,
  GCS_DEFAULT_INFLUENCE_WIDTH, GCS_DEFAULT_SECTIONS, GCS_DEFAULT_TWIST_SPREAD, GCS_COMPACT_FLOATS_PER_JOINT, GCS_GPU_TEXELS_PER_JOINT, GCS_GPU_TEXELS_PER_SECTION, GCS_JOINT_POSES_COMPACT,
  GCS_MAX_INFLUENCES, GCS_MAX_INSTANCES, GCS_MAX_JOINTS, GCS_MAX_SECTIONS, GCS_MIN_SECTIONS, GCS_SECTION_INFO_FLOATS, GCS_SMOOTH_BY_CRITERION,
  GcsClassicPartField, GcsClassicReasonNames, GcsCriterionNames, GcsDeformerKindNames, GcsSectionInfoField, GcsSectionKind,
  GcsSettingsBytes, GcsStat, weightGridSteps as gridSteps, writeGcsSettings,
} from './boundary.generated.js';
import { checkWasmSource, loadFailure } from './core-check.js';
import { asGiven, GcsError, type GcsErrorCode } from './errors.js';
import { instantiateCore, type CoreExports, type WasmSource } from './loader.js';
import type { GcsSettings } from './boundary.generated.js';
import { VERSION, versionNumber, versionString } from './version.js';

export { asGiven, GcsError, type GcsErrorCode } from './errors.js';
export type { WasmSource } from './loader.js';
export { version } from './version.js';

// The limits and defaults below are gcs_skin.h's (read from it by scripts/gen-boundary.mjs into
// boundary.generated.ts): the header is the one statement of each.
/** Fewest sections `buildGcs` takes (gcs_skin.h GCS_MIN_SECTIONS). */
export const MIN_SECTIONS = GCS_MIN_SECTIONS;
/** Most skin influences (joint, weight pairs) per vertex (gcs_skin.h GCS_MAX_INFLUENCES). */
export const MAX_INFLUENCES = GCS_MAX_INFLUENCES;
/** Most sections `buildGcs` takes (gcs_skin.h GCS_MAX_SECTIONS). */
export const MAX_SECTIONS = GCS_MAX_SECTIONS;
/** The ranges `buildClassic` checks: contours per part, rays per contour, muscle bulge gain (gcs_skin.h). */
export const CLASSIC_LIMITS = {
  /** Fewest contours per resampled part. */ minContours: GCS_CLASSIC_MIN_CONTOURS,
  /** Most contours per resampled part. */ maxContours: GCS_CLASSIC_MAX_CONTOURS,
  /** Fewest rays per contour. */ minRays: GCS_CLASSIC_MIN_RAYS,
  /** Most rays per contour. */ maxRays: GCS_CLASSIC_MAX_RAYS,
  /** Largest muscle bulge gain. */ maxBulge: GCS_CLASSIC_MAX_BULGE,
} as const;

/**
 * Weights criterion: the steps of the weight grid at a section count, Q = 2·(sections − 2); node
 * weights are multiples of 1/Q (6 sections → eighths; docs/method.md §2). gcs_skin.h's
 * GCS_WEIGHT_GRID_STEPS, which the core uses too.
 */
export function weightGridSteps(sections: number): number {
  if (typeof sections !== 'number' || !Number.isInteger(sections) || sections < MIN_SECTIONS || sections > MAX_SECTIONS)
    throw new GcsError('SECTION_COUNT', `the section count must be a whole number between ${MIN_SECTIONS} and ${MAX_SECTIONS}; got ${asGiven(sections)}`);
  return gridSteps(sections);
}

type ArrayLikeNumbers = ArrayLike<number>;

/** A skinned mesh and its skeleton in the bind pose (glTF conventions). */
export interface RigInput {
  /** vertexCount × 3 bind-pose positions (mesh space). */
  positions: ArrayLikeNumbers;
  /** vertexCount × 3 normals; computed (area-weighted) when omitted. */
  normals?: ArrayLikeNumbers | null;
  /** Triangle list; each index < vertexCount. */
  indices: ArrayLikeNumbers;
  /** vertexCount × influences joint ids, vertex v's at v · influences (glTF JOINTS_0, then JOINTS_1 for 8). */
  joints: ArrayLikeNumbers;
  /** vertexCount × influences weights (glTF WEIGHTS_0, then WEIGHTS_1); normalised on copy over all of a vertex's. */
  weights: ArrayLikeNumbers;
  /**
   * Influences (joint, weight pairs) per vertex, 1 … MAX_INFLUENCES; default 4 (glTF's JOINTS_0 /
   * WEIGHTS_0). 8 takes a second set (JOINTS_1 / WEIGHTS_1), which three.js's own skinning drops:
   * every method here (GCS, classic, LBS, DQS, both GPU paths, crowds) uses all of them.
   */
  influences?: number;
  /** jointCount parent ids, -1 for a root. */
  parents: ArrayLikeNumbers;
  /** jointCount × 16 column-major inverse bind matrices. */
  inverseBindMatrices: ArrayLikeNumbers;
}

/**
 * How vertices are grouped into sections:
 * - 'weights' (default): bins of the skin weights; each section moves by the dual-quaternion blend
 *   of its joints at its mean weights, a vertex bound 100 % to a joint moves exactly with it.
 * - 'y': the paper's criterion, bins of the bind-pose Y coordinate, its fractional-rotation rule.
 * - 'axial': the paper's rule, bins of the projection on the bone axis (for T-posed arms).
 */
export type Criterion = (typeof GcsCriterionNames)[number];
/** The criteria in the order of their codes (GcsCriterion). */
export const CRITERIA: readonly Criterion[] = GcsCriterionNames;

/** Options of `Rig.buildGcs`: level of detail and how vertices are grouped into sections. */
export interface GcsOptions {
  /**
   * Level of detail, 3..256. Default `GCS_DEFAULTS.sections` (6). Weights criterion: the weight grid step is 1/(2·(sections−2))
   * (6 → eighths; 3 → rigid cores and even splits only). Y/axial: sections per part
   * (2 shared + sections−2 inner).
   */
  sections?: number;
  /** The section criterion. Default `GCS_DEFAULTS.criterion` ('weights'). */
  criterion?: Criterion;
  /** Y/axial only: fraction of a part over which joint influence ramps, (0, 1]. Default `GCS_DEFAULTS.influenceWidth` (1, the paper). */
  influenceWidth?: number;
  /**
   * Each vertex blends the transforms of the two sections around it (no steps between sections).
   * Default `GCS_DEFAULTS.smooth(criterion)`: true under 'weights' (sections are then nodes on the rays from each rigid core, docs/method.md
   * §2: as smooth as DQS, measured by creases), false under the paper's 'y' and 'axial' (the paper's
   * method as published). `false` under 'weights' is the fastest, stepped level of detail.
   */
  smooth?: boolean;
  /** Y/axial only: spread a joint's twist along the child part. Default `GCS_DEFAULTS.twistSpread` (false). */
  twistSpread?: boolean;
  /**
   * Weights criterion: each section of a bending pair (two joints, one the other's parent) turns by
   * its joints' blended rotation about its centre of rotation (Le & Hodgins 2016: the average of the
   * bind-pose surface whose weights resemble the section's, brought to within 1 % of the height of
   * the joint; computed once at build time), the centre moving by linear blend skinning: less of
   * DQS's bulge at a bent joint, some volume lost. `false`: the dual-quaternion blend. Default `GCS_DEFAULTS.centres` (false).
   * Ignored by 'y' and 'axial'.
   */
  centres?: boolean;
}

/** What buildGcs does with an option it is not given (gcs_skin.h GCS_DEFAULT_*). */
export const GCS_DEFAULTS = {
  /** Level of detail (6). */
  sections: GCS_DEFAULT_SECTIONS,
  /** The section criterion ('weights'). */
  criterion: CRITERIA[GCS_DEFAULT_CRITERION],
  /** Y/axial only: fraction of a part over which joint influence ramps (1, the paper). */
  influenceWidth: GCS_DEFAULT_INFLUENCE_WIDTH,
  /** smooth's default depends on the criterion (GCS_SMOOTH_BY_CRITERION): on under 'weights', off under 'y' and 'axial'. */
  smooth: (criterion: Criterion): boolean => criterion === 'weights',
  /** Y/axial only: spread a joint's twist along the child part (false). */
  twistSpread: GCS_DEFAULT_TWIST_SPREAD !== 0,
  /** Weights criterion: turn bending sections about their centres of rotation (false). */
  centres: GCS_DEFAULT_CENTRES !== 0,
} as const;

/** What buildClassic does with an option it is not given (gcs_skin.h GCS_CLASSIC_DEFAULT_*). */
export const CLASSIC_DEFAULTS = {
  /** Contours per resampled part (25). */
  contours: GCS_CLASSIC_DEFAULT_CONTOURS,
  /** Rays per contour (20). */
  rays: GCS_CLASSIC_DEFAULT_RAYS,
  /** Muscle bulge gain (0.3). */
  bulge: GCS_CLASSIC_DEFAULT_BULGE,
} as const;

/** Options of `Rig.buildClassic`: resampling density and muscle bulge. */
export interface ClassicOptions {
  /** Contours per resampled part, 2..256. Default `CLASSIC_DEFAULTS.contours` (25). */
  contours?: number;
  /** Rays per contour, 3..256. Default `CLASSIC_DEFAULTS.rays` (20). */
  rays?: number;
  /** Muscle bulge gain, 0..4. Default `CLASSIC_DEFAULTS.bulge` (0.3). */
  bulge?: number;
}

/** Which method a deformer runs: `'gcs'`, `'classic'`, `'lbs'` or `'dqs'`. */
export type DeformerKind = (typeof GcsDeformerKindNames)[number];

/** One GCS section as `GcsDeformer.sections()` reports it: its run of output vertices and what moves it. */
export interface SectionInfo {
  /** First output vertex of the section (GCS stores vertices section by section). */
  first: number;
  /** Number of output vertices in the section. */
  count: number;
  /** Joint owning the part (Y/axial: for a shared section, the child part; weights: the dominant joint). */
  part: number;
  /** Y/axial: the child part joint the section's branch leads to; weights: the second joint; or -1. */
  distal: number;
  /** A shared generalized section (SGS): between a part and its parent part, or an even weight split. */
  shared: boolean;
  /** Weights criterion: a rigid core, moved exactly by its joint's skin matrix. */
  rigid: boolean;
  /** Y/axial: mean normalised axial coordinate, 0 (proximal) … 1 (distal); weights: the second joint's weight. */
  t: number;
  /** Y/axial: fraction of the part's rotation; weights: the dominant joint's mean weight. */
  alpha: number;
  /** Y/axial: fraction of the distal joint's rotation; weights: the second joint's mean weight. */
  beta: number;
}

/**
 * Why a part of the classic model is resampled or carried (gcs_skin.h, GcsClassicReason; carried
 * skin keeps its triangles and moves by dual-quaternion skinning of its own weights):
 * `resampled` a chain part, joint to joint; `trunk` a branching trunk part (pelvis, chest)
 * resampled along the spine with its branch region (crotch, shoulders) carried; carried ones:
 * `leaf` (head, hands, feet, finger tips), `branching` (a hand with fingers), `too-short`
 * (fingers, zero-length bones), `rays-miss` (a clavicle), `bent` (a foot on a shank), `seam`
 * (its boundary with the carried mesh is not one ring around an end), `off-surface` (measured at
 * build time: at a probe pose (every joint bent 35°) its tube stands off the skin it replaces by more than
 * 1 % of the height at p99 or 2.5 % at most, or its end cap would cut flat across a rounded end).
 */
export type ClassicReason = (typeof GcsClassicReasonNames)[number];
/** The reasons in the order of their codes (GcsClassicReason). */
export const CLASSIC_REASONS: readonly ClassicReason[] = GcsClassicReasonNames;

/** One part of the classic model (one joint's skin): resampled into a tube, or carried. */
export interface ClassicPart {
  /** The joint whose part this is. */
  joint: number;
  /** Whether the part was resampled into contours × rays (false: carried, its own triangles skinned by DQS). */
  resampled: boolean;
  /** Why it is resampled or carried (see ClassicReason). */
  reason: ClassicReason;
  /** Resampled: its rings (contours × rays vertices); carried: its carried input vertices. */
  firstVertex: number;
  /** Number of output vertices from `firstVertex` on. */
  vertexCount: number;
}

/** Owns the instantiated core and the views on its memory. */
export class GcsSkin {
  /** @internal */ readonly core: CoreExports;
  private f32 = new Float32Array(0);
  private u32 = new Uint32Array(0);
  private i32 = new Int32Array(0);
  private u8 = new Uint8Array(0);

  /** @internal */
  constructor(core: CoreExports) {
    this.core = core;
    this.refreshViews();
  }

  /** The wasm memory; its `buffer` is replaced when it grows. */
  get memory(): WebAssembly.Memory {
    return this.core.memory;
  }

  /** @internal Re-creates heap views after memory growth (a grown memory detaches old views). */
  refreshViews(): void {
    const buffer = this.core.memory.buffer;
    if (this.f32.buffer === buffer) return;
    this.f32 = new Float32Array(buffer);
    this.u32 = new Uint32Array(buffer);
    this.i32 = new Int32Array(buffer);
    this.u8 = new Uint8Array(buffer);
  }

  /** @internal A fresh Float32Array view of `length` floats at byte offset `ptr`. */
  viewF32(ptr: number, length: number): Float32Array {
    return new Float32Array(this.core.memory.buffer, ptr, length);
  }
  /** @internal */
  viewU32(ptr: number, length: number): Uint32Array {
    return new Uint32Array(this.core.memory.buffer, ptr, length);
  }
  /** @internal */
  viewI32(ptr: number, length: number): Int32Array {
    return new Int32Array(this.core.memory.buffer, ptr, length);
  }

  /** @internal Throws the core's last error as a GcsError. */
  raise(fallback: string): never {
    const code = this.core.gcs_last_error_code();
    const message = this.readString(this.core.gcs_last_error_message()) || fallback;
    const name = GcsError.codeFromNumber(code);
    if (name === 'UNKNOWN_CORE_ERROR')
      throw new GcsError(name, `the core failed with error code ${code}, which gcs-skin ${VERSION} does not know (is gcs-skin.wasm from another version?): ${message}`);
    throw new GcsError(name, message);
  }

  private readString(ptr: number): string {
    this.refreshViews();
    let end = ptr;
    while (this.u8[end] !== 0 && end < this.u8.length) end++;
    return new TextDecoder().decode(this.u8.subarray(ptr, end));
  }

  /** @internal Copies numbers into a fresh wasm allocation; the caller frees it. */
  copyIn(values: ArrayLikeNumbers, type: 'f32' | 'u32' | 'i32'): number {
    const bytes = Math.max(4, values.length * 4);
    const ptr = this.core.gcs_alloc(bytes);
    if (!ptr) this.raise(`out of memory: could not allocate ${bytes} bytes`);
    this.refreshViews();
    const view = type === 'f32' ? this.f32 : type === 'u32' ? this.u32 : this.i32;
    if (type === 'u32') {
      // Negative or fractional ids must not wrap silently into valid ones: map them out of range.
      for (let i = 0; i < values.length; i++) {
        const v = values[i];
        view[(ptr >>> 2) + i] = Number.isInteger(v) && v >= 0 && v <= 0xffffffff ? v : 0xffffffff;
      }
    } else {
      view.set(values as ArrayLike<number>, ptr >>> 2);
    }
    return ptr;
  }

  /**
   * Validates and copies a skinned mesh and its skeleton into wasm memory.
   * @param input Positions, triangles, joints and weights per vertex, parents and inverse bind
   * matrices (glTF conventions, mesh space); `influences` 1…8 per vertex (default 4).
   * @returns The rig: build deformers from it, dispose it when done.
   * @throws GcsError `LENGTH_MISMATCH`, `INDEX_OUT_OF_RANGE`, `JOINT_OUT_OF_RANGE`, `NON_FINITE`,
   * `BAD_WEIGHTS`, `NO_SKIN`, `INVALID_ARGUMENT` or `OUT_OF_MEMORY`, naming what is wrong.
   */
  createRig(input: RigInput): Rig {
    if (!input || typeof input !== 'object') throw new GcsError('INVALID_ARGUMENT', 'createRig expects an object with positions, indices, joints, weights, parents and inverseBindMatrices');
    for (const key of ['positions', 'indices', 'joints', 'weights', 'parents', 'inverseBindMatrices'] as const) {
      const a = input[key];
      if (!a || typeof a.length !== 'number') throw new GcsError('INVALID_ARGUMENT', `createRig: '${key}' is missing or not an array`);
    }
    const { positions, normals, indices, joints, weights, parents, inverseBindMatrices } = input;
    const influences = checkInfluences(input.influences);
    // Bounds before any loop or allocation: what does not fit in wasm memory (4 GiB) is refused at once.
    const numbers = positions.length + (normals?.length ?? 0) + indices.length + joints.length + weights.length + parents.length + inverseBindMatrices.length;
    if (!(numbers * 4 <= 2 ** 32))
      throw new GcsError('OUT_OF_MEMORY', `out of memory: the rig's arrays hold ${numbers} numbers, more than wasm memory (4 GiB) holds`);
    if (positions.length % 3 !== 0) throw new GcsError('LENGTH_MISMATCH', `positions has ${positions.length} numbers, which is not a multiple of 3`);
    const vertexCount = positions.length / 3;
    const jointCount = parents.length;
    if (vertexCount === 0) throw new GcsError('NO_SKIN', 'the mesh has no vertices');
    if (jointCount === 0) throw new GcsError('NO_SKIN', 'the skeleton has no joints (parents is empty): is the mesh skinned?');
    if (normals && normals.length !== positions.length)
      throw new GcsError('LENGTH_MISMATCH', `normals has ${normals.length} numbers but positions has ${positions.length}`);
    const perVertex = `${influences} per vertex (influences: ${influences}) are expected (${vertexCount * influences})`;
    if (joints.length !== vertexCount * influences)
      throw new GcsError('LENGTH_MISMATCH', `joints has ${joints.length} ids; ${perVertex}`);
    if (weights.length !== vertexCount * influences)
      throw new GcsError('LENGTH_MISMATCH', `weights has ${weights.length} numbers; ${perVertex}`);
    if (inverseBindMatrices.length !== jointCount * 16)
      throw new GcsError('LENGTH_MISMATCH', `inverseBindMatrices has ${inverseBindMatrices.length} numbers; 16 per joint are expected (${jointCount * 16}, from ${jointCount} parents)`);
    for (let i = 0; i < indices.length; i++) {
      const v = indices[i];
      if (!Number.isInteger(v) || v < 0 || v >= vertexCount)
        throw new GcsError('INDEX_OUT_OF_RANGE', `triangle index ${v} (at position ${i}) is out of range: the mesh has ${vertexCount} vertices`);
    }
    if (!(joints instanceof Uint8Array || joints instanceof Uint16Array || joints instanceof Uint32Array))
      for (let i = 0; i < joints.length; i++) {
        const j = joints[i];
        // Copied into wasm as u32, -1 would become 4294967295 and 1.5 would become 1: refuse them as given.
        if (!Number.isInteger(j) || j < 0)
          throw new GcsError('JOINT_OUT_OF_RANGE', `vertex ${(i - (i % influences)) / influences} has joint id ${asGiven(j)} (joints[${i}]): joint ids are whole numbers from 0 to ${jointCount - 1}`);
      }
    for (let j = 0; j < jointCount; j++) {
      const parent = parents[j];
      // Copied into wasm as i32, 1.5 would become 1: refuse it as given (the core checks the range and cycles).
      if (!Number.isInteger(parent))
        throw new GcsError('JOINT_OUT_OF_RANGE', `joint ${j} has parent ${asGiven(parent)}: a parent is a joint index (a whole number) or -1 for a root`);
    }
    const ptrs: number[] = [];
    try {
      const p = this.copyIn(positions, 'f32'); ptrs.push(p);
      const n = normals ? this.copyIn(normals, 'f32') : 0; if (n) ptrs.push(n);
      const ix = this.copyIn(indices, 'u32'); ptrs.push(ix);
      const jt = this.copyIn(joints, 'u32'); ptrs.push(jt);
      const wt = this.copyIn(weights, 'f32'); ptrs.push(wt);
      const pa = this.copyIn(parents, 'i32'); ptrs.push(pa);
      const ib = this.copyIn(inverseBindMatrices, 'f32'); ptrs.push(ib);
      const handle = this.core.gcs_rig_create(p, n, vertexCount, ix, indices.length, jt, wt, influences, pa, ib, jointCount);
      if (!handle) this.raise('the rig was rejected');
      try {
        return new Rig(this, handle);
      } catch (e) {
        this.core.gcs_rig_destroy(handle); // nothing made here outlives a failure
        throw e;
      }
    } finally {
      for (const ptr of ptrs) this.core.gcs_free(ptr);
    }
  }
}

/**
 * Loads the wasm core. `wasm` overrides where the binary comes from (default: beside this module).
 *
 * @param options `wasm`: a URL, a path (node), the bytes or a compiled `WebAssembly.Module`.
 * @returns The core: `createRig` makes rigs from skinned meshes.
 * @throws GcsError `WASM_LOAD` when the binary cannot be fetched or instantiated, or is of another
 * version than the package's.
 *
 * @example
 * ```ts
 * const gcs = await initGcsSkin();
 * const rig = gcs.createRig({ positions, indices, joints, weights, parents, inverseBindMatrices });
 * const deformer = rig.buildGcs({ sections: 8 });
 * deformer.deform(skinMatrices);           // every frame: J × 16 floats
 * const { positions, normals } = deformer;  // Float32Array views on wasm memory
 * deformer.dispose(); rig.dispose();
 * ```
 */
export async function initGcsSkin(options: {
  /** Where gcs-skin.wasm comes from (default: beside this module). */
  wasm?: WasmSource;
} = {}): Promise<GcsSkin> {
  let core: CoreExports;
  try {
    checkOptions(options, 'initGcsSkin');
    checkWasmSource(options?.wasm);
    core = await instantiateCore(options?.wasm);
  } catch (e) {
    if (e instanceof GcsError) throw e;
    throw new GcsError('WASM_LOAD', `could not load gcs-skin.wasm: ${loadFailure(e)}`);
  }
  // A binary of another version would answer the same calls differently: refuse it here.
  const coreVersion = typeof core.gcs_version === 'function' ? core.gcs_version() : null;
  if (coreVersion !== versionNumber(VERSION))
    throw new GcsError('WASM_LOAD', `gcs-skin.wasm is ${coreVersion === null ? 'from before 0.1.0 (no gcs_version)' : `version ${versionString(coreVersion)}`}, ` +
      `but this gcs-skin is ${VERSION}: load the gcs-skin.wasm of the same package`);
  return new GcsSkin(core);
}


/** RigInput.influences: a whole number in 1 … MAX_INFLUENCES, 4 when omitted. */
function checkInfluences(value: unknown): number {
  if (value === undefined) return 4;
  if (typeof value !== 'number' || !Number.isInteger(value))
    throw new GcsError('INVALID_ARGUMENT', `influences must be a whole number of influences per vertex (1 to ${MAX_INFLUENCES}); got ${asGiven(value)}`);
  if (value < 1 || value > MAX_INFLUENCES)
    throw new GcsError('OUT_OF_RANGE', `influences must be 1 to ${MAX_INFLUENCES} per vertex; got ${value}`);
  return value;
}

/** Options must be an object (or undefined): a number or string there is a mistake, not "no options". */
function checkOptions(options: unknown, method: string): void {
  if (options === undefined) return;
  if (options === null || typeof options !== 'object' || Array.isArray(options))
    throw new GcsError('INVALID_ARGUMENT', `${method} takes an options object; got ${asGiven(options)}`);
}

/** A boolean option: true, false or absent; 'no', 0 or 'false' are refused rather than read as truthy or falsy. */
function checkFlag(value: unknown, name: string): void {
  if (value !== undefined && typeof value !== 'boolean')
    throw new GcsError('INVALID_ARGUMENT', `${name} must be true or false; got ${asGiven(value)}`);
}

/**
 * GcsOptions as the core's GcsSettings, its defaults filled in. Only what cannot cross the boundary
 * is refused here (a string for a number, a fraction for a count, an unknown criterion name, a
 * flag that is not a boolean); the core checks every range, once (gcs_build_gcs).
 */
function settingsOf(options: GcsOptions): GcsSettings {
  const sections = options.sections ?? GCS_DEFAULTS.sections;
  const criterion = options.criterion ?? GCS_DEFAULTS.criterion;
  const width = options.influenceWidth ?? GCS_DEFAULTS.influenceWidth;
  if (typeof sections !== 'number' || !Number.isInteger(sections) || sections < 0 || sections > 0xffffffff)
    throw new GcsError('SECTION_COUNT', `the section count must be a whole number between ${MIN_SECTIONS} and ${MAX_SECTIONS}; got ${asGiven(sections)}`);
  if (!CRITERIA.includes(criterion))
    throw new GcsError('INVALID_ARGUMENT', `criterion must be 'weights', 'y' or 'axial'; got ${asGiven(criterion)}`);
  if (typeof width !== 'number')
    throw new GcsError('INVALID_ARGUMENT', `the influence width must be a number in (0, 1]; got ${asGiven(width)}`);
  checkFlag(options.smooth, 'smooth');
  checkFlag(options.twistSpread, 'twistSpread');
  checkFlag(options.centres, 'centres');
  return {
    sections,
    criterion: CRITERIA.indexOf(criterion),
    influenceWidth: width,
    smooth: options.smooth === undefined ? GCS_SMOOTH_BY_CRITERION : Number(options.smooth),
    twistSpread: Number(options.twistSpread ?? GCS_DEFAULTS.twistSpread),
    centres: Number(options.centres ?? GCS_DEFAULTS.centres),
  };
}

/** A validated skinned mesh in wasm memory: the input every deformer is built from. */
export class Rig {
  /** Number of vertices of the skinned mesh. */
  readonly vertexCount: number;
  /** Number of joints of the skeleton. */
  readonly jointCount: number;
  /** Largest extent of the bind-pose bounding box (model units). */
  readonly height: number;
  private handle: number;

  /**
   * @internal
   * @param gcs The core that owns the rig's memory.
   */
  constructor(readonly gcs: GcsSkin, handle: number) {
    this.handle = handle;
    this.vertexCount = gcs.core.gcs_rig_vertex_count(handle);
    this.jointCount = gcs.core.gcs_rig_joint_count(handle);
    this.height = gcs.core.gcs_rig_height(handle);
  }

  private live(): number {
    if (!this.handle) throw new GcsError('DISPOSED', 'this rig has been disposed');
    return this.handle;
  }

  /**
   * Builds a generalized cross-section model (docs/method.md §2–4).
   * @param options Sections (3…256, default 6), criterion (default 'weights'), smooth, centres.
   * @returns The GCS deformer (the rig may be disposed before it).
   * @throws GcsError `SECTION_COUNT`, `INVALID_ARGUMENT` or `OUT_OF_RANGE` for bad options,
   * `OUT_OF_MEMORY`, `DISPOSED` when the rig was disposed.
   */
  buildGcs(options: GcsOptions = {}): GcsDeformer {
    checkOptions(options, 'buildGcs');
    const settings = settingsOf(options);
    const ptr = this.gcs.core.gcs_alloc(GcsSettingsBytes);
    if (!ptr) this.gcs.raise(`out of memory: could not allocate ${GcsSettingsBytes} bytes`);
    let h: number;
    try {
      writeGcsSettings(this.gcs.memory.buffer, ptr, settings);
      h = this.gcs.core.gcs_build_gcs(this.live(), ptr);
    } finally {
      this.gcs.core.gcs_free(ptr);
    }
    if (!h) this.gcs.raise('the GCS model could not be built');
    return new GcsDeformer(this.gcs, h, this.jointCount);
  }

  /**
   * Builds the classic cross-section model (docs/method.md §6).
   * @param options Contours per part, rays per contour, muscle bulge (CLASSIC_LIMITS).
   * @returns The classic deformer: its `parts` say what was resampled and why.
   * @throws GcsError `OUT_OF_RANGE` or `INVALID_ARGUMENT` for bad options, `OUT_OF_MEMORY`, `DISPOSED`.
   */
  buildClassic(options: ClassicOptions = {}): ClassicDeformer {
    checkOptions(options, 'buildClassic');
    const contours = options.contours ?? CLASSIC_DEFAULTS.contours;
    const rays = options.rays ?? CLASSIC_DEFAULTS.rays;
    const bulge = options.bulge ?? CLASSIC_DEFAULTS.bulge;
    const L = CLASSIC_LIMITS;
    if (!Number.isInteger(contours) || contours < L.minContours || contours > L.maxContours)
      throw new GcsError('OUT_OF_RANGE', `contours must be a whole number between ${L.minContours} and ${L.maxContours}; got ${asGiven(contours)}`);
    if (!Number.isInteger(rays) || rays < L.minRays || rays > L.maxRays)
      throw new GcsError('OUT_OF_RANGE', `rays must be a whole number between ${L.minRays} and ${L.maxRays}; got ${asGiven(rays)}`);
    if (typeof bulge !== 'number' || !(bulge >= 0 && bulge <= L.maxBulge))
      throw new GcsError(typeof bulge === 'number' ? 'OUT_OF_RANGE' : 'INVALID_ARGUMENT', `bulge must be a number between 0 and ${L.maxBulge}; got ${asGiven(bulge)}`);
    const h = this.gcs.core.gcs_build_classic(this.live(), contours, rays, bulge);
    if (!h) this.gcs.raise('the classic cross-section model could not be built');
    return new ClassicDeformer(this.gcs, h, this.jointCount);
  }

  /** Linear blend skinning (what three.js does), on the rig's own vertices. */
  buildLbs(): Deformer {
    const h = this.gcs.core.gcs_build_lbs(this.live());
    if (!h) this.gcs.raise('the LBS deformer could not be built');
    return new Deformer(this.gcs, h, this.jointCount);
  }

  /** Dual-quaternion skinning, on the rig's own vertices. */
  buildDqs(): Deformer {
    const h = this.gcs.core.gcs_build_dqs(this.live());
    if (!h) this.gcs.raise('the DQS deformer could not be built');
    return new Deformer(this.gcs, h, this.jointCount);
  }

  /** Builds a deformer by kind name. */
  build(kind: DeformerKind, options: GcsOptions & ClassicOptions = {}): Deformer {
    switch (kind) {
      case 'gcs': return this.buildGcs(options);
      case 'classic': return this.buildClassic(options);
      case 'lbs': return this.buildLbs();
      case 'dqs': return this.buildDqs();
      default: throw new GcsError('INVALID_ARGUMENT', `unknown deformer kind ${asGiven(kind)} (gcs, classic, lbs, dqs)`);
    }
  }

  /** Frees the rig's wasm memory. Deformers built from it stay valid. */
  dispose(): void {
    if (this.handle) this.gcs.core.gcs_rig_destroy(this.handle);
    this.handle = 0;
  }
}

/** J identity matrices: the skin matrices of the bind pose (what `deform` takes at rest). */
export function identitySkin(jointCount: number): Float32Array {
  if (typeof jointCount !== 'number' || !Number.isInteger(jointCount) || jointCount < 0 || jointCount > GCS_MAX_JOINTS)
    throw new GcsError('OUT_OF_RANGE', `the joint count must be a whole number between 0 and ${GCS_MAX_JOINTS}; got ${asGiven(jointCount)}`);
  const skin = new Float32Array(jointCount * 16);
  for (let j = 0; j < jointCount; j++) skin[16 * j] = skin[16 * j + 5] = skin[16 * j + 10] = skin[16 * j + 15] = 1;
  return skin;
}

/** A runtime deformer: owns its output mesh in wasm memory and fills it every frame. */
export class Deformer {
  /** The method this deformer runs. */
  readonly kind: DeformerKind;
  /** Number of output vertices (GCS, LBS, DQS: the rig's; classic: its resampled mesh's). */
  readonly vertexCount: number;
  /** Number of joints: `deform` takes `jointCount × 16` numbers. */
  readonly jointCount: number;
  protected handle: number;
  private positionsPtr: number;
  private normalsPtr: number;
  private skinPtr: number;
  private positionsView: Float32Array;
  private normalsView: Float32Array;
  private skinView: Float32Array;
  private morphPtr = 0;
  private morphCount = 0;
  private morphView: Float32Array = new Float32Array(0);
  private tangentsPtr = 0;
  /** keepPreviousPositions: the two arrays positions alternate between, as views (made once). */
  private swapped: { ptr: number; view: Float32Array }[] | null = null;
  private tangentsView: Float32Array | null = null;

  /**
   * @internal
   * @param gcs The core that owns the deformer's memory.
   */
  constructor(readonly gcs: GcsSkin, handle: number, jointCount: number) {
    const core = gcs.core;
    this.handle = handle;
    this.kind = GcsDeformerKindNames[core.gcs_deformer_kind(handle)] ?? 'gcs';
    this.vertexCount = core.gcs_deformer_vertex_count(handle);
    this.jointCount = jointCount;
    this.positionsPtr = core.gcs_deformer_positions(handle);
    this.normalsPtr = core.gcs_deformer_normals(handle);
    this.skinPtr = core.gcs_alloc(jointCount * 64);
    if (!this.skinPtr) {
      core.gcs_deformer_destroy(handle);
      gcs.raise('out of memory for the skin matrices');
    }
    this.positionsView = gcs.viewF32(this.positionsPtr, this.vertexCount * 3);
    this.normalsView = gcs.viewF32(this.normalsPtr, this.vertexCount * 3);
    this.skinView = gcs.viewF32(this.skinPtr, jointCount * 16);
  }

  protected live(): number {
    if (!this.handle) throw new GcsError('DISPOSED', `this ${this.kind} deformer has been disposed`);
    return this.handle;
  }

  /** Deformed positions (vertexCount × 3): a view on wasm memory, re-created after growth. */
  get positions(): Float32Array {
    this.live();
    if (this.swapped) return this.swappedView(this.gcs.core.gcs_deformer_positions(this.handle));
    if (this.positionsView.buffer !== this.gcs.memory.buffer)
      this.positionsView = this.gcs.viewF32(this.positionsPtr, this.vertexCount * 3);
    return this.positionsView;
  }

  /**
   * Velocity: keep the previous frame's positions (`previousPositions`). The core then writes each
   * frame into the array that held the frame before last and swaps the two, so `positions` and
   * `previousPositions` alternate between two views made once (no copy, no allocation per frame):
   * read both after every `deform`. `false` frees the second array.
   */
  keepPreviousPositions(keep: boolean): void {
    const h = this.live();
    if (!this.gcs.core.gcs_deformer_keep_previous_positions(h, keep ? 1 : 0)) this.gcs.raise('the previous positions could not be kept');
    // Off after an odd number of swaps, the core keeps the other array: the single view follows it.
    this.positionsPtr = this.gcs.core.gcs_deformer_positions(h);
    this.positionsView = this.gcs.viewF32(this.positionsPtr, this.vertexCount * 3);
    this.swapped = keep ? [this.positionsPtr, this.gcs.core.gcs_deformer_previous_positions(h)].map((ptr) => ({ ptr, view: this.gcs.viewF32(ptr, this.vertexCount * 3) })) : null;
  }

  /** The positions of the deform before the last one (keepPreviousPositions), or null. */
  get previousPositions(): Float32Array | null {
    this.live();
    return this.swapped ? this.swappedView(this.gcs.core.gcs_deformer_previous_positions(this.handle)) : null;
  }

  /** The view of one of the two position arrays (re-created after memory growth). */
  private swappedView(ptr: number): Float32Array {
    const entry = this.swapped![this.swapped![0].ptr === ptr ? 0 : 1];
    if (entry.view.buffer !== this.gcs.memory.buffer) entry.view = this.gcs.viewF32(ptr, this.vertexCount * 3);
    return entry.view;
  }

  /** Deformed unit normals (vertexCount × 3): a view on wasm memory, re-created after growth. */
  get normals(): Float32Array {
    this.live();
    if (this.normalsView.buffer !== this.gcs.memory.buffer)
      this.normalsView = this.gcs.viewF32(this.normalsPtr, this.vertexCount * 3);
    return this.normalsView;
  }

  /**
   * Deformed tangents (vertexCount × 4: xyz turned as the normals are, w the handedness carried), a
   * view on wasm memory re-created after growth; null until setTangents. Written by the same
   * `deform` call as positions and normals.
   */
  get tangents(): Float32Array | null {
    this.live();
    if (!this.tangentsPtr) return null;
    if (this.tangentsView!.buffer !== this.gcs.memory.buffer) this.tangentsView = this.gcs.viewF32(this.tangentsPtr, this.vertexCount * 4);
    return this.tangentsView;
  }

  /**
   * Rest tangents for normal maps: vertexCount × 4 numbers in the RIG's vertex order (glTF TANGENT,
   * three.js's `tangent` attribute: xyz unit, w = ±1), or null to remove them. From then on every
   * `deform` also writes `tangents`. GCS, LBS and DQS (the classic model resamples the mesh:
   * INVALID_ARGUMENT). Build time only: it copies.
   */
  setTangents(tangents: ArrayLike<number> | null): void {
    const h = this.live();
    const V = this.vertexCount;
    if (tangents && tangents.length !== V * 4)
      throw new GcsError('LENGTH_MISMATCH', `tangents has ${tangents.length} numbers; ${V * 4} (4 per vertex) are expected`);
    const ptr = tangents ? this.gcs.copyIn(tangents, 'f32') : 0;
    try {
      if (!this.gcs.core.gcs_deformer_set_tangents(h, ptr, tangents ? V : 0)) this.gcs.raise('the tangents were rejected');
    } finally {
      if (ptr) this.gcs.core.gcs_free(ptr);
    }
    this.tangentsPtr = this.gcs.core.gcs_deformer_tangents(h);
    this.tangentsView = this.tangentsPtr ? this.gcs.viewF32(this.tangentsPtr, V * 4) : null;
  }

  /** The output mesh's triangles (a copy: they never change). */
  get indices(): Uint32Array {
    const h = this.live();
    const n = this.gcs.core.gcs_deformer_index_count(h);
    return this.gcs.viewU32(this.gcs.core.gcs_deformer_indices(h), n).slice();
  }

  /** For each output vertex the rig vertex it comes from (a copy), or null (resampled vertices). */
  get sourceVertex(): Uint32Array | null {
    const h = this.live();
    const ptr = this.gcs.core.gcs_deformer_source_vertex(h);
    return ptr ? this.gcs.viewU32(ptr, this.vertexCount).slice() : null;
  }

  /** @internal True when every output vertex is a rig vertex (sourceVertex is not null), without copying them. */
  get keepsVertices(): boolean {
    return this.gcs.core.gcs_deformer_source_vertex(this.live()) !== 0;
  }

  /**
   * @internal Per-vertex data of the rig's vertices in this deformer's output order: `source`
   * holds `count` items `strideBytes` apart, `itemBytes` each; item o of the result is item
   * sourceVertex[o]. Gathered in wasm (the adapters carry uv, colours… at every build, a slider
   * drag every frame). INVALID_ARGUMENT without source vertices or past `count`.
   */
  gather(source: Uint8Array, count: number, strideBytes: number, itemBytes: number): Uint8Array {
    const h = this.live();
    const core = this.gcs.core;
    const bytes = this.vertexCount * itemBytes;
    const src = core.gcs_alloc(Math.max(1, source.byteLength));
    const out = src ? core.gcs_alloc(Math.max(1, bytes)) : 0;
    try {
      if (!out) this.gcs.raise(`out of memory: could not allocate ${source.byteLength + bytes} bytes to gather vertex data`);
      new Uint8Array(core.memory.buffer, src, source.byteLength).set(source);
      if (!core.gcs_deformer_gather(h, src, count, strideBytes, itemBytes, out)) this.gcs.raise('the vertex data could not be gathered');
      return new Uint8Array(core.memory.buffer, out, bytes).slice();
    } finally {
      if (src) core.gcs_free(src);
      if (out) core.gcs_free(out);
    }
  }

  /**
   * Deforms for one frame from J skinning matrices S_j = posed world · inverse bind (column-major,
   * 16 floats each, bind-pose mesh space → posed mesh space). One copy into wasm, no allocation.
   * @param skinMatrices `jointCount × 16` numbers.
   * @throws GcsError `LENGTH_MISMATCH` for another count, `NON_FINITE` for a NaN or infinite
   * matrix, `DISPOSED`.
   */
  deform(skinMatrices: ArrayLike<number>): void {
    const h = this.live();
    if (!skinMatrices || skinMatrices.length !== this.jointCount * 16)
      throw new GcsError('LENGTH_MISMATCH', `deform expects ${this.jointCount * 16} numbers (16 per joint for ${this.jointCount} joints); got ${skinMatrices?.length ?? 0}`);
    if (this.skinView.buffer !== this.gcs.memory.buffer) this.skinView = this.gcs.viewF32(this.skinPtr, this.jointCount * 16);
    this.skinView.set(skinMatrices);
    if (!this.gcs.core.gcs_deformer_deform(h, this.skinPtr, this.jointCount)) this.gcs.raise('deform failed');
  }

  /**
   * Morph targets (blend shapes) applied to the rest mesh before skinning, as three.js does.
   * `deltas[t]`: target t's position deltas, vertexCount × 3 in the RIG's vertex order (glTF /
   * three.js `geometry.morphAttributes.position` with `morphTargetsRelative`); `normalDeltas`
   * likewise or omitted. Replaces previous targets; an empty list removes them. GCS, LBS and DQS
   * (the classic model resamples the mesh: INVALID_ARGUMENT). Build time only: it copies.
   */
  setMorphTargets(deltas: readonly ArrayLike<number>[], normalDeltas?: readonly ArrayLike<number>[] | null): void {
    const h = this.live();
    if (!Array.isArray(deltas) || (normalDeltas != null && !Array.isArray(normalDeltas)))
      throw new GcsError('INVALID_ARGUMENT', 'setMorphTargets takes an array of delta arrays (one per target) and optionally an array of normal delta arrays');
    const T = deltas.length, V = this.vertexCount;
    if (normalDeltas && normalDeltas.length !== T)
      throw new GcsError('LENGTH_MISMATCH', `${normalDeltas.length} normal delta arrays for ${T} morph targets`);
    for (const [t, d] of deltas.entries())
      if (!d || d.length !== V * 3) throw new GcsError('LENGTH_MISMATCH', `morph target ${t} has ${d?.length ?? 0} numbers; ${V * 3} (3 per vertex) are expected`);
    normalDeltas?.forEach((d, t) => {
      if (!d || d.length !== V * 3) throw new GcsError('LENGTH_MISMATCH', `morph target ${t}'s normal deltas have ${d?.length ?? 0} numbers; ${V * 3} are expected`);
    });
    const flat = (arrays: readonly ArrayLike<number>[]) => {
      const out = new Float32Array(T * V * 3);
      arrays.forEach((a, t) => out.set(a, t * V * 3));
      return out;
    };
    const ptrs: number[] = [];
    try {
      const p = T ? this.gcs.copyIn(flat(deltas), 'f32') : 0; if (p) ptrs.push(p);
      const n = T && normalDeltas ? this.gcs.copyIn(flat(normalDeltas), 'f32') : 0; if (n) ptrs.push(n);
      const influences = this.gcs.core.gcs_alloc(Math.max(4, T * 4));
      if (!influences) this.gcs.raise('out of memory for the morph influences');
      if (!this.gcs.core.gcs_deformer_set_morph_targets(h, p, n, T, V)) {
        this.gcs.core.gcs_free(influences);
        this.gcs.raise('the morph targets were rejected');
      }
      if (this.morphPtr) this.gcs.core.gcs_free(this.morphPtr);
      this.morphPtr = influences;
      this.morphCount = T;
      this.morphView = this.gcs.viewF32(influences, T);
    } finally {
      for (const ptr of ptrs) this.gcs.core.gcs_free(ptr);
    }
  }

  /** Morph influences for the next `deform` (three.js's `morphTargetInfluences`); no allocation. */
  setMorphInfluences(influences: ArrayLike<number>): void {
    const h = this.live();
    if (!influences || influences.length !== this.morphCount)
      throw new GcsError('LENGTH_MISMATCH', `got ${influences?.length ?? 0} morph influences, but the deformer has ${this.morphCount} morph targets`);
    if (this.morphCount === 0) return;
    if (this.morphView.buffer !== this.gcs.memory.buffer) this.morphView = this.gcs.viewF32(this.morphPtr, this.morphCount);
    this.morphView.set(influences);
    if (!this.gcs.core.gcs_deformer_set_morph_influences(h, this.morphPtr, this.morphCount)) this.gcs.raise('the morph influences were rejected');
  }

  /** Number of morph targets set with setMorphTargets. */
  get morphTargetCount(): number {
    return this.morphCount;
  }

  /** Sections (GCS) or contours (classic) in the model; 0 for LBS/DQS. */
  get sectionCount(): number {
    return this.gcs.core.gcs_deformer_stat(this.live(), GcsStat.sections);
  }
  /** Parts (joints that own vertices) in the model; 0 for LBS/DQS. */
  get partCount(): number {
    return this.gcs.core.gcs_deformer_stat(this.live(), GcsStat.parts);
  }

  /** Frees the deformer's wasm memory; its views must not be used afterwards. */
  dispose(): void {
    if (!this.handle) return;
    this.gcs.core.gcs_deformer_destroy(this.handle);
    this.gcs.core.gcs_free(this.skinPtr);
    if (this.morphPtr) this.gcs.core.gcs_free(this.morphPtr);
    this.morphPtr = 0;
    this.handle = 0;
  }

  /** Whether `dispose()` has run (every other call then throws GcsError `DISPOSED`). */
  get disposed(): boolean {
    return this.handle === 0;
  }
}

/** The generalized cross-section deformer. */
export class GcsDeformer extends Deformer {
  /** Last frame: share of sections whose transform is not their part's rigid transform. */
  get adjustedShare(): number {
    return this.gcs.core.gcs_deformer_stat(this.live(), GcsStat.adjustedShare);
  }
  /** Last frame: number of sections whose transform is not their part's rigid transform. */
  get adjustedSections(): number {
    return this.gcs.core.gcs_deformer_stat(this.live(), GcsStat.adjustedSections);
  }
  /** Section id of each output vertex (a copy). */
  sectionOfVertex(): Uint32Array {
    const h = this.live();
    return this.gcs.viewU32(this.gcs.core.gcs_gcs_section_of_vertex(h), this.vertexCount).slice();
  }
  /** The sections, in output-vertex order. */
  sections(): SectionInfo[] {
    const h = this.live();
    const n = this.sectionCount;
    const info = this.gcs.viewF32(this.gcs.core.gcs_gcs_section_info(h), n * GCS_SECTION_INFO_FLOATS);
    const F = GcsSectionInfoField;
    const out: SectionInfo[] = [];
    for (let i = 0; i < n; i++) {
      const o = i * GCS_SECTION_INFO_FLOATS;
      out.push({ first: info[o + F.first], count: info[o + F.count], part: info[o + F.part], distal: info[o + F.distal],
        shared: info[o + F.kind] === GcsSectionKind.shared, rigid: info[o + F.kind] === GcsSectionKind.rigid,
        t: info[o + F.t], alpha: info[o + F.alpha], beta: info[o + F.beta] });
    }
    return out;
  }
  /** The last frame's section transforms (sectionCount × 16, a copy). */
  sectionMatrices(): Float32Array {
    const h = this.live();
    return this.gcs.viewF32(this.gcs.core.gcs_gcs_section_matrices(h), this.sectionCount * 16).slice();
  }
  /** Smooth mode: for each output vertex the section it blends with (its own when none), a copy; null in plain mode. */
  blendOther(): Uint32Array | null {
    const ptr = this.gcs.core.gcs_gcs_blend_other(this.live());
    return ptr ? this.gcs.viewU32(ptr, this.vertexCount).slice() : null;
  }
  /** Smooth mode: for each output vertex the factor towards blendOther() (0..1), a copy; null in plain mode. */
  blendFactor(): Float32Array | null {
    const ptr = this.gcs.core.gcs_gcs_blend_factor(this.live());
    return ptr ? this.gcs.viewF32(ptr, this.vertexCount).slice() : null;
  }
  /**
   * Smooth mode: for each output vertex a third section it blends with (a vertex of three joints:
   * its weight-lattice cell's third node; otherwise its own section), a copy; null in plain mode.
   */
  blendThird(): Uint32Array | null {
    const ptr = this.gcs.core.gcs_gcs_blend_third(this.live());
    return ptr ? this.gcs.viewU32(ptr, this.vertexCount).slice() : null;
  }
  /**
   * Smooth mode: for each output vertex the factor towards blendThird() (0..1; 0 without one), a
   * copy; null in plain mode. The vertex moves by A + f·(B − A) + g·(C − A) (A its section, B and
   * f blendOther() and blendFactor(), C and g these).
   */
  blendThirdFactor(): Float32Array | null {
    const ptr = this.gcs.core.gcs_gcs_blend_third_factor(this.live());
    return ptr ? this.gcs.viewF32(ptr, this.vertexCount).slice() : null;
  }
  /**
   * The GPU path's per-frame work: section transforms only, for `instanceCount` poses at once,
   * written as texels (GPU_TEXELS_PER_SECTION RGBA32F texels per section: the rows of its affine
   * 3×4) at byte offset `outPtr` in wasm memory; `skinPtr` holds instanceCount × J × 16 floats.
   * Pointers, not arrays, so that a crowd's buffers live in wasm memory and are never copied
   * (SectionTransforms owns such a pair; GpuSections in gcs-skin/gpu views it). No allocation.
   */
  computeSectionsAt(skinPtr: number, instanceCount: number, outPtr: number): void {
    const h = this.live();
    if (!this.gcs.core.gcs_gcs_compute_sections(h, skinPtr, this.jointCount, instanceCount, outPtr))
      this.gcs.raise('computing the section transforms failed');
  }
  /**
   * Weights criterion: each section's blend, 2 · sectionInfluenceSlots floats per section (per 4
   * slots, two RGBA32F texels: its joints, -1 past the last, then their weights; one joint = a rigid
   * core), a copy; null for the Y and axial criteria. The static table of the joint-level GPU path
   * (gcs_gcs_section_influences).
   */
  sectionInfluences(): Float32Array | null {
    const h = this.live();
    const ptr = this.gcs.core.gcs_gcs_section_influences(h);
    return ptr ? this.gcs.viewF32(ptr, this.sectionCount * 2 * this.gcs.core.gcs_gcs_section_influence_slots(h)).slice() : null;
  }
  /**
   * Joints per section in sectionInfluences(): 4 (every section blends at most 4 joints, as on every
   * rig of at most 4 influences) or 8; 0 for the Y and axial criteria.
   */
  get sectionInfluenceSlots(): number {
    return this.gcs.core.gcs_gcs_section_influence_slots(this.live());
  }
  /**
   * Weights criterion: each section's centre of rotation, 4 floats per section (x, y, z, 1) in the
   * bind pose, or (0, 0, 0, 0) where it has none (a rigid core, built with `centres: false`, or no
   * triangle weighing on two of its joints), a copy; null for the Y and axial criteria. A section
   * with a centre turns by its blend's rotation about it while the centre moves by linear blend
   * skinning (gcs_gcs_section_centres).
   */
  sectionCentres(): Float32Array | null {
    const ptr = this.gcs.core.gcs_gcs_section_centres(this.live());
    return ptr ? this.gcs.viewF32(ptr, this.sectionCount * 4).slice() : null;
  }
  /** True when the joint-level GPU path can drive this deformer (the weights criterion). */
  get jointLevel(): boolean {
    return this.gcs.core.gcs_gcs_section_influences(this.live()) !== 0;
  }
  /**
   * The joint-level GPU path's per-frame work (weights criterion): joint poses only, for
   * `instanceCount` poses at once, GPU_TEXELS_PER_JOINT RGBA32F texels per joint (the rows of S_j,
   * then its rotation quaternion) at byte offset `outPtr`; `skinPtr` holds instanceCount × J × 16
   * floats. No allocation.
   */
  computeJointPosesAt(skinPtr: number, instanceCount: number, outPtr: number): void {
    const h = this.live();
    if (!this.gcs.core.gcs_gcs_compute_joint_poses(h, skinPtr, this.jointCount, instanceCount, outPtr))
      this.gcs.raise('computing the joint poses failed');
  }
  /**
   * As computeJointPosesAt, but in the compact format (COMPACT_FLOATS_PER_JOINT floats per joint:
   * the "smallest three" of its rotation quaternion, then its translation;
   * gcs_gcs_compute_joint_poses_compact) where every joint of every instance is rigid with unit
   * scale, else in the full format. Returns true where it wrote the compact one. No allocation.
   */
  computeCompactJointPosesAt(skinPtr: number, instanceCount: number, outPtr: number): boolean {
    const h = this.live();
    const format = this.gcs.core.gcs_gcs_compute_joint_poses_compact(h, skinPtr, this.jointCount, instanceCount, outPtr);
    if (!format) this.gcs.raise('computing the joint poses failed');
    return format === GCS_JOINT_POSES_COMPACT;
  }
}

/** RGBA32F texels per GCS section in the GPU path's buffer (the rows of its affine 3×4 transform). */
export const GPU_TEXELS_PER_SECTION = GCS_GPU_TEXELS_PER_SECTION;
/** RGBA32F texels per joint in the joint-level GPU path's buffer (the rows of S_j, its rotation quaternion). */
export const GPU_TEXELS_PER_JOINT = GCS_GPU_TEXELS_PER_JOINT;
/** Floats per joint in the joint poses' compact format (rigid joints of unit scale: the "smallest three" of the quaternion, the translation). */
export const COMPACT_FLOATS_PER_JOINT = GCS_COMPACT_FLOATS_PER_JOINT;
/** Most instances one computeSectionsAt call takes. */
export const MAX_INSTANCES = GCS_MAX_INSTANCES;

/** The classic cross-section deformer (resampled contours). */
export class ClassicDeformer extends Deformer {
  /** Which parts were resampled and which are carried (by DQS of their own weights). */
  get parts(): ClassicPart[] {
    const h = this.live();
    const n = this.gcs.core.gcs_classic_part_count(h);
    const ptr = this.gcs.core.gcs_classic_parts(h);
    if (!ptr) return [];
    const a = this.gcs.viewI32(ptr, n * GCS_CLASSIC_PART_INTS);
    const F = GcsClassicPartField;
    const out: ClassicPart[] = [];
    for (let i = 0; i < n; i++) {
      const o = i * GCS_CLASSIC_PART_INTS;
      out.push({
        joint: a[o + F.joint], resampled: a[o + F.resampled] === 1, reason: CLASSIC_REASONS[a[o + F.reason]] ?? 'leaf',
        firstVertex: a[o + F.firstVertex], vertexCount: a[o + F.vertexCount],
      });
    }
    return out;
  }
  /**
   * For each output vertex, the contour (ring) it lies on, 0 … sectionCount − 1, or −1 for a
   * carried input vertex or a band vertex (a point of the input surface between a tube's end ring
   * and the carried skin, moved as carried skin): what the demo colours by. A copy (valid until
   * the next rebuild).
   */
  get contourOfVertex(): Int32Array {
    return this.perVertex(this.gcs.core.gcs_classic_contour_of_vertex(this.live()));
  }
  /**
   * For each output vertex, the rig vertex a carried vertex copies (take its texture coordinates
   * and colours from there), or −1 for a resampled (ring, cap or band) vertex. A copy (valid until
   * the next rebuild).
   */
  get sourceOfVertex(): Int32Array {
    return this.perVertex(this.gcs.core.gcs_classic_source_of_vertex(this.live()));
  }
  /** A copy of an int32-per-output-vertex array of the core (empty when the core gives none). */
  private perVertex(ptr: number): Int32Array {
    return ptr ? this.gcs.viewI32(ptr, this.vertexCount).slice() : new Int32Array(0);
  }
  /** Resampling detail loss, % of model height: RMS and max distance of original vertices to the resampled surface. */
  get detailLoss(): {
    /** RMS distance, % of the model's height. */
    rms: number;
    /** Largest distance, % of the model's height. */
    max: number;
  } {
    const h = this.live();
    return { rms: this.gcs.core.gcs_classic_detail_loss(h, 0), max: this.gcs.core.gcs_classic_detail_loss(h, 1) };
  }
  /** Changes the muscle bulge gain (0..4) without rebuilding. */
  setBulge(bulge: number): void {
    const h = this.live();
    if (typeof bulge !== 'number' || !(bulge >= 0 && bulge <= CLASSIC_LIMITS.maxBulge))
      throw new GcsError('OUT_OF_RANGE', `bulge must be between 0 and ${CLASSIC_LIMITS.maxBulge}; got ${asGiven(bulge)}`);
    if (!this.gcs.core.gcs_classic_set_bulge(h, bulge)) this.gcs.raise('setBulge failed');
  }
}

/**
 * The GPU path's per-frame buffers for one GCS model and `instanceCount` poses of it (a crowd),
 * both in wasm memory: the skin matrices in (instanceCount × J × 16 floats) and the packed texels
 * out, `width × height` RGBA32F texels, `texelsPerInstance` per instance (the tail past the last
 * instance is padding). A float texture views `texels` as it is: nothing is copied. `compute()` is
 * one wasm call for every instance. Views are re-created when wasm memory grew (check
 * `texels.buffer` against `gcs.memory.buffer`, or just read the getters each frame). The deformer
 * stays the caller's; `dispose()` frees only these buffers. See SectionTransforms and JointPoses.
 */
export abstract class PoseTexels {
  /** Number of poses (instances) the buffers hold. */
  readonly instanceCount: number;
  /** Joints per instance: `skinMatrices` holds `instanceCount × jointCount × 16` numbers. */
  readonly jointCount: number;
  /** RGBA32F texels per instance. */
  readonly texelsPerInstance: number;
  /** Texture size in texels: width × height ≥ instanceCount × texelsPerInstance. */
  readonly width: number;
  /** Texture height in texels. */
  readonly height: number;
  private skinPtr: number;
  private texelPtr: number;
  private skinView: Float32Array;
  private texelView: Float32Array;

  /**
   * `maxWidth`: the widest texture row allowed (WebGL2 guarantees 2048). `unit`: texels per section or joint.
   * @param deformer The GCS model whose poses the buffers hold (it stays the caller's).
   */
  protected constructor(readonly deformer: GcsDeformer, instanceCount: number, maxWidth: number, perInstance: () => number, unit: number) {
    if (!(deformer instanceof GcsDeformer)) throw new GcsError('INVALID_ARGUMENT', 'section transforms and joint poses need a GCS deformer (rig.buildGcs)');
    if (deformer.disposed) throw new GcsError('DISPOSED', 'the GCS deformer has been disposed');
    if (!Number.isInteger(instanceCount) || instanceCount < 1 || instanceCount > MAX_INSTANCES)
      throw new GcsError('OUT_OF_RANGE', `the instance count must be a whole number from 1 to ${MAX_INSTANCES}; got ${asGiven(instanceCount)}`);
    if (!Number.isInteger(maxWidth) || maxWidth < unit)
      throw new GcsError('OUT_OF_RANGE', `maxWidth must be a whole number ≥ ${unit}; got ${maxWidth}`);
    this.instanceCount = instanceCount;
    this.jointCount = deformer.jointCount;
    this.texelsPerInstance = perInstance();
    const texels = instanceCount * this.texelsPerInstance;
    this.width = Math.min(maxWidth, texels);
    this.height = Math.ceil(texels / this.width);
    const gcs = deformer.gcs;
    const skinBytes = instanceCount * this.jointCount * 64, texelBytes = this.width * this.height * 16;
    if (skinBytes + texelBytes > 0xffff0000) throw new GcsError('OUT_OF_MEMORY', `${instanceCount} instances need ${skinBytes + texelBytes} bytes: more than wasm memory holds`);
    this.skinPtr = gcs.core.gcs_alloc(skinBytes);
    if (!this.skinPtr) gcs.raise('out of memory for the skin matrices');
    this.texelPtr = gcs.core.gcs_alloc(texelBytes);
    if (!this.texelPtr) {
      gcs.core.gcs_free(this.skinPtr);
      gcs.raise('out of memory for the GPU texels');
    }
    this.skinView = gcs.viewF32(this.skinPtr, instanceCount * this.jointCount * 16);
    this.texelView = gcs.viewF32(this.texelPtr, this.width * this.height * 4);
    this.texelView.fill(0);
    // Every instance starts in the bind pose (identity skins), so the texture is valid at once.
    this.skinView.fill(0);
    for (let k = 0; k < instanceCount * this.jointCount; k++)
      for (let c = 0; c < 4; c++) this.skinView[16 * k + 5 * c] = 1;
  }

  private live(): void {
    if (!this.skinPtr) throw new GcsError('DISPOSED', 'these GPU texels have been disposed');
  }

  /** Every instance's skin matrices (instanceCount × J × 16 floats), a view on wasm memory: write them, then compute(). */
  get skins(): Float32Array {
    this.live();
    if (this.skinView.buffer !== this.deformer.gcs.memory.buffer)
      this.skinView = this.deformer.gcs.viewF32(this.skinPtr, this.instanceCount * this.jointCount * 16);
    return this.skinView;
  }

  /** The packed texels (width × height × 4 floats), a view on wasm memory. */
  get texels(): Float32Array {
    this.live();
    if (this.texelView.buffer !== this.deformer.gcs.memory.buffer)
      this.texelView = this.deformer.gcs.viewF32(this.texelPtr, this.width * this.height * 4);
    return this.texelView;
  }

  /** Bytes of texels that hold `instances` instances' data (what an upload of them moves). */
  bytesFor(instances = this.instanceCount): number {
    return instances * this.texelsPerInstance * 16;
  }

  /** The texels of the first `count` instances from their skins (default: all). No allocation. */
  compute(count = this.instanceCount): void {
    this.live();
    if (!Number.isInteger(count) || count < 0 || count > this.instanceCount)
      throw new GcsError('OUT_OF_RANGE', `compute(count): count must be a whole number from 0 to ${this.instanceCount}; got ${count}`);
    if (count === 0) return;
    this.run(this.skinPtr, count, this.texelPtr);
  }

  /** @internal The wasm call. */
  protected abstract run(skinPtr: number, count: number, outPtr: number): void;

  /** Frees the two buffers (not the deformer). Safe to call twice. */
  dispose(): void {
    if (!this.skinPtr) return;
    this.deformer.gcs.core.gcs_free(this.skinPtr);
    this.deformer.gcs.core.gcs_free(this.texelPtr);
    this.skinPtr = 0;
    this.texelPtr = 0;
  }

  /** Whether `dispose()` has freed the buffers. */
  get disposed(): boolean {
    return this.skinPtr === 0;
  }
}

/**
 * The section-level GPU path's buffers (any criterion): section s of instance k at texel
 * (k·S + s)·3, the rows of its affine 3×4 (gcs_gcs_compute_sections). See PoseTexels.
 */
export class SectionTransforms extends PoseTexels {
  /** Sections of the GCS model: texels per instance are `sectionCount × 3`. */
  readonly sectionCount: number;

  /** `maxWidth`: the widest texture row allowed (WebGL2 guarantees 2048). */
  constructor(deformer: GcsDeformer, instanceCount = 1, maxWidth = 2048) {
    super(deformer, instanceCount, maxWidth, () => deformer.sectionCount * GPU_TEXELS_PER_SECTION, GPU_TEXELS_PER_SECTION);
    this.sectionCount = deformer.sectionCount;
    this.compute();
  }

  protected run(skinPtr: number, count: number, outPtr: number): void {
    this.deformer.computeSectionsAt(skinPtr, count, outPtr);
  }
}

/**
 * The joint-level GPU path's buffers (weights criterion only, else GcsError 'INVALID_ARGUMENT'):
 * joint j of instance k at texel (k·J + j)·4, the rows of S_j then its rotation quaternion
 * (gcs_gcs_compute_joint_poses); O(joints) per instance per frame. See PoseTexels.
 */
export class JointPoses extends PoseTexels {
  /**
   * Whether the last compute() wrote the compact format: joint j of instance k at float
   * (k·J + j)·COMPACT_FLOATS_PER_JOINT of `texels` (gcs_gcs_compute_joint_poses_compact). Only
   * where `compact` was asked for and every joint of every instance was rigid with unit scale.
   */
  compactFormat = false;

  /** Whether compute() writes the compact format where a frame allows it (see compactFormat); else always the full one. */
  readonly compact: boolean;

  /** `compact`: write the compact format where a frame allows it (see compactFormat). */
  constructor(deformer: GcsDeformer, instanceCount = 1, maxWidth = 2048, compact = false) {
    super(deformer, instanceCount, maxWidth, () => {
      if (!deformer.jointLevel) throw new GcsError('INVALID_ARGUMENT', 'joint poses drive the weights criterion only; the Y and axial criteria need SectionTransforms');
      return deformer.jointCount * GPU_TEXELS_PER_JOINT;
    }, GPU_TEXELS_PER_JOINT);
    this.compact = compact;
    this.compute();
  }

  protected run(skinPtr: number, count: number, outPtr: number): void {
    if (this.compact) this.compactFormat = this.deformer.computeCompactJointPosesAt(skinPtr, count, outPtr);
    else this.deformer.computeJointPosesAt(skinPtr, count, outPtr);
  }
}
