// npm run typecheck (scripts/typecheck.mjs) catches a type error in a test, in the demo and in the
// command line: for one real file of each, its project (a) is one typecheck runs, (b) includes the
// file, and (c) finds no error in it as it is but an error where one is planted in a copy held in
// memory (the project's own compiler options; only that file and what it imports are checked).
import { readFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import ts from 'typescript';
import { describe, expect, test } from 'vitest';
import { PROJECTS } from '../scripts/typecheck.mjs';

const ROOT = resolve(__dirname, '..');
const PLANTED = "\nexport const planted: number = 'not a number';\n";

/** The diagnostics of `file` under `project`'s options, its text replaced by `text`. */
function diagnosticsOf(project: string, file: string, text: string): readonly ts.Diagnostic[] {
  const config = ts.getParsedCommandLineOfConfigFile(join(ROOT, project), {}, {
    ...ts.sys, onUnRecoverableConfigFileDiagnostic: (d) => { throw new Error(ts.flattenDiagnosticMessageText(d.messageText, '\n')); },
  })!;
  expect(config.fileNames.map((f) => resolve(f)), `${project} includes ${file}`).toContain(join(ROOT, file));
  const host = ts.createCompilerHost(config.options);
  const getSourceFile = host.getSourceFile;
  host.getSourceFile = (name, language, onError, create) =>
    resolve(name) === join(ROOT, file) ? ts.createSourceFile(name, text, language) : getSourceFile.call(host, name, language, onError, create);
  const program = ts.createProgram({ rootNames: [join(ROOT, file)], options: { ...config.options, noEmit: true }, host });
  return ts.getPreEmitDiagnostics(program, program.getSourceFile(join(ROOT, file)));
}

const CASES = [
  { where: 'a node test', project: 'tests/tsconfig.json', file: 'tests/demo/cost.test.ts' },
  { where: 'the demo', project: 'web/demo/tsconfig.json', file: 'web/demo/cost.ts' },
  { where: 'the command line', project: 'packages/cli/tsconfig.json', file: 'packages/cli/src/args.ts' },
];

describe('npm run typecheck catches a planted type error', () => {
  for (const { where, project, file } of CASES)
    test(`in ${where} (${file}, project ${project})`, () => {
      expect(PROJECTS).toContain(project);
      const text = readFileSync(join(ROOT, file), 'utf8');
      expect(diagnosticsOf(project, file, text).map((d) => ts.flattenDiagnosticMessageText(d.messageText, '\n'))).toEqual([]);
      const planted = diagnosticsOf(project, file, text + PLANTED);
      expect(planted.map((d) => d.code)).toEqual([2322]); // Type 'string' is not assignable to type 'number'.
      expect(dirname(planted[0].file!.fileName)).toBe(dirname(join(ROOT, file)));
    }, 60000);
});
