// What each view's model costs per frame on this machine, measured as `npm run bench` measures it:
// timeInterleaved (gcs-skin/measure) over live poses recorded after each (re)build, the models
// timed in turn (the GCS on screen, a stepped one of the same sections for comparison, the classic
// model), so that whatever else the machine does lands on all alike. Done in short slices after
// frames (the page keeps drawing), the first figures stand a few frames after a build; then the
// same measurement is repeated a few times, a fraction of a second apart, and the figure shown is
// the median of the rounds (one round taken while the page was busy is outvoted), after which it
// stays: no figure that drifts with the page's own load, none that inverts by chance (InversionGuard).
import type { GcsDeformer, GcsOptions } from '../lib/index.js';
import { median, timeInterleaved } from '../lib/measure.js';
import { writeSkinMatrices, type SkinDeformer } from '../lib/three.js';

/** Live poses recorded after a build (frames of the clip as it plays), at most. */
const RECORDED_FRAMES = 4;
/** Slices of timing, one after each frame, and how long each may run. */
const SLICES = 8;
const SLICE_MS = 10;
/**
 * On a slow page (a few frames a second) the figures must still stand within 3 s of the build:
 * recording stops after this long with the poses it has, and past LATE_MS the remaining slices all
 * run after one frame (a frame that slow hides 80 ms more).
 */
const RECORD_MS = 300;
const LATE_MS = 800;
/** A timed sample lasts at least this: a browser's clock moves in 0.1 ms steps (timeInterleaved's repeat). */
const SAMPLE_MS = 1;
/** Rounds of SLICES slices in all (the first included), and the pause before each further one. */
const ROUNDS = 5;
const ROUND_GAP_MS = 400;

export interface FrameCostFigures {
  /** ms per frame of the GCS model on screen (every skinned mesh), NaN until measured. */
  gcs: number;
  /** ms per frame of the stepped (smooth: false) GCS at the same sections; NaN under the paper's criteria. */
  stepped: number;
  /** ms per frame of the classic model; NaN until measured or without one. */
  classic: number;
}

const NONE: FrameCostFigures = { gcs: NaN, stepped: NaN, classic: NaN };

/**
 * Whether a measurement may be shown: stepped GCS does less work per vertex than smooth, so a
 * measurement that finds it slower is noise until it is found so `confirm` times in a row.
 */
export class InversionGuard {
  private run = 0;
  constructor(readonly confirm = 3) {}
  /** True when (smooth, stepped) may be shown; false: measure again. */
  accept(smooth: number, stepped: number): boolean {
    if (!(stepped > smooth)) {
      this.run = 0;
      return true;
    }
    return ++this.run >= this.confirm;
  }
  reset(): void {
    this.run = 0;
  }
}

/** What FrameCost measures: the views' skins (one per source mesh), and how the GCS was built. */
export interface CostModels {
  gcs: readonly SkinDeformer[];
  classic: readonly SkinDeformer[];
  /** The GCS settings on screen: a stepped twin is built when they are smooth under the weights criterion. */
  options: GcsOptions;
}

type Phase = 'idle' | 'recording' | 'measuring' | 'repeating' | 'done';

/** The per-frame cost figures of the models on screen, measured after each build (see the file's head). */
export class FrameCost {
  private phase: Phase = 'idle';
  private models: CostModels | null = null;
  private sources: SkinDeformer['source'][] = [];
  /** poses[f][k]: skin matrices of source k at recorded frame f. */
  private poses: Float32Array[][] = [];
  private stepped: GcsDeformer[] = [];
  private steps: ((frame: number) => void)[] = [];
  private repeat: number[] = [];
  private slices: number[][] = [];
  /** rounds[k]: each finished round's median ms of step k. */
  private rounds: number[][] = [];
  private roundEndedAt = 0;
  private shown: FrameCostFigures = NONE;
  private readonly guard = new InversionGuard();
  private listener: (figures: FrameCostFigures) => void = () => {};
  /** Frames since the last restart (for tests: how soon the figures stand). */
  framesSinceBuild = 0;
  private builtAt = 0;

  constructor(
    private readonly writePose: (source: SkinDeformer['source'], out: Float32Array) => void = (s, out) => writeSkinMatrices(s, out),
    private readonly now: () => number = () => performance.now(),
  ) {}

  /** Calls `listener` whenever the figures change. */
  onChange(listener: (figures: FrameCostFigures) => void): void {
    this.listener = listener;
  }

  figures(): FrameCostFigures {
    return this.shown;
  }

  /** True once figures for the models on screen are shown (the first round); they may still be refined. */
  get settled(): boolean {
    return this.phase === 'repeating' || this.phase === 'done';
  }

  /** True once every round is measured: the figures shown are final until the next build. */
  get final(): boolean {
    return this.phase === 'done';
  }

  /** A model was (re)built: its figures start over. */
  restart(models: CostModels): void {
    this.dropScratch();
    this.models = models;
    this.sources = [...new Set([...models.gcs, ...models.classic].map((s) => s.source))];
    this.poses = [];
    this.slices = [];
    this.rounds = [];
    this.guard.reset();
    this.framesSinceBuild = 0;
    this.builtAt = this.now();
    this.phase = 'recording';
    this.publish(NONE);
  }

  /** Stops measuring and frees the scratch models (the character is gone). */
  stop(): void {
    this.dropScratch();
    this.models = null;
    this.phase = 'idle';
    this.publish(NONE);
  }

  /** After each frame's update(): records a pose, or runs one slice of timing. */
  afterFrame(): void {
    if (this.phase === 'idle' || this.phase === 'done' || !this.models) return;
    if (this.phase === 'repeating') {
      if (this.slices[0].length === 0 && this.now() - this.roundEndedAt < ROUND_GAP_MS) return;
      this.slice();
      return;
    }
    this.framesSinceBuild++;
    if (this.phase === 'recording') {
      this.poses.push(this.sources.map((src) => {
        const out = new Float32Array(src.skeleton.bones.length * 16);
        this.writePose(src, out);
        return out;
      }));
      if (this.poses.length < RECORDED_FRAMES && this.now() - this.builtAt < RECORD_MS) return;
      this.prepare();
      if (this.now() - this.builtAt < LATE_MS) return;
    }
    do this.slice();
    while (this.phase === 'measuring' && this.now() - this.builtAt >= LATE_MS);
  }

  /** The steps to time in turn (each deforms every mesh of one model) and their repeat counts. */
  private prepare(): void {
    const m = this.models!;
    const poseOf = (s: SkinDeformer) => this.sources.indexOf(s.source);
    const step = (deformers: { deform(skin: Float32Array): void }[], sourceIndex: number[]) => (f: number) => {
      const pose = this.poses[f];
      for (let i = 0; i < deformers.length; i++) deformers[i].deform(pose[sourceIndex[i]]);
    };
    const gcsIndex = m.gcs.map(poseOf);
    // The live deformers: the next frame's update() writes the picture again before it is drawn.
    this.steps = [step(m.gcs.map((s) => s.deformer), gcsIndex)];
    const weights = (m.options.criterion ?? 'weights') === 'weights';
    if (weights && m.options.smooth !== false) {
      this.stepped = m.gcs.map((s) => s.rig.buildGcs({ ...m.options, smooth: false }));
      this.steps.push(step(this.stepped, gcsIndex));
    }
    if (m.classic.length) this.steps.push(step(m.classic.map((s) => s.deformer), m.classic.map(poseOf)));
    // Calibration (also the warm-up: the stepped twin's code path has not run yet): ms per call.
    this.repeat = this.steps.map((s) => {
      const t0 = performance.now();
      for (let f = 0; f < this.poses.length; f++) s(f);
      const perCall = (performance.now() - t0) / this.poses.length;
      return Math.max(1, Math.min(200, Math.ceil(SAMPLE_MS / Math.max(perCall, 0.002))));
    });
    this.slices = this.steps.map(() => []);
    this.phase = 'measuring';
  }

  private slice(): void {
    const t = timeInterleaved(this.poses.length, this.steps, { minSamples: 1, minMs: 0, maxMs: SLICE_MS, warmup: 0, repeat: this.repeat });
    t.forEach((x, k) => this.slices[k].push(x.medianMs));
    if (this.slices[0].length < SLICES) return;
    const round = this.slices.map((s) => median(s));
    this.slices = this.steps.map(() => []);
    if (this.phase === 'repeating') {
      // A further round: the figures are the rounds' medians (an inverted round is outvoted, not confirmed).
      this.rounds.push(round);
      this.roundEndedAt = this.now();
      const ms = round.map((_, k) => median(this.rounds.map((r) => r[k])));
      this.publish(this.figuresOf(ms));
      if (this.rounds.length >= ROUNDS) {
        this.dropScratch();
        this.phase = 'done';
      }
      return;
    }
    const ms = round;
    const figures = this.figuresOf(ms);
    if (this.stepped.length > 0 && !this.guard.accept(figures.gcs, figures.stepped)) return; // measure again before showing an inversion
    this.rounds = [ms];
    this.roundEndedAt = this.now();
    this.phase = 'repeating';
    this.publish(figures);
  }

  /** The figures from one median ms per step (the GCS on screen, its stepped twin if built, the classic model). */
  private figuresOf(ms: number[]): FrameCostFigures {
    const m = this.models!;
    const hasStepped = this.stepped.length > 0;
    return {
      gcs: ms[0],
      stepped: hasStepped ? ms[1] : (m.options.criterion ?? 'weights') === 'weights' ? ms[0] : NaN,
      classic: m.classic.length ? ms[hasStepped ? 2 : 1] : NaN,
    };
  }

  private dropScratch(): void {
    for (const d of this.stepped) d.dispose();
    this.stepped = [];
    this.steps = [];
  }

  private publish(figures: FrameCostFigures): void {
    this.shown = figures;
    this.listener(figures);
  }
}
