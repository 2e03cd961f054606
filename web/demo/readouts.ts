// The readouts under each view: deform time per frame (measured after each build as the bench
// measures it, cost.ts: "measuring…" until then), sizes, sections or contours, the criterion and why, the renderer and backend.
import type { ClassicDeformer, Criterion, GcsDeformer } from '../lib/index.js';
import type { SkinDeformer } from '../lib/three.js';
import { rigidVertices } from './colours.js';
import { CRITERION_TEXT } from './criteria.js';
import { escapeHtml as esc } from './gui-text.js';
import { viewRects } from './layout.js';
import { rendererLabel } from './renderer.js';
import { dom, state, type ViewKind } from './state.js';
import type { InfluenceCount } from './influences.js';

export interface Readouts {
  character: string;
  /** ms: NaN while warmingUp (measuring, a few frames after each build). */
  gcs: { ms: number; warmingUp: boolean; vertices: number; triangles: number; sections: number; adjustedShare: number; criterion: Criterion; rigidShare: number } | null;
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
      ms: gcsMs, warmingUp: Number.isNaN(gcsMs), sections, adjustedShare: sections ? adjusted / sections : 0, criterion: state.builtCriterion,
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

/** "deform 0.21 ms / frame", or "deform measuring…" until the figure stands. */
const deformTime = (ms: number) => (Number.isNaN(ms) ? 'deform <b>measuring…</b>' : `deform <b>${ms < 10 ? ms.toFixed(2) : ms.toFixed(1)} ms</b> / frame`);

export function updateReadouts(): void {
  const r = (lastReadouts = collectReadouts());
  const n = (v: number) => Math.round(v).toLocaleString('en');
  const rows: Record<ViewKind, string[]> = { gcs: [], classic: [], lbs: [] };
  if (r.gcs) {
    rows.gcs.push(`${deformTime(r.gcs.ms)} · ${n(r.gcs.vertices)} vertices · ${n(r.gcs.triangles)} triangles`);
    rows.gcs.push(`<b>${n(r.gcs.sections)}</b> sections` +
      (r.gcs.criterion === 'weights' ? ` · <b>${(r.gcs.rigidShare * 100).toFixed(0)} %</b> of vertices in rigid cores` : '') +
      ` · <b>${(r.gcs.adjustedShare * 100).toFixed(0)} %</b> adjusted this frame · rest pose exact`);
    const c = CRITERION_TEXT[r.gcs.criterion];
    rows.gcs.push(`<span class="criterion">criterion <b>${esc(c.name)}</b>: ${esc(c.why)}</span>`);
  }
  if (r.classic) {
    rows.classic.push(`${deformTime(r.classic.ms)} · ${n(r.classic.vertices)} vertices · ${n(r.classic.triangles)} triangles`);
    rows.classic.push(`<b>${n(r.classic.contours)}</b> contours · resampling detail loss <b>${r.classic.detailLoss.rms.toFixed(2)} %</b> rms, ` +
      `<b>${r.classic.detailLoss.max.toFixed(2)} %</b> max (of height)`);
  }
  // Which renderer draws, and where each view's skinning runs.
  const backendOf = (list: SkinDeformer[] | undefined) => (list?.length && list.every((s) => s.backend === 'gpu') ? 'GPU' : 'CPU');
  const renderer = rendererLabel(state.renderer);
  if (r.gcs) rows.gcs.push(`<span class="criterion">${renderer} · ${backendOf(state.current?.gcs)} backend</span>`);
  if (r.classic) rows.classic.push(`<span class="criterion">${renderer} · ${backendOf(state.current?.classic)} backend</span>`);
  if (r.lbs) rows.lbs.push(`skinned on the GPU by three.js · ${n(r.lbs.vertices)} vertices · ${n(r.lbs.triangles)} triangles`);
  // three's skinning reads four influences: say what it drops (the other views use all eight).
  if (r.lbs && r.influences?.overFour)
    rows.lbs.push(`<span class="warn">drops influences 5–${r.influences.most} of <b>${n(r.influences.overFour)}</b> vertices: three.js skins with 4</span>`);
  const influences = r.influences ? ` · up to <b>${r.influences.most}</b> influences per vertex` +
    (r.influences.overFour ? ` (<b>${n(r.influences.overFour)}</b> vertices over 4)` : '') : '';
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
