// Per-frame figures (ms, bytes) as a newcomer should read them (the crowd page). The first frames
// after a build run cold code and upload whole buffers, and a smoothed average keeps them for many
// frames (tens of seconds at a few frames a second); this keeps a window of recent frames instead,
// drops the first frames after each reset, and reports the window's figure once it has stopped
// falling (its older and newer halves agree), or once `deadlineMs` have passed since the reset,
// whatever the frame rate: then from the frames it has (the counted ones when there are 4, else
// every frame since the reset, the first included: a page drawing one frame a second still gets
// a figure at the deadline), and agreed() says whether the halves agree. Until then value() is NaN:
// the page says "warming up".
// The figure is the mean of the window's middle half: spikes (a garbage collection) drop out, and
// the browser's coarse clock (0.1 ms steps) averages out where a median would round it.
export class SteadyFigure {
  private readonly ring: Float64Array;
  private readonly older: Float64Array;
  private readonly newer: Float64Array;
  private readonly whole: Float64Array;
  /** Samples since the last reset, the dropped ones included (the ring keeps them too, for a late figure). */
  private seen = 0;
  /** Samples in the ring that were not dropped (the most recent ones). */
  private counted = 0;
  private stored = 0;
  private next = 0;
  private settled = false;
  private halvesAgree = false;
  private since: number;

  /**
   * @param windowSize frames in the window (a multiple of 4)
   * @param dropped first frames after a reset that never count
   * @param tolerance how far apart the halves' figures may be, as a share of the larger
   * @param deadlineMs after this long since the reset the figure is shown whether or not it agrees
   * @param now the clock (ms)
   */
  constructor(readonly windowSize = 32, readonly dropped = 10, readonly tolerance = 0.2, readonly deadlineMs = 3000,
    private readonly now: () => number = () => performance.now()) {
    this.ring = new Float64Array(windowSize);
    this.older = new Float64Array(windowSize >> 1);
    this.newer = new Float64Array(windowSize >> 1);
    this.whole = new Float64Array(windowSize);
    this.since = now();
  }

  /** Starts over (a model was built: its figures are new). */
  reset(): void {
    this.seen = this.stored = this.next = this.counted = 0;
    this.settled = this.halvesAgree = false;
    this.since = this.now();
  }

  /** Frames counted since the reset (the dropped ones not included). */
  get frames(): number {
    return this.counted;
  }

  /** Frames the figure was taken from: the counted ones, or at the deadline every frame seen when too few were counted. */
  get used(): number {
    return this.counted >= 4 || !this.overdue ? this.counted : this.stored;
  }

  /** True once the deadline has passed (a figure still missing then lacks frames). */
  get overdue(): boolean {
    return this.now() - this.since >= this.deadlineMs;
  }

  /** Whether the figure shown had stopped changing (its halves agreed), or was shown at the deadline. */
  agreed(): boolean {
    return this.halvesAgree;
  }

  add(value: number): void {
    if (!Number.isFinite(value)) return;
    this.ring[this.next] = value;
    this.next = (this.next + 1) % this.windowSize;
    this.stored = Math.min(this.stored + 1, this.windowSize);
    if (++this.seen > this.dropped) this.counted = Math.min(this.counted + 1, this.windowSize);
  }

  /** The window's figure once steady (or at the deadline), else NaN. */
  value(): number {
    const late = this.now() - this.since >= this.deadlineMs;
    // Before the deadline a full window of counted frames; at it, 4 counted, else every frame seen.
    const usable = late ? (this.counted >= 4 ? this.counted : this.stored) : this.counted >= this.windowSize ? this.counted : 0;
    if (usable < 1) return NaN;
    if (usable === 1) {
      if (!this.settled) this.halvesAgree = false;
      this.settled = true;
      return this.ring[(this.next - 1 + this.windowSize) % this.windowSize];
    }
    const n = usable & ~1, half = n >> 1;
    const whole = this.whole.subarray(0, n), older = this.older.subarray(0, half), newer = this.newer.subarray(0, half);
    for (let i = 0; i < n; i++) {
      const v = this.ring[(this.next - n + i + this.windowSize) % this.windowSize]; // oldest first
      whole[i] = v;
      if (i < half) older[i] = v;
      else newer[i - half] = v;
    }
    if (!this.settled) {
      const a = middleMean(older), b = middleMean(newer);
      this.halvesAgree = Math.abs(a - b) <= this.tolerance * Math.max(a, b);
      this.settled = this.halvesAgree || late;
      if (!this.settled) return NaN;
    }
    return middleMean(whole);
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
