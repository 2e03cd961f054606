// The demo's views in headless Chromium, measured on screenshots against the same scene with the
// character hidden (so a pixel is the character's, or its shadow's, when it differs):
// - framing: in every view, for the default human and each shipped character, with and without the
//   LBS view, the character lies clear of the labels and readouts, inside its view, and fills it;
// - the classic view against the GCS view on a real character (Cesium Man, paused): the two
//   silhouettes nearly coincide (a flap, a cut or a part standing off the skin shows as pixels of
//   one and not the other), and the classic view is textured like the GCS view.
import { describe, expect, test } from 'vitest';
import type { Page } from 'playwright-core';
import { demoInChromium, frames, measurePixels, skipReason, type Rect } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

interface ViewFigures {
  /** Character pixels (differing from the empty scene) inside the view. */
  pixels: number;
  /** …of them under a label or a readout. */
  covered: number;
  /** …in the view's outermost 3-pixel columns (cut by the view's edge). */
  atEdge: number;
  /** Bounding box of the character's pixels, relative to the view. */
  box: Rect;
}

/** Screenshots the page with and without the character and measures each view (views(): x, width). */
async function measureViews(page: Page): Promise<{ views: ViewFigures[]; overlap: { xor: number; union: number; colour: number }; height: number }> {
  await frames(page, 3);
  // The text's boxes as shown; the shots without the text (its numbers change by themselves).
  const boxes = await page.evaluate(() => [...document.querySelectorAll('.label, .readout')].map((el) => {
    const r = el.getBoundingClientRect();
    return { left: r.left, right: r.right, top: r.top, bottom: r.bottom };
  }));
  await page.addStyleTag({ content: '#labels, #readouts { visibility: hidden !important; }' });
  const shot = (await page.screenshot()).toString('base64');
  await page.evaluate(() => window.__demo.hideCharacter(true));
  await frames(page, 3);
  const empty = (await page.screenshot()).toString('base64');
  await page.evaluate(() => window.__demo.hideCharacter(false));
  await page.evaluate(() => document.querySelectorAll('style').forEach((s) => { if (s.textContent?.includes('visibility: hidden !important')) s.remove(); }));
  await frames(page, 2);
  return measurePixels(page, [shot, empty], ([a, b], boxes) => {
    const W = a.width, H = a.height;
    type Box = { left: number; right: number; top: number; bottom: number };
    const inside = (list: Box[]) => (x: number, y: number) => list.some((r) => x >= r.left && x < r.right && y >= r.top && y < r.bottom);
    const text = inside(boxes);
    // The frame-rate panel (three's Stats, top left) changes by itself: not the character.
    const stats = inside([...document.querySelectorAll('body > div')].filter((d) => (d as HTMLElement).style.zIndex === '10000')
      .map((el) => el.getBoundingClientRect()));
    const isCharacter = (x: number, y: number) => {
      if (stats(x, y)) return false;
      const i = 4 * (y * W + x);
      return Math.abs(a.data[i] - b.data[i]) > 24 || Math.abs(a.data[i + 1] - b.data[i + 1]) > 24 || Math.abs(a.data[i + 2] - b.data[i + 2]) > 24;
    };
    const rects = window.__demo.views();
    const views = rects.map((v) => {
      let pixels = 0, covered = 0, atEdge = 0, x0 = Infinity, y0 = Infinity, x1 = -1, y1 = -1;
      for (let y = 0; y < H; y++)
        for (let x = v.x + 2; x < v.x + v.width - 2; x++) {
          if (!isCharacter(x, y)) continue;
          pixels++;
          if (text(x, y)) covered++;
          if (x < v.x + 5 || x >= v.x + v.width - 5) atEdge++;
          x0 = Math.min(x0, x - v.x); x1 = Math.max(x1, x - v.x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
        }
      return { pixels, covered, atEdge, box: { x: x0, y: y0, width: x1 - x0 + 1, height: y1 - y0 + 1 } };
    });
    // The first two views (GCS, classic) pixel by pixel, away from the text.
    let xor = 0, union = 0, colour = 0, both = 0;
    const width = Math.min(rects[0].width, rects[1].width);
    for (let y = 0; y < H; y++)
      for (let x = 2; x < width - 2; x++) {
        const i = 4 * (y * W + rects[0].x + x), j = 4 * (y * W + rects[1].x + x);
        if (text(rects[0].x + x, y) || text(rects[1].x + x, y)) continue;
        const g = isCharacter(rects[0].x + x, y), c = isCharacter(rects[1].x + x, y);
        if (g || c) union++;
        if (g !== c) xor++;
        if (g && c) {
          both++;
          colour += (Math.abs(a.data[i] - a.data[j]) + Math.abs(a.data[i + 1] - a.data[j + 1]) + Math.abs(a.data[i + 2] - a.data[j + 2])) / 3;
        }
      }
    return { views, overlap: { xor, union, colour: colour / Math.max(1, both) }, height: H };
  }, boxes);
}

describe.skipIf(!!reason)('the demo\'s views measured on screenshots (headless Chromium)', () => {
  const demo = demoInChromium();

  async function open(query: string): Promise<Page> {
    const { page } = await demo.open(`?${query}`);
    await page.evaluate(() => window.__demo.idle());
    expect(await page.evaluate(() => window.__demo.error())).toBe('');
    return page;
  }

  for (const model of ['human', 'fox', 'cesiumman', 'robot'])
    for (const lbs of [false, true])
      test(`${model}${lbs ? ' with the LBS view' : ''}: every view frames the character, clear of labels and readouts`, async () => {
        const page = await open(`model=${model}&paused=1${lbs ? '&lbs=1' : ''}`);
        try {
          await page.evaluate(() => window.__demo.pause(0.4));
          const { views, height } = await measureViews(page);
          expect(views.length).toBe(lbs ? 3 : 2);
          const rects = await page.evaluate(() => window.__demo.views());
          views.forEach((v, i) => {
            const label = `${model} view ${i}`;
            console.log(`${label}: ${v.pixels} px, ${v.covered} under text, ${v.atEdge} at the edge, box ${JSON.stringify(v.box)} of ${rects[i].width} × ${height}`);
            expect(v.pixels, label).toBeGreaterThan(2000);
            expect(v.covered, `${label}: character pixels under a label or readout`).toBe(0);
            expect(v.atEdge, `${label}: character cut by the view's edge`).toBe(0);
            // Framed: it fills a good part of the view's height or width (the camera fits the bounding
            // box, whose corners reach farther than the silhouette: the long, low fox fills 44 % of
            // the width in the two-view layout).
            expect(Math.max(v.box.height / height, v.box.width / rects[i].width), `${label}: fills its view`).toBeGreaterThan(0.4);
          });
        } finally {
          await page.close();
        }
      }, 300000);

  test('Cesium Man, paused: the classic view\'s silhouette and texture match the GCS view\'s', async () => {
    const page = await open('model=cesiumman&paused=1');
    try {
      const figures = [];
      for (const t of [0.3, 0.9]) {
        await page.evaluate((time) => window.__demo.pause(time), t);
        const { views, overlap } = await measureViews(page);
        const mismatch = overlap.xor / overlap.union;
        console.log(`Cesium Man t = ${t}: GCS ${views[0].pixels} px, classic ${views[1].pixels} px; silhouettes differ on ${(100 * mismatch).toFixed(2)} % of their union; mean colour difference where both ${overlap.colour.toFixed(1)} / 255`);
        figures.push({ mismatch, colour: overlap.colour });
        expect(views[1].pixels).toBeGreaterThan(0.9 * views[0].pixels);
        // Resampling loses detail: 3.0–3.7 % of the union differs here. Before issue 21 (carried
        // parts moved by one rigid bone, rings along the straight bone) it was 5.1–5.3 %, with
        // colours 9.8–10.5 apart where both cover (7 now): the bounds sit between.
        expect(mismatch).toBeLessThan(0.045);
        // The classic view wears the source's texture (uv through the library): colours agree.
        expect(overlap.colour).toBeLessThan(8.5);
      }
    } finally {
      await page.close();
    }
  }, 300000);
});
