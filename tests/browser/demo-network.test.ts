// The demo page talks to its own origin only (issue 28), in headless Chromium: ?model= values on
// another origin, a ?model= or dropped glTF whose buffers or images lead to another origin, are
// refused in one sentence with a code and no request leaves for that origin. Run twice: with the
// page's Content-Security-Policy bypassed (the page's own checks alone hold), and with it (the
// second wall: a request the page's code would make anyway is blocked). A valid data: glTF in
// ?model= loads. The other origin is routed by the test, so any request to it is seen, never sent.
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { splitGlb, type Json } from '../helpers/glb.js';
import { launchChromium, openDemoPage, skipReason, startDemo, type DemoServer } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

const OTHER = 'http://other.test';

describe.skipIf(!!reason)('demo page: no request to another origin (headless Chromium)', () => {
  let server: DemoServer;
  /** With the page's CSP, and with it bypassed. */
  const contexts: Record<'csp' | 'bypassed', BrowserContext> = {} as never;
  /** Requests that reached another origin (any context). */
  const leaks: string[] = [];
  const served = new Map<string, string>();
  let gltf: Json; // the default human as a self-contained .gltf (data: buffer)

  beforeAll(async () => {
    const human = splitGlb(await humanToGlb(createHuman({ vertices: 2000 })));
    gltf = structuredClone(human.json);
    gltf.buffers[0].uri = `data:application/octet-stream;base64,${Buffer.from(human.bin).toString('base64')}`;
    served.set('remote-buffer.gltf', JSON.stringify(withBuffer(`${OTHER}/human.bin`)));
    served.set('remote-image.gltf', JSON.stringify(withImage(`${OTHER}/skin.png`)));
    served.set('protocol-relative-image.gltf', JSON.stringify(withImage('//other.test/skin.png')));
    [server, contexts.csp, contexts.bypassed] = await Promise.all([startDemo(), launchChromium(), launchChromium({ bypassCSP: true })]);
    for (const context of Object.values(contexts)) {
      await context.route((url) => url.hostname === 'other.test', (route) => {
        leaks.push(route.request().url());
        return route.fulfill({ status: 200, body: 'x' });
      });
      // A page URL whose data: model is longer than the server takes in a request line: its page is fetched without the query.
      await context.route((url) => url.pathname === '/' && url.search.length > 4000, async (route) =>
        route.fulfill({ response: await route.fetch({ url: server.url }) }));
      await context.route(`${server.url}gen/**`, (route) => {
        const body = served.get(new URL(route.request().url()).pathname.replace(/^\/gen\//, ''));
        return body ? route.fulfill({ body, contentType: 'model/gltf+json' }) : route.fulfill({ status: 404 });
      });
    }
  });
  afterAll(async () => {
    for (const context of Object.values(contexts)) await context?.close();
    await server?.close();
  });

  /** The human .gltf with its buffer at `uri`. */
  function withBuffer(uri: string): Json {
    const json = structuredClone(gltf);
    json.buffers[0].uri = uri;
    return json;
  }

  /** The human .gltf with a base colour texture whose image is at `uri`. */
  function withImage(uri: string): Json {
    const json = structuredClone(gltf);
    json.images = [{ uri }];
    json.textures = [{ source: 0 }];
    json.materials[0].pbrMetallicRoughness.baseColorTexture = { index: 0 };
    return json;
  }

  const dataUri = (json: Json) => `data:model/gltf+json;base64,${Buffer.from(JSON.stringify(json)).toString('base64')}`;

  async function open(context: BrowserContext, model: string): Promise<{ page: Page; errors: string[]; message: string }> {
    const { page, errors } = await openDemoPage(context, server, `?vertices=2000&model=${encodeURIComponent(model)}`, { dialogs: true });
    await page.evaluate(() => window.__demo.idle());
    return { page, errors, message: await page.evaluate(() => window.__demo.error()) };
  }

  async function drop(page: Page, files: [string, string][]): Promise<string> {
    return page.evaluate(async (list) => {
      const dt = new DataTransfer();
      for (const [name, text] of list) dt.items.add(new File([text], name));
      window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
      await new Promise((r) => setTimeout(r, 50));
      await window.__demo.idle();
      return window.__demo.error();
    }, files);
  }

  /** One sentence of ours with the code, the default human shown instead, no page error. */
  function expectRefused(message: string, code: string, errors: string[], what: string): void {
    expect(message, what).toMatch(new RegExp(`\\(${code}\\) Showing the default human instead\\.$`));
    expect(message.split('\n'), what).toHaveLength(1);
    expect(message.length, what).toBeLessThanOrEqual(300);
    expect(errors, what).toEqual([]);
  }

  for (const wall of ['bypassed', 'csp'] as const)
    describe(wall === 'csp' ? 'with the page\'s CSP' : 'CSP bypassed: the page\'s own checks', () => {
      test.each([
        ['another origin', `${OTHER}/x.glb`, 'OUTSIDE_FOLDER', /on another site \(http:\/\/other\.test\)/],
        ['//host', '//other.test/x.glb', 'OUTSIDE_FOLDER', /on another site/],
        ['javascript:', 'javascript:alert(1)', 'OUTSIDE_FOLDER', /not a path of this site/],
        ['a same-origin .gltf whose buffer is on another origin', 'gen/remote-buffer.gltf', 'OUTSIDE_FOLDER', /buffer 0's uri 'http:\/\/other\.test\/human\.bin' leads to another site/],
        ['a same-origin .gltf whose image is on another origin', 'gen/remote-image.gltf', 'OUTSIDE_FOLDER', /image 0's uri .* leads to another site/],
        ['a same-origin .gltf whose image is at //host', 'gen/protocol-relative-image.gltf', 'OUTSIDE_FOLDER', /image 0's uri .* leads to another site/],
      ])('?model= %s: refused before any request', async (what, model, code, text) => {
        const { page, errors, message } = await open(contexts[wall], model);
        expectRefused(message, code, errors, what);
        expect(message, what).toMatch(text);
        expect(leaks, what).toEqual([]);
        await page.close();
      });

      test('?model=data: a self-contained glTF loads; one whose image is on another origin is refused', async () => {
        let { page, errors, message } = await open(contexts[wall], dataUri(gltf));
        expect(message).toBe('');
        expect(await page.evaluate(() => window.__demo.character())).toMatch(/^data:model\/gltf\+json;base64,.{10,}…$/);
        expect(errors).toEqual([]);
        await page.close();
        ({ page, errors, message } = await open(contexts[wall], dataUri(withImage(`${OTHER}/skin.png`))));
        expectRefused(message, 'OUTSIDE_FOLDER', errors, 'data: glTF, remote image');
        expect(leaks).toEqual([]);
        await page.close();
      });

      test('dropped .gltf files: a remote buffer or image is refused, a missing image named', async () => {
        const { page, errors } = await openDemoPage(contexts[wall], server, '?vertices=2000', { dialogs: true });
        const character = await page.evaluate(() => window.__demo.character());
        const cases: [string, Json, string, RegExp][] = [
          ['remote-buffer.gltf', withBuffer(`${OTHER}/human.bin`), 'OUTSIDE_FOLDER', /is a URL: a dropped file's buffers and images are read only from the files dropped with it/],
          ['remote-image.gltf', withImage(`${OTHER}/skin.png`), 'OUTSIDE_FOLDER', /image 0's uri 'http:\/\/other\.test\/skin\.png' is a URL/],
          ['missing-image.gltf', withImage('skin.png'), 'UNREADABLE', /keeps image 0 in the file 'skin\.png', which was not dropped with it/],
          ['data-image.gltf', withImage('data:image/png;base64,AAAA'), '', /./],
        ];
        for (const [name, json, code, text] of cases) {
          const message = await drop(page, [[name, JSON.stringify(json)]]);
          if (!code) continue; // a broken inline image: whatever three makes of it, never a request
          expect(message, name).toMatch(new RegExp(`^${name}.*\\((${code})\\)$`));
          expect(message, name).toMatch(text);
          expect(await page.evaluate(() => window.__demo.character()), name).toBe(character);
        }
        expect(leaks).toEqual([]);
        expect(errors).toEqual([]);
        await page.close();
      });
    });

  test('the CSP is the second wall: a request the page\'s code makes to another origin is blocked (and, bypassed, seen)', async () => {
    const attempt = (page: Page) => page.evaluate(async (other) => {
      const fetched = await fetch(`${other}/fetch`).then(() => 'sent', () => 'blocked');
      const image = await new Promise<string>((resolve) => {
        const img = new Image();
        img.onload = () => resolve('sent');
        img.onerror = () => resolve('blocked');
        img.src = `${other}/image.png`;
      });
      return { fetched, image };
    }, OTHER);
    const { page, errors } = await openDemoPage(contexts.csp, server, '?vertices=2000');
    const violations: string[] = [];
    page.on('console', (m) => { if (/Content Security Policy/.test(m.text())) violations.push(m.text()); });
    expect(await attempt(page)).toEqual({ fetched: 'blocked', image: 'blocked' });
    expect(leaks).toEqual([]);
    expect(violations.length).toBeGreaterThanOrEqual(2);
    expect(errors).toEqual([]);
    await page.close();
    // The detector works: without the CSP, the same calls reach the routed origin.
    const bypassed = await openDemoPage(contexts.bypassed, server, '?vertices=2000');
    await attempt(bypassed.page);
    expect(leaks.sort()).toEqual([`${OTHER}/fetch`, `${OTHER}/image.png`]);
    leaks.length = 0;
    await bypassed.page.close();
  });
});
