// README.md as the tests read it: its fenced blocks under a heading, and the git URL its install
// lines give for the library (tests/browser/app.test.ts, tests/clone.test.ts run them as written,
// with that URL pointing at a snapshot of this checkout).
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';

const ROOT = resolve(__dirname, '../..');

export const readme = () => readFileSync(join(ROOT, 'README.md'), 'utf8');

/** The README's fenced blocks of a language under a heading (up to the next heading of that level or higher). */
export function readmeBlocks(heading: string, lang: string): string[] {
  const text = readme();
  const start = text.indexOf(`\n${heading}\n`);
  if (start < 0) throw new Error(`README.md has no heading "${heading}"`);
  const level = /^#+/.exec(heading)![0].length;
  const rest = text.slice(start + heading.length + 2);
  const end = rest.search(new RegExp(`\\n#{1,${level}} `));
  const section = end < 0 ? rest : rest.slice(0, end);
  return [...section.matchAll(new RegExp(`\`\`\`${lang}\\n([\\s\\S]*?)\`\`\``, 'g'))].map((m) => m[1]);
}

/** The repository's URL in the README's install lines (its owner is wherever the reader got it from). */
export const README_REPOSITORY = 'https://github.com/OWNER/gcs-skin.git';
export const INSTALLING = '## Installing before the registry release';
