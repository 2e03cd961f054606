// The label over each view: which model, its settings, and (classic) the parts it carries and why.
// Names from files (bones, errors) reach the page escaped.
import { weightGridSteps, type ClassicReason } from '../lib/index.js';
import { CRITERION_TEXT } from './criteria.js';
import { escapeHtml as esc } from './gui-text.js';
import { sidebarWidth, viewRects } from './layout.js';
import { dom, params, state } from './state.js';

export function updateLabels(): void {
  const rects = viewRects();
  const ch = state.current;
  let html = '';
  rects.forEach((r, i) => {
    const overlaid = i === rects.length - 1 && sidebarWidth() === 0; // the GUI covers its right part
    const maxWidth = Math.max(160, Math.min(440, r.width - (overlaid ? 300 : 20)));
    let body = '';
    if (r.kind === 'gcs') {
      const byWeights = state.builtCriterion === 'weights';
      const detail = byWeights
        ? `${params.sections} sections: weight step 1/${weightGridSteps(params.sections)}`
        : `${params.sections} sections per part`;
      body = '<h2>GCS — generalized cross-sections</h2><div class="sub">Li, Wang, Mao · ' +
        `${esc(CRITERION_TEXT[state.builtCriterion].name)} criterion · ${detail}` +
        `${params.smooth ? ', smooth' : ''}${!byWeights && params.twistSpread ? ', twist spread' : ''}</div>`;
      if (params.colourBySection) {
        body += '<div class="sub">colour = section · <span style="color:#ffd83d">yellow = shared section (SGS)</span>' +
          (byWeights ? ' · <span style="color:#c4c8cc">pale grey = rigid core (moves exactly with its bone)</span>' : '') + '</div>';
      }
    } else if (r.kind === 'classic') {
      body = '<h2>Classic cross-sections</h2><div class="sub">Shen, Magnenat-Thalmann, Thalmann 1994 · ' +
        `${params.contours} contours × ${params.rays} rays per limb</div>`;
      if (ch?.classicError) body += `<div class="err">Not available: ${esc(ch.classicError)}</div>`;
      else {
        if (ch?.trunkParts.length) body += `<div class="sub">trunk resampled along the spine through ${esc(summariseBones(ch.trunkParts))} (crotch and shoulders carried)</div>`;
        if (ch?.rigidParts.length) body += `<div class="warn">Carried (own triangles, skinned by DQS) — ${esc(groupCarried(ch.rigidParts))}</div>`;
      }
      if (params.colourBySection && !ch?.classicError)
        body += '<div class="sub">colour = contour (bands alternate along each limb) · grey = carried skin</div>';
    } else {
      body = '<h2>three.js skinning (LBS)</h2><div class="sub">the source SkinnedMesh itself, for reference</div>';
    }
    html += `<div class="label" data-view="${r.kind}" style="left:${r.x + 10}px;max-width:${maxWidth}px">${body}</div>`;
    if (i > 0) html += `<div class="divider" style="left:${r.x - 1}px"></div>`;
  });
  dom.labels.innerHTML = html;
}

/** A short list of bone names: no common prefix (e.g. "mixamorig"), fingers counted, at most 10. */
function summariseBones(names: string[]): string {
  let prefix = names.length > 1 ? names[0] : '';
  for (const n of names) while (prefix && !n.startsWith(prefix)) prefix = prefix.slice(0, -1);
  prefix = prefix.slice(0, prefix.search(/[:|_][^:|_]*$/) + 1); // up to a separator ("mixamorig:"), never "joint "
  const short = names.map((n) => n.slice(prefix.length) || n);
  const fingers = short.filter((n) => /thumb|index|middle|ring|pinky|finger/i.test(n));
  const rest = short.filter((n) => !fingers.includes(n));
  if (fingers.length) rest.push(`${fingers.length} finger bones`);
  return rest.length > 10 ? `${rest.slice(0, 10).join(', ')} and ${rest.length - 10} more` : rest.join(', ');
}

/** Why the classic model carries a part, as the page groups it. */
const CARRIED_WHY: Record<Exclude<ClassicReason, 'resampled' | 'trunk'>, string> = {
  leaf: 'ends', branching: 'branch regions', 'too-short': 'bones too short', 'rays-miss': 'not tube-like (rays miss)',
  bent: 'bent off their limb', seam: 'no clean ring to the carried skin', 'off-surface': 'a tube would leave the skin',
};

/** "fingers: 30 joints · ends: Head, LeftHand, … · branch regions: Chest": carried parts grouped by reason. */
function groupCarried(parts: { name: string; reason: ClassicReason }[]): string {
  const finger = (n: string) => /thumb|index|middle|ring|pinky|finger/i.test(n);
  const groups: string[] = [];
  const fingers = parts.filter((p) => finger(p.name));
  if (fingers.length) groups.push(`fingers: ${fingers.length} joints`);
  for (const [reason, label] of Object.entries(CARRIED_WHY)) {
    const names = parts.filter((p) => p.reason === reason && !finger(p.name)).map((p) => p.name);
    if (names.length) groups.push(`${label}: ${summariseBones(names)}`);
  }
  return groups.join(' · ');
}
