// The README's quoted sizes and timings stay true: the wasm's size and gzipped size against the
// committed binary, and the intro's per-frame figures against docs/figures.json, which
// `npm run bench -- --save` writes from a real run (with its host). A quote passes when it is within
// 5 % of the measured figure, or within half a unit of its own last digit (a quote of "0.06" stands
// for 0.055–0.065). The tarball and installed sizes are checked where they are measured
// (tests/package.test.ts, which packs them).
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { gzipSync } from 'node:zlib';
import { expect, test } from 'vitest';
import { quoted, quotes } from './helpers/readme.js';

const ROOT = resolve(__dirname, '..');

test('quotes: within 5 %, or within the rounding of the quote', () => {
  expect(quotes('0.06', 0.0586)).toBe(true);
  expect(quotes('0.06', 0.0651)).toBe(false);
  expect(quotes('252', 251.9)).toBe(true);
  expect(quotes('230', 251.9)).toBe(false);
  expect(quotes('1.9', 1.88)).toBe(true);
  expect(quotes('1.9', 2.4)).toBe(false);
  expect(quotes('0.67', 0.7)).toBe(true);
  expect(quotes('0.67', 0.71)).toBe(false);
  expect(quotes('17,000', 17048)).toBe(true);
});

test("the wasm's size and gzipped size as the README quotes them (kB of 1000 bytes, gzip's default level)", () => {
  const wasm = readFileSync(join(ROOT, 'web/lib/gcs-skin.wasm'));
  const measured = { size: wasm.length / 1000, gzipped: gzipSync(wasm).length / 1000 };
  const [size, gzipped] = quoted(/(\d+) KB, (\d+) KB gzipped/);
  expect({ size, gzipped, ok: quotes(size, measured.size) && quotes(gzipped, measured.gzipped) }, `measured ${JSON.stringify(measured)}`)
    .toEqual({ size, gzipped, ok: true });
});

test("the intro's per-frame figures as the bench measured them (docs/figures.json, npm run bench -- --save)", () => {
  const figures = JSON.parse(readFileSync(join(ROOT, 'docs/figures.json'), 'utf8'));
  expect(figures.host, 'the host is named').toMatch(/cores/);
  // (Its ratios to a memcpy are quoted per named run, quiet and loaded: docs/benchmarks.md keeps those runs.)
  const [msPerFrame, vertices] = quoted(/about \*\*([\d.]+) ms per frame for a ([\d,]+)-vertex human\*\*/);
  const measured = { msPerFrame: figures.defaultMsPerFrame, vertices: figures.human.vertices };
  const ok = { msPerFrame: quotes(msPerFrame, measured.msPerFrame), vertices: quotes(vertices, measured.vertices) };
  expect(ok, `README: ${msPerFrame} ms, ${vertices} vertices; measured (${figures.measured}, ${figures.host}): ${JSON.stringify(measured)}`)
    .toEqual({ msPerFrame: true, vertices: true });
});
