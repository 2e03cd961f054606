#!/usr/bin/env node
// `gcs-skin <command>` from the library package. The command line and its glTF readers are the
// package @gcs-skin/cli, so that `npm install gcs-skin` stays lean; `npx gcs-skin report` fetches
// this package (npx runs the bin of the package named like the command), and this file hands the
// arguments to @gcs-skin/cli's bin: the one installed beside gcs-skin or in the current project,
// else the same version fetched with `npm exec` (as `eslint --init` runs `npm init @eslint/config`).
import { spawnSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { pathToFileURL } from 'node:url';

const CLI = '@gcs-skin/cli';
const { version } = JSON.parse(readFileSync(new URL('../package.json', import.meta.url), 'utf8'));
/** How to install the command line, true whether or not it is on the registry yet. */
const INSTALL = `install ${CLI} beside gcs-skin: npm install -D ${CLI}@${version} once it is on the registry, ` +
  `until then its tarball (in a clone of gcs-skin: npm install && npm pack -w packages/cli, then npm install -D <clone>/gcs-skin-cli-${version}.tgz)`;
const FETCHED = 'GCS_SKIN_CLI_FETCHED'; // set for the fetched CLI: never fetch twice

/** The path of @gcs-skin/cli's bin, resolved beside this package or from the current folder; null when absent. */
function installedCli() {
  for (const from of [import.meta.url, join(process.cwd(), 'package.json')]) {
    try {
      const manifest = createRequire(from).resolve(`${CLI}/package.json`);
      return join(dirname(manifest), JSON.parse(readFileSync(manifest, 'utf8')).bin['gcs-skin']);
    } catch { /* not there */ }
  }
  return null;
}

const bin = installedCli();
if (bin) {
  await import(pathToFileURL(bin).href); // it reads process.argv: the same arguments
} else if (process.env[FETCHED]) {
  process.stderr.write(`gcs-skin: npm exec ran without ${CLI}; ${INSTALL}\n`);
  process.exitCode = 1;
} else {
  process.stderr.write(`gcs-skin: the command line is the package ${CLI}; running ${CLI}@${version} through npm exec ` +
    `(if npm cannot find it, or to keep it at hand: ${INSTALL})\n`);
  // No --yes: npm asks on a terminal (or refuses where the user's npmrc says yes=false), as npx did for gcs-skin.
  const args = ['exec', `--package=${CLI}@${version}`, '--', 'gcs-skin', ...process.argv.slice(2)];
  const env = { ...process.env, [FETCHED]: '1' };
  // Under npx/npm exec, npm_execpath is the npm that runs us: use the same one.
  const npmCli = process.env.npm_execpath?.endsWith('npm-cli.js') ? process.env.npm_execpath : null;
  const r = npmCli
    ? spawnSync(process.execPath, [npmCli, ...args], { stdio: 'inherit', env })
    : spawnSync(process.platform === 'win32' ? 'npm.cmd' : 'npm', args, { stdio: 'inherit', env, shell: process.platform === 'win32' });
  if (r.error) process.stderr.write(`gcs-skin: cannot run npm (${r.error.message}); ${INSTALL}\n`);
  process.exitCode = r.status ?? 1;
}
