// The readouts under each view: deform time per frame (measured after each build as the bench
// measures it, cost.ts: "measuring…" until then), sizes, sections or contours, the criterion and why, the renderer and backend.
import type { ClassicDeformer, Criterion, GcsDeformer } from '../lib/index.js';
import type { SkinDeformer } from '../lib/three.js';
import { rigidVertices } from './colours.js';
import { CRITERION_TEXT } from './criteria.js';
import { counted, msText, percentText } from './figure-text.js';
import { escapeHtml as esc } from './gui-text.js';
import { viewRects } from './layout.js';
import { rendererLabel } from './renderer.js';
import { dom, state, type ViewKind } from './state.js';
import type { InfluenceCount } from './influences.js';

export interface Readouts {
  character: string;
  /** ms: NaN while warmingUp (measuring, a few frames after each build). */
  /** final: the cost figures are every round's median, and stay until the next build (cost.ts). */
  gcs: { ms: number; warmingUp: boolean; final: boolean; vertices: number; triangles: number; sections: number; adjustedShare: number; criterion: Criterion; rigidShare: number } | null;
  classic: { ms: number; warmingUp: boolean; vertices: number; triangles: number; contours: number; detailLoss: { rms: number; max: number } } | null;
  lbs: { vertices: number; triangles: number } | null;
  influences: InfluenceCount | null;
}
let lastReadouts: Readouts = { character: '', gcs: null, classic: null, lbs: null, influences: null };

export function collectReadouts(): Readouts {
  const ch = state.current;
  if (!ch) return { character: '', gcs: null, classic: null, lbs: null, influences: null };
  const tri = (s: SkinDeformer) => (s.mesh.geometry.index?.count ?? 0) / 3;
  let gcsInfo: Readouts['gcs'] = null;
  let classicInfo: Readouts['classic'] = null;
  try {
    let sections = 0, adjusted = 0, rigid = 0, vertices = 0;
    for (const s of ch.gcs) {
      const d = s.deformer as GcsDeformer;
      rigid += rigidVertices.get(s) ?? 0;
      vertices += d.vertexCount;
      sections += d.sectionCount;
      adjusted += d.adjustedShare * d.sectionCount;
    }
    const cost = state.frameCost.figures();
    const gcsMs = cost.gcs;
    gcsInfo = {
      ms: gcsMs, warmingUp: Number.isNaN(gcsMs), final: state.frameCost.final, sections, adjustedShare: sections ? adjusted / sections : 0, criterion: state.builtCriterion,
      rigidShare: vertices ? rigid / vertices : 0, vertices, triangles: ch.gcs.reduce((n, s) => n + tri(s), 0),
    };
    if (ch.classic.length) {
      let rms2 = 0, max = 0, n = 0;
      for (const s of ch.classic) {
        const loss = (s.deformer as ClassicDeformer).detailLoss;
        const w = s.deformer.vertexCount;
        rms2 += loss.rms * loss.rms * w; n += w; max = Math.max(max, loss.max);
      }
      const classicMs = cost.classic;
      classicInfo = {
        ms: classicMs, warmingUp: Number.isNaN(classicMs), vertices: ch.classic.reduce((k, s) => k + s.deformer.vertexCount, 0),
        triangles: ch.classic.reduce((k, s) => k + tri(s), 0), contours: ch.classic.reduce((k, s) => k + s.deformer.sectionCount, 0),
        detailLoss: { rms: Math.sqrt(rms2 / Math.max(1, n)), max },
      };
    }
  } catch {
    /* a deformer mid-rebuild: keep the last numbers */
    return lastReadouts;
  }
  return { character: ch.name, gcs: gcsInfo, classic: classicInfo, lbs: { vertices: ch.sourceVertices, triangles: ch.sourceTriangles }, influences: ch.influences };
}

/** "deform 0.21 ms / frame" ("< 0.01 ms" below the last digit), or "deform measuring…" until the figure stands. */
const deformTime = (ms: number) => (Number.isNaN(ms) ? 'deform <b>measuring…</b>' : `deform <b>${msText(ms)} ms</b> / frame`);
/** "<b>1,342</b> sections", "<b>1</b> contour": the count in bold, the word in its number. */
const bold = (count: number, singular: string, plural?: string) => counted(count, singular, plural).replace(/^(\S+)/, '<b>$1</b>');

export function updateReadouts(): void {
  const r = (lastReadouts = collectReadouts());
  const rows: Record<ViewKind, string[]> = { gcs: [], classic: [], lbs: [] };
  if (r.gcs) {
    rows.gcs.push(`${deformTime(r.gcs.ms)} · ${counted(r.gcs.vertices, 'vertex', 'vertices')} · ${counted(r.gcs.triangles, 'triangle')}`);
    rows.gcs.push(bold(r.gcs.sections, 'section') +
      (r.gcs.criterion === 'weights' ? ` · <b>${(r.gcs.rigidShare * 100).toFixed(0)} %</b> of vertices in rigid cores` : '') +
      ` · <b>${(r.gcs.adjustedShare * 100).toFixed(0)} %</b> adjusted this frame · rest pose exact`);
    const c = CRITERION_TEXT[r.gcs.criterion];
    rows.gcs.push(`<span class="criterion">criterion <b>${esc(c.name)}</b>: ${esc(c.why)}</span>`);
  }
  if (r.classic) {
    rows.classic.push(`${deformTime(r.classic.ms)} · ${counted(r.classic.vertices, 'vertex', 'vertices')} · ${counted(r.classic.triangles, 'triangle')}`);
    // Nothing resampled (every part carried): no contours, no detail lost; say that, not "0 contours · 0.00 %".
    rows.classic.push(r.classic.contours === 0
      ? 'nothing resampled: every part is carried, its own skin moved by DQS'
      : `${bold(r.classic.contours, 'contour')} · resampling detail loss <b>${percentText(r.classic.detailLoss.rms)} %</b> rms, ` +
        `<b>${percentText(r.classic.detailLoss.max)} %</b> max (of height)`);
  }
  // Which renderer draws, and where each view's skinning runs.
  const backendOf = (list: SkinDeformer[] | undefined) => (list?.length && list.every((s) => s.backend === 'gpu') ? 'GPU' : 'CPU');
  const renderer = rendererLabel(state.renderer);
  if (r.gcs) rows.gcs.push(`<span class="criterion">${renderer} · ${backendOf(state.current?.gcs)} backend</span>`);
  if (r.classic) rows.classic.push(`<span class="criterion">${renderer} · ${backendOf(state.current?.classic)} backend</span>`);
  if (r.lbs) rows.lbs.push(`skinned on the GPU by three.js · ${counted(r.lbs.vertices, 'vertex', 'vertices')} · ${counted(r.lbs.triangles, 'triangle')}`);
  // three's skinning reads four influences: say what it drops (the other views use all eight).
  if (r.lbs && r.influences?.overFour)
    rows.lbs.push(`<span class="warn">drops influences 5–${r.influences.most} of ${bold(r.influences.overFour, 'vertex', 'vertices')}: three.js skins with 4</span>`);
  const influences = r.influences ? ` · up to ${bold(r.influences.most, 'influence')} per vertex` +
    (r.influences.overFour ? ` (${counted(r.influences.overFour, 'vertex', 'vertices')} over 4)` : '') : '';
  const clip = state.current?.action ? state.current.action.getClip().name : '';
  let html = '';
  viewRects().forEach((v, i) => {
    const lines = rows[v.kind].slice();
    if (i === 0 && r.character) lines.unshift(`<b>${esc(r.character)}</b>${clip ? ` · ${esc(clip)}` : ''}${influences}`);
    if (lines.length)
      html += `<div class="readout" data-view="${v.kind}" style="left:${v.x + 10}px;max-width:${v.width - 20}px">` +
        lines.map((l) => `<div class="row">${l}</div>`).join('') + '</div>';
  });
  dom.readouts.innerHTML = html;
}
