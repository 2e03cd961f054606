// What an app gets from `npm install <specs…>`: installs them into an empty temp folder and prints
// each installed package's unpacked size (bytes on disk, files only) and the total, as JSON.
//   node scripts/install-size.mjs ./gcs-skin-0.1.0.tgz three@0.187.0
// tests/package.test.ts uses installedSizes() on a library user's install of the packed tarball.
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readdirSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

function bytesUnder(path) {
  const s = statSync(path);
  if (!s.isDirectory()) return s.size;
  return readdirSync(path).reduce((sum, name) => sum + bytesUnder(join(path, name)), 0);
}

/** Every package in `app`/node_modules (scoped ones by their full name) and its size in bytes, largest first. */
export function installedSizes(app) {
  const modules = join(app, 'node_modules');
  const names = readdirSync(modules).filter((n) => !n.startsWith('.'))
    .flatMap((n) => (n.startsWith('@') ? readdirSync(join(modules, n)).map((m) => `${n}/${m}`) : [n]));
  const packages = Object.fromEntries(names.map((n) => [n, bytesUnder(join(modules, n))]).sort((a, b) => b[1] - a[1]));
  return { packages, total: Object.values(packages).reduce((a, b) => a + b, 0) };
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const specs = process.argv.slice(2).map((s) => (/\.tgz$/.test(s) ? resolve(s) : s));
  if (!specs.length) {
    console.error('usage: node scripts/install-size.mjs <tarball|package@version>…');
    process.exit(2);
  }
  const app = mkdtempSync(join(tmpdir(), 'gcs-skin-size-'));
  try {
    writeFileSync(join(app, 'package.json'), JSON.stringify({ name: 'size-probe', private: true }));
    const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';
    const r = spawnSync(npm, ['install', '--no-audit', '--no-fund', '--prefer-offline', ...specs], { cwd: app, encoding: 'utf8' });
    if (r.status !== 0) throw new Error(`npm install failed:\n${r.stderr}`);
    console.log(JSON.stringify({ specs: process.argv.slice(2), ...installedSizes(app) }, null, 2));
  } finally {
    rmSync(app, { recursive: true, force: true });
  }
}
