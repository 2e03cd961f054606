// Builds both packages: TypeScript → ESM + .d.ts in dist/ (the library `gcs-skin`; its
// package.json `files` leaves out the command line's modules), plus the committed wasm binary;
// then packages/cli/dist (`@gcs-skin/cli`): the command line's modules and every module of dist/
// they import, found by following their relative imports, with the wasm, the licence and the
// command line's docs.
import { execFileSync } from 'node:child_process';
import { copyFileSync, existsSync, mkdirSync, readFileSync, rmSync } from 'node:fs';
import { dirname, join, relative } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createRequire } from 'node:module';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
let tsc;
try {
  tsc = require.resolve('typescript/bin/tsc');
} catch {
  // Installed as a dependency without devDependencies: dist/ ships prebuilt in the tarball.
  console.log('gcs-skin: typescript not installed, keeping the prebuilt dist/');
  process.exit(0);
}
const dist = join(root, 'dist');
rmSync(dist, { recursive: true, force: true });
execFileSync(process.execPath, [tsc, '-p', join(root, 'tsconfig.json')], { stdio: 'inherit' });
mkdirSync(dist, { recursive: true });
copyFileSync(join(root, 'web', 'lib', 'gcs-skin.wasm'), join(dist, 'gcs-skin.wasm'));

/** The command line's entry modules (paths in dist/), as packages/cli/bin and its exports name them. */
const CLI_ENTRIES = ['cli/report.js', 'cli/gltf.js', 'human/cli.js'];
const cli = join(root, 'packages', 'cli');
const cliDist = join(cli, 'dist');
rmSync(cliDist, { recursive: true, force: true });
// Static `from '…'` and `import('…')` with a relative specifier, in .js and .d.ts alike.
const RELATIVE_IMPORT = /(?:\bfrom\s*|\bimport\s*\(\s*)['"](\.{1,2}\/[^'"]+)['"]/g;
const seen = new Set();
const queue = CLI_ENTRIES.flatMap((e) => [e, e.replace(/\.js$/, '.d.ts')]);
while (queue.length) {
  const file = queue.pop();
  if (seen.has(file)) continue;
  seen.add(file);
  const source = join(dist, file);
  if (!existsSync(source)) throw new Error(`build-lib: ${file} is imported by the command line but tsc did not emit it`);
  mkdirSync(dirname(join(cliDist, file)), { recursive: true });
  copyFileSync(source, join(cliDist, file));
  for (const [, spec] of readFileSync(source, 'utf8').matchAll(RELATIVE_IMPORT)) {
    const target = relative(dist, join(dirname(source), spec)).split('\\').join('/');
    queue.push(target, ...(file.endsWith('.d.ts') ? [] : [target.replace(/\.js$/, '.d.ts')]));
  }
}
copyFileSync(join(dist, 'gcs-skin.wasm'), join(cliDist, 'gcs-skin.wasm'));
// The package's own copies of the licence and the command line's docs (git ignores them).
copyFileSync(join(root, 'LICENSE'), join(cli, 'LICENSE'));
mkdirSync(join(cli, 'docs'), { recursive: true });
for (const doc of ['node.md', 'report-json.md']) copyFileSync(join(root, 'docs', doc), join(cli, 'docs', doc));
