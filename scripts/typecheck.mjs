// npm run typecheck: every TypeScript project of the repository, type-checked without emitting —
// the library, the demo (with the browser tests), the command line, the node tests, and the
// scripts (JavaScript, checkJs; they import the built dist/, so build:lib runs first). Two at a
// time (tsc is single-threaded). Exits 1 when any project has an error.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
/** The projects, as tsconfig paths from the repository's root (tests/typecheck.test.ts reads this list). */
export const PROJECTS = ['tsconfig.json', 'web/demo/tsconfig.json', 'packages/cli/tsconfig.json', 'tests/tsconfig.json', 'scripts/tsconfig.json'];

function check(project) {
  const tsc = createRequire(import.meta.url).resolve('typescript/bin/tsc');
  return new Promise((done) => {
    const child = spawn(process.execPath, [tsc, '-p', join(root, project), '--noEmit', '--pretty', 'false'], { cwd: root });
    let out = '';
    child.stdout.on('data', (d) => { out += d; });
    child.stderr.on('data', (d) => { out += d; });
    child.on('close', (code) => done({ project, code, out }));
  });
}

if (process.argv[1] && fileURLToPath(import.meta.url) === process.argv[1]) {
  const queue = [...PROJECTS];
  const results = [];
  await Promise.all([0, 1].map(async () => {
    while (queue.length) results.push(await check(queue.shift()));
  }));
  let failed = 0;
  for (const { project, code, out } of results) {
    if (code === 0) continue;
    failed++;
    process.stderr.write(`typecheck: ${project}:\n${out}`);
  }
  if (failed) {
    console.error(`typecheck: ${failed} of ${PROJECTS.length} projects have errors`);
    process.exit(1);
  }
  console.log(`typecheck: ${PROJECTS.length} projects clean (${PROJECTS.join(', ')})`);
}
