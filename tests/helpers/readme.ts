// README.md as the tests read it: its fenced blocks under a heading, and the git URL its install
// lines give for the library (tests/browser/app.test.ts, tests/clone.test.ts run them as written,
// with that URL pointing at a snapshot of this checkout).
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';

const ROOT = resolve(__dirname, '../..');

export const readme = (file = 'README.md') => readFileSync(join(ROOT, file), 'utf8');

/** The README's (or another markdown file's) fenced blocks of a language under a heading (up to the next heading of that level or higher). */
export function readmeBlocks(heading: string, lang: string, file = 'README.md'): string[] {
  const text = `\n${readme(file)}`;
  const start = text.indexOf(`\n${heading}\n`);
  if (start < 0) throw new Error(`${file} has no heading "${heading}"`);
  const level = /^#+/.exec(heading)![0].length;
  const rest = text.slice(start + heading.length + 2);
  const end = rest.search(new RegExp(`\\n#{1,${level}} `));
  const section = end < 0 ? rest : rest.slice(0, end);
  return [...section.matchAll(new RegExp(`\`\`\`${lang}\\n([\\s\\S]*?)\`\`\``, 'g'))].map((m) => m[1]);
}

/** The repository's URL in the README's install lines (its owner is wherever the reader got it from). */
export const README_REPOSITORY = 'https://github.com/OWNER/gcs-skin.git';
export const INSTALLING = '## Installing before the registry release';

/** Whether `quoted` (as written in the README) stands for `measured`: within 5 %, or within its own rounding. */
export function quotes(quoted: string, measured: number): boolean {
  const q = Number(quoted.replace(/,/g, ''));
  const decimals = quoted.includes('.') ? quoted.split('.')[1].length : 0;
  return Math.abs(q - measured) <= Math.max(0.05 * measured, 0.5 * 10 ** -decimals);
}

/** The one match of `pattern` in the README, read with its line breaks as spaces (its capture groups), or a failure naming the pattern. */
export function quoted(pattern: RegExp): string[] {
  const all = [...readme().replace(/\s+/g, ' ').matchAll(new RegExp(pattern.source, 'g'))];
  if (all.length !== 1) throw new Error(`README.md quotes ${pattern} ${all.length} times (once expected)`);
  return all[0].slice(1);
}
