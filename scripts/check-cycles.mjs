// Import circles: follows every relative import and re-export (static, dynamic, type-only too) of
// the TypeScript under web/lib, web/demo and packages/cli/src, and fails on a cycle, printing it.
// A circle makes module order matter (a value read before its module ran) and makes rooms that
// cannot be understood one at a time. Run by npm test (after typecheck) and CI.
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { dirname, join, relative, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
export const TREES = ['web/lib', 'web/demo', 'packages/cli/src'];
const IMPORT = /(?:\bfrom\s*|\bimport\s*\(\s*|^\s*import\s+)(['"])(\.{1,2}\/[^'"]+)\1/gm;

/** Each .ts file's relative imports, resolved to files (a .js specifier names its .ts source). */
export function importGraph(trees = TREES) {
  const graph = new Map();
  const files = trees.flatMap((t) => readdirSync(join(root, t), { recursive: true }).map((f) => join(root, t, String(f))))
    .filter((f) => f.endsWith('.ts') && !f.endsWith('.d.ts'));
  for (const file of files) {
    const text = readFileSync(file, 'utf8').replace(/\/\*[\s\S]*?\*\//g, '').replace(/^\s*\/\/.*$/gm, '');
    const targets = new Set();
    for (const [, , spec] of text.matchAll(IMPORT)) {
      const target = resolve(dirname(file), spec.replace(/\.js$/, '.ts'));
      if (existsSync(target)) targets.add(target);
    }
    graph.set(file, [...targets]);
  }
  return graph;
}

/** The import circles of a graph, each as its files in order (the first repeated at the end). */
export function cyclesOf(graph) {
  const state = new Map(); // 1: on the current path, 2: done
  const path = [];
  const cycles = [];
  const visit = (file) => {
    state.set(file, 1);
    path.push(file);
    for (const next of graph.get(file) ?? []) {
      if (state.get(next) === 1) cycles.push([...path.slice(path.indexOf(next)), next]);
      else if (!state.has(next)) visit(next);
    }
    path.pop();
    state.set(file, 2);
  };
  for (const file of graph.keys()) if (!state.has(file)) visit(file);
  return cycles;
}

if (process.argv[1] && fileURLToPath(import.meta.url) === process.argv[1]) {
  const graph = importGraph();
  const cycles = cyclesOf(graph);
  for (const c of cycles) console.error(`check-cycles: ${c.map((f) => relative(root, f)).join(' → ')}`);
  if (cycles.length) {
    console.error(`check-cycles: FAIL: ${cycles.length} import circle(s) in ${TREES.join(', ')}`);
    process.exit(1);
  }
  console.log(`check-cycles: no import circle in ${TREES.join(', ')} (${graph.size} files)`);
}
