// The acceptance test: the README's "Using it with three.js" path, followed to the letter
// by a newcomer outside this repository. A fresh Vite + TypeScript app is made in a temp folder
// as create-vite 9.3.0's vanilla-ts template makes it (tests/browser/app-fixture: its index.html,
// without the template's favicon, and its tsconfig.json; vite and typescript at this repo's
// versions); then each `npm install` line of the README's sh block runs there as written, the
// library from the README's git URL pointing at a git repository of this checkout (npm clones it,
// installs its dev dependencies and builds it there), then again from the library's tarball (packed
// from a copy of the sources, so `prepack` builds there): both routes must install the same files.
// Every other package comes at this repo's version (nothing else is installed: a package the README
// forgets, like @types/three, fails `tsc`); src/main.ts is
// the README's ts block itself, between one import and one call of a test hook
// (app-fixture/src/test-hook.ts: a known scene, fixed clip times, switches). It must type-check
// with `tsc --noEmit --strict`, build with `vite build` and, served by `vite preview` in headless
// Chromium, draw:
// - with GcsCharacter 'lbs', the same picture as three.js's own SkinnedMesh (reference.html: the
//   README's block without its gcs-skin lines);
// - shadows on the ground under the character, both ways;
// - with GCS (the README's method), the character at the same place (silhouette overlap);
// and keep doing it through a clip change, rebuilds ('gcs' → 'dqs' → 'gcs') and dispose (then
// the original SkinnedMeshes draw again, the same pixels as three's), with no page or WebGL error,
// with no scrollbar (the page needs no CSS the README does not show). The README's WebGPURenderer
// block is the app's second page (webgpu.html, the same hook): it type-checks, fills the window
// with no scrollbar and draws the character (GCS on the GPU backend, TSL) where three's own
// skinning draws it. Characters from ../shared/models, served to the page as
// the README's 'character.glb' (never copied into the repository; skipped, with the reason
// printed, when absent): Soldier (two skinned meshes on their own skeletons) and CesiumMan (textured).
import { spawn, spawnSync, type ChildProcess } from 'node:child_process';
import { createHash } from 'node:crypto';
import { cpSync, existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import { packTarballs, snapshotRepository, userEnv } from '../helpers/pack.js';
import { README_REPOSITORY, readmeBlocks } from '../helpers/readme.js';
import { freePort, launchChromium, measurePixels, MODELS_DIR, ROOT, skipReason } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);
const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';
const WIDTH = 640, HEIGHT = 480;

/** The characters drawn: file, first clip, a second clip for the clip change ('' = none). */
const CHARACTERS = [
  { file: 'Soldier.glb', clip: 'Walk', next: 'Run', skinned: 2, textured: true },
  { file: 'CesiumMan.glb', clip: '', next: '', skinned: 1, textured: true },
];

/**
 * Tolerances, from measurements on this machine (Chromium 156, SwiftShader, 640×480 = 307,200
 * pixels, Soldier at Walk 0.5 s / CesiumMan at 0.5 s). A pixel "differs" when one of its channels
 * differs by more than DIFF_THRESHOLD (of 255).
 */
const DIFF_THRESHOLD = 16;
/**
 * GcsCharacter 'lbs' vs three's own skinning, whole frame, share of differing pixels. Measured:
 * none (2 and 1 pixels differ at all, by 1/255: float rounding of the same sums). The default GCS
 * differs from three's LBS by 0.6 % (Soldier) and 1.0 % (CesiumMan) of the frame; three's own
 * picture shifted by one pixel differs by 2.0 % / 1.5 %. 0.05 % stays 12× below the smallest
 * real difference while leaving room for another rasteriser's rounding along edges.
 */
const LBS_TOLERANCE = 0.0005;
/**
 * GCS and DQS silhouettes vs three's (intersection over union of the character's pixels, drawn
 * without the ground). Measured: GCS 0.990 / 0.986 (Soldier Walk / Run), 0.959 (CesiumMan, thin
 * limbs: most of its pixels are near an edge); DQS, the reference GCS converges to, 0.986 and
 * 0.970. Three's own silhouette shifted by 2 pixels: 0.924 (Soldier), 0.883 (CesiumMan).
 */
const SILHOUETTE_IOU = 0.93;
/**
 * Shadows: ground pixels outside the character that are darker by more than 20 (luminance) than
 * in the same frame without the character, per pixel of the character's silhouette. Measured
 * with three's skinning: 0.20 (Soldier), 0.34 (CesiumMan); LBS the same, GCS 1.00× / 0.99× that.
 * Required: three's above 0.1, and each method's at least 0.9× three's.
 */
const SHADOW_MIN = 0.1;

const USING = '## Using it with three.js';
/** The README's install commands: `npm install [-D] names…` lines of its sh block, comments dropped. */
function readmeInstalls(): { flags: string[]; names: string[] }[] {
  const sh = readmeBlocks(USING, 'sh');
  if (sh.length !== 1) throw new Error(`expected one sh block under "${USING}", found ${sh.length}`);
  return sh[0].split('\n').map((l) => l.replace(/#.*$/, '').trim()).filter(Boolean).map((line) => {
    const words = line.split(/\s+/);
    if (words[0] !== 'npm' || !['install', 'i', 'add'].includes(words[1])) throw new Error(`not an npm install line: ${line}`);
    return { flags: words.slice(2).filter((w) => w.startsWith('-')), names: words.slice(2).filter((w) => !w.startsWith('-')) };
  });
}

/** Lines of the README's example that need gcs-skin: left out of the three.js reference page. */
const GCS_SKIN_LINE = /gcs-skin|GcsCharacter|\bgcs\b|\bcharacter\.(update|rebuild|dispose)\(/;

function versionOf(pkg: string): string {
  return JSON.parse(readFileSync(join(ROOT, 'node_modules', pkg, 'package.json'), 'utf8')).version;
}

let dir = '';
let app = '';
let preview: ChildProcess | null = null;
let url = '';
let context: BrowserContext | null = null;
let lab: Page;
const timings: Record<string, number> = {};
const missing = CHARACTERS.filter((c) => !existsSync(join(MODELS_DIR, c.file))).map((c) => c.file);
if (missing.length) console.log(`app test: ${missing.join(', ')} not in ${MODELS_DIR}: those characters are skipped`);

function run(cmd: string, args: string[], cwd: string): string {
  const r = spawnSync(cmd, args, { cwd, encoding: 'utf8', env: userEnv({ NO_COLOR: '1' }) });
  if (r.status !== 0) throw new Error(`${cmd} ${args.join(' ')} failed (${r.status}):\n${r.stdout}\n${r.stderr}`);
  return r.stdout;
}

function timed<T>(name: string, f: () => T): T {
  const t0 = performance.now();
  try {
    return f();
  } finally {
    timings[name] = Math.round(performance.now() - t0);
  }
}

/** Every file of an installed package, path → sha1 (to compare two installs of it). */
function fileHashes(root: string, sub = ''): Record<string, string> {
  const out: Record<string, string> = {};
  for (const entry of readdirSync(join(root, sub), { withFileTypes: true })) {
    const path = sub ? `${sub}/${entry.name}` : entry.name;
    if (entry.isDirectory()) Object.assign(out, fileHashes(root, path));
    else out[path] = createHash('sha1').update(readFileSync(join(root, path))).digest('hex');
  }
  return out;
}

/** The package gcs-skin as installed from the git URL and from the tarball (the README's two routes). */
const installed: { git?: Record<string, string>; tarball?: Record<string, string> } = {};

describe.skipIf(!!reason)('the README example in a fresh Vite + TypeScript app (installed from the git URL, then the tarball)', () => {
  beforeAll(async () => {
    dir = mkdtempSync(join(tmpdir(), 'gcs-skin-app-'));
    const repository = timed('snapshot', () => snapshotRepository(join(dir, 'repo')));
    const packed = timed('pack', () => packTarballs(dir));

    // The app as create-vite writes it, with no dependency but its tools.
    app = join(dir, 'app');
    cpSync(join(ROOT, 'tests/browser/app-fixture'), app, { recursive: true });
    writeFileSync(join(app, 'package.json'), JSON.stringify({
      name: 'vite-typescript-starter', private: true, version: '0.0.0', type: 'module',
      scripts: { dev: 'vite', build: 'tsc && vite build', preview: 'vite preview' },
      devDependencies: { typescript: versionOf('typescript'), vite: versionOf('vite') },
    }, null, 2));
    timed('install', () => run(npm, ['install', '--no-audit', '--no-fund', '--prefer-offline'], app));
    // The README's install lines, as written: the library from its git URL (this checkout as a
    // repository: npm clones it, installs its dev dependencies and builds there), any other package at
    // this repo's version. Then the same lines with the library's tarball, the README's other route:
    // both must install the same files (the app is built and drawn with the second).
    for (const [route, library] of [['git', repository], ['tarball', packed.library]] as const) {
      for (const { flags, names } of readmeInstalls()) {
        const specs = names.map((n) => (n === `git+${README_REPOSITORY}` ? library : `${n}@${versionOf(n)}`));
        timed(`${route}: npm install ${[...flags, ...names].join(' ')}`, () => run(npm, ['install', '--no-audit', '--no-fund', '--prefer-offline', ...flags, ...specs], app));
      }
      installed[route] = fileHashes(join(app, 'node_modules/gcs-skin'));
    }
    // The README's example itself, and the same without gcs-skin for the reference page.
    const [example] = readmeBlocks(USING, 'ts');
    const hook = 'installTestHook({ renderer, scene, camera, gltf, mixer, character });';
    writeFileSync(join(app, 'src/main.ts'), `import { installTestHook } from './test-hook';\n${example}\n${hook}\n`);
    const plain = example.split('\n').filter((l) => !GCS_SKIN_LINE.test(l.replace(/\/\/.*$/, ''))).join('\n');
    writeFileSync(join(app, 'src/reference.ts'), `import { installTestHook } from './test-hook';\n${plain}\n${hook.replace('character }', 'character: null }')}\n`);
    const page = readFileSync(join(app, 'index.html'), 'utf8');
    writeFileSync(join(app, 'reference.html'), page.replace('/src/main.ts', '/src/reference.ts'));
    const [webgpu] = readmeBlocks('# gcs-skin with WebGPURenderer', 'ts', 'docs/webgpu.md');
    writeFileSync(join(app, 'src/webgpu.ts'), `import { installTestHook } from './test-hook';\n${webgpu}\n${hook}\n`);
    writeFileSync(join(app, 'webgpu.html'), page.replace('/src/main.ts', '/src/webgpu.ts'));

    const port = await freePort();
    preview = spawn(join(app, 'node_modules/.bin/vite'), ['preview', '--host', '127.0.0.1', '--port', String(port), '--strictPort'], {
      cwd: app, stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, NO_COLOR: '1' }, detached: false,
    });
    url = `http://127.0.0.1:${port}/`;
  }, 480000);

  test('the git URL and the tarball install the same package: built dist/ and the committed wasm', () => {
    expect(installed.git?.['dist/three.js'], 'the git install has no built dist/').toBeDefined();
    expect(installed.git).toEqual(installed.tarball);
    const wasm = createHash('sha1').update(readFileSync(join(ROOT, 'web/lib/gcs-skin.wasm'))).digest('hex');
    expect(installed.git?.['dist/gcs-skin.wasm']).toBe(wasm);
  });

  afterAll(async () => {
    await context?.close();
    if (preview && preview.exitCode === null) {
      const p = preview;
      await new Promise<void>((r) => { p.once('exit', () => r()); p.kill('SIGTERM'); setTimeout(r, 5000); });
    }
    if (dir) rmSync(dir, { recursive: true, force: true });
    console.log(`app test timings (ms): ${JSON.stringify(timings)}, screenshots ${JSON.stringify(shotMs)}, console warnings ${JSON.stringify([...new Set(warnings)])}`);
  });

  test('src/main.ts type-checks with tsc --noEmit --strict and builds with vite build', () => {
    // The app's own tools, from its own node_modules.
    timed('tsc', () => run(join(app, 'node_modules/.bin/tsc'), ['--noEmit', '--strict', '-p', '.'], app));
    timed('vite build', () => run(join(app, 'node_modules/.bin/vite'), ['build'], app));
    const assets = readdirSync(join(app, 'dist/assets'));
    expect(assets.some((f) => /^gcs-skin.*\.wasm$/.test(f)), assets.join(' ')).toBe(true);
    // The app resolved the installed package, not this checkout.
    expect(existsSync(join(app, 'node_modules/gcs-skin/dist/three.js'))).toBe(true);
    expect(existsSync(join(app, 'node_modules/@gltf-transform')), 'a library user got the glTF readers').toBe(false);
    expect(readFileSync(join(app, 'package.json'), 'utf8')).not.toContain(ROOT);
    for (const f of assets.filter((a) => a.endsWith('.js'))) expect(readFileSync(join(app, 'dist/assets', f), 'utf8')).not.toContain(ROOT);
  }, 120000);

  for (const c of CHARACTERS) {
    test.skipIf(missing.includes(c.file))(`${c.file}: GcsCharacter 'lbs' draws three's pixels, GCS the same silhouette, shadows both ways; clip change, rebuilds, dispose`, async () => {
      expect(existsSync(join(app, 'dist/index.html')), 'the app was not built').toBe(true);
      await waitForServer(url);
      if (!context) {
        context = await launchChromium();
        lab = await context.newPage();
        await lab.setViewportSize({ width: 64, height: 64 });
      }
      const t0 = performance.now();
      const steps: Record<string, number> = {};
      let last = t0;
      const lap = (name: string) => { const now = performance.now(); steps[name] = Math.round(now - last); last = now; };
      const clip = c.clip ? `clip=${c.clip}` : '';
      const q = (method: string) => (method === 'three' ? `${url}reference.html?${clip}` : `${url}?method=${method}&${clip}`);
      const model = join(MODELS_DIR, c.file);

      // three.js's own SkinnedMesh: the reference.
      const three = await open(context, q('three'), model);
      lap('open three');
      expect(await three.page.evaluate(() => window.__app.deformedMeshes())).toBe(0);
      expect(await three.page.evaluate(() => window.__app.skinnedMeshes())).toBe(c.skinned);
      expect(await three.page.evaluate(() => window.__app.textured())).toBe(c.textured);
      const ref = {
        full: await shot(three.page, { ground: true, character: true }),
        sil: await shot(three.page, { ground: false, character: true }),
        empty: await shot(three.page, { ground: true, character: false }),
      };
      let ref2 = ref;
      if (c.next) {
        await three.page.evaluate((n) => window.__app.play(n), c.next);
        ref2 = { full: await shot(three.page, { ground: true, character: true }), sil: await shot(three.page, { ground: false, character: true }), empty: ref.empty };
      }
      await three.close();
      lap('three shots');

      // GcsCharacter, LBS: three's pixels.
      const lbs = await open(context, q('lbs'), model);
      lap('open lbs');
      expect(await lbs.page.evaluate(() => window.__app.deformedMeshes())).toBe(c.skinned);
      const lbsFull = await shot(lbs.page, { ground: true, character: true });
      await lbs.close();
      lap('lbs shots');

      // GCS (the default method): same place; then the lifecycle.
      const gcsPage = await open(context, q('gcs'), model);
      const page = gcsPage.page;
      lap('open gcs');
      expect(await page.evaluate(() => window.__app.method())).toBe('gcs');
      const gcsFull = await shot(page, { ground: true, character: true });
      const gcsSil = await shot(page, { ground: false, character: true });
      if (c.next) await page.evaluate((n) => window.__app.play(n), c.next);
      await animate(page, 3);
      const gcs2Full = await shot(page, { ground: true, character: true });
      const gcs2Sil = await shot(page, { ground: false, character: true });
      await page.evaluate(() => window.__app.rebuild('dqs'));
      expect(await page.evaluate(() => window.__app.method())).toBe('dqs');
      const dqsSil = await shot(page, { ground: false, character: true });
      await animate(page, 3);
      await page.evaluate(() => window.__app.rebuild('gcs'));
      expect(await page.evaluate(() => window.__app.method())).toBe('gcs');
      const regcsFull = await shot(page, { ground: true, character: true });
      await animate(page, 3);
      await page.evaluate(() => window.__app.dispose());
      expect(await page.evaluate(() => window.__app.deformedMeshes())).toBe(0);
      const disposedFull = await shot(page, { ground: true, character: true });
      await animate(page, 3);
      await gcsPage.close();
      lap('gcs lifecycle');

      // The README's WebGPURenderer example (its WebGL2 backend here): GCS in the vertex stage.
      const gpuPage = await open(context, `${url}webgpu.html?${clip}`, model);
      lap('open webgpu');
      expect(await gpuPage.page.evaluate(() => [window.__app.method(), window.__app.backend()])).toEqual(['gcs', 'gpu']);
      const webgpuSil = await shot(gpuPage.page, { ground: false, character: true });
      await gpuPage.close();
      lap('webgpu shots');

      const m = {
        silhouetteArea: await area(lab, ref.sil),
        lbsFullDiff: await diff(lab, lbsFull, ref.full),
        lbsExact: await exact(lab, lbsFull, ref.full),
        shadowThree: await shadow(lab, ref.full, ref.empty, ref.sil),
        shadowLbs: await shadow(lab, lbsFull, ref.empty, ref.sil), // the same silhouette: lbsFull equals ref.full
        shadowGcs: await shadow(lab, gcsFull, ref.empty, gcsSil),
        gcsIou: await iou(lab, gcsSil, ref.sil),
        gcsFullDiff: await diff(lab, gcsFull, ref.full),
        gcs2Iou: await iou(lab, gcs2Sil, ref2.sil),
        dqsIou: await iou(lab, dqsSil, ref2.sil),
        regcsDiff: await diff(lab, regcsFull, gcs2Full),
        webgpuIou: await iou(lab, webgpuSil, ref.sil),
        disposedDiff: await diff(lab, disposedFull, ref2.full),
        disposedExact: await exact(lab, disposedFull, ref2.full),
        steps: (lap('measures'), steps),
        errors: [...three.errors, ...lbs.errors, ...gcsPage.errors, ...gpuPage.errors],
        ms: Math.round(performance.now() - t0),
      };
      console.log(`app test ${c.file}: ${JSON.stringify(m)}`);
      if (process.env.APP_TEST_SHOTS) { // keep the pictures to look at
        mkdirSync(process.env.APP_TEST_SHOTS, { recursive: true });
        const shots = { webgpuSil, refFull: ref.full, refSil: ref.sil, refEmpty: ref.empty, ref2Full: ref2.full, lbsFull, gcsFull, gcs2Full, dqsSil, disposedFull };
        for (const [k, v] of Object.entries(shots)) writeFileSync(join(process.env.APP_TEST_SHOTS, `${c.file}-${k}.png`), Buffer.from(v, 'base64'));
      }
      expect(m.errors).toEqual([]);
      expect(m.silhouetteArea).toBeGreaterThan(0.03); // the character is in the picture
      expect(m.lbsFullDiff).toBeLessThanOrEqual(LBS_TOLERANCE);
      expect(m.shadowThree).toBeGreaterThan(SHADOW_MIN);
      expect(m.shadowLbs).toBeGreaterThan(0.9 * m.shadowThree);
      expect(m.shadowGcs).toBeGreaterThan(0.9 * m.shadowThree);
      expect(m.gcsIou).toBeGreaterThan(SILHOUETTE_IOU);
      expect(m.gcs2Iou).toBeGreaterThan(SILHOUETTE_IOU);
      expect(m.dqsIou).toBeGreaterThan(SILHOUETTE_IOU);
      expect(m.webgpuIou).toBeGreaterThan(SILHOUETTE_IOU); // the WebGPURenderer example draws it where three does
      expect(m.regcsDiff).toBeLessThanOrEqual(LBS_TOLERANCE); // the same build again draws the same picture
      expect(m.disposedDiff).toBeLessThanOrEqual(LBS_TOLERANCE); // three's own skinning again
    }, 150000);
  }
});

test("the README's install lines and example are what the app is made of", () => {
  // What the app test takes from README.md: the install lines (library, three, three's types) and
  // an example that loads 'character.glb' and keeps `character` (the hook's one call names it).
  const installs = readmeInstalls();
  expect(installs.flatMap((i) => i.names)).toEqual(expect.arrayContaining([`git+${README_REPOSITORY}`, 'three', '@types/three']));
  const [example] = readmeBlocks(USING, 'ts');
  expect(example).toContain("loadAsync('character.glb')");
  for (const name of ['renderer', 'scene', 'camera', 'gltf', 'mixer', 'character'])
    expect(example, name).toMatch(new RegExp(`^const ${name} = `, 'm'));
  expect(readmeBlocks('# gcs-skin with WebGPURenderer', 'ts', 'docs/webgpu.md')).toHaveLength(1);
});

async function waitForServer(address: string): Promise<void> {
  const t0 = performance.now();
  for (;;) {
    try {
      const r = await fetch(address);
      if (r.ok) return;
    } catch { /* not yet */ }
    if (preview?.exitCode !== null) throw new Error(`vite preview exited (${preview?.exitCode})`);
    if (performance.now() - t0 > 30000) throw new Error(`vite preview did not answer at ${address}`);
    await new Promise((r) => setTimeout(r, 100));
  }
}

interface AppHook {
  frames(): number;
  clips(): string[];
  skinnedMeshes(): number;
  deformedMeshes(): number;
  method(): string;
  backend(): string;
  textured(): boolean;
  play(name: string): void;
  rebuild(method: 'gcs' | 'lbs' | 'dqs' | 'classic'): void;
  dispose(): void;
  show(what: { ground?: boolean; character?: boolean }): void;
  still(stop: boolean): void;
  glError(): number;
}
declare global {
  interface Window { __app: AppHook }
}

/** Console warnings of every page, printed (not asserted). */
const warnings: string[] = [];
/**
 * Opens the app with `model` served as the README's 'character.glb', collects page errors, console
 * errors and WebGL messages, waits until it draws, and checks the page has no scrollbar.
 */
async function open(ctx: BrowserContext, address: string, model: string): Promise<{ page: Page; errors: string[]; close(): Promise<void> }> {
  const page = await ctx.newPage();
  await page.setViewportSize({ width: WIDTH, height: HEIGHT });
  await page.route('**/character.glb', (route) => route.fulfill({ path: model, contentType: 'model/gltf-binary' }));
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(`pageerror: ${e.message}`));
  page.on('response', (r) => { if (r.status() >= 400) errors.push(`HTTP ${r.status()} ${r.url()}`); });
  page.on('console', (msg) => {
    const text = msg.text();
    if (msg.type() === 'error' || /GL_INVALID|GL ERROR|WebGL: |THREE\.WebGL/i.test(text)) errors.push(`console.${msg.type()}: ${text}`);
    else if (msg.type() === 'warning') warnings.push(text);
  });
  await page.goto(address);
  await page.waitForFunction(() => document.title === 'ready' && window.__app?.frames() >= 2, undefined, { timeout: 60000, polling: 100 })
    .catch((e) => { throw new Error(`${address} did not draw: ${errors.join('; ') || (e as Error).message}`); });
  // The canvas fills the window exactly: no scrollbar, no margin (the README's own style lines).
  const layout = await page.evaluate(() => {
    const canvas = document.querySelector('canvas')!.getBoundingClientRect();
    const root = document.documentElement;
    return { scrollW: root.scrollWidth, scrollH: root.scrollHeight, x: canvas.left, y: canvas.top, w: canvas.width, h: canvas.height };
  });
  expect(layout, address).toEqual({ scrollW: WIDTH, scrollH: HEIGHT, x: 0, y: 0, w: WIDTH, h: HEIGHT });
  return {
    page,
    errors,
    close: async () => {
      const gl = await page.evaluate(() => window.__app.glError());
      if (gl !== 0) errors.push(`gl.getError() = 0x${gl.toString(16)}`);
      await page.close();
    },
  };
}

/** Lets the README's loop run `n` frames (the pose is fixed: the same picture each time). */
async function animate(page: Page, n: number): Promise<void> {
  const f = await page.evaluate(() => { window.__app.still(false); return window.__app.frames(); });
  await page.waitForFunction((k) => window.__app.frames() >= k, f + n, { timeout: 30000, polling: 50 });
}

const shotMs: number[] = [];
/** Shows or hides the ground and the character, lets a frame draw, and screenshots the page. */
async function shot(page: Page, what: { ground: boolean; character: boolean }): Promise<string> {
  const f = await page.evaluate((w) => { window.__app.show(w); window.__app.still(true); return window.__app.frames(); }, what);
  await page.waitForFunction((n) => window.__app.frames() >= n, f + 1, { timeout: 30000, polling: 50 });
  const gl = await page.evaluate(() => window.__app.glError());
  if (gl !== 0) throw new Error(`gl.getError() = 0x${gl.toString(16)}`);
  const t = performance.now();
  const png = (await page.screenshot({ type: 'png' })).toString('base64');
  shotMs.push(Math.round(performance.now() - t));
  return png;
}

/**
 * Pixel measures, run in a blank page of the same browser (decoded by the harness's measurePixels).
 * Silhouettes come from pictures without the ground: a pixel is the character's when it differs
 * from the background (the top-left pixel) by more than 40 in some channel.
 */
async function measure(page: Page, kind: 'diff' | 'anydiff' | 'maxdiff' | 'iou' | 'shadow' | 'area', images: string[]): Promise<number> {
  return measurePixels(page, images, (imgs, { kind, threshold }) => {
    const n = imgs[0].width * imgs[0].height;
    const mask = (img: ImageData) => {
      const d = img.data, out = new Uint8Array(n);
      for (let i = 0; i < n; i++)
        out[i] = Math.max(Math.abs(d[4 * i] - d[0]), Math.abs(d[4 * i + 1] - d[1]), Math.abs(d[4 * i + 2] - d[2])) > 40 ? 1 : 0;
      return out;
    };
    const lum = (d: Uint8ClampedArray, i: number) => 0.2126 * d[4 * i] + 0.7152 * d[4 * i + 1] + 0.0722 * d[4 * i + 2];
    if (kind === 'diff' || kind === 'anydiff' || kind === 'maxdiff') {
      const [a, b] = imgs;
      let over = 0, any = 0, max = 0;
      for (let i = 0; i < n; i++) {
        const d = Math.max(Math.abs(a.data[4 * i] - b.data[4 * i]), Math.abs(a.data[4 * i + 1] - b.data[4 * i + 1]), Math.abs(a.data[4 * i + 2] - b.data[4 * i + 2]));
        if (d > threshold) over++;
        if (d > 0) any++;
        if (d > max) max = d;
      }
      return kind === 'diff' ? over / n : kind === 'anydiff' ? any / n : max;
    }
    if (kind === 'area') {
      const m = mask(imgs[0]);
      let k = 0;
      for (let i = 0; i < n; i++) k += m[i];
      return k / n;
    }
    if (kind === 'iou') {
      const a = mask(imgs[0]), b = mask(imgs[1]);
      let inter = 0, union = 0;
      for (let i = 0; i < n; i++) { inter += a[i] & b[i]; union += a[i] | b[i]; }
      return union ? inter / union : 0;
    }
    // shadow: [full, empty (no character), silhouette]: darker ground pixels outside the character, per silhouette pixel.
    const [full, empty, sil] = imgs;
    const m = mask(sil);
    let dark = 0, area = 0;
    for (let i = 0; i < n; i++) {
      area += m[i];
      if (!m[i] && lum(empty.data, i) - lum(full.data, i) > 20) dark++;
    }
    return area ? dark / area : 0;
  }, { kind, threshold: DIFF_THRESHOLD });
}
const diff = (p: Page, a: string, b: string) => measure(p, 'diff', [a, b]);
/** For the record: share of pixels that differ at all, and the largest channel difference. */
const exact = async (p: Page, a: string, b: string) => ({ any: await measure(p, 'anydiff', [a, b]), max: await measure(p, 'maxdiff', [a, b]) });
const iou = (p: Page, a: string, b: string) => measure(p, 'iou', [a, b]);
const area = (p: Page, a: string) => measure(p, 'area', [a]);
const shadow = (p: Page, full: string, empty: string, sil: string) => measure(p, 'shadow', [full, empty, sil]);
