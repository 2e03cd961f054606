// docs/react-three-fiber.md's App.tsx, as a reader copies it: its one tsx block (the component and
// the app around it) written to tests/.tmp/r3f/GcsModel.tsx, compiled with `tsc --strict` (jsx
// react-jsx) beside the test page that uses its component (tests/browser/r3f-fixture), then served
// by Vite and drawn in headless Chromium inside
// <StrictMode>: the character (CesiumMan, ../shared/models) is deformed by GcsCharacter (its
// SkinnedMesh hidden from the camera: layers 0), animated, with no page error; unmounting gives
// the SkinnedMesh back (dispose). The docs page's warning holds too: the same component with the
// character in useMemo ends up disposed by StrictMode's extra cleanup (three's skinning draws).
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import type { ViteDevServer } from 'vite';
import { README_REPOSITORY, readmeBlocks } from '../helpers/readme.js';
import { analyse, launchChromium, MODELS_DIR, ROOT, skipReason } from './harness.js';

declare global {
  interface Window { __r3f: { frames(): number; layerMasks(): number[]; unmount(): void } }
}

const reason = skipReason();
if (reason) console.log(reason);
const model = join(MODELS_DIR, 'CesiumMan.glb');
const noModel = existsSync(model) ? null : `r3f test: ${model} absent`;
if (noModel) console.log(noModel);
const TMP = join(ROOT, 'tests/.tmp/r3f');
const FIXTURE = join(ROOT, 'tests/browser/r3f-fixture');

const PAGE = '# gcs-skin in React Three Fiber';

test('the docs page is one complete App.tsx and the install line it needs', () => {
  const blocks = readmeBlocks(PAGE, 'tsx', 'docs/react-three-fiber.md');
  expect(blocks, 'one tsx block: the whole file').toHaveLength(1);
  const [app] = blocks;
  // Canvas and Suspense imported, GCS_OPTIONS defined before its first use, an App to render.
  expect(app).toMatch(/^import \{[^}]*\bSuspense\b[^}]*\} from 'react';$/m);
  expect(app).toMatch(/^import \{[^}]*\bCanvas\b[^}]*\} from '@react-three\/fiber';$/m);
  expect(app.indexOf('const GCS_OPTIONS')).toBeGreaterThan(-1);
  expect(app.indexOf('const GCS_OPTIONS')).toBeLessThan(app.indexOf('GCS_OPTIONS}'));
  expect(app).toMatch(/^export default function App\(\)/m);
  const [install] = readmeBlocks(PAGE, 'sh', 'docs/react-three-fiber.md');
  expect(install).toContain(`git+${README_REPOSITORY}`);
  expect(install).toMatch(/^npm install .*@react-three\/fiber/m);
});

beforeAll(() => {
  const [component] = readmeBlocks(PAGE, 'tsx', 'docs/react-three-fiber.md');
  mkdirSync(TMP, { recursive: true });
  writeFileSync(join(TMP, 'GcsModel.tsx'), component);
});

test('the docs page component compiles with tsc --strict (and the page that uses it)', () => {
  writeFileSync(join(TMP, 'tsconfig.json'), JSON.stringify({
    compilerOptions: {
      strict: true, noEmit: true, jsx: 'react-jsx', target: 'ES2022', module: 'ESNext', moduleResolution: 'Bundler',
      lib: ['ES2022', 'DOM'], types: [], skipLibCheck: true,
      paths: { 'gcs-skin': [join(ROOT, 'dist/index.d.ts')], 'gcs-skin/three': [join(ROOT, 'dist/three.d.ts')] },
    },
    files: [join(TMP, 'GcsModel.tsx'), join(FIXTURE, 'main.tsx')],
  }));
  const r = spawnSync(process.execPath, [join(ROOT, 'node_modules/typescript/bin/tsc'), '-p', join(TMP, 'tsconfig.json')], { encoding: 'utf8' });
  expect(r.status, r.stdout + r.stderr).toBe(0);
}, 120000);

describe.skipIf(!!reason || !!noModel)('the docs page component in headless Chromium (React 19, @react-three/fiber 9, <StrictMode>)', () => {
  let server: ViteDevServer;
  let context: BrowserContext;
  beforeAll(async () => {
    const vite = await import('vite');
    server = await vite.createServer({
      root: FIXTURE, configFile: false, logLevel: 'error',
      resolve: { alias: [{ find: /^gcs-skin$/, replacement: join(ROOT, 'dist/index.js') }, { find: /^gcs-skin\/three$/, replacement: join(ROOT, 'dist/three.js') }] },
      server: { host: '127.0.0.1', port: 0, fs: { allow: [ROOT] } },
    });
    await server.listen();
    context = await launchChromium();
  }, 120000);
  afterAll(async () => {
    await context?.close();
    await server?.close();
  });

  async function open(query: string): Promise<{ page: Page; errors: string[] }> {
    const page = await context.newPage();
    await page.setViewportSize({ width: 480, height: 480 });
    const errors: string[] = [];
    page.on('pageerror', (e) => errors.push(e.message));
    page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    await page.route('**/character.glb', (route) => route.fulfill({ path: model, contentType: 'model/gltf-binary' }));
    await page.goto(`${server.resolvedUrls!.local[0]}${query}`);
    await page.waitForFunction(() => window.__r3f?.layerMasks().length > 0 && window.__r3f.frames() > 5, null, { timeout: 120000, polling: 100 });
    return { page, errors };
  }
  const region = { x: 0, y: 0, width: 480, height: 480 };

  test('draws the character through GcsCharacter, animated; unmounting gives the SkinnedMesh back', async () => {
    const { page, errors } = await open('');
    try {
      expect(await page.evaluate(() => window.__r3f.layerMasks()), 'GcsCharacter hides the source (layers 0) and draws its own mesh').toEqual([0]);
      const a = await page.screenshot();
      const f = await page.evaluate(() => window.__r3f.frames());
      await page.waitForFunction((n) => window.__r3f.frames() > n + 10, f, { timeout: 60000 });
      const [stats] = await analyse(page, await page.screenshot(), [region], a);
      console.log(`r3f: ${(100 * stats.changed).toFixed(1)} % of pixels changed over 10 frames, ${stats.colours} colours`);
      expect(stats.changed, 'the character moves').toBeGreaterThan(0.002);
      expect(stats.colours, 'the character is drawn (textured, lit)').toBeGreaterThan(50);
      await page.evaluate(() => window.__r3f.unmount());
      await page.waitForFunction(() => window.__r3f.layerMasks().every((m) => m !== 0), null, { timeout: 30000 });
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 180000);

  test('a clip name the file lacks is said in a warning naming its clips, and the first clip plays', async () => {
    const warnings: string[] = [];
    const page = await context.newPage();
    page.on('console', (m) => { if (m.type() === 'warning') warnings.push(m.text()); });
    await page.setViewportSize({ width: 480, height: 480 });
    await page.route('**/character.glb', (route) => route.fulfill({ path: model, contentType: 'model/gltf-binary' }));
    try {
      await page.goto(`${server.resolvedUrls!.local[0]}?clip=Walk`);
      await page.waitForFunction(() => window.__r3f?.layerMasks().length > 0 && window.__r3f.frames() > 5, null, { timeout: 120000, polling: 100 });
      const said = warnings.filter((w) => w.includes('no clip named "Walk"'));
      console.log(`r3f, clip="Walk" on CesiumMan: ${said[0]}`);
      expect(said.length).toBeGreaterThan(0);
      expect(said[0]).toMatch(/its clips: "/);
      const a = await page.screenshot();
      const f = await page.evaluate(() => window.__r3f.frames());
      await page.waitForFunction((n) => window.__r3f.frames() > n + 10, f, { timeout: 60000 });
      const [stats] = await analyse(page, await page.screenshot(), [region], a);
      expect(stats.changed, 'the first clip plays').toBeGreaterThan(0.002);
    } finally {
      await page.close();
    }
  }, 180000);

  test("the docs page's warning: in useMemo, StrictMode's extra cleanup disposes the character", async () => {
    const { page, errors } = await open('?variant=memo');
    try {
      const f = await page.evaluate(() => window.__r3f.frames());
      await page.waitForFunction((n) => window.__r3f.frames() > n + 5, f, { timeout: 60000 });
      expect(await page.evaluate(() => window.__r3f.layerMasks()), 'disposed: the source SkinnedMesh is back').toEqual([1]);
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 180000);
});
