// The demo's rough edges a newcomer met (issue 20), in headless Chromium:
// - crowd mode frames every character left of the opaque control column, not under it;
// - the deform-time readouts say "measuring…" until measured (within 3 s of a build), and then the
//   figure settles (the median of a few rounds of measurement) and then stays put (a smoothed
//   average showed start-up figures for many seconds);
// - ?paused=1 opens on the clip's first frame, not the rest pose.
// (The note beside the criterion menu under the paper's criteria: demo.test.ts, with the criteria.)
import { describe, expect, test } from 'vitest';
import type { Page } from 'playwright-core';
import { analyse, demoInChromium, frames, skipReason, type Rect } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

interface GcsReadout { ms: number; warmingUp: boolean; final: boolean }
const gcsReadout = (page: Page) => page.evaluate(() => (window.__demo.readouts() as { gcs: GcsReadout }).gcs);

describe.skipIf(!!reason)('the demo as a newcomer meets it (headless Chromium)', () => {
  const demo = demoInChromium();

  async function open(query: string): Promise<{ page: Page; errors: string[] }> {
    const { page, errors } = await demo.open(query);
    expect(await page.evaluate(() => window.__demo.error())).toBe('');
    return { page, errors };
  }

  test('crowd mode: every character is framed left of the control column, inside the window', async () => {
    const { page, errors } = await open('?crowd=100&vertices=2000');
    try {
      await page.waitForFunction(() => window.__crowd !== undefined && window.__crowd.frame() > 2, null, { timeout: 120000 });
      const { bounds, sidebar, canvas, height } = await page.evaluate(() => {
        const rect = (el: Element) => { const r = el.getBoundingClientRect(); return { left: r.left, right: r.right, top: r.top, bottom: r.bottom }; };
        return { bounds: window.__crowd.screenBounds(), sidebar: rect(document.getElementById('sidebar')!), canvas: rect(document.querySelector('canvas')!), height: innerHeight };
      });
      console.log(`crowd of 100: characters at x ${bounds.left.toFixed(0)}–${bounds.right.toFixed(0)}, y ${bounds.top.toFixed(0)}–${bounds.bottom.toFixed(0)}; the control column from x ${sidebar.left}`);
      expect(sidebar.right - sidebar.left, 'the control column is there (1280 px window)').toBeGreaterThan(200);
      expect(bounds.right, 'clear of the control column').toBeLessThanOrEqual(sidebar.left);
      expect(bounds.left).toBeGreaterThanOrEqual(0);
      expect(bounds.top).toBeGreaterThanOrEqual(0);
      expect(bounds.bottom).toBeLessThanOrEqual(height);
      expect(canvas.right, 'the picture ends where the column starts').toBeLessThanOrEqual(sidebar.left + 1);
      // Framed: the crowd fills a good part of the picture, and the picture shows it.
      expect((bounds.right - bounds.left) / (sidebar.left - canvas.left)).toBeGreaterThan(0.5);
      const region: Rect = { x: 0, y: 0, width: Math.floor(sidebar.left), height };
      const [stats] = await analyse(page, await page.screenshot(), [region]);
      expect(stats.skin, 'characters on screen').toBeGreaterThan(0.02);
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 300000);

  test('the deform-time readouts say "measuring…" until measured, stand within 3 s of a rebuild, then stay put', async () => {
    const { page, errors } = await open('');
    try {
      await page.waitForFunction(() => !(window.__demo.readouts() as { gcs: GcsReadout }).gcs.warmingUp, null, { timeout: 60000, polling: 100 });
      await expect(page.locator('.readout[data-view=gcs]').innerText()).resolves.toMatch(/deform [\d.]+ ms \/ frame · [\d,]+ vertices/);
      // Stays put once final: the median of a few rounds after each build (as the bench measures), not a running average.
      await page.waitForFunction(() => (window.__demo.readouts() as { gcs: GcsReadout }).gcs.final, null, { timeout: 60000, polling: 100 });
      const figures: number[] = [];
      for (let i = 0; i < 3; i++) {
        figures.push((await gcsReadout(page)).ms);
        await page.waitForTimeout(1000);
      }
      console.log(`GCS deform readouts over 3 s: ${figures.map((f) => f.toFixed(3)).join(', ')} ms`);
      expect(new Set(figures).size).toBe(1);
      // A rebuild: "measuring…" at once, a figure again within 3 s (timed in the page).
      const { measuringAtOnce, ms, frames } = await page.evaluate(async () => {
        type R = { gcs: { warmingUp: boolean } };
        const t0 = performance.now(), f0 = window.__demo.frame();
        window.__demo.setSections(8);
        let measuringAtOnce = false;
        for (;;) {
          await new Promise((r) => requestAnimationFrame(r));
          const r = window.__demo.readouts() as R;
          if (window.__demo.sectionsPerPart() === 8 && r.gcs.warmingUp) measuringAtOnce = true;
          if (measuringAtOnce && !r.gcs.warmingUp) break;
          if (performance.now() - t0 > 30000) break;
        }
        return { measuringAtOnce, ms: performance.now() - t0, frames: window.__demo.frame() - f0 };
      });
      console.log(`after a rebuild: figures again in ${ms.toFixed(0)} ms (${frames} frames)`);
      expect(measuringAtOnce).toBe(true);
      expect(ms).toBeLessThanOrEqual(3000);
      await expect(page.locator('.readout[data-view=gcs]').innerText()).resolves.toMatch(/deform [\d.]+ ms \/ frame/);
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 300000);

  test('?paused=1 opens on the clip\'s first frame, not the rest pose', async () => {
    const { page, errors } = await open('?paused=1');
    try {
      const { views, height } = await page.evaluate(() => ({ views: window.__demo.views(), height: innerHeight }));
      const regions: Rect[] = views.map((v) => ({ x: v.x + 8, y: 0, width: v.width - 16, height }));
      await page.addStyleTag({ content: '#labels, #readouts { visibility: hidden !important; }' }); // their numbers change by themselves
      const shot = async () => { await frames(page, 3); return page.screenshot(); };
      expect(await page.evaluate(() => ({ time: window.__demo.time(), clip: window.__demo.clip() }))).toEqual({ time: 0, clip: 'walk' });
      const opened = await shot();
      await page.evaluate(() => window.__demo.restPose(true));
      const rest = await shot();
      await page.evaluate(() => window.__demo.restPose(false));
      const firstFrame = await shot();
      const vsRest = await analyse(page, opened, regions, rest);
      const vsFirstFrame = await analyse(page, opened, regions, firstFrame);
      console.log(`?paused=1 against the rest pose: ${vsRest.map((d) => (100 * d.changed).toFixed(2)).join(' %, ')} % of each view differs; against the clip at 0: ${vsFirstFrame.map((d) => (100 * d.changed).toFixed(2)).join(' %, ')} %`);
      vsRest.forEach((d, i) => expect(d.changed, `view ${i}: not the rest pose`).toBeGreaterThan(0.005));
      vsFirstFrame.forEach((d, i) => expect(d.changed, `view ${i}: the clip's first frame`).toBeLessThan(0.001));
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 300000);
});
