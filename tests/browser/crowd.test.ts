// The demo's crowd mode (?crowd=N) in headless Chromium: N characters drawn (GPU backend: one
// instanced mesh, a handful of draw calls; CPU backend: one mesh each), each moving on its own,
// the readouts on the page, the bytes each GPU path uploads (joint poses by default, section
// transforms on request), the backend switch, every control of its GUI, and no page or WebGL error.
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import { analyse, launchChromium, skipReason, startDemo, type DemoServer } from './harness.js';

/** Clicks a lil-gui checkbox by its label. */
async function toggle(page: Page, name: string): Promise<void> {
  await page.locator('.lil-gui .controller.boolean').filter({ has: page.locator('.name', { hasText: new RegExp(`^${name}$`) }) }).locator('input').click();
}

/** A lil-gui menu's select, by its label. */
const menu = (page: Page, name: string) =>
  page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: new RegExp(`^${name}$`) }) }).locator('select');

/** Waits until the readout shows steady figures (it says "warming up" before). */
const steadyReadout = (page: Page) => page.waitForFunction(() => /ms\/frame/.test(window.__crowd.readout()), null, { timeout: 240000, polling: 250 });

/** Software rendering on a loaded machine: a few frames a second, sometimes fewer. */
const slow = { timeout: 120000 };

const reason = skipReason();
if (reason) console.log(reason);

let server: DemoServer | null = null;
let context: BrowserContext | null = null;

beforeAll(async () => {
  if (reason) return;
  server = await startDemo();
  context = await launchChromium();
});
afterAll(async () => {
  await context?.close();
  await server?.close();
});

async function open(query: string, viewport?: { width: number; height: number }): Promise<{ page: Page; errors: string[] }> {
  const page = await context!.newPage();
  if (viewport) await page.setViewportSize(viewport); // software rendering: fewer pixels, a faster test
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(server!.url + query);
  await page.waitForFunction(() => window.__demo !== undefined);
  await page.evaluate(() => window.__demo.ready);
  const message = await page.evaluate(() => window.__demo.error());
  expect(message).toBe('');
  await page.waitForFunction(() => window.__crowd !== undefined && window.__crowd.frame() > 2, null, { timeout: 120000 });
  return { page, errors };
}

describe.skipIf(!!reason)('crowd mode', () => {
  test('?crowd=24 draws 24 walking characters in one instanced draw call, then switches to the CPU backend', async () => {
    const { page, errors } = await open('?crowd=24');
    expect(await page.evaluate(() => window.__crowd.count())).toBe(24);
    expect(await page.evaluate(() => window.__crowd.drawn())).toBe(24);
    expect(await page.evaluate(() => window.__crowd.backend())).toBe('gpu');
    // Ground + the crowd's one instanced mesh (no shadows by default).
    expect(await page.evaluate(() => window.__crowd.drawCalls())).toBeLessThanOrEqual(3);
    const gpu = await page.evaluate(() => window.__crowd.measure(4));
    console.log(`GPU backend (joint poses), 24 characters: ${gpu.msPerFrame.toFixed(3)} ms skinning CPU per frame, ${gpu.bytesPerFrame} bytes uploaded per frame (${gpu.joints} joints, ${gpu.sections} sections)`);
    expect(gpu.path).toBe('joints');
    // The frame uploads the joint poses, compact (a walk is rigid with unit scale): 24 × joints × 24 bytes (+ half a texel of padding), nothing per section or vertex.
    expect(gpu.bytesPerFrame).toBeGreaterThanOrEqual(24 * gpu.joints * 24);
    expect(gpu.bytesPerFrame).toBeLessThanOrEqual(24 * gpu.joints * 24 + 16);
    expect(gpu.bytesPerFrame / 24).toBeLessThanOrEqual(8 * 1024); // the target
    // The first readouts: what runs, and "warming up" (the first frames upload whole buffers) or, once the
    // page has timed a few frames (within 3 s, however slow they are), its figure; steady figures: the GUI's test.
    expect(await page.evaluate(() => window.__crowd.readout())).toMatch(/24 characters .*GPU backend \(joint poses\).*(warming up…|skinning CPU [\d.]+ ms\/frame)/);
    // Every character is on screen and moving: pixels of the skin colour, changing between frames.
    const region = { x: 0, y: 0, width: 1280 - 300, height: 720 };
    const a = await page.screenshot();
    await page.waitForFunction((f) => window.__crowd.frame() > f + 3, await page.evaluate(() => window.__crowd.frame()));
    const b = await page.screenshot();
    const [stats] = await analyse(page, b, [region], a);
    console.log(`crowd pixels: ${(100 * stats.skin).toFixed(1)} % skin colour, ${(100 * stats.changed).toFixed(1)} % changed in 3 frames`);
    expect(stats.skin).toBeGreaterThan(0.02);
    expect(stats.changed).toBeGreaterThan(0.005);
    // The section-level path: the section texture, 24 × sections × 48 bytes (+ padding).
    await page.evaluate(() => window.__crowd.set(24, 'gpu', 'sections'));
    await page.waitForFunction(() => window.__crowd.frame() > 1);
    const sections = await page.evaluate(() => window.__crowd.measure(3));
    console.log(`GPU backend (section transforms), 24 characters: ${sections.msPerFrame.toFixed(3)} ms, ${sections.bytesPerFrame} bytes per frame`);
    expect(sections.path).toBe('sections');
    expect(sections.bytesPerFrame).toBeGreaterThanOrEqual(24 * sections.sections * 48);
    expect(sections.bytesPerFrame).toBeLessThan(24 * sections.sections * 48 + 2048 * 16);
    expect(await page.evaluate(() => window.__crowd.readout())).toMatch(/GPU backend \(section transforms\)/);
    // The CPU backend: one mesh per character, the vertex buffers uploaded every frame.
    await page.evaluate(() => window.__crowd.set(6, 'cpu'));
    await page.waitForFunction(() => window.__crowd.backend() === 'cpu' && window.__crowd.frame() > 0);
    expect(await page.evaluate(() => window.__crowd.drawn())).toBe(6);
    const cpu = await page.evaluate(() => window.__crowd.measure(3));
    console.log(`CPU backend, 6 characters: ${cpu.msPerFrame.toFixed(3)} ms, ${cpu.bytesPerFrame} bytes per frame`);
    expect(cpu.bytesPerFrame).toBeGreaterThanOrEqual(6 * cpu.vertices * 24); // positions + normals, float32
    expect(errors).toEqual([]);
    await page.close();
  }, 300000);

  test('?crowd=16&renderer=webgpu: WebGPURenderer (WebGL2 fallback here) with gcs-skin/webgpu, drawn and moving, the joint poses uploaded', async () => {
    const { page, errors } = await open('?crowd=16&renderer=webgpu', { width: 640, height: 360 });
    expect(await page.evaluate(() => window.__crowd.drawn())).toBe(16);
    expect(await page.evaluate(() => window.__crowd.backend())).toBe('gpu');
    const m = await page.evaluate(() => window.__crowd.measure(4));
    console.log(`${m.renderer}, GPU backend, 16 characters: ${m.msPerFrame.toFixed(3)} ms skinning CPU per frame, ${m.bytesPerFrame} bytes uploaded per frame`);
    expect(m.renderer).toBe('WebGPURenderer (WebGL2 fallback)');
    expect(m.path).toBe('joints');
    // The joint poses (compact: 24 bytes per joint), plus the renderer's own per-frame uniforms (camera, lights: a few KB).
    expect(m.bytesPerFrame).toBeGreaterThanOrEqual(16 * m.joints * 24);
    expect(m.bytesPerFrame / 16).toBeLessThanOrEqual(8 * 1024);
    expect(await page.evaluate(() => window.__crowd.readout())).toMatch(/16 characters .*WebGPURenderer \(WebGL2 fallback\) · GPU backend \(joint poses\)/);
    const region = { x: 0, y: 0, width: 640 - 300, height: 360 };
    const a = await page.screenshot();
    await page.waitForFunction((f) => window.__crowd.frame() > f + 3, await page.evaluate(() => window.__crowd.frame()));
    const [stats] = await analyse(page, await page.screenshot(), [region], a);
    console.log(`WebGPURenderer crowd pixels: ${(100 * stats.skin).toFixed(1)} % skin colour, ${(100 * stats.changed).toFixed(1)} % changed in 3 frames`);
    expect(stats.skin).toBeGreaterThan(0.02);
    expect(stats.changed).toBeGreaterThan(0.005);
    expect(errors).toEqual([]);
    await page.close();
  }, 300000);

  test('the crowd\'s GUI: characters, backend, GPU path, smooth, shadows, paused (and the renderer switch, as in the views)', async () => {
    const { page, errors } = await open('?crowd=8&vertices=2000', { width: 960, height: 540 });
    try {
      expect(await page.locator('.lil-gui .controller .name').allInnerTexts())
        .toEqual(['renderer', 'characters', 'backend', 'GPU path', 'smooth (no steps)', 'shadows', 'paused']);
      await expect(menu(page, 'renderer').evaluate((el: HTMLSelectElement) => Array.from(el.options).map((o) => o.text), null, slow)).resolves.toEqual(['WebGLRenderer', 'WebGPURenderer']);

      const characters = page.locator('.lil-gui .controller.number').filter({ has: page.locator('.name', { hasText: /^characters$/ }) }).locator('input');
      await characters.fill('12');
      await characters.press('Enter');
      await page.waitForFunction(() => window.__crowd.count() === 12 && window.__crowd.drawn() === 12, null, slow);

      await menu(page, 'backend').selectOption('CPU (wasm, every vertex)');
      await page.waitForFunction(() => window.__crowd.backend() === 'cpu' && window.__crowd.drawn() === 12, null, slow);
      await menu(page, 'backend').selectOption('GPU (vertex shader)');
      await page.waitForFunction(() => window.__crowd.backend() === 'gpu', null, slow);

      await menu(page, 'GPU path').selectOption('section transforms');
      expect((await page.evaluate(() => window.__crowd.measure(2))).path).toBe('sections');
      await menu(page, 'GPU path').selectOption('joint poses');
      expect((await page.evaluate(() => window.__crowd.measure(2))).path).toBe('joints');

      await toggle(page, 'smooth \\(no steps\\)');
      await page.waitForFunction(() => !/\(smooth\)/.test(window.__crowd.readout()) && /12 characters/.test(window.__crowd.readout()), null, slow);
      await toggle(page, 'smooth \\(no steps\\)');
      await page.waitForFunction(() => /\(smooth\)/.test(window.__crowd.readout()), null, slow);

      const calls = await page.evaluate(() => window.__crowd.drawCalls());
      await toggle(page, 'shadows');
      await page.waitForFunction((n) => window.__crowd.drawCalls() > n, calls, slow);
      await toggle(page, 'shadows');

      await toggle(page, 'paused');
      const region = { x: 0, y: 60, width: 960 - 300, height: 540 - 60 - 90 }; // not the FPS panel, not the readout
      await page.waitForFunction((f) => window.__crowd.frame() > f + 2, await page.evaluate(() => window.__crowd.frame()), slow);
      const a = await page.screenshot();
      await page.waitForFunction((f) => window.__crowd.frame() > f + 3, await page.evaluate(() => window.__crowd.frame()), slow);
      const [still] = await analyse(page, await page.screenshot(), [region], a);
      await toggle(page, 'paused');
      await page.waitForFunction((f) => window.__crowd.frame() > f + 3, await page.evaluate(() => window.__crowd.frame()), slow);
      const [moving] = await analyse(page, await page.screenshot(), [region], a);
      console.log(`crowd paused: ${(100 * still.changed).toFixed(2)} % changed in 3 frames; playing again: ${(100 * moving.changed).toFixed(2)} %`);
      expect(still.changed).toBeLessThan(0.001);
      expect(moving.changed).toBeGreaterThan(0.002);
      // The readout: "warming up" after the rebuilds, then steady figures.
      await steadyReadout(page);
      expect(await page.evaluate(() => window.__crowd.readout())).toMatch(/12 characters .*GPU backend \(joint poses\) \(smooth\)skinning CPU [\d.]+ ms\/frame .*uploaded [\d.]+ KB\/frame/);
      expect(errors).toEqual([]);
    } finally {
      await page.close();
    }
  }, 600000);

  // 300 characters of a lighter human (2,000 vertices): software rendering of 300 × 17 k vertices takes minutes.
  test('?crowd=300&smooth=1&vertices=2000 renders 300 characters with no page error', async () => {
    const { page, errors } = await open('?crowd=300&smooth=1&vertices=2000', { width: 480, height: 270 });
    expect(await page.evaluate(() => window.__crowd.drawn())).toBe(300);
    const m = await page.evaluate(() => window.__crowd.measure(2));
    expect(m.path).toBe('joints');
    expect(m.bytesPerFrame).toBeLessThan(300 * m.joints * 24 + 2048 * 16); // the compact joint poses (+ the padding of the last row)
    expect(errors).toEqual([]);
    await page.close();
  }, 300000);
});
