#!/usr/bin/env node
// Close-ups of the classic model against GCS for docs/classic.md: the demo with Cesium Man paused
// in a stride, coloured by section / contour (carried skin pale grey), the shared camera moved close
// to the hips and legs, then to the shoulder and arm (GCS left, classic right).
//
//   node scripts/screenshot-classic.mjs                     → docs/classic-hips.png, docs/classic-arm.png
//   node scripts/screenshot-classic.mjs --out DIR --suffix -before
//                                                           → DIR/classic-hips-before.png, …
// (The "before" pictures in docs/ were taken with the wasm of commit a0a4518 copied over
// web/lib/gcs-skin.wasm: the classic model before issue 21.)
import { existsSync, mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { build, preview } from 'vite';
import { chromium } from 'playwright-core';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : fallback;
};
const outDir = resolve(arg('--out', join(root, 'docs')));
const suffix = arg('--suffix', '');
const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
if (!existsSync(chromiumPath)) {
  console.error(`screenshot-classic: ${chromiumPath} not found (set CHROMIUM=/path/to/chromium)`);
  process.exit(1);
}
const configFile = join(root, 'web/demo/vite.config.ts');
const dist = mkdtempSync(join(tmpdir(), 'gcs-demo-'));
await build({ configFile, logLevel: 'error', build: { outDir: dist, emptyOutDir: true } });
const server = await preview({ configFile, logLevel: 'error', build: { outDir: dist }, preview: { host: '127.0.0.1', port: 0 } });
const url = server.resolvedUrls.local[0];
const context = await chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'gcs-chromium-')), {
  executablePath: chromiumPath,
  headless: true,
  viewport: { width: 1200, height: 700 },
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
mkdirSync(outDir, { recursive: true });
try {
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(`${url}?model=cesiumman&colour=1&paused=1`);
  await page.waitForFunction(() => window.__demo !== undefined);
  await page.evaluate(() => window.__demo.ready);
  await page.evaluate(() => window.__demo.idle());
  const message = await page.evaluate(() => window.__demo.error());
  if (message) throw new Error(`the page says: ${message}`);
  await page.evaluate(() => window.__demo.pause(0.9));
  const shots = [
    { file: `classic-hips${suffix}.png`, eye: [0.75, 1.05, 1.25], target: [0, 0.78, 0] },
    { file: `classic-arm${suffix}.png`, eye: [1.5, 1.2, 0.9], target: [0.15, 0.95, 0] },
  ];
  for (const shot of shots) {
    await page.evaluate(([eye, target]) => window.__demo.lookAt(eye, target), [shot.eye, shot.target]);
    await page.waitForFunction((f) => window.__demo.frame() > f + 3, await page.evaluate(() => window.__demo.frame()));
    if (errors.length) throw new Error(`page errors: ${errors.join('; ')}`);
    await page.screenshot({ path: join(outDir, shot.file) });
    console.log('wrote', join(outDir, shot.file));
  }
} finally {
  await context.close();
  await server.close();
  rmSync(dist, { recursive: true, force: true });
}
