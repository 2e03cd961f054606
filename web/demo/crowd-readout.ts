// The crowd page's readout: what runs (characters, renderer, backend, path) at once after a build,
// and the skinning CPU time and bytes uploaded per frame once steady (SteadyFigure: "warming up…"
// before, at most 3 s, then a figure from whatever frames there are, saying how few and whether
// they still vary), with the last frames' samples kept for the test hook's medians.
import { counted, msText } from './figure-text.js';
import { SteadyFigure } from './steady-figure.js';

const fmtBytes = (b: number) => (b >= 1e6 ? `${(b / 1e6).toFixed(2)} MB` : b >= 1e3 ? `${(b / 1e3).toFixed(1)} KB` : `${b.toFixed(0)} B`);

/** Frames whose samples are kept for the test hook. */
const KEPT = 240;

export class CrowdReadout {
  readonly element = document.createElement('div');
  // The last KEPT frames' skinning ms and bytes uploaded, in two rings (nothing made per frame).
  private readonly ms = new Float64Array(KEPT);
  private readonly bytes = new Float64Array(KEPT);
  private kept = 0;
  private next = 0;
  private readonly steadyMs = new SteadyFigure();
  private readonly steadyBytes = new SteadyFigure();
  private due = true; // a rebuild shows its settings at once, its figures when steady
  private figureShown = false; // until a figure is shown, every frame may bring it (a slow page's deadline)

  constructor() {
    this.element.className = 'readout';
    this.element.style.left = '10px';
    this.element.dataset.view = 'crowd';
    document.getElementById('readouts')!.append(this.element);
  }

  /** A rebuild: figures start over. */
  reset(): void {
    this.kept = 0;
    this.next = 0;
    this.steadyMs.reset();
    this.steadyBytes.reset();
    this.due = true;
    this.figureShown = false;
  }

  add(ms: number, bytes: number): void {
    this.ms[this.next] = ms;
    this.bytes[this.next] = bytes;
    this.next = (this.next + 1) % KEPT;
    if (this.kept < KEPT) this.kept++;
    this.steadyMs.add(ms);
    this.steadyBytes.add(bytes);
  }

  /** The last `frames` frames' samples (all kept when fewer, or when `frames` is 0), oldest first. */
  last(frames: number): { ms: number[]; bytes: number[] } {
    const n = frames > 0 ? Math.min(frames, this.kept) : this.kept;
    const ms: number[] = [], bytes: number[] = [];
    for (let k = n; k > 0; k--) {
      const i = (this.next - k + KEPT) % KEPT;
      ms.push(this.ms[i]);
      bytes.push(this.bytes[i]);
    }
    return { ms, bytes };
  }

  /** Whether show() is due at `frame`: right after a rebuild, every frame until a figure is shown, then every 10th frame. */
  shows(frame: number): boolean {
    return this.due || !this.figureShown || frame % 10 === 1;
  }

  /** Rewrites the readout (when shows(frame) says so: the text is built only then). */
  show(head: string, count: number, note: string): void {
    this.due = false;
    const perFrame = this.steadyMs.value(), uploaded = this.steadyBytes.value();
    let figures: string;
    if (Number.isNaN(perFrame) || Number.isNaN(uploaded)) {
      figures = 'skinning CPU and uploads per frame: <b>warming up…</b>';
      if (this.steadyMs.overdue) figures += ' <span class="criterion">(no frame drawn yet since the change)</span>';
    } else {
      this.figureShown = true;
      figures = `skinning CPU <b>${msText(perFrame)} ms</b>/frame (${(perFrame / count * 1000).toFixed(1)} µs per character)` +
        ` · uploaded <b>${fmtBytes(uploaded)}</b>/frame (${fmtBytes(uploaded / count)} per character)`;
      const used = this.steadyMs.used;
      if (used < 4)
        figures += ` <span class="criterion">(from ${counted(used, 'frame')} since the change, the first ones included: the page draws slowly)</span>`;
      else if (!this.steadyMs.agreed() || !this.steadyBytes.agreed())
        figures += ` <span class="criterion">(over the last ${counted(used, 'frame')}: still varying by more than 20 % between them)</span>`;
    }
    this.element.innerHTML = `${head}<br>${figures}${note ? `<br><span class="criterion">${note}</span>` : ''}`;
  }
}
