// The demo's joint close-up (?joint, web/demo/joint-mode.ts) in headless Chromium: the knees and
// elbows found on our human and on CesiumMan (no bone names), one bent to 135°, GCS / DQS / LBS side
// by side from one camera. Unbent, the three views are the same picture; bent, LBS's differs from
// DQS's (its collapse at the inner side), and the readouts say so: LBS loses volume, DQS keeps it
// and bulges more.
import { describe, expect, test } from 'vitest';
import { mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import type { Page } from 'playwright-core';
import { demoInChromium, measurePixels, ROOT, skipReason } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

interface Figures { volumeChange: number; bulgeP95: number; bulgeMax: number; collapseP5: number; collapseMin: number; creases: number; newIntersections: number }
interface JointHook {
  joints(): string[]; joint(): string; character(): string; choose(label: string): Promise<void>; bend(degrees: number): Promise<void>;
  readouts(): Record<'gcs' | 'dqs' | 'lbs', Figures | null>; views(): { kind: string; x: number; width: number }[]; error(): string;
  centres(on: boolean): Promise<void>;
}
// The demo's hook has `joint` in ?joint mode: typed once here, so the calls below need no cast.
declare module './harness.js' {
  interface DemoHook { joint: JointHook }
}
const hook = (page: Page) => ({
  joints: () => page.evaluate(() => window.__demo.joint.joints()),
  joint: () => page.evaluate(() => window.__demo.joint.joint()),
  choose: (label: string) => page.evaluate((l) => window.__demo.joint.choose(l), label),
  bend: (deg: number) => page.evaluate((d) => window.__demo.joint.bend(d), deg),
  readouts: () => page.evaluate(() => window.__demo.joint.readouts()),
  views: () => page.evaluate(() => window.__demo.joint.views()),
  centres: (on: boolean) => page.evaluate((o) => window.__demo.joint.centres(o), on),
});

/**
 * Share of pixels that differ (any channel by > 24) between column `a` of one screenshot and column
 * `b` of the same one (or of `other`), both cut to the narrower width.
 */
async function viewDifference(page: Page, png: Buffer, a: { x: number; width: number }, b: { x: number; width: number }, other?: Buffer): Promise<number> {
  const pngs = other ? [png, other] : [png];
  return measurePixels(page, pngs.map((p) => p.toString('base64')), ([first, second = first], { a, b }) => {
    // Between the labels and the readouts, clear of the dividers at the columns' edges: the picture itself.
    const w = Math.min(a.width, b.width) - 6, h = first.height;
    const top = Math.round(0.22 * h), bottom = Math.round(0.82 * h);
    let changed = 0;
    for (let y = top; y < bottom; y++)
      for (let x = 0; x < w; x++) {
        const i = 4 * (y * first.width + a.x + 3 + x), j = 4 * (y * second.width + b.x + 3 + x);
        const A = first.data, B = second.data;
        if (Math.abs(A[i] - B[j]) > 24 || Math.abs(A[i + 1] - B[j + 1]) > 24 || Math.abs(A[i + 2] - B[j + 2]) > 24) changed++;
      }
    return changed / (w * (bottom - top));
  }, { a, b });
}

describe.skipIf(!!reason)('the joint close-up (headless Chromium)', () => {
  const demo = demoInChromium();

  test('our human\'s left elbow: the same picture unbent; at 135° LBS differs from DQS, loses volume, and DQS bulges more', async () => {
    const { page, errors } = await demo.open('?joint');
    try {
      const j = hook(page);
      expect(await page.evaluate(() => window.__demo.error())).toBe('');
      expect(await j.joints()).toEqual(['left knee (LeftLeg)', 'right knee (RightLeg)', 'left elbow (LeftForeArm)', 'right elbow (RightForeArm)']);
      await j.choose('left elbow (LeftForeArm)');
      const [gcsView, dqsView, lbsView] = await j.views();
      expect([gcsView.kind, dqsView.kind, lbsView.kind]).toEqual(['gcs', 'dqs', 'lbs']);
      await j.bend(0);
      const flat = await page.screenshot();
      const unbent = await j.readouts();
      for (const f of Object.values(unbent)) {
        expect(Math.abs(f!.volumeChange)).toBeLessThan(1e-3);
        expect(f!.bulgeMax).toBeCloseTo(1, 4);
      }
      expect(await viewDifference(page, flat, lbsView, dqsView)).toBeLessThan(0.002);
      expect(await viewDifference(page, flat, gcsView, dqsView)).toBeLessThan(0.002);
      await j.bend(135);
      const bent = await page.screenshot();
      const out = join(ROOT, 'tests/.tmp');
      mkdirSync(out, { recursive: true });
      writeFileSync(join(out, 'joint-mode-human-elbow-135.png'), bent);
      const r = await j.readouts();
      const lbsVsDqs = await viewDifference(page, bent, lbsView, dqsView);
      const gcsVsDqs = await viewDifference(page, bent, gcsView, dqsView);
      console.log(`human left elbow at 135°: volume GCS ${r.gcs!.volumeChange.toFixed(1)} %, DQS ${r.dqs!.volumeChange.toFixed(1)} %, ` +
        `LBS ${r.lbs!.volumeChange.toFixed(1)} %; bulge p95 ${r.gcs!.bulgeP95.toFixed(2)} / ${r.dqs!.bulgeP95.toFixed(2)} / ` +
        `${r.lbs!.bulgeP95.toFixed(2)}; pixels differing from DQS: LBS ${(100 * lbsVsDqs).toFixed(2)} %, GCS ${(100 * gcsVsDqs).toFixed(2)} % ` +
        '(picture in tests/.tmp)');
      expect(r.lbs!.volumeChange).toBeLessThan(-3);
      expect(Math.abs(r.dqs!.volumeChange)).toBeLessThan(1);
      expect(r.dqs!.bulgeP95).toBeGreaterThan(r.lbs!.bulgeP95);
      expect(lbsVsDqs).toBeGreaterThan(0.005);
      // The bend shows: every view changed from the unbent picture.
      for (const v of [gcsView, dqsView, lbsView]) expect(await viewDifference(page, bent, v, v, flat)).toBeGreaterThan(0.02);
      await expect(page.locator('.readout[data-view=lbs]').innerText()).resolves.toMatch(/volume -\d+\.\d %/);
      // Centres of rotation in the GCS view: less bulge than the default (measured 1.03 against 1.09), the label says so.
      await j.centres(true);
      const withCentres = (await j.readouts()).gcs!;
      expect(withCentres.bulgeP95).toBeLessThan(r.gcs!.bulgeP95 - 0.03);
      await expect(page.locator('.label[data-view=gcs]').innerText()).resolves.toMatch(/GCS \(centres of rotation\)/);
      const centresShot = await page.screenshot();
      expect(await viewDifference(page, centresShot, gcsView, gcsView, bent)).toBeGreaterThan(0.001);
      await j.centres(false);
      expect((await j.readouts()).gcs!.bulgeP95).toBeCloseTo(r.gcs!.bulgeP95, 6);
      expect(await page.evaluate(() => window.__demo.error())).toBe('');
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 300000);

  test('the comparison page\'s joint close-up button opens ?joint on the character on screen', async () => {
    const { page, errors } = await demo.open('?model=cesiumman');
    try {
      await Promise.all([
        page.waitForURL(/[?&]joint(&|=|$)/),
        page.locator('.lil-gui .controller').filter({ has: page.locator('.name', { hasText: 'joint close-up (knees, elbows) ↗' }) }).locator('button').click(),
      ]);
      await page.waitForFunction(() => window.__demo !== undefined);
      await page.evaluate(() => window.__demo.ready);
      expect(new URL(page.url()).searchParams.get('model')).toBe('cesiumman');
      expect(await hook(page).joints()).toEqual(['left knee', 'right knee', 'left elbow', 'right elbow']);
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 300000);

  test('CesiumMan (no bone names): two knees and two elbows found, a knee bent to 135° measured in every view', async () => {
    const { page, errors } = await demo.open('?joint=right%20knee&model=cesiumman&bend=135');
    try {
      const j = hook(page);
      expect(await page.evaluate(() => window.__demo.error())).toBe('');
      expect(await j.joints()).toEqual(['left knee', 'right knee', 'left elbow', 'right elbow']);
      expect(await j.joint()).toBe('right knee');
      const r = await j.readouts();
      expect(r.lbs!.volumeChange).toBeLessThan(r.dqs!.volumeChange - 5);
      expect(r.dqs!.bulgeP95).toBeGreaterThan(r.lbs!.bulgeP95);
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 300000);
});
