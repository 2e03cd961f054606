#!/usr/bin/env node
// Close-ups of bent joints for the README, from the demo's joint close-up (?joint): GCS, DQS and LBS
// side by side from one camera, the figures under each view. Builds the demo, serves it with
// `vite preview` and photographs it in headless Chromium (SwiftShader); the control column is cut off.
//
//   node scripts/screenshot-joints.mjs            → docs/joints-elbow.png (our human's left elbow at 135°),
//                                                 docs/joints-elbow-centres.png (the same, GCS with centres of rotation),
//                                                 docs/joints-knee.png (its left knee at 135°),
//                                                 docs/joints-cesiumman.png (CesiumMan's right knee at 135°)
//   node scripts/screenshot-joints.mjs --out DIR  → the same files in DIR
// A page that shows a message or throws is an error: no picture.
import { mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { loadDemo, openDemo, option, root, watchErrors } from './demo-browser.mjs';

const outDir = resolve(option('--out', join(root, 'docs')));
const shots = [
  { file: 'joints-elbow.png', query: '?joint=left%20elbow&bend=135' },
  { file: 'joints-elbow-centres.png', query: '?joint=left%20elbow&bend=135&centres=1' },
  { file: 'joints-knee.png', query: '?joint=left%20knee&bend=135' },
  { file: 'joints-cesiumman.png', query: '?joint=right%20knee&model=cesiumman&bend=135' },
];
const WIDTH = 1500, HEIGHT = 620;
const { url, context, close } = await openDemo('screenshot-joints', WIDTH, HEIGHT);
mkdirSync(outDir, { recursive: true });
try {
  for (const shot of shots) {
    const page = await context.newPage();
    const checkErrors = watchErrors(page);
    await loadDemo(page, url + shot.query, shot.file);
    checkErrors(shot.file);
    const views = await page.evaluate(() => window.__demo.joint.views());
    const last = views[views.length - 1];
    await page.screenshot({ path: join(outDir, shot.file), clip: { x: 0, y: 0, width: last.x + last.width, height: HEIGHT } });
    console.log('wrote', join(outDir, shot.file));
    await page.close();
  }
} finally {
  await close();
}
