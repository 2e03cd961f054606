// No import circle in the library, the demo or the command line (scripts/check-cycles.mjs, run by
// npm test): the real tree has none, and a planted one is found and named.
import { describe, expect, test } from 'vitest';
import { cyclesOf, importGraph } from '../scripts/check-cycles.mjs';

describe('import circles', () => {
  test('web/lib, web/demo and packages/cli/src have none', () => {
    const graph = importGraph();
    expect(graph.size).toBeGreaterThan(80);
    expect(cyclesOf(graph)).toEqual([]);
  });

  test('a circle is found, however long, and named file by file', () => {
    const graph = new Map([['a', ['b']], ['b', ['c', 'd']], ['c', ['a']], ['d', []]]);
    expect(cyclesOf(graph)).toEqual([['a', 'b', 'c', 'a']]);
    expect(cyclesOf(new Map([['a', ['b']], ['b', []]]))).toEqual([]);
  });
});
