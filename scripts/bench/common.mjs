// Helpers shared by scripts/bench.mjs, metrics.mjs and classic.mjs: argument parsing, tables, machine info.
import { execFileSync } from 'node:child_process';
import os from 'node:os';

/** Parses --flag and --key value / --key=value arguments. */
export function parseArgs(argv, spec) {
  const out = {};
  for (const [k, v] of Object.entries(spec)) out[k] = v.default;
  for (let i = 0; i < argv.length; i++) {
    let a = argv[i];
    if (a === '-h' || a === '--help') { out.help = true; continue; }
    if (!a.startsWith('--')) throw new Error(`unexpected argument '${a}'`);
    let value;
    const eq = a.indexOf('=');
    if (eq > 0) { value = a.slice(eq + 1); a = a.slice(0, eq); }
    const key = a.slice(2).replace(/-([a-z])/g, (_, c) => c.toUpperCase());
    const s = spec[key];
    if (!s) throw new Error(`unknown option '${a}'`);
    if (s.type === 'flag') { out[key] = true; continue; }
    if (value === undefined) value = argv[++i];
    if (value === undefined) throw new Error(`${a} needs a value`);
    out[key] = s.parse ? s.parse(value, a) : value;
  }
  return out;
}

/**
 * This process's arguments by `spec` (parseArgs) for the command-line tool `tool`: a bad one is
 * named on stderr and exits 2; -h / --help prints `usage` and exits 0.
 */
export function argsOrExit(tool, spec, usage) {
  let args;
  try {
    args = parseArgs(process.argv.slice(2), spec);
  } catch (e) {
    console.error(`${tool}: ${e.message}`);
    process.exit(2);
  }
  if (args.help) {
    console.log(usage);
    process.exit(0);
  }
  return args;
}

/** A text table: first row is the header; numbers right-aligned. */
export function table(rows) {
  const widths = rows[0].map((_, c) => Math.max(...rows.map((r) => String(r[c] ?? '').length)));
  const line = (r) => r.map((cell, c) => (c === 0 ? String(cell ?? '').padEnd(widths[c]) : String(cell ?? '').padStart(widths[c]))).join('  ');
  return [line(rows[0]), widths.map((w) => '-'.repeat(w)).join('  '), ...rows.slice(1).map(line)].join('\n');
}

/** A markdown table of the same rows. */
export function markdownTable(rows) {
  const esc = (s) => String(s ?? '').replace(/\|/g, '\\|');
  return [`| ${rows[0].map(esc).join(' | ')} |`, `|${rows[0].map((_, c) => (c === 0 ? ' --- ' : ' ---: ')).join('|')}|`,
    ...rows.slice(1).map((r) => `| ${r.map(esc).join(' | ')} |`)].join('\n');
}

/** Formats ms with 3 significant digits (n/a for null/undefined/NaN). */
export function ms(x) {
  if (x === null || x === undefined || Number.isNaN(x)) return 'n/a';
  if (x >= 100) return x.toFixed(0);
  if (x >= 10) return x.toFixed(1);
  if (x >= 1) return x.toFixed(2);
  return x.toPrecision(3);
}

export function num(x, digits = 3) {
  if (x === null || x === undefined) return 'n/a';
  if (typeof x === 'string') return x;
  if (!Number.isFinite(x)) return String(x);
  if (x === 0) return '0';
  if (Math.abs(x) < 10 ** -digits) return x.toExponential(1);
  return x.toFixed(digits);
}

/** CPU, cores, node and V8 versions, for the docs. */
export function machine() {
  let lscpu = '';
  try {
    lscpu = execFileSync('lscpu', { encoding: 'utf8' }).split('\n').slice(0, 10).join('\n');
  } catch { /* not Linux */ }
  const cpu = os.cpus()[0];
  return { cpu: cpu?.model ?? 'unknown', cores: os.cpus().length, node: process.version, v8: process.versions.v8, platform: `${os.platform()} ${os.arch()}`, lscpu };
}
