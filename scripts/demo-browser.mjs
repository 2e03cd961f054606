// The built demo served by `vite preview` and a headless Chromium (SwiftShader) to photograph it:
// what scripts/screenshot-demo.mjs, screenshot-classic.mjs and screenshot-joints.mjs share.
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { build, preview } from 'vite';
import { chromium } from 'playwright-core';

export const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');

/**
 * Builds and serves the demo and starts Chromium with a `width × height` viewport (exits with a
 * message naming `tool` when Chromium is absent). Returns the page URL, the browser context and
 * close(), which stops both and removes the build.
 */
export async function openDemo(tool, width, height) {
  const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
  if (!existsSync(chromiumPath)) {
    console.error(`${tool}: ${chromiumPath} not found (set CHROMIUM=/path/to/chromium)`);
    process.exit(1);
  }
  const configFile = join(root, 'web/demo/vite.config.ts');
  const dist = mkdtempSync(join(tmpdir(), 'gcs-demo-'));
  await build({ configFile, logLevel: 'error', build: { outDir: dist, emptyOutDir: true } });
  const server = await preview({ configFile, logLevel: 'error', build: { outDir: dist }, preview: { host: '127.0.0.1', port: 0 } });
  const context = await chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'gcs-chromium-')), {
    executablePath: chromiumPath,
    headless: true,
    viewport: { width, height },
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  return {
    url: server.resolvedUrls.local[0],
    context,
    close: async () => {
      await context.close();
      await server.close();
      rmSync(dist, { recursive: true, force: true });
    },
  };
}

/** The value after `name` on the command line, or `fallback`. */
export function option(name, fallback) {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : fallback;
}

/** Collects `page`'s errors; the function returned throws, naming `what`, once there are any. */
export function watchErrors(page) {
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  return (what) => {
    if (errors.length) throw new Error(`${what}: page errors: ${errors.join('; ')}`);
  };
}

/**
 * Opens the demo at `address` in `page` and waits for its first build (with `idle`, until its builds
 * have settled too); throws, naming `what`, when the page shows a message.
 */
export async function loadDemo(page, address, what, { idle = false } = {}) {
  await page.goto(address);
  await page.waitForFunction(() => window.__demo !== undefined);
  await page.evaluate(() => window.__demo.ready);
  if (idle) await page.evaluate(() => window.__demo.idle());
  const message = await page.evaluate(() => window.__demo.error());
  if (message) throw new Error(`${what}: the page says: ${message}`);
}
