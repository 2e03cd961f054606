// The demo's steady per-frame figure (web/demo/steady-figure.ts): no figure while warming up (the
// first frames dropped, the window not full, the figure still falling), then the mean of the
// window's middle half; a reset starts over; at the deadline the figure is shown from what there is.
import { describe, expect, test } from 'vitest';
import { SteadyFigure } from '../../web/demo/steady-figure.js';

describe('SteadyFigure', () => {
  test('NaN until the dropped frames and a full window have passed', () => {
    const f = new SteadyFigure(8, 3);
    for (let i = 0; i < 3 + 7; i++) {
      f.add(1);
      expect(f.value()).toBeNaN();
    }
    f.add(1);
    expect(f.value()).toBe(1);
  });

  test('the slow first frames never count', () => {
    const f = new SteadyFigure(8, 3);
    for (const ms of [50, 20, 10]) f.add(ms);
    for (let i = 0; i < 8; i++) f.add(0.2);
    expect(f.value()).toBeCloseTo(0.2, 12);
  });

  test('warming up while the figure still falls (cold code getting hot), steady once the halves agree', () => {
    const f = new SteadyFigure(8, 0);
    for (const ms of [1, 1, 1, 1, 0.5, 0.5, 0.5, 0.5]) f.add(ms);
    expect(f.value(), 'older half 1 ms, newer 0.5 ms').toBeNaN();
    for (let i = 0; i < 4; i++) f.add(0.5);
    expect(f.value()).toBeCloseTo(0.5, 12);
    // Steady stays steady: noise later does not bring "warming up" back.
    for (const ms of [0.9, 0.9, 0.9, 0.9]) f.add(ms);
    expect(f.value()).not.toBeNaN();
  });

  test('the mean of the middle half: a spike drops out, the clock\'s 0.1 ms steps average out', () => {
    const f = new SteadyFigure(8, 0);
    for (const ms of [0.2, 0.3, 0.2, 30, 0.2, 0.3, 0.2, 0.3]) f.add(ms);
    // Sorted: 0.2 ×4, 0.3 ×3, 30; the middle half: 0.2, 0.2, 0.3, 0.3.
    expect(f.value()).toBeCloseTo(0.25, 12);
  });

  test('a figure that never settles is shown at the deadline (3 s after the reset), saying it did not agree', () => {
    let clock = 0;
    const f = new SteadyFigure(8, 0, 0.2, 3000, () => clock);
    let ms = 1;
    const falling = () => f.add((ms *= 0.9)); // the newer half always a third below the older
    for (let i = 0; i < 8 * 6; i++) { falling(); clock += 50; expect(f.value()).toBeNaN(); }
    clock = 3000;
    expect(f.value()).toBeGreaterThan(0);
    expect(f.agreed()).toBe(false);
  });

  test('a slow page (a crowd on the CPU backend: a few frames a second) gets its figure at the deadline from the frames it has', () => {
    let clock = 0;
    const f = new SteadyFigure(32, 2, 0.2, 3000, () => clock);
    for (let i = 0; i < 2 + 3; i++) { f.add(200); clock += 400; }
    expect(f.value(), '3 frames counted: too few even at the deadline').toBeNaN();
    f.add(200);
    clock += 400;
    expect(clock).toBeGreaterThanOrEqual(2400);
    expect(f.value(), 'not yet 3 s').toBeNaN();
    clock = 3000;
    expect(f.frames).toBe(4);
    expect(f.value()).toBe(200);
    expect(f.agreed()).toBe(true);
  });

  test('reset starts over', () => {
    const f = new SteadyFigure(8, 2);
    for (let i = 0; i < 10; i++) f.add(1);
    expect(f.value()).toBe(1);
    f.reset();
    expect(f.value()).toBeNaN();
    for (let i = 0; i < 10; i++) f.add(2);
    expect(f.value()).toBe(2);
  });
});

describe('SteadyFigure at the deadline on a very slow page', () => {
  test('one or two frames, all within the dropped ones: a figure from them at 3 s, not "warming up"', () => {
    let clock = 0;
    const f = new SteadyFigure(32, 10, 0.2, 3000, () => clock);
    f.add(900);
    clock += 1200;
    f.add(700);
    clock += 1200;
    expect(f.value(), 'before the deadline: nothing yet').toBeNaN();
    clock = 3000;
    expect(f.frames, 'none counted: both were dropped frames').toBe(0);
    expect(f.used).toBe(2);
    expect(f.value()).toBe(800);
    expect(f.agreed()).toBe(false);
  });

  test('a single frame by the deadline is the figure', () => {
    let clock = 0;
    const f = new SteadyFigure(32, 10, 0.2, 3000, () => clock);
    f.add(450);
    clock = 3100;
    expect(f.value()).toBe(450);
    expect(f.used).toBe(1);
  });

  test('no frame at all by the deadline: still NaN', () => {
    let clock = 0;
    const f = new SteadyFigure(32, 10, 0.2, 3000, () => clock);
    clock = 5000;
    expect(f.value()).toBeNaN();
  });
});
