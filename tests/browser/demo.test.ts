// The demo page in headless Chromium: both views render, animate, follow the GUI's section
// slider in each GCS criterion (weights, the default; the paper's Y and axial), load a dropped
// character, and keep the old one when a file is broken. The three characters shipped in public/
// (Fox, Cesium Man, Robot Expressive) load from the menu and from ?model=, each complete and in
// its own materials in every view, animated, with its licence on the page. Every control of the
// GUI is driven by a test here (CONTROLS lists which; a control added to the GUI fails the list
// until it has one).
import { createHash } from 'node:crypto';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { BrowserContext, Page } from 'playwright-core';
import { analyse, existsSync, frames, launchChromium, MODELS_DIR, ROOT, skipReason, startDemo, type DemoServer, type Rect } from './harness.js';

const reason = skipReason();
if (reason) console.log(reason);

/** The 3D part of each view: below the labels, above the readouts. */
async function viewRegions(page: Page): Promise<Rect[]> {
  const { views, height } = await page.evaluate(() => ({ views: window.__demo.views(), height: window.innerHeight }));
  return views.map((v) => ({ x: v.x + 8, y: 140, width: v.width - 16, height: height - 140 - 80 }));
}

/** Clicks a lil-gui checkbox by its label. */
async function toggle(page: Page, name: string): Promise<void> {
  await page.locator('.lil-gui .controller.boolean').filter({ has: page.locator('.name', { hasText: new RegExp(`^${name}$`) }) }).locator('input').click();
}

/** Clicks a lil-gui button by its label. */
async function press(page: Page, name: string): Promise<void> {
  await page.locator('.lil-gui .controller.function').filter({ has: page.locator('.name', { hasText: new RegExp(`^${name}$`) }) }).locator('button').click();
}

/** Sets a lil-gui number controller by typing into its input. */
async function setNumber(page: Page, name: string, value: number): Promise<void> {
  const input = page.locator('.lil-gui .controller.number').filter({ has: page.locator('.name', { hasText: new RegExp(`^${name}$`) }) }).locator('input');
  await input.fill(String(value));
  await input.press('Enter');
}

/** Picks a criterion in the GUI's menu (by its label) and waits until the GCS model is rebuilt with it. */
async function setCriterion(page: Page, label: string, value: string): Promise<void> {
  const builds = await page.evaluate(() => window.__demo.gcsBuilds());
  await page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: /^criterion$/ }) }).locator('select').selectOption(label);
  await page.waitForFunction(([n, c]) => window.__demo.gcsBuilds() > (n as number) && window.__demo.criterion() === c, [builds, value] as const);
}

/** The section count as the GCS view's readout shows it ("320 sections"). */
async function sectionReadout(page: Page): Promise<number> {
  const text = await page.locator('.readout[data-view=gcs]').innerText();
  const m = /([\d,]+) sections/.exec(text);
  if (!m) throw new Error(`no section count in the GCS readout: ${text}`);
  return Number(m[1].replace(/,/g, ''));
}

/** Whether a lil-gui controller (by its label) is disabled. */
async function disabled(page: Page, name: string): Promise<boolean> {
  return page.locator('.lil-gui .controller').filter({ has: page.locator('.name', { hasText: new RegExp(`^${name}$`) }) })
    .evaluate((el) => el.classList.contains('disabled'));
}

/** Drops files on the page as a user would (a synthetic drop event carrying a DataTransfer). */
async function drop(page: Page, files: { name: string; bytes: Buffer }[]): Promise<void> {
  await page.evaluate(async (list) => {
    const dt = new DataTransfer();
    for (const f of list) dt.items.add(new File([Uint8Array.from(atob(f.b64), (c) => c.charCodeAt(0))], f.name));
    const canvas = document.querySelector('canvas')!;
    canvas.dispatchEvent(new DragEvent('dragenter', { dataTransfer: dt, bubbles: true, cancelable: true }));
    canvas.dispatchEvent(new DragEvent('dragover', { dataTransfer: dt, bubbles: true, cancelable: true }));
    canvas.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
    await new Promise((r) => setTimeout(r, 50));
    await window.__demo.idle();
  }, files.map((f) => ({ name: f.name, b64: f.bytes.toString('base64') })));
}

/** The characters shipped in public/: menu label, ?model= key, file, sha256 (../shared/models/SOURCES.md), licence named on the page. */
const SHIPPED = [
  { label: 'Fox', key: 'fox', file: 'Fox.glb', sha256: 'd97044e701822bac5a62696459b27d7b375aada5de8574ed4362edbba94771f7', licence: /CC0 1\.0.*CC BY 4\.0/, textured: true },
  { label: 'Cesium Man', key: 'cesiumman', file: 'CesiumMan.glb', sha256: 'd3868164b6d5df6f097b2ee3e056c572ebcf064d064016429a4f1ce66e4a58c8', licence: /CC BY 4\.0.*trademark/, textured: true },
  { label: 'Robot Expressive', key: 'robot', file: 'RobotExpressive.glb', sha256: '047f5e5fb3bb6d378bd1df16ca6137f2a596c99b3a1b5690b4020c05aaf6f319', licence: /CC0 1\.0/, textured: false },
];

/** Every control of the demo's GUI (its label, in order) and the test that drives it. */
const CONTROLS: Record<string, string> = {
  'character': 'the character menu loads …, the character menu goes back to the default human',
  'load file… (.glb / .gltf)': 'a broken file, a mesh without skin and a .gltf with external buffers …',
  'criterion': 'each criterion (weights, Y, axial) renders …',
  'sections': 'the section-count slider rebuilds the GCS model live …',
  'smooth (no steps)': 'smooth (no steps) rebuilds the GCS model stepped, and back',
  'cost / frame': 'the page opens with the weights criterion … (read-only: the measured cost)',
  'influence width': 'under the paper\'s Y criterion, influence width and twist spread rebuild the GCS model',
  'twist spread': 'under the paper\'s Y criterion, influence width and twist spread rebuild the GCS model',
  'contours': 'the other controls: clip, third (three.js LBS) view, classic contours, rays and bulge',
  'rays': 'the other controls: clip, third (three.js LBS) view, classic contours, rays and bulge',
  'muscle bulge': 'the other controls: clip, third (three.js LBS) view, classic contours, rays and bulge',
  'clip': 'the other controls: clip, third (three.js LBS) view, classic contours, rays and bulge',
  'speed': 'the picture changes over time (the walk is animated)',
  'pause': 'pause, step one frame and their keys (space, ".")',
  'step one frame': 'pause, step one frame and their keys (space, ".")',
  'wireframe': 'wireframe and show skeleton change every view',
  'colour by section': 'the section-count slider rebuilds the GCS model live …',
  'show skeleton': 'wireframe and show skeleton change every view',
  'three.js LBS view': 'the other controls: clip, third (three.js LBS) view, classic contours, rays and bulge',
  'joint close-up (knees, elbows) ↗': 'joint-mode.test.ts: the comparison page\'s joint close-up button opens ?joint on the character on screen',
  'renderer': 'the renderer switch reloads the page with ?renderer=webgpu …',
};

/** The character menu's select. */
const characterMenu = (page: Page) =>
  page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: /^character$/ }) }).locator('select');

describe.skipIf(!!reason)('demo page (headless Chromium)', () => {
  let server: DemoServer;
  let context: BrowserContext;
  let page: Page;
  const pageErrors: string[] = [];

  beforeAll(async () => {
    const t0 = performance.now();
    [server, context] = await Promise.all([startDemo(), launchChromium()]);
    page = await context.newPage();
    page.on('pageerror', (e) => pageErrors.push(e.message));
    await page.goto(server.url);
    await page.waitForFunction(() => window.__demo !== undefined);
    await page.evaluate(() => window.__demo.ready);
    await frames(page, 3);
    console.log(`demo served in ${server.startMs.toFixed(0)} ms; page ready (human built, first frames) after ${(performance.now() - t0).toFixed(0)} ms`);
  });

  afterAll(async () => {
    await context?.close();
    await server?.close();
  });

  test('every control of the GUI is listed in CONTROLS, with the test that drives it', async () => {
    const names = await page.locator('.lil-gui .controller .name').allInnerTexts();
    expect(names).toEqual(Object.keys(CONTROLS));
  });

  test('the page starts walking the default human, with both views labelled', async () => {
    const state = await page.evaluate(() => ({
      error: window.__demo.error(), character: window.__demo.character(), sections: window.__demo.sectionCount(), criterion: window.__demo.criterion(),
      views: window.__demo.views().map((v) => v.kind), classicError: window.__demo.classicError(), rigid: window.__demo.rigidParts(),
    }));
    expect(state.error).toBe('');
    expect(state.character).toMatch(/Human/);
    expect(state.sections).toBeGreaterThan(50);
    expect(state.views).toEqual(['gcs', 'classic']);
    await expect(page.locator('.label[data-view=gcs]').innerText()).resolves.toMatch(/GCS/);
    const classicLabel = await page.locator('.label[data-view=classic]').innerText();
    expect(classicLabel).toMatch(/Classic cross-sections/);
    // Either the classic model runs and names the parts it carries, or it says why it cannot.
    if (state.classicError) expect(classicLabel).toContain(state.classicError);
    else {
      expect(state.rigid.length).toBeGreaterThan(0);
      expect(classicLabel).toMatch(/Carried \(own triangles, skinned by DQS\)/);
    }
    await expect(page.locator('.lil-gui .controller .name', { hasText: /^sections$/ }).isVisible()).resolves.toBe(true);
  });

  test('the page opens with the weights criterion; the paper-only controls are disabled; the readout says why', async () => {
    expect(await page.evaluate(() => window.__demo.criterion())).toBe('weights');
    const menu = page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: /^criterion$/ }) }).locator('select');
    await expect(menu.evaluate((el: HTMLSelectElement) => Array.from(el.options).map((o) => o.text)))
      .resolves.toEqual(['weights (default)', 'Y (paper)', "axial (paper's rule, bone axis)"]);
    await expect(menu.evaluate((el: HTMLSelectElement) => el.options[el.selectedIndex].text)).resolves.toBe('weights (default)');
    expect(await disabled(page, 'influence width')).toBe(true);
    expect(await disabled(page, 'twist spread')).toBe(true);
    expect(await disabled(page, 'smooth \\(no steps\\)')).toBe(false);
    await expect(page.locator('.label[data-view=gcs]').innerText()).resolves.toMatch(/weights criterion · 6 sections: weight step 1\/8/);
    const readout = await page.locator('.readout[data-view=gcs]').innerText();
    expect(readout).toMatch(/criterion weights: vertices bound 100 % to a bone move exactly with it; the paper's Y rule bends them/);
    expect(readout).toMatch(/\d+ % of vertices in rigid cores/);
    // What the settings cost, measured in the page once it rests: the default (smooth) beside the stepped mode.
    const cost = page.locator('.lil-gui .controller').filter({ has: page.locator('.name', { hasText: /^cost \/ frame$/ }) }).locator('input');
    await expect.poll(async () => cost.inputValue(), { timeout: 30000 }).toMatch(/^[\d.]+ ms · stepped [\d.]+$/);
  });

  test('both views render a lit character (not blank, many colours in each)', async () => {
    const regions = await viewRegions(page);
    const stats = await analyse(page, await page.screenshot(), regions);
    const classicError = await page.evaluate(() => window.__demo.classicError());
    stats.forEach((s, i) => {
      expect(s.colours, `distinct colours in view ${i}`).toBeGreaterThan(150);
      if (i === 0 || !classicError) expect(s.skin, `share of skin pixels in view ${i}`).toBeGreaterThan(0.02);
    });
  });

  test('the picture changes over time (the walk is animated)', async () => {
    // At speed 0.3 a walk cycle takes ~3.7 s: two shots a moment apart can never be a whole cycle apart.
    await setNumber(page, 'speed', 0.3);
    try {
      const regions = await viewRegions(page);
      const t0 = await page.evaluate(() => window.__demo.time());
      const a = await page.screenshot();
      await page.waitForTimeout(300);
      await frames(page, 3);
      const b = await page.screenshot();
      const stats = await analyse(page, b, regions, a);
      expect(await page.evaluate(() => window.__demo.time())).toBeGreaterThan(t0);
      expect(stats[0].changed).toBeGreaterThan(0.003);
      if (!(await page.evaluate(() => window.__demo.classicError()))) expect(stats[1].changed).toBeGreaterThan(0.003);
    } finally {
      await setNumber(page, 'speed', 1);
    }
  });

  test('the section-count slider rebuilds the GCS model live and changes the picture', async () => {
    const regions = await viewRegions(page);
    await toggle(page, 'pause');
    await toggle(page, 'colour by section');
    try {
    await frames(page, 3);
    const before = { count: await page.evaluate(() => window.__demo.sectionCount()), shot: await page.screenshot() };
    expect(await page.evaluate(() => window.__demo.sectionsPerPart())).toBe(6);

    // Type into the slider's number input, as a user would.
    const sections = page.locator('.lil-gui .controller.number').filter({ has: page.locator('.name', { hasText: /^sections$/ }) });
    await sections.locator('input').fill('12');
    await sections.locator('input').press('Enter');
    await page.waitForFunction((n) => window.__demo.sectionCount() !== n, before.count);
    await frames(page, 3);
    const after12 = await page.evaluate(() => ({ perPart: window.__demo.sectionsPerPart(), count: window.__demo.sectionCount() }));
    expect(after12.perPart).toBe(12);
    expect(after12.count).toBeGreaterThan(before.count);
    const shot12 = await page.screenshot();
    const diff = await analyse(page, shot12, regions, before.shot);
    expect(diff[0].changed, 'GCS view changed').toBeGreaterThan(0.005);
    expect(diff[1].changed, 'classic view unchanged (paused, not rebuilt)').toBeLessThan(0.002);
    await expect(page.locator('.label[data-view=gcs]').innerText()).resolves.toMatch(/12 sections: weight step 1\/20/);

    // Drag on the slider track itself: near its left end is few sections.
    const box = (await page.locator('.sections-track').boundingBox())!;
    await page.mouse.click(box.x + 1, box.y + box.height / 2);
    await page.waitForFunction(() => window.__demo.sectionsPerPart() <= 4);
    await page.waitForFunction((n) => window.__demo.sectionCount() < n, before.count);
    await frames(page, 2);
    } finally {
      await toggle(page, 'colour by section');
      await toggle(page, 'pause');
      await page.evaluate(() => window.__demo.setSections(6));
      await frames(page, 2);
    }
  });

  test('each criterion (weights, Y, axial) renders; its section slider changes the section count readout and the picture', async () => {
    const regions = await viewRegions(page);
    await toggle(page, 'pause');
    await toggle(page, 'colour by section');
    const errorsBefore = pageErrors.length;
    try {
      const criteria = [
        { label: 'Y (paper)', value: 'y', text: /Y \(paper\) criterion · 6 sections per part/ },
        { label: "axial (paper's rule, bone axis)", value: 'axial', text: /axial \(paper's rule\) criterion · 6 sections per part/ },
        { label: 'weights (default)', value: 'weights', text: /weights criterion · 6 sections: weight step 1\/8/ },
      ];
      for (const c of criteria) {
        await setCriterion(page, c.label, c.value);
        await frames(page, 3);
        expect(await page.evaluate(() => window.__demo.error()), `${c.value}: no message`).toBe('');
        await expect(page.locator('.label[data-view=gcs]').innerText()).resolves.toMatch(c.text);
        await expect(page.locator('.readout[data-view=gcs]').innerText()).resolves.toMatch(new RegExp(`criterion ${c.value === 'y' ? 'Y' : c.value}`));
        const paperOnly = c.value !== 'weights';
        expect(await disabled(page, 'influence width'), `${c.value}: influence width enabled`).toBe(!paperOnly);
        expect(await disabled(page, 'twist spread'), `${c.value}: twist spread enabled`).toBe(!paperOnly);
        // Under the paper's criteria, a note beside the menu says why the picture looks broken: text only.
        const note = page.locator('.lil-gui .criterion-note');
        await expect(note.isVisible(), `${c.value}: the note on the paper's criteria`).resolves.toBe(paperOnly);
        if (paperOnly) {
          expect(await note.innerText()).toMatch(/broken.*bound 100 % to one bone.*weights, keeps it rigid.*docs\/method\.md/s);
          expect(await note.evaluate((el) => ({ elements: el.children.length, afterMenu: !!el.previousElementSibling?.querySelector('select') })))
            .toEqual({ elements: 0, afterMenu: true });
        }

        const before = { readout: await sectionReadout(page), shot: await page.screenshot() };
        expect(before.readout).toBe(await page.evaluate(() => window.__demo.sectionCount()));
        const builds = await page.evaluate(() => window.__demo.gcsBuilds());
        await setNumber(page, 'sections', 10);
        await page.waitForFunction((n) => window.__demo.gcsBuilds() > n, builds);
        await frames(page, 3);
        const after = await sectionReadout(page);
        expect(after, `${c.value}: the section count readout follows the slider`).toBeGreaterThan(before.readout);
        const diff = await analyse(page, await page.screenshot(), regions, before.shot);
        expect(diff[0].colours, `${c.value}: the GCS view renders`).toBeGreaterThan(150);
        expect(diff[0].changed, `${c.value}: the GCS view changed`).toBeGreaterThan(0.005);
        expect(diff[1].changed, `${c.value}: the classic view unchanged`).toBeLessThan(0.002);
        await setNumber(page, 'sections', 6);
        await page.waitForFunction((n) => window.__demo.sectionCount() === n, before.readout);
      }
      expect(pageErrors.slice(errorsBefore)).toEqual([]);
    } finally {
      await toggle(page, 'colour by section');
      await toggle(page, 'pause');
      await frames(page, 2);
    }
  }, 360000); // three rebuilds and six screenshots: minutes on a loaded 2-core machine (SwiftShader)

  test('?criterion=y opens with the paper\'s Y criterion', async () => {
    const other = await context.newPage();
    other.on('pageerror', (e) => pageErrors.push(e.message));
    await other.goto(`${server.url}?criterion=y&sections=8`);
    await other.waitForFunction(() => window.__demo !== undefined);
    await other.evaluate(() => window.__demo.ready);
    expect(await other.evaluate(() => ({ criterion: window.__demo.criterion(), perPart: window.__demo.sectionsPerPart(), error: window.__demo.error() })))
      .toEqual({ criterion: 'y', perPart: 8, error: '' });
    await expect(other.locator('.label[data-view=gcs]').innerText()).resolves.toMatch(/Y \(paper\) criterion · 8 sections per part/);
    await other.close();
  });

  test('the other controls: clip, third (three.js LBS) view, classic contours, rays and bulge', async () => {
    await page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: /^clip$/ }) }).locator('select').selectOption('run');
    await page.waitForFunction(() => window.__demo.clip() === 'run');

    await toggle(page, 'three.js LBS view');
    await frames(page, 2);
    expect((await page.evaluate(() => window.__demo.views())).map((v) => v.kind)).toEqual(['gcs', 'classic', 'lbs']);
    await expect(page.locator('.label[data-view=lbs]').innerText()).resolves.toMatch(/three\.js skinning/);
    const stats = await analyse(page, await page.screenshot(), await viewRegions(page));
    expect(stats[2].colours, 'the LBS view renders').toBeGreaterThan(150);
    expect(stats[2].skin).toBeGreaterThan(0.02);
    await toggle(page, 'three.js LBS view');

    if (!(await page.evaluate(() => window.__demo.classicError()))) {
      const contours = () => page.evaluate(() => (window.__demo.readouts() as { classic: { contours: number } }).classic.contours);
      const builds = await page.evaluate(() => window.__demo.classicBuilds());
      const before = await contours();
      await setNumber(page, 'contours', 10);
      await page.waitForFunction((n) => window.__demo.classicBuilds() > n, builds);
      expect(await contours()).toBeLessThan(before);
      await setNumber(page, 'rays', 10);
      await page.waitForFunction((n) => window.__demo.classicBuilds() > n + 1, builds);
      await expect(page.locator('.label[data-view=classic]').innerText()).resolves.toMatch(/10 contours × 10 rays per limb/);
      await setNumber(page, 'rays', 20);
      await page.waitForFunction((n) => window.__demo.classicBuilds() > n + 2, builds);
      const afterContours = await page.evaluate(() => window.__demo.classicBuilds());
      await setNumber(page, 'muscle bulge', 2);
      await frames(page, 2);
      expect(await page.evaluate(() => window.__demo.classicBuilds()), 'bulge changes without a rebuild').toBe(afterContours);
      await setNumber(page, 'muscle bulge', 0.3);
      await setNumber(page, 'contours', 25);
    }
    await page.locator('.lil-gui .controller.option').filter({ has: page.locator('.name', { hasText: /^clip$/ }) }).locator('select').selectOption('walk');
    expect(await page.evaluate(() => window.__demo.error())).toBe('');
  });

  test('smooth (no steps) rebuilds the GCS model stepped, and back', async () => {
    const label = () => page.locator('.label[data-view=gcs]').innerText();
    await expect(label()).resolves.toMatch(/weight step 1\/8, smooth$/m);
    for (const smooth of [false, true]) {
      const builds = await page.evaluate(() => window.__demo.gcsBuilds());
      await toggle(page, 'smooth \\(no steps\\)');
      await page.waitForFunction((n) => window.__demo.gcsBuilds() > n, builds);
      await frames(page, 2);
      if (smooth) await expect(label()).resolves.toMatch(/weight step 1\/8, smooth$/m);
      else await expect(label()).resolves.toMatch(/weight step 1\/8$/m);
    }
    expect(await page.evaluate(() => window.__demo.error())).toBe('');
  });

  test('under the paper\'s Y criterion, influence width and twist spread rebuild the GCS model', async () => {
    await toggle(page, 'pause');
    await setCriterion(page, 'Y (paper)', 'y');
    try {
      await page.evaluate(() => window.__demo.pause(0.4)); // a bent pose: the knees and elbows show the ramp
      await frames(page, 3);
      const regions = await viewRegions(page);
      const before = await page.screenshot();
      let builds = await page.evaluate(() => window.__demo.gcsBuilds());
      await setNumber(page, 'influence width', 0.2);
      await page.waitForFunction((n) => window.__demo.gcsBuilds() > n, builds);
      await frames(page, 3);
      const diff = await analyse(page, await page.screenshot(), regions, before);
      expect(diff[0].changed, 'the GCS view changed').toBeGreaterThan(0.001);
      expect(diff[1].changed, 'the classic view unchanged').toBeLessThan(0.002);

      builds = await page.evaluate(() => window.__demo.gcsBuilds());
      await toggle(page, 'twist spread');
      await page.waitForFunction((n) => window.__demo.gcsBuilds() > n, builds);
      await expect(page.locator('.label[data-view=gcs]').innerText()).resolves.toMatch(/Y \(paper\) criterion · 6 sections per part, smooth, twist spread/);
      expect(await page.evaluate(() => window.__demo.error())).toBe('');
    } finally {
      await toggle(page, 'twist spread');
      await setNumber(page, 'influence width', 1);
      await setCriterion(page, 'weights (default)', 'weights');
      await toggle(page, 'pause');
      await frames(page, 2);
    }
  });

  test('pause, step one frame and their keys (space, ".")', async () => {
    const checked = () => page.locator('.lil-gui .controller.boolean').filter({ has: page.locator('.name', { hasText: /^pause$/ }) }).locator('input').isChecked();
    const time = () => page.evaluate(() => window.__demo.time());
    // The keys act on the page, not inside the GUI (lil-gui keeps its key events to itself).
    const key = async (k: string) => {
      await page.evaluate(() => (document.activeElement as HTMLElement | null)?.blur());
      await page.keyboard.press(k);
    };
    try {
      await key('Space');
      expect(await checked(), 'space pauses (the checkbox shows it)').toBe(true);
      let t = await time();
      await frames(page, 3);
      expect(await time(), 'paused: the clip stands still').toBe(t);
      await press(page, 'step one frame');
      expect(await time()).toBeCloseTo(t + 1 / 30, 6);
      t = await time();
      await key('.');
      expect(await time()).toBeCloseTo(t + 1 / 30, 6);
      await key('Space');
      expect(await checked(), 'space again plays').toBe(false);
      t = await time();
      await frames(page, 3);
      expect(await time()).toBeGreaterThan(t);
      // The button pauses a playing clip first, then steps.
      await press(page, 'step one frame');
      expect(await checked()).toBe(true);
    } finally {
      if (await checked()) await toggle(page, 'pause');
    }
  });

  test('wireframe and show skeleton change every view', async () => {
    await toggle(page, 'pause');
    try {
      const regions = await viewRegions(page);
      for (const control of ['wireframe', 'show skeleton']) {
        await frames(page, 2);
        const before = await page.screenshot();
        await toggle(page, control);
        await frames(page, 3);
        const diff = await analyse(page, await page.screenshot(), regions, before);
        await toggle(page, control);
        diff.forEach((d, i) => expect(d.changed, `${control}: view ${i} changed`).toBeGreaterThan(control === 'wireframe' ? 0.003 : 0.001));
      }
    } finally {
      await toggle(page, 'pause');
    }
  }, 300000); // wireframe in software rendering: slow frames

  test('a broken file, a mesh without skin and a .gltf with external buffers give clear messages; the character stays', async () => {
    const character = await page.evaluate(() => window.__demo.character());

    await drop(page, [{ name: 'broken.glb', bytes: Buffer.from('this is not a glTF file at all') }]);
    let error = await page.evaluate(() => window.__demo.error());
    expect(error).toMatch(/broken\.glb/);
    await expect(page.locator('#message').isVisible()).resolves.toBe(true);
    expect(await page.evaluate(() => window.__demo.character())).toBe(character);

    // A valid glTF with one triangle and no skin, through the "load file…" input.
    const triangle = Buffer.from(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]).buffer);
    const noSkin = {
      asset: { version: '2.0' }, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0 }],
      meshes: [{ primitives: [{ attributes: { POSITION: 0 } }] }],
      accessors: [{ bufferView: 0, componentType: 5126, count: 3, type: 'VEC3', min: [0, 0, 0], max: [1, 1, 0] }],
      bufferViews: [{ buffer: 0, byteLength: 36 }],
      buffers: [{ byteLength: 36, uri: `data:application/octet-stream;base64,${triangle.toString('base64')}` }],
    };
    const [chooser] = await Promise.all([page.waitForEvent('filechooser'), press(page, 'load file… \\(\\.glb / \\.gltf\\)')]);
    await chooser.setFiles({ name: 'triangle.gltf', mimeType: 'model/gltf+json', buffer: Buffer.from(JSON.stringify(noSkin)) });
    await page.waitForFunction(() => /triangle\.gltf/.test(window.__demo.error()));
    await page.evaluate(() => window.__demo.idle());
    error = await page.evaluate(() => window.__demo.error());
    expect(error).toMatch(/no skinned mesh/);
    expect(await page.evaluate(() => window.__demo.character())).toBe(character);

    const external = { ...noSkin, buffers: [{ byteLength: 36, uri: 'triangle.bin' }] };
    await drop(page, [{ name: 'external.gltf', bytes: Buffer.from(JSON.stringify(external)) }]);
    error = await page.evaluate(() => window.__demo.error());
    expect(error).toMatch(/keeps buffer 0 in the file 'triangle\.bin', which was not dropped with it/);
    expect(await page.evaluate(() => window.__demo.character())).toBe(character);

    // The old character still animates.
    const t = await page.evaluate(() => window.__demo.time());
    await frames(page, 3);
    expect(await page.evaluate(() => window.__demo.time())).toBeGreaterThan(t);
    await page.locator('#message-close').click();
  });

  const model = ['CesiumMan.glb', 'Soldier.glb'].map((f) => join(MODELS_DIR, f)).find((f) => existsSync(f));
  test.skipIf(!model)(`a character dropped on the page loads (${model ?? `skipped: no CesiumMan.glb or Soldier.glb in ${MODELS_DIR}`})`, async () => {
    const name = model!.split('/').pop()!;
    await drop(page, [{ name, bytes: readFileSync(model!) }]);
    const state = await page.evaluate(() => ({ error: window.__demo.error(), character: window.__demo.character(), sections: window.__demo.sectionCount() }));
    expect(state.error).toBe('');
    expect(state.character).toBe(name);
    expect(state.sections).toBeGreaterThan(10);
    // The menu lists the dropped file and shows it; no shipped attribution for the user's own file.
    await expect(characterMenu(page).evaluate((el: HTMLSelectElement) => el.options[el.selectedIndex].text)).resolves.toBe(name);
    expect(await page.evaluate(() => window.__demo.credit())).toMatch(/your own file/);
    await setNumber(page, 'speed', 0.3); // shots a moment apart are never a whole cycle apart
    await frames(page, 3);
    const regions = await viewRegions(page);
    const a = await page.screenshot();
    await page.waitForTimeout(300);
    await frames(page, 3);
    const stats = await analyse(page, await page.screenshot(), regions, a);
    await setNumber(page, 'speed', 1);
    expect(stats[0].colours).toBeGreaterThan(150);
    expect(stats[0].changed).toBeGreaterThan(0.002);
  });

  test('?model= with a URL that fails says so and falls back to the default human', async () => {
    const other = await context.newPage();
    other.on('pageerror', (e) => pageErrors.push(e.message));
    await other.goto(`${server.url}?model=missing/nothing-here.glb`);
    await other.waitForFunction(() => window.__demo !== undefined);
    await other.evaluate(() => window.__demo.ready);
    await other.evaluate(() => window.__demo.idle());
    expect(await other.evaluate(() => window.__demo.error())).toMatch(/nothing-here\.glb/);
    await expect(other.locator('#message').isVisible()).resolves.toBe(true);
    expect(await other.evaluate(() => window.__demo.character())).toMatch(/Human/);
    await other.close();
  });

  test('the build ships Fox, Cesium Man and Robot Expressive byte-exact, with LICENSES.md (and no Soldier)', async () => {
    for (const m of SHIPPED) {
      const res = await fetch(server.url + m.file);
      expect(res.status, m.file).toBe(200);
      const bytes = Buffer.from(await res.arrayBuffer());
      expect(createHash('sha256').update(bytes).digest('hex'), m.file).toBe(m.sha256);
      expect(bytes.equals(readFileSync(join(ROOT, 'public', m.file))), `${m.file} as in public/`).toBe(true);
    }
    const licences = await fetch(`${server.url}LICENSES.md`);
    expect(licences.status).toBe(200);
    const text = await licences.text();
    for (const words of ['PixelMannen', '@tomkranis', '@AsoboStudio', '@scurest', 'Cesium Trademark Terms', 'Tomás Laulhé', 'Don McCurdy', 'CC BY 4.0', 'CC0 1.0'])
      expect(text, words).toContain(words);
    // Soldier.glb (Mixamo) is test data only: never shipped.
    expect(existsSync(join(ROOT, 'public', 'Soldier.glb'))).toBe(false);
  });

  // Each shipped character from the menu, in all three views: the GCS and classic views must
  // show it as completely as three.js does (the robot's rigid limbs are not skinned: they hang on
  // its bones) and in its own materials (textures: the classic model's resampled skin gets
  // texture coordinates from the source surface).
  for (const m of SHIPPED) {
    test(`the character menu loads ${m.label}: complete, in its own materials in every view, animated, credited`, async () => {
      const errorsBefore = pageErrors.length;
      await characterMenu(page).selectOption(m.label);
      await page.waitForFunction((key) => window.__demo.model() === key && !window.__demo.busy(), m.key, { timeout: 60000 });
      await page.evaluate(() => window.__demo.idle());
      expect(await page.evaluate(() => window.__demo.error())).toBe('');
      expect(await page.evaluate(() => window.__demo.character())).toBe(m.label);
      await expect(characterMenu(page).evaluate((el: HTMLSelectElement) => el.options[el.selectedIndex].text)).resolves.toBe(m.label);

      const parts = await page.evaluate(() => window.__demo.parts());
      expect(parts.skinned).toBeGreaterThan(0);
      expect(parts.gcs, 'a GCS mesh per skinned mesh').toBe(parts.skinned);
      expect(parts.classic, 'a classic mesh per skinned mesh').toBe(parts.skinned);
      expect(parts.ownMaterials, 'every deformed mesh wears its source material').toEqual({ gcs: true, classic: true });
      expect(parts.textured).toEqual({ gcs: m.textured, classic: m.textured });
      if (m.key === 'robot') expect(parts.rigid, 'the robot\'s rigid parts').toBeGreaterThan(10);

      const credit = await page.evaluate(() => window.__demo.credit());
      expect(credit).toMatch(m.licence);
      await expect(page.locator('#credit a').getAttribute('href')).resolves.toBe('LICENSES.md');
      await expect(page.locator('#credit').isVisible()).resolves.toBe(true);

      if (!(await page.evaluate(() => window.__demo.views())).some((v) => v.kind === 'lbs')) await toggle(page, 'three.js LBS view');
      await setNumber(page, 'speed', 0.3); // shots a moment apart are never a whole cycle apart
      try {
        await frames(page, 3);
        const regions = await viewRegions(page);
        const t0 = await page.evaluate(() => window.__demo.time());
        const a = await page.screenshot();
        await page.waitForTimeout(300);
        await frames(page, 3);
        const stats = await analyse(page, await page.screenshot(), regions, a);
        expect(await page.evaluate(() => window.__demo.time())).toBeGreaterThan(t0);
        const [gcsView, classicView, lbsView] = stats;
        stats.forEach((st, i) => {
          expect(st.colours, `${m.label}: distinct colours in view ${i}`).toBeGreaterThan(150);
          expect(st.changed, `${m.label}: view ${i} animates`).toBeGreaterThan(0.002);
        });
        // Complete: as much of the fox's and the robot's orange in the GCS and classic views as in three.js's own.
        if (lbsView.skin > 0.01) {
          expect(gcsView.skin, `${m.label}: GCS view as complete as LBS`).toBeGreaterThan(0.7 * lbsView.skin);
          expect(classicView.skin, `${m.label}: classic view as complete as LBS`).toBeGreaterThan(0.6 * lbsView.skin);
        }
      } finally {
        await setNumber(page, 'speed', 1);
      }
      expect(pageErrors.slice(errorsBefore)).toEqual([]);
    });
  }

  test('the character menu goes back to the default human', async () => {
    if ((await page.evaluate(() => window.__demo.views())).some((v) => v.kind === 'lbs')) await toggle(page, 'three.js LBS view');
    await characterMenu(page).selectOption('default human');
    await page.waitForFunction(() => window.__demo.model() === 'human' && !window.__demo.busy(), null, { timeout: 60000 });
    expect(await page.evaluate(() => ({ character: window.__demo.character(), error: window.__demo.error() }))).toEqual({ character: 'Human (procedural)', error: '' });
    expect(await page.evaluate(() => window.__demo.credit())).toMatch(/MIT/);
  });

  test('?model=fox|cesiumman|robot opens that character, credited, rendering in both views', async () => {
    for (const m of SHIPPED) {
      const other = await context.newPage();
      const errors: string[] = [];
      other.on('pageerror', (e) => errors.push(e.message));
      await other.goto(`${server.url}?model=${m.key}`);
      await other.waitForFunction(() => window.__demo !== undefined);
      await other.evaluate(() => window.__demo.ready);
      await other.evaluate(() => window.__demo.idle());
      expect(await other.evaluate(() => ({ model: window.__demo.model(), character: window.__demo.character(), error: window.__demo.error() })))
        .toEqual({ model: m.key, character: m.label, error: '' });
      expect(await other.evaluate(() => window.__demo.credit())).toMatch(m.licence);
      await frames(other, 2);
      const stats = await analyse(other, await other.screenshot(), await viewRegions(other));
      stats.forEach((st, i) => expect(st.colours, `?model=${m.key}: distinct colours in view ${i}`).toBeGreaterThan(150));
      expect(errors, `?model=${m.key}: page errors`).toEqual([]);
      await other.close();
    }
  }, 180000);

  test('the renderer switch reloads the page with ?renderer=webgpu: WebGPURenderer (its WebGL2 fallback here: no GPU) draws both views, walking; the readouts name renderer and backend', async () => {
    expect(await page.locator('.readout[data-view=gcs]').innerText()).toMatch(/WebGLRenderer · CPU backend/);
    const other = await context.newPage();
    const errors: string[] = [];
    other.on('pageerror', (e) => errors.push(e.message));
    other.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    try {
      await other.goto(server.url);
      await other.waitForFunction(() => window.__demo !== undefined);
      await other.evaluate(() => window.__demo.ready);
      await Promise.all([
        other.waitForURL(/[?&]renderer=webgpu/),
        other.locator('.lil-gui .controller.option').filter({ has: other.locator('.name', { hasText: /^renderer$/ }) }).locator('select').selectOption('WebGPURenderer'),
      ]);
      await other.waitForFunction(() => window.__demo !== undefined);
      await other.evaluate(() => window.__demo.ready);
      await frames(other, 3);
      expect(await other.evaluate(() => window.__demo.error())).toBe('');
      for (const view of ['gcs', 'classic'])
        expect(await other.locator(`.readout[data-view=${view}]`).innerText()).toMatch(/WebGPURenderer \(WebGL2 fallback\) · CPU backend/);
      const regions = await viewRegions(other);
      const a = await other.screenshot();
      await other.waitForTimeout(300);
      await frames(other, 3);
      const stats = await analyse(other, await other.screenshot(), regions, a);
      stats.forEach((s, i) => {
        expect(s.colours, `distinct colours in view ${i}`).toBeGreaterThan(150);
        expect(s.skin, `share of skin pixels in view ${i}`).toBeGreaterThan(0.02);
      });
      expect(stats[0].changed).toBeGreaterThan(0.003); // walking
      await expect(other.locator('.lil-gui .controller .name', { hasText: /^renderer$/ }).isVisible()).resolves.toBe(true);
      expect(errors).toEqual([]);
    } finally {
      await other.close();
    }
  }, 180000);

  test('no uncaught errors in the page', () => {
    expect(pageErrors).toEqual([]);
  });
});
