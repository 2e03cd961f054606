// The README's quoted sizes and timings stay true: the wasm's size and gzipped size against the
// committed binary, and the intro's and the Measured table's per-frame figures against docs/figures.json, which
// `npm run bench -- --save` writes from a real run (with its host). A quote passes when it is within
// 5 % of the measured figure, or within half a unit of its own last digit (a quote of "0.06" stands
// for 0.055–0.065). The tarball and installed sizes are checked where they are measured
// (tests/package.test.ts, which packs them).
import { readdirSync, readFileSync, statSync } from 'node:fs';
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

test("the Measured table's figures as the bench measured them (docs/figures.json)", () => {
  const figures = JSON.parse(readFileSync(join(ROOT, 'docs/figures.json'), 'utf8'));
  const row = (label: string) => quoted(new RegExp(`\\| ${label.replace(/[()`.]/g, '\\$&')} \\| ([\\d.]+)×? \\|`))[0];
  const [vertices] = quoted(/our human \(([\d,]+) vertices, \d+ joints\)/);
  const rows = {
    vertices: [vertices, figures.human.vertices],
    default: [row('GCS default (smooth)'), figures.defaultMsPerFrame],
    stepped: [row('GCS stepped (`smooth: false`)'), figures.steppedMsPerFrame],
    memcpy: [row('memcpy of the same bytes'), figures.memcpyMsPerFrame],
    ratio: [row('GCS default / memcpy, timed in turn'), figures.defaultOverMemcpy],
  } as const;
  const wrong = Object.entries(rows).filter(([, [quote, measured]]) => !quotes(quote, measured))
    .map(([name, [quote, measured]]) => `${name}: README ${quote}, measured ${measured}`);
  expect(wrong, `measured ${figures.measured} on ${figures.host}`).toEqual([]);
});

/** Every markdown file users read: the README and docs/ (the generated API reference included). */
function userDocs(dir = join(ROOT, 'docs')): string[] {
  return readdirSync(dir).flatMap((name) => {
    const path = join(dir, name);
    if (statSync(path).isDirectory()) return userDocs(path);
    return name.endsWith('.md') ? [path] : [];
  });
}

test('README and docs speak to users: no "session N", "issue N" or "turn N"', () => {
  const internal = /\b(sessions?|issues?|turns?)\s+#?\d+/gi;
  const found = [join(ROOT, 'README.md'), ...userDocs()].flatMap((file) => readFileSync(file, 'utf8').split('\n')
    .flatMap((line, i) => [...line.matchAll(internal)].map((m) => `${file.slice(ROOT.length + 1)}:${i + 1}: ${m[0]}`)));
  expect(found).toEqual([]);
});

test('the internal-reference check catches what it is for', () => {
  const internal = /\b(sessions?|issues?|turns?)\s+#?\d+/i;
  for (const text of ['since session 8', 'Issue 21', 'turn 3', 'issues #4']) expect(internal.test(text), text).toBe(true);
  for (const text of ['a 3-turn twist', 'the issue is', 'session storage']) expect(internal.test(text), text).toBe(false);
});
