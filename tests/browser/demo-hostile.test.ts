// The demo page against hostile input, in headless Chromium: markup in ?clip=, ?model=, a dropped
// file's name and a glTF's animation name reaches the page as text (lil-gui writes its option
// labels with innerHTML: an <img onerror> there would run), and broken or crafted files are
// refused by the same validation as the CLI, in one sentence ending with its code.
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { compressGlb } from '../helpers/compressed-gltf.js';
import { packGlb, splitGlb, type Json } from '../helpers/glb.js';
import { launchChromium, openDemoPage, skipReason, startDemo, type DemoServer } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

/** Markup that, run, counts itself in window.__pwned. */
const markup = (tag: string) => `<img src=x-${tag} onerror="window.__pwned=(window.__pwned||0)+1">`;

declare global { interface Window { __pwned?: number } }

describe.skipIf(!!reason)('demo page: hostile names and files (headless Chromium)', () => {
  let server: DemoServer;
  let context: BrowserContext;
  let human: { json: Json; bin: Uint8Array };
  /** The same human compressed: Draco (edgebreaker and sequential) and meshopt. */
  const compressed: Record<string, { json: Json; bin: Uint8Array }> = {};

  beforeAll(async () => {
    const glb = await humanToGlb(createHuman({ vertices: 2000 }));
    for (const how of ['draco', 'draco-sequential', 'meshopt'] as const) compressed[how] = splitGlb(await compressGlb(glb, how));
    [server, context] = await Promise.all([startDemo(), launchChromium()]);
    human = splitGlb(glb);
  });
  afterAll(async () => {
    await context?.close();
    await server?.close();
  });

  /** A page at `query`, ready and idle, with its page errors collected. */
  async function open(query: string): Promise<{ page: Page; errors: string[] }> {
    const { page, errors } = await openDemoPage(context, server, query, { dialogs: true });
    await page.evaluate(() => window.__demo.idle());
    return { page, errors };
  }

  /** Nothing ran, and no element was made from the markup anywhere in the page. */
  async function expectInert(page: Page, errors: string[]): Promise<void> {
    await page.waitForTimeout(300); // an injected image's error event would have fired by now
    expect(await page.evaluate(() => window.__pwned)).toBeUndefined();
    expect(await page.evaluate(() => document.querySelectorAll('img[onerror], [onerror]').length)).toBe(0);
    expect(errors).toEqual([]);
  }

  /** The options of a lil-gui menu, as the page shows them. */
  const menu = (page: Page, name: string) =>
    page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: new RegExp(`^${name}$`) }) })
      .locator('select').evaluate((el: HTMLSelectElement) => Array.from(el.options).map((o) => o.text));

  /** Drops a file on the page as a user would. */
  async function drop(page: Page, name: string, bytes: Uint8Array): Promise<void> {
    await page.evaluate(async ({ name, b64 }) => {
      const dt = new DataTransfer();
      dt.items.add(new File([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], name));
      window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
      await new Promise((r) => setTimeout(r, 50));
      await window.__demo.idle();
    }, { name, b64: Buffer.from(bytes).toString('base64') });
  }

  /** The default human (or a compressed copy of it) as .glb, its JSON changed by `edit`. */
  function humanGlb(edit: (json: Json, bin: DataView) => void = () => {}, source = human): Uint8Array {
    const json = structuredClone(source.json);
    const bin = source.bin.slice();
    edit(json, new DataView(bin.buffer));
    return packGlb(json, bin);
  }

  /** Every attribute of mesh 0's primitive 0 declaring `vertices`, its indices `indices` (a Draco primitive's accessors lie). */
  const declare = (vertices: number, indices?: number) => (json: Json) => {
    const p = json.meshes[0].primitives[0];
    for (const a of Object.values(p.attributes) as number[]) json.accessors[a].count = vertices;
    if (indices !== undefined) json.accessors[p.indices].count = indices;
  };

  /** The human with a base colour texture whose image (in a buffer view) is `image`, of `mimeType`. */
  function withImage(image: Uint8Array, mimeType: string): Uint8Array {
    const json = structuredClone(human.json);
    const bin = new Uint8Array(human.bin.length + image.length + 4);
    bin.set(human.bin);
    bin.set(image, human.bin.length);
    json.buffers[0].byteLength = bin.length;
    json.bufferViews.push({ buffer: 0, byteOffset: human.bin.length, byteLength: image.length });
    json.images = [{ bufferView: json.bufferViews.length - 1, mimeType }];
    const ktx2 = mimeType === 'image/ktx2';
    json.textures = [ktx2 ? { extensions: { KHR_texture_basisu: { source: 0 } } } : { source: 0 }];
    if (ktx2) json.extensionsUsed = json.extensionsRequired = ['KHR_texture_basisu'];
    json.materials[0].pbrMetallicRoughness.baseColorTexture = { index: 0 };
    return packGlb(json, bin);
  }

  /** A PNG's first 33 bytes (signature and IHDR) declaring width × height. */
  function pngHeader(width: number, height: number): Uint8Array {
    const out = new Uint8Array(33);
    out.set([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13, 0x49, 0x48, 0x44, 0x52]);
    const view = new DataView(out.buffer);
    view.setUint32(16, width);
    view.setUint32(20, height);
    out.set([8, 6, 0, 0, 0], 24);
    return out;
  }

  /** A KTX2 header (no data) declaring a Basis (vkFormat 0) texture of width × height. */
  function ktx2Header(width: number, height: number): Uint8Array {
    const out = new Uint8Array(80);
    out.set([0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a]);
    const view = new DataView(out.buffer);
    view.setUint32(20, width, true);
    view.setUint32(24, height, true);
    view.setUint32(36, 1, true); // faces
    view.setUint32(40, 1, true); // levels
    view.setUint32(44, 1, true); // BasisLZ
    return out;
  }

  /**
   * A 66-byte RLE8 BMP declaring width × height (a two-colour palette and an end-of-bitmap code):
   * decoded, 20,000² is 1.6 GB of pixels.
   */
  function rleBmp(width: number, height: number): Uint8Array {
    const out = new Uint8Array(66);
    const view = new DataView(out.buffer);
    out.set([0x42, 0x4d]); // 'BM'
    view.setUint32(2, 66, true);
    view.setUint32(10, 62, true); // pixels after the 14 + 40 byte headers and 8 bytes of palette
    view.setUint32(14, 40, true); // BITMAPINFOHEADER
    view.setInt32(18, width, true);
    view.setInt32(22, height, true);
    view.setUint16(26, 1, true); // planes
    view.setUint16(28, 8, true); // bits per pixel
    view.setUint32(30, 1, true); // BI_RLE8
    view.setUint32(34, 4, true);
    view.setUint32(46, 2, true); // colours used
    out.set([0, 0, 0, 0, 255, 255, 255, 0], 54);
    out.set([0, 0, 0, 1], 62); // end of line, end of bitmap
    return out;
  }

  /** A real size × size RGBA PNG (stored, uncompressed deflate) of one colour. */
  function smallPng(size: number): Uint8Array {
    const crcTable = Array.from({ length: 256 }, (_, n) => { let c = n; for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1; return c >>> 0; });
    const crc = (bytes: Uint8Array) => { let c = 0xffffffff; for (const b of bytes) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8); return (c ^ 0xffffffff) >>> 0; };
    const adler = (bytes: Uint8Array) => { let a = 1, b = 0; for (const x of bytes) { a = (a + x) % 65521; b = (b + a) % 65521; } return ((b << 16) | a) >>> 0; };
    const raw = new Uint8Array(size * (1 + 4 * size));
    for (let y = 0; y < size; y++) for (let x = 0; x < size; x++) raw.set([200, 120, 60, 255], y * (1 + 4 * size) + 1 + 4 * x);
    const z = new Uint8Array(2 + 5 + raw.length + 4);
    z.set([0x78, 0x01, 1, raw.length & 0xff, raw.length >> 8, ~raw.length & 0xff, (~raw.length >> 8) & 0xff]);
    z.set(raw, 7);
    new DataView(z.buffer).setUint32(7 + raw.length, adler(raw));
    const chunk = (type: string, data: Uint8Array) => {
      const out = new Uint8Array(12 + data.length), view = new DataView(out.buffer);
      view.setUint32(0, data.length);
      out.set(new TextEncoder().encode(type), 4);
      out.set(data, 8);
      view.setUint32(8 + data.length, crc(out.subarray(4, 8 + data.length)));
      return out;
    };
    const ihdr = new Uint8Array(13);
    new DataView(ihdr.buffer).setUint32(0, size);
    new DataView(ihdr.buffer).setUint32(4, size);
    ihdr.set([8, 6, 0, 0, 0], 8);
    const parts = [new Uint8Array([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]), chunk('IHDR', ihdr), chunk('IDAT', z), chunk('IEND', new Uint8Array(0))];
    const png = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
    parts.reduce((at, p) => { png.set(p, at); return at + p.length; }, 0);
    return png;
  }

  /** meshopt's human with the middle of every compressed stream overwritten. */
  function brokenMeshopt(json: Json, bin: DataView): void {
    for (const v of json.bufferViews) {
      const m = v.extensions?.EXT_meshopt_compression;
      if (!m || json.buffers[m.buffer].uri !== undefined || m.buffer !== 0) continue;
      for (let k = m.byteOffset + 1; k < m.byteOffset + m.byteLength - 1; k++) bin.setUint8(k, 0xff);
    }
  }

  test('?clip=<img onerror> runs nothing; the clip menu showed it as text', async () => {
    const clip = markup('clip');
    const { page, errors } = await open(`?clip=${encodeURIComponent(clip)}`);
    await expectInert(page, errors);
    expect(await page.evaluate(() => window.__demo.error())).toBe('');
    await page.close();
  });

  test('?model=<img onerror>.glb (a URL that fails) runs nothing: its message is text, the human is shown', async () => {
    const { page, errors } = await open(`?model=${encodeURIComponent(`${markup('model')}.glb`)}`);
    await expectInert(page, errors.filter((e) => !/404|Failed to load/.test(e)));
    const message = await page.evaluate(() => window.__demo.error());
    expect(message).toContain(`${markup('model')}.glb`);
    // A 404, or the preview server's index page served in its place (NOT_GLTF): a code either way.
    expect(message).toMatch(/\((UNREADABLE|NOT_GLTF)\) Showing the default human instead\.$/);
    expect(await page.evaluate(() => window.__demo.character())).toMatch(/Human/);
    await page.close();
  });

  test('a dropped file whose name and animation name are markup loads, shown as text in both menus', async () => {
    const { page, errors } = await open('');
    const clip = markup('animation');
    const file = `${markup('file')}.glb`;
    await drop(page, file, humanGlb((json) => { json.animations[1].name = clip; }));
    expect(await page.evaluate(() => window.__demo.error())).toBe('');
    expect(await page.evaluate(() => window.__demo.character())).toBe(file);
    expect(await menu(page, 'character')).toContain(file);
    expect(await menu(page, 'clip')).toContain(clip);
    // Choosing the markup-named clip plays it (the value is the name as given).
    await page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: /^clip$/ }) }).locator('select').selectOption({ label: clip });
    expect(await page.evaluate(() => window.__demo.clip())).toBe(clip);
    await expectInert(page, errors);
    await page.close();
  });

  test('images by their bytes: one over the budget or mislabelled is skipped before it decodes (drawn untextured, with a note); a real one is drawn', async () => {
    const { page, errors } = await open('');
    const cases: [string, Uint8Array, RegExp][] = [
      ['png-bomb.glb', withImage(pngHeader(60_000, 60_000), 'image/png'), /image 0 is a PNG of 60,000 × 60,000 pixels, past the 16,384 a side this page decodes, so it was skipped/],
      ['bmp-as-png.glb', withImage(rleBmp(20_000, 20_000), 'image/png'), /image 0 is a BMP of 20,000 × 20,000 pixels, past the 16,384 a side this page decodes, so it was skipped/],
      ['bmp-texels.glb', withImage(rleBmp(12_000, 12_000), 'image/png'), /image 0 is a BMP of 12,000 × 12,000 pixels, past the 67,108,864 texels this page decodes/],
      ['ktx2-bomb.glb', withImage(ktx2Header(60_000, 60_000), 'image/ktx2'), /image 0 is a KTX2 of 60,000 × 60,000 pixels/],
      ['unknown-image.glb', withImage(new TextEncoder().encode('not an image at all, whatever it says'), 'image/png'), /image 0 is not an image this page can size/],
    ];
    for (const [name, bytes, note] of cases) {
      const t0 = performance.now();
      await drop(page, name, bytes);
      expect(await page.evaluate(() => window.__demo.character()), name).toBe(name);
      const message = await page.evaluate(() => window.__demo.error());
      expect(message, name).toMatch(note);
      expect(message, name).toMatch(/the character is drawn without those textures\.$/);
      expect((await page.evaluate(() => window.__demo.parts())).textured.gcs, name).toBe(false);
      console.log(`demo skips the image of ${name} (${((performance.now() - t0) / 1000).toFixed(1)} s): ${message}`);
    }
    await drop(page, 'real-png.glb', withImage(smallPng(4), 'image/jpeg')); // mislabelled, but a PNG by its bytes: drawn
    expect(await page.evaluate(() => window.__demo.character())).toBe('real-png.glb');
    expect(await page.evaluate(() => window.__demo.error())).toBe('');
    expect((await page.evaluate(() => window.__demo.parts())).textured.gcs).toBe(true);
    await expectInert(page, errors);
    await page.close();
  }, 600_000);

  test('broken and crafted files: one sentence with the code of the CLI, no engine message, the character stays', async () => {
    const { page, errors } = await open('');
    const character = await page.evaluate(() => window.__demo.character());
    const cases: [string, Uint8Array, string][] = [
      ['not-gltf.glb', new TextEncoder().encode('this is not a glTF file at all'), 'NOT_GLTF'],
      ['truncated.glb', humanGlb().subarray(0, 5000), 'TRUNCATED'],
      ['past-view.glb', humanGlb((json) => { json.accessors[0].count = 100000; }), 'OUT_OF_BOUNDS'],
      ['unknown-ext.glb', humanGlb((json) => { json.extensionsRequired = json.extensionsUsed = ['KHR_hostile']; }), 'UNSUPPORTED'],
      ['huge-count.glb', humanGlb((json) => { json.accessors.push({ componentType: 5125, type: 'SCALAR', count: 2 ** 31 - 1 }); }), 'TOO_LARGE'],
      ['nan-time.glb', humanGlb((json, bin) => {
        const times = json.accessors[json.animations[0].samplers[0].input];
        bin.setFloat32(json.bufferViews[times.bufferView].byteOffset + times.byteOffset, NaN, true);
      }), 'BAD_DATA'],
      ['bad-data-uri.gltf', new TextEncoder().encode(JSON.stringify({ asset: { version: '2.0' }, buffers: [{ byteLength: 4, uri: 'data:application/octet-stream;base64,@@' }] })), 'BAD_URI'],
      ['no-skin.glb', humanGlb((json) => { for (const d of json.nodes) delete d.skin; delete json.skins; }), 'NO_SKINNED_MESH'],
      // Compressed data that lies (issue 28): refused before the decoder, or by the counts it decodes to.
      ['draco-liar.glb', humanGlb(declare(3, 3), compressed.draco), 'BAD_DATA'],
      ['draco-seq-liar.glb', humanGlb(declare(100), compressed['draco-sequential']), 'BAD_DATA'],
      ['draco-seam-liar.glb', humanGlb(declare(100), compressed.draco), 'BAD_DATA'],
      ['meshopt-broken.glb', humanGlb(brokenMeshopt, compressed.meshopt), 'BAD_DATA'],
      ['zero-weights.glb', humanGlb((json, bin) => {
        const w = json.accessors[json.meshes[0].primitives[0].attributes.WEIGHTS_0];
        const view = json.bufferViews[w.bufferView];
        for (let c = 0; c < 4; c++) bin.setFloat32(view.byteOffset + w.byteOffset + 7 * view.byteStride + 4 * c, 0, true);
      }), 'BAD_WEIGHTS'],
    ];
    for (const [name, bytes, code] of cases) {
      const t0 = performance.now();
      await drop(page, name, bytes);
      const message = await page.evaluate(() => window.__demo.error());
      expect(message, name).toContain(name.replace(/\.[^.]+$/, ''));
      expect(message, name).toMatch(new RegExp(`\\(${code}\\)$`));
      expect(message.split(/\n/), name).toHaveLength(1);
      expect(message, name).not.toMatch(/Invalid typed array|DataView|Cannot read properties|Maximum call stack|URIError|URI malformed|Malformed|THREE\./);
      expect(message.length, name).toBeLessThanOrEqual(300);
      expect(await page.evaluate(() => window.__demo.character()), name).toBe(character);
      console.log(`demo refuses ${name} (${((performance.now() - t0) / 1000).toFixed(1)} s): ${message}`);
    }
    await expectInert(page, errors);
    await page.close();
  }, 600_000); // each file built or refused in turn on a software renderer (5–45 s each on a busy host)
});
