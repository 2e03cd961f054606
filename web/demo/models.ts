// The two models on screen, built from the GUI's settings: GCS (left) and classic (right), their
// live rebuilds (asked for by the GUI, done by the frame loop), the muscle bulge (no rebuild), and
// what the GCS settings cost per frame, measured once the sliders rest.
import { msText } from './figure-text.js';
import type * as THREE from 'three';
import type { ClassicDeformer, ClassicOptions, ClassicReason, GcsOptions } from '../lib/index.js';
import type { SkinDeformer } from '../lib/three.js';
import { classicColours, gcsColours } from './colours.js';
import type { FrameCostFigures } from './cost.js';
import { updateLabels } from './labels.js';
import { describeError, showMessage } from './page.js';
import { updateReadouts } from './readouts.js';
import { LAYER, params, state, type Character } from './state.js';

export function gcsOptions(): GcsOptions {
  const options: GcsOptions = { sections: params.sections, criterion: params.criterion, smooth: params.smooth };
  if (params.criterion !== 'weights') Object.assign(options, { influenceWidth: params.influenceWidth, twistSpread: params.twistSpread });
  return options;
}

function classicOptions(): ClassicOptions {
  return { contours: params.contours, rays: params.rays, bulge: params.bulge };
}

/** The GCS model of one source mesh, in the source's own material (the same object: textures, colours). */
export function buildGcs(source: THREE.SkinnedMesh): SkinDeformer {
  const skin = new state.Skin(state.gcs, source, { method: 'gcs', gcs: gcsOptions(), material: source.material });
  skin.mesh.layers.set(LAYER.gcs);
  state.builtCriterion = params.criterion;
  return skin;
}

/** The classic model of every source mesh, or why it cannot be built. */
export function buildClassic(sources: THREE.SkinnedMesh[]): { skins: SkinDeformer[]; error: string | null } {
  const skins: SkinDeformer[] = [];
  state.classicBuilds++;
  try {
    for (const src of sources) {
      const skin = new state.Skin(state.gcs, src, { method: 'classic', classic: classicOptions(), material: src.material });
      skins.push(skin);
      skin.mesh.layers.set(LAYER.classic);
      classicColours(skin);
    }
    return { skins, error: null };
  } catch (e) {
    for (const s of skins) s.dispose();
    return { skins: [], error: describeError(e) };
  }
}

/** Which parts the classic model carries rigidly and why, and which trunk parts it resamples. */
export function classicSummary(ch: Character): void {
  const carried = new Map<string, ClassicReason>(), trunk = new Set<string>();
  ch.classic.forEach((s, i) => {
    const bones = ch.sources[i].skeleton.bones;
    for (const p of (s.deformer as ClassicDeformer).parts) {
      const name = bones[p.joint]?.name || `joint ${p.joint}`;
      if (p.reason === 'trunk') trunk.add(name);
      else if (!p.resampled) carried.set(name, p.reason);
    }
  });
  ch.rigidParts = [...carried].map(([name, reason]) => ({ name, reason }));
  ch.trunkParts = [...trunk];
}

/** Rebuilds what the GUI asked for since the last frame (coalesced: a slider drag rebuilds once a frame). */
export function rebuildPending(ch: Character): void {
  if (state.pendingGcs) rebuildGcs(ch);
  if (state.pendingClassic) rebuildClassic(ch);
}

function rebuildGcs(ch: Character): void {
  state.pendingGcs = false;
  state.gcsBuilds++;
  try {
    for (const s of ch.gcs) {
      s.rebuild('gcs', { gcs: gcsOptions() });
      state.builtCriterion = params.criterion;
      gcsColours(s);
    }
  } catch (e) {
    showMessage(`GCS model: ${describeError(e)}`);
  }
  updateLabels();
  updateReadouts();
  scheduleCostMeasure(ch);
}

function rebuildClassic(ch: Character): void {
  state.pendingClassic = false;
  if (ch.classic.length) {
    state.classicBuilds++;
    try {
      for (const s of ch.classic) {
        s.rebuild('classic', { classic: classicOptions() });
        classicColours(s);
      }
      ch.classicError = null;
    } catch (e) {
      ch.classicError = describeError(e);
    }
  } else {
    const { skins, error } = buildClassic(ch.sources);
    ch.classic = skins;
    ch.classicError = error;
    for (const s of skins) { s.mesh.castShadow = true; state.classicGroup.add(s.mesh); }
  }
  classicSummary(ch);
  updateLabels();
  updateReadouts();
  scheduleCostMeasure(ch);
}

export function setBulge(): void {
  if (!state.current) return;
  try {
    for (const s of state.current.classic) (s.deformer as ClassicDeformer).setBulge(params.bulge);
  } catch (e) {
    showMessage(describeError(e));
  }
}

// What the settings cost (cost.ts): measured after every build, shown in the GCS folder beside the
// controls that set it (controls.ts listens) and in the views' readouts.
let costListener: (text: string) => void = () => {};

/** Calls `listener` with the cost line's text whenever it changes. */
export function onCostChange(listener: (text: string) => void): void {
  costListener = listener;
  costListener(costText(state.frameCost.figures()));
}

state.frameCost.onChange((figures) => {
  costListener(costText(figures));
  updateReadouts();
});

/** Starts the cost measurement over for the models `ch` shows now. */
export function scheduleCostMeasure(ch: Character): void {
  state.frameCost.restart({ gcs: ch.gcs, classic: ch.classic, options: gcsOptions() });
}

function costText(figures: FrameCostFigures): string {
  const f = msText;
  return Number.isNaN(figures.gcs) ? 'measuring…'
    : Number.isNaN(figures.stepped) ? `${f(figures.gcs)} ms`
    : `${f(figures.gcs)} ms · stepped ${f(figures.stepped)}`;
}
