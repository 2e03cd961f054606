// Builds the npm package into dist/: TypeScript → ESM + .d.ts, plus the committed wasm binary.
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
rmSync(join(root, 'dist'), { recursive: true, force: true });
execFileSync(process.execPath, [tsc, '-p', join(root, 'tsconfig.json')], { stdio: 'inherit' });
mkdirSync(join(root, 'dist'), { recursive: true });
copyFileSync(join(root, 'web', 'lib', 'gcs-skin.wasm'), join(root, 'dist', 'gcs-skin.wasm'));
