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
// Beside each picture, NAME.readouts.json: the figures the picture shows (the page's readouts once
// its cost figures are final; the crowd's readout), so that tests/pictures.test.ts can hold the
// pictures to the current build and to docs/figures.json.
import { mkdirSync, writeFileSync } from 'node:fs';
import { cpus } from 'node:os';
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
      await page.waitForFunction(() => /skinning CPU [<\d.\s]+ ms/.test(window.__crowd.readout()), null, { timeout: 600000 });
      checkErrors(shot.file);
      await page.screenshot({ path: join(outDir, shot.file), timeout: 600000 }); // software rendering of the whole crowd
      const crowd = await page.evaluate(() => ({ characters: window.__crowd.count(), backend: window.__crowd.backend(), readout: window.__crowd.readout() }));
      writeReadouts(shot, { crowd });
      await page.close();
      continue;
    }
    // The cost figures final (every round measured), then a stride of the walk with legs apart,
    // held so every view shows the same pose.
    await page.waitForFunction(() => { const r = window.__demo.readouts(); return !!r.gcs && r.gcs.final; }, null, { timeout: 120000 });
    await page.waitForFunction(() => window.__demo.time() > 0.9, null, { timeout: 60000 });
    await page.evaluate(() => window.__demo.pause(0.32));
    await page.waitForFunction((f) => window.__demo.frame() > f + 3, await page.evaluate(() => window.__demo.frame()));
    checkErrors(shot.file);
    await page.screenshot({ path: join(outDir, shot.file) });
    const readouts = await page.evaluate(() => window.__demo.readouts());
    const text = await page.locator('#readouts').innerText();
    writeReadouts(shot, { readouts, text });
    await page.close();
  }
} finally {
  await close();
}

/** docs/NAME.readouts.json beside docs/NAME.png: where and when it was taken, and what it shows. */
function writeReadouts(shot, shown) {
  const file = join(outDir, shot.file.replace(/\.png$/, '.readouts.json'));
  const host = `${cpus()[0]?.model.trim() ?? 'unknown CPU'}, ${cpus().length} cores, headless Chromium (SwiftShader)`;
  writeFileSync(file, `${JSON.stringify({ picture: shot.file, query: shot.query, taken: new Date().toISOString().slice(0, 10), host, ...shown }, null, 2)}\n`);
  console.log('wrote', join(outDir, shot.file), 'and', file);
}
