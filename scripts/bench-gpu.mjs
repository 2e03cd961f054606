// npm run bench:gpu — the demo's GPU cost bench (?bench=gpu, web/demo/bench-gpu.ts) in headless
// Chromium: N characters drawn by three.js's SkinnedMesh and by each GPU path and method of
// gcs-skin, interleaved in one page; prints ms per frame and the ratio to three.js.
//
//   npm run bench:gpu                       our human ×8 and Soldier ×16 (../shared/models), 640×360 and 64×36,
//                                           on WebGLRenderer, then on WebGPURenderer (its WebGL2 backend here)
//   npm run bench:gpu -- --model human --n 8 --size 640x360 --frames 40 --methods three,gpu,crowd --renderer webgl
//
// Headless Chromium here draws with SwiftShader, a CPU rasteriser: its vertex and fragment shaders
// run on the CPU, so the figures are a proxy for shader arithmetic, not a GPU's timings. On a
// machine with a GPU, open the page itself (npm start, then /?bench=gpu) in a browser that uses it.
import { existsSync, mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer } from 'vite';
import { chromium } from 'playwright-core';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const models = resolve(root, '../shared/models');

const args = process.argv.slice(2);
const arg = (name, fallback) => { const i = args.indexOf(`--${name}`); return i >= 0 ? args[i + 1] : fallback; };

const soldier = join(models, 'Soldier.glb');
const cases = arg('model') ? [{ model: arg('model'), n: Number(arg('n', 8)) }]
  : [{ model: 'human', n: 8 }, ...(existsSync(soldier) ? [{ model: soldier, n: 16 }] : [])];
if (!arg('model') && !existsSync(soldier)) console.log(`Soldier skipped: ${soldier} is absent (the shared test models are not on this machine)`);
const sizes = (arg('size') ? [arg('size')] : ['640x360', '64x36']).map((s) => s.split('x').map(Number));
const frames = Number(arg('frames', 30));
const methods = arg('methods');
const renderers = (arg('renderer') ?? 'webgl,webgpu').split(',');
// WebGPURenderer: three.js's SkinnedMesh against gcs-skin/webgpu's default (GcsCharacter, GcsCrowd), DQS and LBS.
const webgpuMethods = arg('methods') ?? 'three,gpu,crowd,dqs,lbs';

const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
if (!existsSync(chromiumPath)) {
  console.error(`bench:gpu: ${chromiumPath} not found (set CHROMIUM=/path/to/chromium)`);
  process.exit(1);
}
const server = await createServer({
  configFile: join(root, 'web/demo/vite.config.ts'), logLevel: 'error',
  // No hot reload: an edited source must not reload the page mid-run.
  server: { host: '127.0.0.1', port: 0, fs: { allow: [root, models] }, hmr: false, watch: null },
});
await server.listen();
const { port } = /** @type {import('node:net').AddressInfo} */ (server.httpServer.address());
const context = await chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'gcs-chromium-')), {
  executablePath: chromiumPath, headless: true, viewport: { width: 1280, height: 720 },
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
const results = [];
try {
  for (const c of cases) {
    for (const [w, h] of sizes) for (const renderer of renderers) {
      const page = await context.newPage();
      const errors = [];
      page.on('pageerror', (e) => errors.push(String(e)));
      const model = c.model === 'human' ? 'human' : `/@fs${c.model}`;
      const which = renderer === 'webgpu' ? { renderer: 'webgpu', forceWebGL: '1', methods: webgpuMethods } : methods ? { methods } : {};
      const q = new URLSearchParams({ bench: 'gpu', model, n: String(c.n), w: String(w), h: String(h), frames: String(frames), ...which });
      await page.goto(`http://127.0.0.1:${port}/?${q}`);
      // The page leaves its result on window.__benchGpu (web/demo/bench-gpu.ts).
      await page.waitForFunction(() => /** @type {any} */ (window).__benchGpu !== undefined, null, { timeout: 120000 });
      const r = await page.evaluate(() => /** @type {any} */ (window).__benchGpu);
      if (errors.length) console.log(errors.join('\n'));
      results.push(r);
      const name = c.model === 'human' ? 'human' : c.model.split('/').pop().replace(/\.glb$/, '');
      console.log(`\n${name} ×${r.n}, ${r.width}×${r.height}, ${r.frames} frames interleaved; ${r.renderer}; ${r.timer ? 'GPU timer queries' : 'no timer query: render + 1-pixel read-back'}`);
      console.log(`${'method'.padEnd(52)} ${'ms/frame'.padStart(9)} ${'× three'.padStart(8)} ${'KB/char'.padStart(8)} ${'update ms/char'.padStart(15)}${r.timer ? '  GPU ms' : ''}`);
      for (const x of r.rows)
        console.log(`${x.label.padEnd(52)} ${x.msPerFrame.toFixed(2).padStart(9)} ${x.ratio.toFixed(2).padStart(8)} ${(x.bytesPerCharacter / 1024).toFixed(2).padStart(8)} ${x.updateMsPerCharacter.toFixed(4).padStart(15)}${x.gpuMs !== null ? x.gpuMs.toFixed(2).padStart(8) : ''}${x.note ? `  [${x.note}]` : ''}`);
      await page.close();
    }
  }
} finally {
  await context.close();
  await server.close();
}
if (arg('json')) {
  const { writeFileSync } = await import('node:fs');
  writeFileSync(arg('json'), JSON.stringify(results, null, 2));
}
