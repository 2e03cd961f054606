// The section slider's track: stepped, not linear. On a linear 3–256 track the useful counts (3–16)
// sat 3 px apart; here every count to 16 is one step, then coarser steps reach 256, so at the
// GUI's width each step is over 8 px. The number box beside it still takes any count 3–256.
import { MAX_SECTIONS, MIN_SECTIONS } from '../lib/index.js';

/** The track's values: every count to 16, then coarser steps up to 256. */
export const SECTION_STOPS: readonly number[] = [
  MIN_SECTIONS, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 20, 24, 32, 48, 64, 96, 128, 192, MAX_SECTIONS,
];

/** The track position of `sections`: its stop, or the nearest stop below it. */
export function stopIndex(sections: number): number {
  let i = 0;
  while (i + 1 < SECTION_STOPS.length && SECTION_STOPS[i + 1] <= sections) i++;
  return i;
}
