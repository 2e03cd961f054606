// Compressed glTF in the demo page, in headless Chromium (issue 29): a Draco, a meshopt and a KTX2
// (Basis Universal) copy of the default human, made here with @gltf-transform
// (tests/helpers/compressed-gltf.ts), each opened by drop and by ?model= (a path of the page's own
// site, served by the test), must load and animate with no page error, their decoders fetched
// from the page's own decoders/ folder and no request leaving for another origin.
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { splitGlb } from '../helpers/glb.js';
import { compressDocument, compressGlb, compressionIO, type Compression } from '../helpers/compressed-gltf.js';
import { launchChromium, openDemoPage, skipReason, startDemo, type DemoServer } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

const KINDS: [Compression, string][] = [['draco', 'KHR_draco_mesh_compression'], ['meshopt', 'EXT_meshopt_compression'], ['ktx2', 'KHR_texture_basisu']];

describe.skipIf(!!reason)('demo page: compressed glTF (headless Chromium)', () => {
  let server: DemoServer;
  let context: BrowserContext;
  /** Files the test serves on the page's own site, under gen/. */
  const served = new Map<string, Uint8Array>();

  beforeAll(async () => {
    const human = await humanToGlb(createHuman({ vertices: 2000 }));
    for (const [kind, extension] of KINDS) {
      const glb = await compressGlb(human, kind);
      expect(splitGlb(glb).json.extensionsRequired, kind).toContain(extension);
      served.set(`${kind}.glb`, glb);
    }
    // The KTX2 copy as a .gltf with its buffer and texture in files of their own, beside it.
    const io = await compressionIO();
    const doc = await io.readBinary(human);
    await compressDocument(doc, 'ktx2');
    const { json, resources } = await io.writeJSON(doc);
    for (const [uri, bytes] of Object.entries(resources)) served.set(uri, bytes);
    served.set('ktx2.gltf', new TextEncoder().encode(JSON.stringify(json)));
    [server, context] = await Promise.all([startDemo(), launchChromium()]);
  });
  afterAll(async () => {
    await context?.close();
    await server?.close();
  });

  /** A page at `query` with the generated files served under gen/, every request it makes recorded. */
  async function open(query: string): Promise<{ page: Page; errors: string[]; requests: string[] }> {
    const requests: string[] = [];
    context.on('request', (r) => requests.push(r.url()));
    await context.route(`${server.url}gen/**`, (route) => {
      const bytes = served.get(decodeURIComponent(new URL(route.request().url()).pathname.replace(/^\/gen\//, '')));
      return bytes ? route.fulfill({ body: Buffer.from(bytes), contentType: 'application/octet-stream' }) : route.fulfill({ status: 404 });
    });
    const { page, errors } = await openDemoPage(context, server, query, { dialogs: true });
    page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
    await page.evaluate(() => window.__demo.idle());
    return { page, errors, requests };
  }

  async function close(page: Page): Promise<void> {
    await page.close();
    context.removeAllListeners('request');
    await context.unrouteAll();
  }

  /** The page shows `name`, no message, and its clip runs: time advances and frames are drawn. */
  async function expectAnimating(page: Page, name: string): Promise<void> {
    expect(await page.evaluate(() => window.__demo.error()), name).toBe('');
    expect(await page.evaluate(() => window.__demo.character()), name).toBe(name);
    const [t0, f0] = await page.evaluate(() => [window.__demo.time(), window.__demo.frame()]);
    await page.waitForFunction((f) => window.__demo.frame() >= f + 5, f0, { timeout: 60000 });
    expect(await page.evaluate(() => window.__demo.time()), name).toBeGreaterThan(t0);
    expect(await page.evaluate(() => window.__demo.parts().gcs), name).toBeGreaterThan(0);
  }

  /** Every request went to the page's own origin (or stayed in the page: data:, blob:). */
  function expectOwnOrigin(requests: string[]): void {
    const origin = new URL(server.url).origin;
    expect(requests.filter((u) => !u.startsWith(`${origin}/`) && !/^(data|blob):/.test(u))).toEqual([]);
  }

  async function drop(page: Page, files: [string, Uint8Array][]): Promise<void> {
    await page.evaluate(async (list) => {
      const dt = new DataTransfer();
      for (const [name, b64] of list) dt.items.add(new File([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], name));
      window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
      await new Promise((r) => setTimeout(r, 50));
      await window.__demo.idle();
    }, files.map(([name, bytes]) => [name, Buffer.from(bytes).toString('base64')] as [string, string]));
  }

  /**
   * The decoder files a kind needs, fetched from the page's own origin: Draco's from its decoders/
   * folder, Basis's as the build emits three's KTX2Loader's own (assets/, a hash in the name).
   */
  const DECODERS: Record<string, RegExp[]> = {
    draco: [/\/decoders\/draco\/draco_wasm_wrapper\.js$/, /\/decoders\/draco\/draco_decoder\.wasm$/],
    ktx2: [/\/assets\/basis_transcoder-[\w-]+\.js$/, /\/assets\/basis_transcoder-[\w-]+\.wasm$/],
  };

  /** The files a test drops for `file`: a .glb alone, a .gltf with every file it names. */
  const dropped = (file: string): [string, Uint8Array][] =>
    [...served].filter(([name]) => name === file || (file.endsWith('.gltf') && !/\.gl(b|tf)$/.test(name)))
      .map(([name, bytes]) => [name === file ? `dropped-${name}` : name, bytes]);

  for (const file of ['draco.glb', 'meshopt.glb', 'ktx2.glb', 'ktx2.gltf'])
    test(`${file}: by ?model= (this site) and dropped, it loads and animates; decoders from the page's own folder`, async () => {
      const { page, errors, requests } = await open(`?model=gen/${file}`);
      await expectAnimating(page, file);
      await drop(page, dropped(file));
      await expectAnimating(page, `dropped-${file}`);
      const kind = file.replace(/\..*/, '');
      if (kind === 'ktx2') expect(await page.evaluate(() => window.__demo.parts().textured.gcs), 'the KTX2 texture is on').toBe(true);
      const own = new URL(server.url).origin;
      for (const decoder of DECODERS[kind] ?? [])
        expect(requests.filter((r) => r.startsWith(own) && decoder.test(r)), String(decoder)).not.toHaveLength(0);
      expectOwnOrigin(requests);
      expect(errors).toEqual([]);
      await close(page);
    });
});
