// The API reference (docs/api, `npm run docs`): TypeDoc over every entry of both packages'
// "exports", failing on an undocumented export (typedoc.json: validation.notDocumented,
// treatWarningsAsErrors), and the committed markdown as the doc comments generate it today.
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, expect, test } from 'vitest';

const ROOT = resolve(__dirname, '..');
const config = JSON.parse(readFileSync(join(ROOT, 'typedoc.json'), 'utf8'));
const out = mkdtempSync(join(tmpdir(), 'gcs-api-'));
afterAll(() => rmSync(out, { recursive: true, force: true }));

/** A package's code entries: its "exports" with an `import`, as source files (dist/x.js → src x.ts). */
function entries(packageDir: string, sourceDir: string): string[] {
  const manifest = JSON.parse(readFileSync(join(ROOT, packageDir, 'package.json'), 'utf8'));
  return Object.values(manifest.exports as Record<string, string | { import?: string }>)
    .flatMap((target) => (typeof target === 'object' && target.import ? [target.import] : []))
    .map((file) => join(packageDir, sourceDir, file.replace(/^\.\/dist\//, '').replace(/\.js$/, '.ts')).replace(/^\.\//, ''));
}

test("typedoc.json documents every entry of both packages' exports", () => {
  const wanted = [...entries('.', 'web/lib'), ...entries('packages/cli', 'src')].sort();
  expect(wanted.length).toBeGreaterThanOrEqual(9);
  expect([...config.entryPoints].sort()).toEqual(wanted);
  expect(config.validation?.notDocumented).toBe(true);
  expect(config.treatWarningsAsErrors).toBe(true);
});

test('every exported symbol has a doc comment, and docs/api is what the comments generate', () => {
  const r = spawnSync(process.execPath, [join(ROOT, 'node_modules/typedoc/bin/typedoc'), '--out', out], { cwd: ROOT, encoding: 'utf8' });
  // TypeDoc prints each undocumented symbol as a warning, and fails with warnings as errors.
  const undocumented = `${r.stdout}${r.stderr}`.split('\n').filter((line) => /warning|error/i.test(line) && !/Found 0 errors and 0 warnings/.test(line));
  expect({ status: r.status, undocumented }).toEqual({ status: 0, undocumented: [] });
  const generated = readdirSync(out).sort();
  const committed = readdirSync(join(ROOT, 'docs/api')).sort();
  expect(committed, 'docs/api holds the files npm run docs writes').toEqual(generated);
  const stale = generated.filter((f) => readFileSync(join(out, f), 'utf8') !== readFileSync(join(ROOT, 'docs/api', f), 'utf8'));
  expect(stale, 'stale pages in docs/api: run npm run docs').toEqual([]);
}, 180000);
