// The crowd page's readout: what runs (characters, renderer, backend, path) at once after a build,
// and the skinning CPU time and bytes uploaded per frame once steady (SteadyFigure: "warming up…"
// before, at most 3 s; a figure still varying then says so), with the last frames' samples kept
// for the test hook's medians.
import { SteadyFigure } from './steady-figure.js';

const fmtBytes = (b: number) => (b >= 1e6 ? `${(b / 1e6).toFixed(2)} MB` : b >= 1e3 ? `${(b / 1e3).toFixed(1)} KB` : `${b.toFixed(0)} B`);

export class CrowdReadout {
  readonly element = document.createElement('div');
  /** The last 240 frames' skinning ms and bytes uploaded. */
  readonly samples: { ms: number; bytes: number }[] = [];
  private readonly steadyMs = new SteadyFigure();
  private readonly steadyBytes = new SteadyFigure();
  private due = true; // a rebuild shows its settings at once, its figures when steady

  constructor() {
    this.element.className = 'readout';
    this.element.style.left = '10px';
    this.element.dataset.view = 'crowd';
    document.getElementById('readouts')!.append(this.element);
  }

  /** A rebuild: figures start over. */
  reset(): void {
    this.samples.length = 0;
    this.steadyMs.reset();
    this.steadyBytes.reset();
    this.due = true;
  }

  add(ms: number, bytes: number): void {
    this.samples.push({ ms, bytes });
    if (this.samples.length > 240) this.samples.shift();
    this.steadyMs.add(ms);
    this.steadyBytes.add(bytes);
  }

  /** Rewrites the readout right after a rebuild, then every 10th frame. */
  show(frame: number, head: string, count: number, note: string): void {
    if (!this.due && frame % 10 !== 1) return;
    this.due = false;
    const perFrame = this.steadyMs.value(), uploaded = this.steadyBytes.value();
    let figures: string;
    if (Number.isNaN(perFrame) || Number.isNaN(uploaded)) {
      figures = 'skinning CPU and uploads per frame: <b>warming up…</b>';
      if (this.steadyMs.overdue)
        figures += ` <span class="criterion">(${this.steadyMs.frames} frames counted so far, 4 needed: ` +
          `the page draws slowly, and the first ${this.steadyMs.dropped} frames after a change are not counted)</span>`;
    } else {
      figures = `skinning CPU <b>${perFrame.toFixed(2)} ms</b>/frame (${(perFrame / count * 1000).toFixed(1)} µs per character)` +
        ` · uploaded <b>${fmtBytes(uploaded)}</b>/frame (${fmtBytes(uploaded / count)} per character)`;
      if (!this.steadyMs.agreed() || !this.steadyBytes.agreed())
        figures += ` <span class="criterion">(over the last ${this.steadyMs.frames} frames: still varying by more than 20 % between them)</span>`;
    }
    this.element.innerHTML = `${head}<br>${figures}${note ? `<br><span class="criterion">${note}</span>` : ''}`;
  }
}
