// Per-frame figures (ms, bytes) as a newcomer should read them. The first frames after a build run
// cold code and upload whole buffers, and a smoothed average keeps them for many frames (tens of
// seconds at a few frames a second); this keeps a window of recent frames instead, drops the
// first frames after each reset, and reports the window's figure only once it has stopped falling
// (its older and newer halves agree). Until then value() is NaN: the page says "warming up".
// The figure is the mean of the window's middle half: spikes (a garbage collection) drop out, and
// the browser's coarse clock (0.1 ms steps) averages out where a median would round it.
export class SteadyFigure {
  private readonly ring: Float64Array;
  private readonly older: Float64Array;
  private readonly newer: Float64Array;
  private readonly whole: Float64Array;
  /** Samples since the last reset, the dropped ones included. */
  private seen = 0;
  private stored = 0;
  private next = 0;
  private settled = false;

  /**
   * @param windowSize frames in the window (a multiple of 4)
   * @param dropped first frames after a reset that never count
   * @param tolerance how far apart the halves' figures may be, as a share of the larger
   */
  constructor(readonly windowSize = 32, readonly dropped = 10, readonly tolerance = 0.2) {
    this.ring = new Float64Array(windowSize);
    this.older = new Float64Array(windowSize >> 1);
    this.newer = new Float64Array(windowSize >> 1);
    this.whole = new Float64Array(windowSize);
  }

  /** Starts over (a model was built: its figures are new). */
  reset(): void {
    this.seen = this.stored = this.next = 0;
    this.settled = false;
  }

  add(value: number): void {
    if (++this.seen <= this.dropped || !Number.isFinite(value)) return;
    this.ring[this.next] = value;
    this.next = (this.next + 1) % this.windowSize;
    this.stored = Math.min(this.stored + 1, this.windowSize);
  }

  /** The window's figure once steady, else NaN. */
  value(): number {
    if (this.stored < this.windowSize) return NaN;
    const n = this.windowSize, half = n >> 1;
    for (let i = 0; i < n; i++) {
      const v = this.ring[(this.next + i) % n]; // oldest first
      this.whole[i] = v;
      if (i < half) this.older[i] = v;
      else this.newer[i - half] = v;
    }
    if (!this.settled) {
      const a = middleMean(this.older), b = middleMean(this.newer);
      // A machine too noisy to ever agree still gets its figure after a while.
      this.settled = Math.abs(a - b) <= this.tolerance * Math.max(a, b) || this.seen > this.dropped + 6 * n;
      if (!this.settled) return NaN;
    }
    return middleMean(this.whole);
  }
}

/** The mean of the middle half of `values` (sorted in place). */
function middleMean(values: Float64Array): number {
  values.sort();
  const from = values.length >> 2, to = values.length - from;
  let sum = 0;
  for (let i = from; i < to; i++) sum += values[i];
  return sum / (to - from);
}
