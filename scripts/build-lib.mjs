// Builds both packages. The library `gcs-skin`: web/lib → dist/ (TypeScript → ESM + .d.ts) with
// the committed wasm binary. The command line `@gcs-skin/cli`: packages/cli/src → packages/cli/dist
// (its own modules, which import the library by name), with the licence and the command line's docs.
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, rmSync } from 'node:fs';
import { dirname, join } from 'node:path';
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

// The command line: packages/cli/src → packages/cli/dist, its own modules only. It imports the
// library by its package name (gcs-skin, gcs-skin/three, gcs-skin/gltf, …): in this repository the
// workspace links node_modules/gcs-skin to the root (packages/cli's devDependency file:../..), so
// tsc reads the dist/ built above; an install gets the library as @gcs-skin/cli's peer.
const cli = join(root, 'packages', 'cli');
rmSync(join(cli, 'dist'), { recursive: true, force: true });
execFileSync(process.execPath, [tsc, '-p', join(cli, 'tsconfig.json')], { stdio: 'inherit' });
// The package's own copies of the licence and the command line's docs (git ignores them).
copyFileSync(join(root, 'LICENSE'), join(cli, 'LICENSE'));
mkdirSync(join(cli, 'docs'), { recursive: true });
for (const doc of ['node.md', 'report-json.md', 'method.md']) copyFileSync(join(root, 'docs', doc), join(cli, 'docs', doc));
