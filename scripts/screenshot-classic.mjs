#!/usr/bin/env node
// Close-ups of the classic model against GCS for docs/classic.md: the demo with Cesium Man paused
// in a stride, coloured by section / contour (carried skin pale grey), the shared camera moved close
// to the hips and legs, then to the shoulder and arm (GCS left, classic right); then our human's
// left hip, where the zip band joins the thigh's tube to the carried crotch (rows of band vertices
// from the hip loop down to the thigh's first ring at mid-thigh).
//
//   node scripts/screenshot-classic.mjs                     → docs/classic-hips.png, docs/classic-arm.png,
//                                                             docs/classic-bands.png
//   node scripts/screenshot-classic.mjs --out DIR --suffix -before
//                                                           → DIR/classic-hips-before.png, …
// (The "before" pictures in docs/ were taken with the wasm of commit a0a4518 copied over
// web/lib/gcs-skin.wasm: the classic model before issue 21.)
import { mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { loadDemo, openDemo, option, root, watchErrors } from './demo-browser.mjs';

const outDir = resolve(option('--out', join(root, 'docs')));
const suffix = option('--suffix', '');
const { url, context, close } = await openDemo('screenshot-classic', 1200, 700);
mkdirSync(outDir, { recursive: true });
try {
  const page = await context.newPage();
  const checkErrors = watchErrors(page);
  const shots = [
    { query: '?model=cesiumman&colour=1&paused=1', file: `classic-hips${suffix}.png`, eye: [0.75, 1.05, 1.25], target: [0, 0.78, 0] },
    { query: '?model=cesiumman&colour=1&paused=1', file: `classic-arm${suffix}.png`, eye: [1.5, 1.2, 0.9], target: [0.15, 0.95, 0] },
    { query: '?colour=1&paused=1&wireframe=1', file: `classic-bands${suffix}.png`, eye: [0.55, 0.95, 0.95], target: [0.08, 0.78, 0] },
  ];
  let loaded = '';
  for (const shot of shots) {
    if (shot.query !== loaded) {
      await loadDemo(page, `${url}${shot.query}`, shot.query, { idle: true });
      await page.evaluate(() => window.__demo.pause(0.9));
      loaded = shot.query;
    }
    await page.evaluate(([eye, target]) => window.__demo.lookAt(eye, target), [shot.eye, shot.target]);
    await page.waitForFunction((f) => window.__demo.frame() > f + 3, await page.evaluate(() => window.__demo.frame()));
    checkErrors(shot.file);
    await page.screenshot({ path: join(outDir, shot.file) });
    console.log('wrote', join(outDir, shot.file));
  }
} finally {
  await close();
}
