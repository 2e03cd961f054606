// The frame loop (renderer.setAnimationLoop): pending rebuilds, the mixer, every deformer's
// update(), the views drawn, a slice of the cost measurement (cost.ts), the readouts refreshed
// four times a second.
import type * as THREE from 'three';
import { rebuildPending } from './models.js';
import { describeError, showMessage } from './page.js';
import { updateReadouts } from './readouts.js';
import { params, state } from './state.js';
import { render } from './views.js';

/** Plays the clip params.clip names; paused, the character shows the clip's first frame (not the rest pose). */
export function playClip(): void {
  const ch = state.current;
  if (!ch) return;
  const clip = ch.clips.find((c) => c.name === params.clip);
  ch.mixer.stopAllAction();
  ch.action = clip ? ch.mixer.clipAction(clip).play() : null;
  ch.mixer.update(0); // applies the clip at its start now, whether or not the loop advances it
}

/** One frame of the clip forward (the caller pauses first). */
export function stepFrame(): void {
  state.current?.mixer.update(1 / 30);
}

const noWorldUpdate = { updateMatrixWorld: false };
let lastTime = performance.now();
let lastReadout = 0;

export function animate(): void {
  const now = performance.now();
  const dt = Math.min((now - lastTime) / 1000, 0.1);
  lastTime = now;
  state.controls.update();

  const ch = state.current;
  if (ch) {
    rebuildPending(ch);
    ch.mixer.timeScale = params.speed;
    if (!params.paused) ch.mixer.update(dt);
    try {
      // One world-matrix pass for the shared skeletons, then every deformer skips its own.
      let root: THREE.Object3D | undefined = ch.gcs[0]?.source ?? ch.classic[0]?.source;
      while (root?.parent) root = root.parent;
      root?.updateMatrixWorld();
      for (const s of ch.gcs) s.update(noWorldUpdate);
      for (const s of ch.classic) s.update(noWorldUpdate);
    } catch (e) {
      showMessage(`deform: ${describeError(e)}`);
    }
  }
  render();
  // After the picture: the cost measurement deforms the live models with recorded poses, and the
  // next frame's update() writes the picture again before it is drawn.
  try {
    state.frameCost.afterFrame();
  } catch (e) {
    state.frameCost.stop();
    showMessage(`cost / frame: ${describeError(e)}`);
  }
  state.stats.update();
  state.frameCount++;
  if (now - lastReadout > 250) {
    lastReadout = now;
    updateReadouts();
  }
}
