// What the page says about the GCS criteria: the menu, a short name and one line each, and the
// note shown beside the menu under the paper's criteria (docs/method.md, section 10: why the default
// differs from the paper).
import type { Criterion } from '../lib/index.js';

/** The criterion menu: label → value. */
export const CRITERION_MENU: Record<string, Criterion> = {
  'weights (default)': 'weights',
  'Y (paper)': 'y',
  "axial (paper's rule, bone axis)": 'axial',
};

/** What the GCS view says about each criterion: a short name and one line on why the default differs from the paper. */
export const CRITERION_TEXT: Record<Criterion, { name: string; why: string }> = {
  weights: { name: 'weights', why: 'vertices bound 100 % to a bone move exactly with it; the paper\'s Y rule bends them' },
  y: { name: 'Y (paper)', why: 'bins of bind-pose height; skin bound 100 % to one bone bends too (weights keeps it rigid)' },
  axial: { name: 'axial (paper\'s rule)', why: 'bins along each bone; skin bound 100 % to one bone bends too (weights keeps it rigid)' },
};

/** Why the paper's criteria look broken on real characters: shown beside the menu when one is chosen. */
export const PAPER_CRITERIA_NOTE =
  'Looks broken on real characters? Expected: the paper bins skin by height (Y) or along the bone (axial), ' +
  'not by its weights, so skin bound 100 % to one bone bends with the joint and leaves that bone. ' +
  'The default, weights, keeps it rigid (docs/method.md, section 10: why the default differs from the paper).';
