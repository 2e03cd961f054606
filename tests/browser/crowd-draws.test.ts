// A crowd's draw calls, counted on WebGL itself: the demo's crowd page (?crowd=N, GPU backend,
// the joint-level path) issues one instanced draw per skin for all N characters, one joint pass and
// one node pass (each a draw into float render targets holding every instance's joints or nodes),
// whatever N. Every draw
// call of a frame is recorded in the page (the context's draw functions wrapped before the page's
// own code runs), with its instance count and whether it drew into a framebuffer of its own.
import { describe, expect, test } from 'vitest';
import type { Page } from 'playwright-core';
import { demoInChromium, skipReason } from './harness.js';

interface Draw { call: string; instances: number; offscreen: boolean }

/** Wraps WebGL2's draw calls: window.__draws() gives the calls of the last whole frame. */
function recordDraws(): void {
  const proto = WebGL2RenderingContext.prototype as unknown as Record<string, (...a: unknown[]) => unknown>;
  let frame: Draw[] = [], last: Draw[] = [];
  const tick = () => { last = frame; frame = []; requestAnimationFrame(tick); };
  requestAnimationFrame(tick);
  const instanced: Record<string, number> = { drawArraysInstanced: 3, drawElementsInstanced: 4 };
  for (const call of ['drawArrays', 'drawElements', 'drawRangeElements', 'drawArraysInstanced', 'drawElementsInstanced']) {
    const f = proto[call];
    proto[call] = function (this: WebGL2RenderingContext, ...a: unknown[]) {
      frame.push({ call, instances: call in instanced ? (a[instanced[call]] as number) : 1, offscreen: this.getParameter(this.DRAW_FRAMEBUFFER_BINDING) !== null });
      return f.apply(this, a);
    };
  }
  Object.assign(window, { __draws: () => last });
}

const reason = skipReason();
if (reason) console.log(reason);

describe.skipIf(!!reason)('a crowd draws once per skin plus one joint pass and one node pass', () => {
  const demo = demoInChromium();

  /** The crowd page with N characters, and the draws of one of its frames once it runs. */
  async function drawsOf(n: number): Promise<{ draws: Draw[]; page: Page }> {
    const page = await demo.context.newPage();
    await page.setViewportSize({ width: 320, height: 180 }); // software rendering: fewer pixels
    await page.addInitScript(recordDraws);
    const errors: string[] = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(`${demo.server.url}?crowd=${n}&backend=gpu&path=joints`);
    await page.waitForFunction(() => window.__crowd !== undefined && window.__crowd.frame() > 2, null, { timeout: 120000 });
    expect(await page.evaluate(() => window.__crowd.drawn())).toBe(n);
    const draws = await page.evaluate(() => (window as unknown as { __draws: () => Draw[] }).__draws());
    expect(errors).toEqual([]);
    return { draws, page };
  }

  test('100 characters: one instanced draw of all 100, one joint pass and one node pass, and no more draws than with 10', async () => {
    const many = await drawsOf(100), few = await drawsOf(10);
    const summary = (d: Draw[]) => d.map((x) => `${x.call}×${x.instances}${x.offscreen ? ' (offscreen)' : ''}`).join(', ');
    console.log(`crowd of 100, one frame's draws: ${summary(many.draws)}; crowd of 10: ${summary(few.draws)}`);
    // The human has one skin: one draw of its 100 instances…
    expect(many.draws.filter((d) => d.instances === 100 && !d.offscreen)).toHaveLength(1);
    // …one joint pass and one node pass, into the render targets every instance's joints and nodes share.
    expect(many.draws.filter((d) => d.offscreen)).toHaveLength(2);
    // Nothing else grows with the count: the same draws as 10 characters (the scene's ground and the like).
    expect(many.draws.length).toBe(few.draws.length);
    expect(many.draws.filter((d) => d.instances > 1)).toHaveLength(1);
    await many.page.close();
    await few.page.close();
  }, 240000);
});
