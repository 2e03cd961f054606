// Shared by the browser tests: build and serve the demo, launch headless Chromium, read pixels.
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { createServer as createNetServer } from 'node:net';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import type { BrowserContext, Page } from 'playwright-core';
import type { ViteDevServer } from 'vite';
import { afterAll, beforeAll } from 'vitest';

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
export const MODELS_DIR = resolve(ROOT, '../shared/models');
export const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';

/** Why the browser tests cannot run here, or null when they can. */
export function skipReason(): string | null {
  return existsSync(CHROMIUM) ? null : `browser tests skipped: no Chromium at ${CHROMIUM} (apt-get install chromium, or set CHROMIUM=/path)`;
}

/** A TCP port free on 127.0.0.1 now. */
export async function freePort(): Promise<number> {
  return new Promise((resolvePort, reject) => {
    const srv = createNetServer();
    srv.once('error', reject);
    srv.listen(0, '127.0.0.1', () => {
      const { port } = srv.address() as { port: number };
      srv.close(() => resolvePort(port));
    });
  });
}

export interface DemoServer {
  url: string;
  /** ms from start until the page can be served */
  startMs: number;
  close(): Promise<void>;
}

/**
 * Serves the demo. 'preview' (default): `vite build` into a temp dir + `vite preview`, i.e. the
 * page as it ships; 'dev': the dev server (DEMO_SERVER=dev). Measured on this machine (2 cores):
 * preview serves after ~1.5 s and the page is walking after ~4.2 s; dev serves after ~0.5 s and
 * is walking after ~3.9 s; whole suite ~33 s either way. Preview wins on testing the real build.
 */
export async function startDemo(mode = process.env.DEMO_SERVER === 'dev' ? 'dev' : 'preview'): Promise<DemoServer> {
  const t0 = performance.now();
  const vite = await import('vite');
  const configFile = join(ROOT, 'web/demo/vite.config.ts');
  const port = await freePort();
  if (mode === 'dev') {
    const server = await vite.createServer({ configFile, logLevel: 'error', server: { host: '127.0.0.1', port, strictPort: true } });
    await server.listen();
    return { url: `http://127.0.0.1:${port}/`, startMs: performance.now() - t0, close: () => server.close() };
  }
  const outDir = mkdtempSync(join(tmpdir(), 'gcs-demo-build-'));
  await vite.build({ configFile, logLevel: 'error', build: { outDir, emptyOutDir: true } });
  const server = await vite.preview({ configFile, logLevel: 'error', build: { outDir }, preview: { host: '127.0.0.1', port, strictPort: true } });
  return {
    url: `http://127.0.0.1:${port}/`,
    startMs: performance.now() - t0,
    close: async () => {
      await new Promise<void>((r) => server.httpServer.close(() => r()));
      rmSync(outDir, { recursive: true, force: true });
    },
  };
}

/** Headless Chromium; `bypassCSP` ignores the pages' Content-Security-Policy (to test what the page's own code does without it). */
export async function launchChromium(options: { bypassCSP?: boolean } = {}): Promise<BrowserContext> {
  const { chromium } = await import('playwright-core');
  return chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'gcs-chromium-')), {
    executablePath: CHROMIUM,
    headless: true,
    bypassCSP: options.bypassCSP ?? false,
    viewport: { width: 1280, height: 720 },
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

/**
 * A new page of the served demo at `query`, its page errors collected (and, with `dialogs`, any
 * dialog recorded as an error and dismissed), once the demo's hook exists and its first build is ready.
 */
export async function openDemoPage(context: BrowserContext, server: DemoServer, query: string, options: { dialogs?: boolean } = {}): Promise<{ page: Page; errors: string[] }> {
  const page = await context.newPage();
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  if (options.dialogs) page.on('dialog', (d) => { errors.push(`dialog: ${d.message()}`); void d.dismiss(); });
  await page.goto(`${server.url}${query}`);
  await page.waitForFunction(() => (window as unknown as { __demo?: unknown }).__demo !== undefined);
  await page.evaluate(() => (window as unknown as { __demo: { ready: Promise<unknown> } }).__demo.ready);
  return { page, errors };
}

/** The served demo and a headless Chromium for a describe block's tests: started before them, closed after. */
export interface DemoInChromium {
  server: DemoServer;
  context: BrowserContext;
  /** openDemoPage on this server and browser. */
  open(query: string, options?: { dialogs?: boolean }): Promise<{ page: Page; errors: string[] }>;
}

/** Call in a describe block: the demo and Chromium start in its beforeAll and close in its afterAll. */
export function demoInChromium(): DemoInChromium {
  const demo = { open: (query, options) => openDemoPage(demo.context, demo.server, query, options) } as DemoInChromium;
  beforeAll(async () => {
    [demo.server, demo.context] = await Promise.all([startDemo(), launchChromium()]);
  });
  afterAll(async () => {
    await demo.context?.close();
    await demo.server?.close();
  });
  return demo;
}

/** Waits until the demo has drawn `n` more frames. */
export async function frames(page: Page, n: number): Promise<void> {
  const f = await page.evaluate(() => window.__demo.frame());
  await page.waitForFunction((target) => window.__demo.frame() >= target, f + n, { timeout: 60000 });
}

/** A fixture page (tests/browser/<folder>/index.html) served by Vite's dev server and open in Chromium. */
export interface FixturePage {
  page: Page;
  /** Page errors and console errors, as they come. */
  errors: string[];
  close(): Promise<void>;
}

/** Serves tests/browser/`folder` (the shared models readable through /@fs) and opens it; resolves once `window[hook]` exists. */
export async function openFixture(folder: string, hook: string): Promise<FixturePage> {
  const vite = await import('vite');
  const server: ViteDevServer = await vite.createServer({
    root: join(ROOT, 'tests/browser', folder),
    configFile: false,
    logLevel: 'error',
    server: { host: '127.0.0.1', port: 0, fs: { allow: [ROOT, MODELS_DIR] } },
  });
  await server.listen();
  const context = await launchChromium();
  const page = await context.newPage();
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(server.resolvedUrls!.local[0]);
  await page.waitForFunction((h) => (window as unknown as Record<string, unknown>)[h] !== undefined, hook, { timeout: 120000 });
  return { page, errors, close: async () => { await context.close(); await server.close(); } };
}

/** A fixture's page for a test file's tests: opened (openFixture) in beforeAll unless `skip`, closed in afterAll. */
export function fixtureForTests(folder: string, hook: string, skip: boolean): { page: Page; errors: string[] } {
  const shared = { errors: [] as string[] } as { page: Page; errors: string[] };
  let fixture: FixturePage | null = null;
  beforeAll(async () => {
    if (skip) return;
    fixture = await openFixture(folder, hook);
    ({ page: shared.page, errors: shared.errors } = fixture);
  });
  afterAll(async () => {
    await fixture?.close();
  });
  return shared;
}

export interface Rect { x: number; y: number; width: number; height: number }
export interface RegionStats {
  /** distinct colours, quantised to 5 bits a channel */
  colours: number;
  /** share of pixels that look like skin (red well above blue), as the default material is */
  skin: number;
  /** share of pixels that differ (any channel by > 24) from the same pixel of `before` */
  changed: number;
}

/** A PNG (base64) decoded inside the page: createImageBitmap + OffscreenCanvas, no npm PNG package. */
async function decodePng(b64: string): Promise<ImageData> {
  const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
  const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
  const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
  const ctx = canvas.getContext('2d')!;
  ctx.drawImage(bitmap, 0, 0);
  return ctx.getImageData(0, 0, bitmap.width, bitmap.height);
}

/**
 * Runs `measure` inside the page on the PNGs (base64) decoded there: the one decoder of every
 * browser test's pixel measures. Like page.evaluate's function, `measure` sees only its arguments.
 */
export function measurePixels<A, R>(page: Page, pngs: string[], measure: (images: ImageData[], arg: A) => R | Promise<R>, arg: A): Promise<R> {
  // An expression (page.evaluate calls no function given as a string), its input written into it as JSON.
  return page.evaluate<R>(`(async ({ pngs, arg }) => (${measure})(await Promise.all(pngs.map(${decodePng})), arg))(${JSON.stringify({ pngs, arg })})`);
}

/** Measures regions of a PNG screenshot (and, with `before`, what changed from that one). */
export async function analyse(page: Page, png: Buffer, regions: Rect[], before?: Buffer): Promise<RegionStats[]> {
  const pngs = before ? [png, before] : [png];
  return measurePixels(page, pngs.map((p) => p.toString('base64')), ([a, b], regions) => regions.map((r) => {
    const colours = new Set<number>();
    let skin = 0, changed = 0, total = 0;
    for (let y = Math.max(0, r.y); y < Math.min(a.height, r.y + r.height); y++) {
      for (let x = Math.max(0, r.x); x < Math.min(a.width, r.x + r.width); x++) {
        const i = 4 * (y * a.width + x);
        const R = a.data[i], G = a.data[i + 1], B = a.data[i + 2];
        colours.add(((R >> 3) << 10) | ((G >> 3) << 5) | (B >> 3));
        if (R > 110 && R - B > 40) skin++;
        if (b && (Math.abs(R - b.data[i]) > 24 || Math.abs(G - b.data[i + 1]) > 24 || Math.abs(B - b.data[i + 2]) > 24)) changed++;
        total++;
      }
    }
    return { colours: colours.size, skin: skin / Math.max(1, total), changed: changed / Math.max(1, total) };
  }), regions);
}

export { existsSync };

/** The demo's testing hook (web/demo/main.ts, window.__demo). */
export interface DemoHook {
  ready: Promise<void>;
  frame(): number;
  busy(): boolean;
  error(): string;
  character(): string;
  /** The character menu's value: 'human', 'fox', 'cesiumman', 'robot' or 'file'. */
  model(): string;
  /** The attribution line on the page ('' when hidden). */
  credit(): string;
  parts(): {
    skinned: number; rigid: number; gcs: number; classic: number;
    ownMaterials: { gcs: boolean; classic: boolean };
    textured: { gcs: boolean; classic: boolean };
  };
  sectionCount(): number;
  sectionsPerPart(): number;
  setSections(n: number): void;
  criterion(): string;
  gcsBuilds(): number;
  lookAt(eye: [number, number, number], target: [number, number, number]): void;
  classicError(): string | null;
  rigidParts(): string[];
  readouts(): unknown;
  views(): { kind: string; x: number; width: number }[];
  time(): number;
  clip(): string;
  classicBuilds(): number;
  pause(t?: number): void;
  hideCharacter(hidden: boolean): void;
  /** The rest pose (true: the clip stopped), or back on the clip at its start (false). */
  restPose(rest: boolean): void;
  idle(): Promise<void>;
}

/** The crowd mode's figures over some frames (web/demo/crowd.ts). */
export interface CrowdMeasure { renderer: string; characters: number; backend: string; path: string | null; joints: number; msPerFrame: number; bytesPerFrame: number; msPerCharacter: number; bytesPerCharacter: number; vertices: number; sections: number }
/** The crowd mode's testing hook (web/demo/crowd.ts, window.__crowd). */
export interface CrowdHook {
  frame(): number; count(): number; backend(): string; drawn(): number; drawCalls(): number; readout(): string;
  set(n: number, backend?: string, path?: string): void; measure(frames: number): Promise<CrowdMeasure>; pause(t?: number): void;
  /** The characters' extent on the page (px). */
  screenBounds(): { left: number; right: number; top: number; bottom: number };
}
declare global {
  interface Window { __demo: DemoHook; __crowd: CrowdHook }
}
