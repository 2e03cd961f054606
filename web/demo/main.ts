// gcs-skin demo: the generalized cross-section model (left) and the classic cross-section model
// (right) deforming the same character in the same pose, with one shared camera; optionally
// three.js's own skinning (LBS) as a third, reference view. Characters: the procedural human, the
// three shipped in public/ (Fox, Cesium Man, Robot Expressive), or any dropped / ?model= glTF.
//
// Every view draws the character with its own materials: the deformed meshes share the source's
// material (textures, colours), the classic model's resampled skin gets its texture coordinates
// from the source surface (the library does it: gcs-skin/three), and the parts that are not skinned (e.g. the robot's
// rigid limbs, children of its bones) are drawn in every view, moved by the bones as three.js
// moves them. One scene, one mixer: camera layers pick what each view draws.
//
// Structure as in the three.js examples: init() · GUI · onWindowResize() · animate() driven by
// renderer.setAnimationLoop, around one state object (state.ts):
//   views.ts     renderer, scene, camera, layout of the views, framing, render()
//   controls.ts  lil-gui and keys          loading.ts  characters: load, build, swap
//   models.ts    GCS / classic builds      colours.ts  colour by section, wireframe
//   labels.ts, readouts.ts  the text over and under each view
//   animate.ts   the frame loop
// ?crowd=N opens the crowd mode instead (crowd.ts), ?joint the joint close-up (joint-mode.ts). A small hook on window.__demo lets browser
// tests drive the page.
import { initGcsSkin } from '../lib/index.js';
import { animate } from './animate.js';
import { initControls, setPaused, setSections } from './controls.js';
import { crowdRequested, startCrowd } from './crowd.js';
import { attributesNeeded } from './material-attributes.js';
import { jointHook, jointRequested, startJointMode } from './joint-mode.js';
import { CHARACTER_MENU, chooseCharacter, initFileInput, loadFirstCharacter, loadsDone } from './loading.js';
import { viewRects } from './layout.js';
import { describeError, shownMessage, showMessage, showStatus } from './page.js';
import { collectReadouts } from './readouts.js';
import { dom, params, state } from './state.js';
import type { SkinDeformer } from '../lib/three.js';
import { initViews, onWindowResize, relayout } from './views.js';

async function init(): Promise<void> {
  await initViews();
  initControls(CHARACTER_MENU, { choose: chooseCharacter });
  initFileInput();
  window.addEventListener('resize', relayout);
  onWindowResize();
  state.renderer.setAnimationLoop(animate);

  showStatus('building… loading the WebAssembly core');
  state.gcs = await initGcsSkin();
  await loadFirstCharacter();
}

/** Resolves once the page has drawn two frames after `start` settled. */
function afterFrames(start: Promise<unknown>, frame: () => number): Promise<void> {
  return start.then(() => new Promise<void>((resolve) => { const f = frame(); const wait = () => (frame() > f + 1 ? resolve() : setTimeout(wait, 16)); wait(); }));
}

// ---------------------------------------------------------------------------------------------
// Testing hook

// ?crowd=N: the crowd mode (web/demo/crowd.ts) instead of the comparison views; ?bench=gpu the GPU cost bench (bench-gpu.ts).
const ready = new URLSearchParams(location.search).get('bench') === 'gpu'
  ? import('./bench-gpu.js').then((m) => m.startBench()).catch((e) => showMessage(`The GPU bench could not run: ${describeError(e)}`))
  : crowdRequested()
  ? startCrowd().catch((e) => showMessage(`The crowd could not start: ${describeError(e)}`))
  : jointRequested() ? startJointMode().catch((e) => showMessage(`The joint close-up could not start: ${describeError(e)}`))
  : afterFrames(init().catch((e) => showMessage(`The demo could not start: ${describeError(e)}`)), () => state.frameCount);

Object.assign(window, {
  __demo: {
    ready,
    frame: () => state.frameCount,
    busy: () => state.busy > 0,
    error: shownMessage,
    character: () => state.current?.name ?? '',
    /** The character menu's value: 'human', 'fox', 'cesiumman', 'robot' or 'file'. */
    model: () => state.current?.key ?? '',
    /** The attribution line on the page. */
    credit: () => (dom.credit.hidden ? '' : dom.credit.textContent ?? ''),
    /**
     * What each view draws of the character: skinned meshes (one deformed mesh each in the GCS and
     * classic views), the meshes that are not skinned (drawn in every view), and whether every
     * deformed mesh wears its source's material with the attributes that material reads.
     */
    parts: () => {
      const ch = state.current;
      const own = (list: SkinDeformer[]) => list.every((s) =>
        (params.colourBySection || s.mesh.material === s.source.material) &&
        attributesNeeded(s.source.material).every((n) => !!s.mesh.geometry.getAttribute(n)));
      const textured = (list: SkinDeformer[]) => list.some((s) => attributesNeeded(s.source.material).includes('uv'));
      return {
        skinned: ch?.sources.length ?? 0, rigid: ch?.rigidMeshes ?? 0, gcs: ch?.gcs.length ?? 0, classic: ch?.classic.length ?? 0,
        ownMaterials: { gcs: own(ch?.gcs ?? []), classic: own(ch?.classic ?? []) },
        textured: { gcs: textured(ch?.gcs ?? []), classic: textured(ch?.classic ?? []) },
      };
    },
    sectionCount: () => state.current?.gcs.reduce((n, s) => n + s.deformer.sectionCount, 0) ?? 0,
    sectionsPerPart: () => params.sections,
    setSections,
    /** The criterion of the GCS model on screen. */
    criterion: () => state.builtCriterion,
    gcsBuilds: () => state.gcsBuilds,
    /** For leak checks: wasm memory's size, the core's heap in use (bytes), the geometries and textures the renderer holds. */
    memory: () => ({ wasmBytes: state.gcs.memory.buffer.byteLength, heapInUse: state.gcs.core.gcs_heap_in_use(),
      geometries: state.renderer.info.memory.geometries, textures: state.renderer.info.memory.textures }),
    classicError: () => state.current?.classicError ?? null,
    rigidParts: () => state.current?.rigidParts.map((p) => `${p.name}: ${p.reason}`) ?? [],
    readouts: collectReadouts,
    views: viewRects,
    time: () => state.current?.mixer.time ?? 0,
    clip: () => state.current?.action?.getClip().name ?? '',
    classicBuilds: () => state.classicBuilds,
    /** Pauses (through the GUI's checkbox), optionally at clip time t seconds. */
    pause: (t?: number) => {
      setPaused(true);
      if (t !== undefined) state.current?.mixer.setTime(t);
    },
    /** Moves the shared camera (for close-ups): eye position and target, world units. */
    lookAt: (eye: [number, number, number], target: [number, number, number]) => {
      state.camera.position.set(...eye);
      state.controls.target.set(...target);
      state.controls.update();
    },
    /** Hides (or shows again) the character in every view: screenshots of the empty scene, to find its pixels. */
    hideCharacter: (hidden: boolean) => {
      for (const o of [state.gcsGroup, state.classicGroup, state.current?.holder]) if (o) o.visible = !hidden;
    },
    /**
     * Puts the character in its rest pose (the clip stopped: three.js restores the bones it
     * animated), or back on its clip at the start: screenshots to compare with a paused page.
     */
    restPose: (rest: boolean) => {
      const ch = state.current;
      if (!ch) return;
      if (rest) ch.mixer.stopAllAction();
      else if (ch.action) { ch.action.play(); ch.mixer.setTime(0); }
    },
    /** Settles when every queued load has finished. */
    idle: loadsDone,
    /** The joint close-up (?joint): its joints, bend, figures. */
    joint: jointHook,
  },
});
