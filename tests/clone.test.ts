// A fresh clone as the README's newcomer meets it: `npm install` builds both packages (the private
// workspace packages/prepare) and leaves the tree clean; the command line then runs as the "Two
// commands" section shows it; and the README's tarball route ("Installing before the registry
// release") runs as written, line by line in bash, from `git clone` to `npm install -D` of the
// command line's tarball in another app, whose `npx gcs-skin report` then works. The clone is of a
// git repository made from this checkout's files (tests/helpers/pack.ts), standing in for the
// README's `https://github.com/OWNER/gcs-skin.git`.
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, expect, test } from 'vitest';
import { snapshotRepository, userEnv } from './helpers/pack.js';
import { INSTALLING, readme, README_REPOSITORY, readmeBlocks } from './helpers/readme.js';

let dir = '';
let repository = '';
const env = userEnv({ npm_config_prefer_offline: 'true', npm_config_audit: 'false', npm_config_fund: 'false', npm_config_update_notifier: 'false' });

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-skin-clone-'));
  // Named as the README's URL ends, so `git clone` makes the folder the README's next `cd` names.
  repository = snapshotRepository(join(dir, 'origin/gcs-skin.git')).replace(/^git\+/, '');
}, 60000);
afterAll(() => {
  rmSync(dir, { recursive: true, force: true });
  // npx in the clone runs the project's own bin through an install of it in npm's npx cache: drop it.
  const npxCache = join(spawnSync('npm', ['config', 'get', 'cache'], { env, encoding: 'utf8' }).stdout.trim(), '_npx');
  for (const entry of existsSync(npxCache) ? readdirSync(npxCache) : []) {
    const manifest = join(npxCache, entry, 'package.json');
    if (existsSync(manifest) && readFileSync(manifest, 'utf8').includes(dir)) rmSync(join(npxCache, entry), { recursive: true, force: true });
  }
});

function bash(script: string, cwd: string) {
  const r = spawnSync('bash', ['-euo', 'pipefail', '-c', script], { cwd, env: { ...env, BASH_ENV: '' }, encoding: 'utf8' });
  expect(r.status, `${script}\n${r.stdout}\n${r.stderr}`).toBe(0);
  return r;
}

test("the README's tarball route as written, then the command line in a fresh clone as the README shows it", () => {
  const blocks = readmeBlocks(INSTALLING, 'sh');
  const route = blocks.find((b) => b.includes('git clone'));
  expect(route, 'the tarball route').toBeDefined();
  expect(route).toContain(README_REPOSITORY);
  // my-app: any project (create-vite's, in the README's three.js section).
  mkdirSync(join(dir, 'my-app'));
  writeFileSync(join(dir, 'my-app/package.json'), JSON.stringify({ name: 'my-app', private: true, type: 'module' }));
  const t0 = performance.now();
  bash(route!.replaceAll(README_REPOSITORY, repository), dir);
  const routeMs = Math.round(performance.now() - t0);

  // my-app holds both packages from their tarballs, and its npx gcs-skin runs the command line.
  const app = join(dir, 'my-app');
  const built = (pkg: string, entry: string) => {
    const manifest = JSON.parse(readFileSync(join(app, 'node_modules', pkg, 'package.json'), 'utf8'));
    return join(app, 'node_modules', pkg, manifest.exports[entry].import);
  };
  for (const file of [built('gcs-skin', './three'), built('@gcs-skin/cli', './report')]) expect(existsSync(file), file).toBe(true);
  bash('npx gcs-skin human --vertices 3000 -o model.glb && npx gcs-skin report model.glb --frames 4 --time-ms 5 --json > report.json', app);
  const report = JSON.parse(readFileSync(join(app, 'report.json'), 'utf8'));
  expect(report.meshes[0].methods.gcs.fidelity.nonFinite).toBe(0);

  // The clone: `npm install` changed no tracked file and left nothing but the two tarballs.
  const clone = join(dir, 'gcs-skin');
  const status = spawnSync('git', ['status', '--porcelain'], { cwd: clone, encoding: 'utf8' }).stdout.trim().split('\n').sort();
  expect(status).toEqual(['?? gcs-skin-0.1.0.tgz', '?? gcs-skin-cli-0.1.0.tgz']);

  // The "Two commands" section's command line, exactly as it reads there.
  const t1 = performance.now();
  for (const command of ['npx gcs-skin human -o human.glb', 'npx gcs-skin report human.glb']) {
    expect(readme()).toContain(`\`${command}\``);
    const r = bash(command, clone);
    if (command.includes('report')) expect(r.stdout).toMatch(/GCS/);
  }
  expect(readdirSync(clone)).toContain('human.glb');
  console.log(`clone test: tarball route ${routeMs} ms, command line in the clone ${Math.round(performance.now() - t1)} ms`);
}, 600000);
