#!/usr/bin/env node
// Screenshots of the demo page for the README: builds the demo, serves it with `vite preview`
// and photographs it in headless Chromium (SwiftShader).
//
//   node scripts/screenshot-demo.mjs            → docs/demo.png (the default: weights criterion),
//                                                 docs/demo-sections.png (colour by section, 8 sections),
//                                                 docs/demo-fox.png (the shipped Fox, all three views),
//                                                 docs/demo-crowd.png (crowd mode: 64 humans, GPU backend),
//                                                 docs/demo-classic.png (CesiumMan coloured by section / contour)
//   node scripts/screenshot-demo.mjs --out DIR  → the same files in DIR
//   node scripts/screenshot-demo.mjs --only demo-fox.png → only that one
//   EXTRA='?criterion=y&colour=1' node scripts/screenshot-demo.mjs → also extra.png
// A page that shows a message (e.g. the wasm failed to load) or throws is an error: no picture.
import { mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { loadDemo, openDemo, option, root, watchErrors } from './demo-browser.mjs';

const outDir = resolve(option('--out', join(root, 'docs')));
const only = option('--only', null);
const { url, context, close } = await openDemo('screenshot-demo', 1440, 800);
mkdirSync(outDir, { recursive: true });
try {
  const shots = [
    { file: 'demo.png', query: '' },
    { file: 'demo-sections.png', query: '?colour=1&sections=8' },
    { file: 'demo-fox.png', query: '?model=fox&lbs=1' },
    { file: 'demo-crowd.png', query: '?crowd=64&shadows=1', crowd: true },
    { file: 'demo-classic.png', query: '?model=cesiumman&colour=1' },
    ...(process.env.EXTRA ? [{ file: 'extra.png', query: process.env.EXTRA }] : []),
  ].filter((s) => !only || s.file === only);
  if (!shots.length) throw new Error(`--only ${only}: no such shot`);
  for (const shot of shots) {
    const page = await context.newPage();
    const checkErrors = watchErrors(page);
    await loadDemo(page, url + shot.query, shot.file, { idle: true });
    if (shot.crowd) {
      // Crowd mode: let every character take a few steps, then hold the pose; the readout refreshes every 10 frames.
      await page.waitForFunction(() => window.__crowd.frame() > 12, null, { timeout: 600000 });
      await page.evaluate(() => window.__crowd.pause());
      checkErrors(shot.file);
      await page.screenshot({ path: join(outDir, shot.file), timeout: 600000 }); // software rendering of the whole crowd
      console.log('wrote', join(outDir, shot.file));
      await page.close();
      continue;
    }
    // A stride of the walk with legs apart, then hold it so every view shows the same pose.
    await page.waitForFunction(() => window.__demo.time() > 0.9, null, { timeout: 60000 });
    await page.evaluate(() => window.__demo.pause(0.32));
    await page.waitForFunction((f) => window.__demo.frame() > f + 3, await page.evaluate(() => window.__demo.frame()));
    checkErrors(shot.file);
    await page.screenshot({ path: join(outDir, shot.file) });
    console.log('wrote', join(outDir, shot.file));
    await page.close();
  }
} finally {
  await close();
}
