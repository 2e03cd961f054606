// How the demo writes its figures (web/demo/figure-text.ts) and the section track's stops
// (web/demo/section-stops.ts).
import { describe, expect, test } from 'vitest';
import { counted, msText } from '../../web/demo/figure-text.js';
import { SECTION_STOPS, stopIndex } from '../../web/demo/section-stops.js';
import { MAX_SECTIONS, MIN_SECTIONS } from '../../web/lib/index.js';

describe('figure text', () => {
  test('milliseconds never read 0.00', () => {
    expect(msText(0.0612)).toBe('0.06');
    expect(msText(0.005)).toBe('0.01');
    expect(msText(0.0049)).toBe('< 0.01');
    expect(msText(0)).toBe('< 0.01');
    expect(msText(12.34)).toBe('12.3');
    for (let ms = 0; ms < 1; ms += 0.0003) expect(msText(ms)).not.toMatch(/^0\.00$/);
  });

  test('counts with their plural', () => {
    expect(counted(1, 'influence')).toBe('1 influence');
    expect(counted(2, 'influence')).toBe('2 influences');
    expect(counted(1, 'vertex', 'vertices')).toBe('1 vertex');
    expect(counted(17048, 'vertex', 'vertices')).toBe('17,048 vertices');
    expect(counted(0, 'contour')).toBe('0 contours');
  });
});

describe('section track', () => {
  test('every count 3–16 is a stop of its own, the ends are the limits, the stops rise', () => {
    for (let n = 3; n <= 16; n++) expect(SECTION_STOPS[stopIndex(n)]).toBe(n);
    expect(SECTION_STOPS[0]).toBe(MIN_SECTIONS);
    expect(SECTION_STOPS.at(-1)).toBe(MAX_SECTIONS);
    for (let i = 1; i < SECTION_STOPS.length; i++) expect(SECTION_STOPS[i]).toBeGreaterThan(SECTION_STOPS[i - 1]);
  });

  test('a count between stops sits at the stop below it', () => {
    expect(SECTION_STOPS[stopIndex(17)]).toBe(16);
    expect(SECTION_STOPS[stopIndex(100)]).toBe(96);
    expect(SECTION_STOPS[stopIndex(256)]).toBe(256);
  });
});
