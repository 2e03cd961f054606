// Packs both packages as `npm publish` would, from a copy of their sources (the library's
// `prepack` builds dist/ and packages/cli/dist there, never under the feet of other test files
// that use this checkout's builds); and makes a git repository of this checkout for the README's
// git-URL install. Used by tests/package.test.ts, tests/clone.test.ts and tests/browser/app.test.ts.
import { execFileSync } from 'node:child_process';
import { cpSync, existsSync, mkdirSync, readFileSync, readdirSync, rmSync, statSync, symlinkSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';

export const ROOT = resolve(__dirname, '../..');
export const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';

/** What the tarballs are packed from: the files both packages' `files`, `prepack` and build read. */
const SOURCES = ['package.json', 'package-lock.json', 'tsconfig.json', 'README.md', 'LICENSE', 'bin', 'docs/node.md', 'docs/report-json.md', 'docs/method.md',
  'web/lib', 'wasm/include', 'scripts/build-lib.mjs', 'packages/cli/package.json', 'packages/cli/tsconfig.json', 'packages/cli/src', 'packages/cli/bin', 'packages/cli/README.md'];

export interface Tarballs {
  /** gcs-skin */
  library: string;
  /** @gcs-skin/cli */
  cli: string;
  version: string;
}

/**
 * Packs into `dir`. `version`, when given, replaces both packages' version in the copy (the npx
 * test needs a version no earlier run left in npm's npx cache).
 */
export function packTarballs(dir: string, version?: string): Tarballs {
  const src = join(dir, 'src');
  for (const entry of SOURCES) cpSync(join(ROOT, entry), join(src, entry), { recursive: true });
  // This checkout's node_modules, entry by entry, but for gcs-skin (the workspace's link to the
  // root): the copy's own, so that the command line's build reads the copy's dist/.
  mkdirSync(join(src, 'node_modules'));
  for (const entry of readdirSync(join(ROOT, 'node_modules')))
    if (entry !== 'gcs-skin') symlinkSync(join(ROOT, 'node_modules', entry), join(src, 'node_modules', entry));
  symlinkSync('..', join(src, 'node_modules', 'gcs-skin'));
  if (version) {
    for (const file of ['package.json', 'packages/cli/package.json']) {
      const manifest = JSON.parse(readFileSync(join(src, file), 'utf8'));
      // @gcs-skin/cli's peer gcs-skin: the same version, as a release pins it.
      const peers = manifest.peerDependencies?.['gcs-skin'] ? { peerDependencies: { ...manifest.peerDependencies, 'gcs-skin': version } } : {};
      writeFileSync(join(src, file), JSON.stringify({ ...manifest, version, ...peers }, null, 2));
    }
  }
  const pack = (cwd: string, ...flags: string[]) => {
    const before = new Set(readdirSync(dir));
    execFileSync(npm, ['pack', '--silent', '--pack-destination', dir, ...flags], { cwd, env: userEnv(), stdio: ['ignore', 'pipe', 'pipe'] });
    const made = readdirSync(dir).filter((f) => f.endsWith('.tgz') && !before.has(f));
    if (made.length !== 1) throw new Error(`npm pack in ${cwd} wrote ${made.length} tarballs`);
    return join(dir, made[0]);
  };
  // The library's prepack builds both packages; the CLI's (the same script) need not run again.
  const library = pack(src);
  const cli = pack(join(src, 'packages/cli'), '--ignore-scripts');
  if (!existsSync(join(src, 'packages/cli/dist/report.js'))) throw new Error('prepack did not build packages/cli/dist');
  rmSync(src, { recursive: true, force: true });
  return { library, cli, version: version ?? JSON.parse(readFileSync(join(ROOT, 'package.json'), 'utf8')).version };
}

/**
 * The environment of a user's shell: this process's, without the npm_* variables npm sets for the
 * script that runs the tests (npm_config_local_prefix would point npx at this checkout, an empty
 * npm_config_yes makes npx refuse to install).
 */
export function userEnv(extra: Record<string, string> = {}): NodeJS.ProcessEnv {
  const env = Object.fromEntries(Object.entries(process.env).filter(([k]) => !/^npm_/i.test(k)));
  return { ...env, ...extra };
}

/**
 * A git repository in `dir` holding this checkout's files as they are on disk (committed or not,
 * untracked ones included, ignored ones left out) in one commit: what a push of the working tree
 * would publish. Returns its `git+file://` URL, the form `npm install` takes for a git dependency.
 */
export function snapshotRepository(dir: string): string {
  const files = execFileSync('git', ['ls-files', '-z', '--cached', '--others', '--exclude-standard'], { cwd: ROOT, encoding: 'utf8' })
    .split('\0').filter((f) => f && existsSync(join(ROOT, f)));
  for (const f of files) {
    mkdirSync(dirname(join(dir, f)), { recursive: true });
    cpSync(join(ROOT, f), join(dir, f));
  }
  const git = (...args: string[]) => execFileSync('git', args, { cwd: dir, stdio: 'ignore' });
  git('init', '-q');
  git('add', '-A');
  git('-c', 'user.name=test', '-c', 'user.email=test@localhost', '-c', 'commit.gpgsign=false', 'commit', '-q', '-m', 'snapshot');
  return `git+file://${dir}`;
}

/** Bytes of a file. */
export const sizeOf = (file: string) => statSync(file).size;
