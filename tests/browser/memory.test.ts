// The demo's memory under a slider drag, in headless Chromium: 200 moves of the section slider
// (each one a GCS rebuild), or 200 changes of the classic model's contours (each one a classic
// rebuild), must not grow the tab's memory by more than 5 % after the first 40.
// Measured after each sweep of 20 moves, garbage collected first (CDP HeapProfiler.collectGarbage),
// growth as the peak of the last two samples over the peak of those at 40 and 60 moves:
//   JS heap      CDP Performance.getMetrics JSHeapUsedSize, and at 40 and 200 moves a heap snapshot
//                split into the page's JavaScript objects, V8's compiled code (it grows as
//                functions are optimised) and native memory (DOM, array buffers — wasm memory
//                among them —, the browser's performance-timeline entries);
//   wasm         wasm memory's size and the core's heap in use (gcs_heap_in_use), from the page;
//   WebGL        the geometries and textures the renderer holds (renderer.info.memory);
//   processes    resident memory (VmRSS) of this browser's renderer and GPU processes (Linux /proc):
//                what the operating system sees of the tab, WebGL buffers in software included.
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { describe, expect, test } from 'vitest';
import type { CDPSession, Page } from 'playwright-core';
import { demoInChromium, skipReason, type DemoInChromium } from './harness.js';

/** The section slider dragged up and back over its stops: 20 moves a sweep. */
const SWEEP = [3, 4, 5, 6, 8, 10, 12, 16, 24, 32, 48, 32, 24, 16, 12, 10, 8, 6, 5, 4];
/** The classic model's contours, up and back: 20 changes a sweep. */
const CONTOURS = [8, 10, 12, 14, 16, 18, 20, 22, 24, 25, 26, 28, 26, 24, 22, 20, 18, 16, 12, 10];
const MOVES = 200, SETTLED = 40;

interface PageMemory { wasmBytes: number; heapInUse: number; geometries: number; textures: number }
interface Sample extends PageMemory { moves: number; jsHeap: number; rendererRss: number | null; gpuRss: number | null }

/** Resident kB of this process's Chromium renderers and GPU process (descendants of this node process), or nulls off Linux. */
function chromiumRss(): { renderer: number | null; gpu: number | null } {
  if (!existsSync('/proc/self/status')) return { renderer: null, gpu: null };
  const parent = new Map<number, number>(), type = new Map<number, string>(), rss = new Map<number, number>();
  for (const name of readdirSync('/proc')) {
    if (!/^\d+$/.test(name)) continue;
    const pid = Number(name);
    try {
      parent.set(pid, Number(readFileSync(`/proc/${pid}/stat`, 'utf8').split(') ')[1].split(' ')[1]));
      type.set(pid, /--type=([\w-]+)/.exec(readFileSync(`/proc/${pid}/cmdline`, 'utf8'))?.[1] ?? '');
      rss.set(pid, Number(/VmRSS:\s+(\d+)/.exec(readFileSync(`/proc/${pid}/status`, 'utf8'))?.[1] ?? 0));
    } catch { /* the process ended meanwhile */ }
  }
  const ours = (pid: number) => {
    for (let p = parent.get(pid); p !== undefined && p > 1; p = parent.get(p)) if (p === process.pid) return true;
    return false;
  };
  let renderer = 0, gpu = 0;
  for (const [pid, t] of type) {
    if (!ours(pid)) continue;
    if (t === 'renderer') renderer += rss.get(pid) ?? 0;
    if (t === 'gpu-process') gpu += rss.get(pid) ?? 0;
  }
  return { renderer: renderer * 1024, gpu: gpu * 1024 };
}

/** Moves the section slider's track to each count in turn, waiting for each rebuild. */
async function drag(page: Page, counts: number[]): Promise<void> {
  await page.evaluate(async (list) => {
    const track = document.querySelector<HTMLInputElement>('input.sections-track');
    if (!track) throw new Error('no section slider on the page');
    for (const n of list) {
      const builds = window.__demo.gcsBuilds();
      // The track's stops: every count to 16, then 20, 24, 32, 48… (web/demo/section-stops.ts).
      const index = n <= 16 ? n - 3 : 14 + [20, 24, 32, 48].indexOf(n);
      track.value = String(index);
      track.dispatchEvent(new Event('input', { bubbles: true }));
      await new Promise<void>((resolve) => {
        const wait = () => (window.__demo.gcsBuilds() > builds && window.__demo.sectionsPerPart() === n ? resolve() : requestAnimationFrame(wait));
        wait();
      });
    }
  }, counts);
}

/** Self sizes in a heap snapshot (bytes): the page's JavaScript objects, V8's compiled code, native memory. */
async function heapParts(cdp: CDPSession): Promise<{ objects: number; code: number; native: number }> {
  await cdp.send('HeapProfiler.collectGarbage');
  let text = '';
  const onChunk = (e: { chunk: string }) => { text += e.chunk; };
  cdp.on('HeapProfiler.addHeapSnapshotChunk', onChunk);
  await cdp.send('HeapProfiler.takeHeapSnapshot', { reportProgress: false });
  cdp.off('HeapProfiler.addHeapSnapshotChunk', onChunk);
  const snap = JSON.parse(text) as { snapshot: { meta: { node_fields: string[]; node_types: [string[]] } }; nodes: number[] };
  const fields = snap.snapshot.meta.node_fields, types = snap.snapshot.meta.node_types[0];
  const type = fields.indexOf('type'), size = fields.indexOf('self_size');
  const parts = { objects: 0, code: 0, native: 0 };
  for (let i = 0; i < snap.nodes.length; i += fields.length) {
    const t = types[snap.nodes[i + type]];
    parts[t === 'code' ? 'code' : t === 'native' ? 'native' : 'objects'] += snap.nodes[i + size];
  }
  return parts;
}

async function sample(page: Page, cdp: CDPSession, moves: number): Promise<Sample> {
  await cdp.send('HeapProfiler.collectGarbage');
  const metrics = (await cdp.send('Performance.getMetrics')).metrics;
  const jsHeap = metrics.find((m) => m.name === 'JSHeapUsedSize')?.value ?? NaN;
  const mem = await page.evaluate(() => (window.__demo as unknown as { memory(): PageMemory }).memory());
  const { renderer, gpu } = chromiumRss();
  return { moves, jsHeap, ...mem, rendererRss: renderer, gpuRss: gpu };
}

/**
 * MOVES slider moves (`move` through `sweep`, one sweep of 20 at a time) on the demo's human:
 * samples after every sweep, heap snapshots at SETTLED and MOVES; the goal asserted.
 */
async function memoryUnderDrag(demo: DemoInChromium, what: string, builds: 'gcsBuilds' | 'classicBuilds', sweep: number[],
  move: (page: Page, counts: number[]) => Promise<void>): Promise<void> {
  const { page, errors } = await demo.open('');
  await page.setViewportSize({ width: 640, height: 360 }); // software rendering: fewer pixels, a faster drag
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Performance.enable');
  const samples: Sample[] = [];
  let settledParts: Awaited<ReturnType<typeof heapParts>> | null = null;
  for (let moves = 0; moves < MOVES; moves += sweep.length) {
    await move(page, sweep);
    samples.push(await sample(page, cdp, moves + sweep.length));
    if (moves + sweep.length === SETTLED) settledParts = await heapParts(cdp);
  }
  const mb = (x: number | null) => (x === null ? 'n/a' : `${(x / 2 ** 20).toFixed(1)} MB`);
  for (const s of samples)
    console.log(`${what}, after ${s.moves} moves: JS heap ${mb(s.jsHeap)}, wasm memory ${mb(s.wasmBytes)} (heap in use ${mb(s.heapInUse)}), ` +
      `WebGL ${s.geometries} geometries / ${s.textures} textures, renderer RSS ${mb(s.rendererRss)}, GPU process RSS ${mb(s.gpuRss)}`);
  const at = (n: number) => samples.find((s) => s.moves === n)!;
  const settled = at(SETTLED), end = at(MOVES);
  // Growth: the larger of the two samples after the last two sweeps over the larger of those at
  // SETTLED and one sweep later (a peak against a peak).
  const peak = (key: keyof Sample, first: number) => Math.max(at(first)[key] as number, at(first + sweep.length)[key] as number);
  const growth = (key: keyof Sample) => peak(key, MOVES - sweep.length) / peak(key, SETTLED) - 1;
  const figures = ['jsHeap', 'wasmBytes', 'heapInUse', 'rendererRss', 'gpuRss'] as const;
  const pct = (x: number) => `${(100 * x).toFixed(2)} %`;
  console.log(`${what}, growth from ${SETTLED} to ${MOVES} moves: ${figures.map((k) => `${k} ${settled[k] === null ? 'n/a' : pct(growth(k))}`).join(', ')}`);
  const [heapSettled, heapEnd] = [settledParts!, await heapParts(cdp)];
  const kb = (x: number) => `${(x / 1024).toFixed(0)} kB`;
  console.log(`${what}, JS heap by part, ${SETTLED} → ${MOVES} moves: the page's objects ${kb(heapSettled.objects)} → ${kb(heapEnd.objects)} (${pct(heapEnd.objects / heapSettled.objects - 1)}), ` +
    `compiled code ${kb(heapSettled.code)} → ${kb(heapEnd.code)}, native ${kb(heapSettled.native)} → ${kb(heapEnd.native)}`);
  expect(await page.evaluate((k) => window.__demo[k](), builds)).toBeGreaterThanOrEqual(MOVES);
  // The tab as the operating system sees it and wasm memory: ≤ 5 %. The core's heap in use is
  // printed, not asserted here: in the page it moves between two levels one 1.3 MB block apart,
  // early or late as the drag's timing falls (tests/lib/memory.test.ts holds it, rebuild by
  // rebuild, to ≤ 5 % and to 0 bytes after dispose).
  for (const k of ['wasmBytes', 'rendererRss', 'gpuRss'] as const) if (settled[k] !== null) expect(growth(k), k).toBeLessThanOrEqual(0.05);
  // The page's JavaScript objects ≤ 5 % (JSHeapUsedSize also counts V8's compiled code: printed above).
  expect(heapEnd.objects / heapSettled.objects - 1).toBeLessThanOrEqual(0.05);
  // Each rebuild frees its old geometry and textures: the renderer holds as many as before.
  expect(end.geometries).toBeLessThanOrEqual(settled.geometries);
  expect(end.textures).toBeLessThanOrEqual(settled.textures);
  expect(errors).toEqual([]);
  await page.close();
}

/** The classic model's contour box (lil-gui's number input, folded or not): each count entered, waiting for its rebuild. */
async function typeContours(page: Page, counts: number[]): Promise<void> {
  await page.evaluate(async (list) => {
    const box = [...document.querySelectorAll('.lil-gui .controller.number')].find((c) => c.querySelector('.name')?.textContent === 'contours');
    const input = box?.querySelector('input');
    if (!input) throw new Error('no contours box on the page');
    for (const n of list) {
      const builds = window.__demo.classicBuilds();
      input.value = String(n);
      input.dispatchEvent(new Event('input', { bubbles: true }));
      input.dispatchEvent(new Event('change', { bubbles: true }));
      await new Promise<void>((resolve) => {
        const wait = () => (window.__demo.classicBuilds() > builds ? resolve() : requestAnimationFrame(wait));
        wait();
      });
    }
  }, counts);
}

const reason = skipReason();
if (reason) console.log(reason);

describe.skipIf(!!reason)('the demo under a slider drag', () => {
  const demo = demoInChromium();

  test('200 section-slider moves grow the tab\'s memory by at most 5 % after the first 40', async () => {
    await memoryUnderDrag(demo, 'section slider', 'gcsBuilds', SWEEP, drag);
  }, 600000);

  test('200 classic contour changes: the same', async () => {
    await memoryUnderDrag(demo, 'classic contours', 'classicBuilds', CONTOURS, typeContours);
  }, 900000);
});
