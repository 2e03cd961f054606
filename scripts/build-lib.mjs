// Builds both packages. The library `gcs-skin`: web/lib → dist/ (TypeScript → ESM + .d.ts) with
// the committed wasm binary. The command line `@gcs-skin/cli`: packages/cli/src and the library
// modules it imports, compiled by tsc from the same sources (tsc emits only the files the
// command line reaches), laid out as packages/cli/dist/*.js (its own modules) beside
// packages/cli/dist/lib/ (the library's), with the wasm, the licence and the command line's docs.
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, readdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { dirname, join, relative, sep } from 'node:path';
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

// The command line: tsc writes build/cli/packages/cli/src/… and build/cli/web/lib/… (its rootDir
// is the repository); they become packages/cli/dist/… and packages/cli/dist/lib/….
const cli = join(root, 'packages', 'cli');
const cliDist = join(cli, 'dist');
const staging = join(root, 'build', 'cli');
rmSync(staging, { recursive: true, force: true });
rmSync(cliDist, { recursive: true, force: true });
execFileSync(process.execPath, [tsc, '-p', join(cli, 'tsconfig.json')], { stdio: 'inherit' });
const PLACES = [[join(staging, 'packages', 'cli', 'src'), cliDist], [join(staging, 'web', 'lib'), join(cliDist, 'lib')]];
/** Where a staged file goes in packages/cli/dist (null: outside both trees). */
const placed = (file) => {
  for (const [from, to] of PLACES) if (file.startsWith(from + sep)) return join(to, relative(from, file));
  return null;
};
// Static `from '…'` and `import('…')` with a relative specifier, in .js and .d.ts alike.
const RELATIVE_IMPORT = /(\bfrom\s*|\bimport\s*\(\s*)(['"])(\.{1,2}\/[^'"]+)\2/g;
const files = readdirSync(staging, { recursive: true, withFileTypes: true }).filter((e) => e.isFile()).map((e) => join(e.parentPath ?? /** @type {any} */ (e).path, e.name));
for (const file of files) {
  const target = placed(file);
  if (!target) throw new Error(`build-lib: tsc emitted ${relative(root, file)} for the command line, outside packages/cli/src and web/lib`);
  const text = readFileSync(file, 'utf8').replace(RELATIVE_IMPORT, (all, head, quote, spec) => {
    const to = placed(join(dirname(file), spec));
    if (!to) throw new Error(`build-lib: ${relative(root, file)} imports ${spec}, outside packages/cli/src and web/lib`);
    const moved = relative(dirname(target), to).split(sep).join('/');
    return `${head}${quote}${moved.startsWith('.') ? moved : `./${moved}`}${quote}`;
  });
  mkdirSync(dirname(target), { recursive: true });
  writeFileSync(target, text);
}
rmSync(staging, { recursive: true, force: true });
copyFileSync(join(dist, 'gcs-skin.wasm'), join(cliDist, 'lib', 'gcs-skin.wasm'));
// The package's own copies of the licence and the command line's docs (git ignores them).
copyFileSync(join(root, 'LICENSE'), join(cli, 'LICENSE'));
mkdirSync(join(cli, 'docs'), { recursive: true });
for (const doc of ['node.md', 'report-json.md', 'method.md']) copyFileSync(join(root, 'docs', doc), join(cli, 'docs', doc));
