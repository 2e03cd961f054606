// Part of `npm run bench` (alone: `npm run bench -- --gpu-cpu-only`): the CPU the GPU backend spends
// per character-frame, in node, against the target of ≤ 0.01 ms.
//   character  GcsCharacter({ backend: 'gpu' }).update(), split where it calls three.js: the world
//              matrices of the character (updateWorld: three's own work, timed and printed beside)
//              and ours — each skeleton's skin matrices, the joint poses written into the texture's
//              wasm memory (one wasm call per skin), the bounds from the bones, the texture flagged.
//              The mixer (three's animation) is set before each frame and not timed.
//   crowd      100 instances per skin (GcsCrowd, one per skinned mesh of the file): every instance
//              posed from a baked clip (setBakedPose, the demo's crowd) and crowd.update(); per
//              character-frame = the frame / 100. update() alone is printed beside.
// Each frame is timed on its own (performance.now(), sub-microsecond in node); medians over many
// frames. The node pass and the draws happen in the renderer (the page bench, `npm run bench:gpu`).
// Characters: our human, and CesiumMan and Soldier from ../shared/models (skipped with a reason
// when absent).
import { existsSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { GcsCharacter } from '../../dist/three.js';
import { GcsCrowd, bakeClip } from '../../dist/crowd.js';
import { median, percentile } from '../../dist/measure.js';
import { loadGltfFile, rootOf } from '../../packages/cli/dist/gltf-node.js';

const MODELS = resolve(dirname(fileURLToPath(import.meta.url)), '../../../shared/models');
export const GPU_CPU_MODELS = ['CesiumMan', 'Soldier'];
export const GPU_CPU_TARGET_MS = 0.01;
export const CROWD_COUNT = 100;

/** Our human and the shared models found: { name, root, meshes, clip }; `skipped` says which were absent. */
export async function loadGpuCpuCharacters(human, log = console.log) {
  const characters = [{ name: 'our human', root: rootOf(human.mesh), meshes: [human.mesh], clip: human.clips.find((c) => c.name === 'walk') ?? human.clips[0] }];
  const skipped = [];
  for (const name of GPU_CPU_MODELS) {
    const file = `${MODELS}/${name}.glb`;
    if (!existsSync(file)) { skipped.push(`${name}: not measured (no ${file})`); continue; }
    log(`bench: loading ${name}…`);
    const model = await loadGltfFile(file);
    if (!model.clips.length) { skipped.push(`${name}: not measured (no animation clip)`); continue; }
    characters.push({ name, root: model.scene, meshes: model.skinnedMeshes, clip: model.clips[0] });
  }
  return { characters, skipped };
}

const stats = (samples) => ({ medianMs: median(samples), p95Ms: percentile(samples, 95), samples: samples.length });

/**
 * Frames of `clip` at 60 fps, each posed by a mixer (untimed), then `steps` timed one after the
 * other in the same frame; samples until `minSamples` and `minMs`, or `maxMs`.
 */
function timePosedFrames(root, clip, steps, { minSamples, minMs, maxMs, warmup }) {
  const mixer = new THREE.AnimationMixer(root);
  mixer.clipAction(clip).play();
  const frameCount = Math.max(30, Math.round(clip.duration * 60));
  const samples = steps.map(() => []);
  const start = performance.now();
  for (let i = 0; ; i++) {
    mixer.setTime((clip.duration * (i % frameCount)) / frameCount);
    for (let k = 0; k < steps.length; k++) {
      const t0 = performance.now();
      steps[k](i);
      const t1 = performance.now();
      if (i >= warmup) samples[k].push(t1 - t0);
    }
    const elapsed = performance.now() - start;
    if (i >= warmup && ((samples[0].length >= minSamples && elapsed >= minMs) || elapsed >= maxMs)) break;
  }
  mixer.stopAllAction();
  mixer.uncacheRoot(root);
  return samples.map(stats);
}

/**
 * One GcsCharacter on the GPU backend: three's world matrices and our part of update(), timed
 * apart in each frame, and the whole update() as a cross-check.
 */
function characterTimes(gcs, c, timing) {
  const character = new GcsCharacter(gcs, c.root, { backend: 'gpu' });
  try {
    if (character.backend !== 'gpu') throw new Error(`${c.name}: the GPU backend did not build (${character.skins.map((s) => s.backendNote).join('; ')})`);
    // update() is updateWorld(scope) then the loop below: the same steps, split at three's.
    const inner = /** @type {any} */ (character); // its private parts: the bench splits update() where the class does not
    const scope = inner.scope, poses = inner.poses, skinUpdate = inner.skinUpdate, skins = character.skins;
    if (!scope || !poses || !skinUpdate) throw new Error('GcsCharacter.update() changed: the bench no longer splits it (scripts/bench/gpu-cpu.mjs)');
    const [three, ours, whole] = timePosedFrames(c.root, c.clip, [
      () => { scope.parent?.updateWorldMatrix(true, false); scope.updateMatrixWorld(true); },
      () => { poses.nextFrame(); for (let i = 0; i < skins.length; i++) skins[i].update(skinUpdate); },
      () => character.update(),
    ], timing);
    const joints = skins.reduce((n, s) => n + s.rig.jointCount, 0);
    const bytes = skins.reduce((n, s) => n + s.bytesPerFrame, 0);
    return { three, ours, whole, skins: skins.length, joints, bytesPerFrame: bytes, path: skins.map((s) => s.gpuPath).join('+') };
  } finally {
    character.dispose();
  }
}

/** CROWD_COUNT instances of every skin of `c`: baked poses copied and crowd.update() per frame. */
function crowdTimes(gcs, c, timing) {
  const crowds = [], baked = [];
  try {
    for (const mesh of c.meshes) {
      crowds.push(new GcsCrowd(gcs, mesh, CROWD_COUNT));
      baked.push(bakeClip(mesh, c.clip, 60));
    }
    const frameCount = Math.max(30, Math.round(c.clip.duration * 60));
    const dt = 1 / 60;
    const pose = (f) => {
      for (let k = 0; k < crowds.length; k++)
        for (let i = 0; i < CROWD_COUNT; i++) crowds[k].setBakedPose(i, baked[k], (f % frameCount) * dt + i * 0.37);
    };
    const update = () => { for (let k = 0; k < crowds.length; k++) crowds[k].update(); };
    const [posing, updating] = timePosedFrames(c.root, c.clip, [pose, update], timing);
    const bytes = crowds.reduce((n, x) => n + x.bytesPerFrame, 0);
    return { posing, update: updating, bytesPerFrame: bytes, skins: crowds.length };
  } finally {
    for (const x of crowds) x.dispose();
  }
}

/** Every character: rows of ms per character-frame, and the target met or not on the worst of them. */
export function gpuCpuBench(gcs, characters, skipped, { quick = false, log = console.log } = {}) {
  const timing = quick ? { minSamples: 200, minMs: 200, maxMs: 1500, warmup: 30 } : { minSamples: 1000, minMs: 1000, maxMs: 6000, warmup: 60 };
  const crowdTiming = quick ? { minSamples: 30, minMs: 200, maxMs: 1500, warmup: 5 } : { minSamples: 150, minMs: 1000, maxMs: 6000, warmup: 10 };
  const rows = [];
  for (const c of characters) {
    log(`bench: GPU backend CPU time, ${c.name}…`);
    const one = characterTimes(gcs, c, timing);
    const crowd = crowdTimes(gcs, c, crowdTiming);
    rows.push({ name: c.name, skins: one.skins, joints: one.joints, path: one.path,
      character: { oursMs: one.ours.medianMs, oursP95Ms: one.ours.p95Ms, threeMs: one.three.medianMs, wholeMs: one.whole.medianMs, bytes: one.bytesPerFrame, samples: one.ours.samples },
      crowd: { perCharacterMs: (crowd.posing.medianMs + crowd.update.medianMs) / CROWD_COUNT, updatePerCharacterMs: crowd.update.medianMs / CROWD_COUNT,
        frameMs: crowd.posing.medianMs + crowd.update.medianMs, bytesPerCharacter: crowd.bytesPerFrame / CROWD_COUNT, samples: crowd.update.samples } });
  }
  const worst = (key) => rows.reduce((w, r) => (key(r) > key(w) ? r : w), rows[0]);
  const one = worst((r) => r.character.oursMs), many = worst((r) => r.crowd.perCharacterMs);
  const targets = [
    { name: 'GPU backend CPU ms per character-frame, one character (GcsCharacter.update without three\'s world matrices)', value: one.character.oursMs, unit: 'ms',
      goal: `≤ ${GPU_CPU_TARGET_MS} ms`, met: one.character.oursMs <= GPU_CPU_TARGET_MS, note: `worst: ${one.name}; ${rows.map((r) => `${r.name} ${r.character.oursMs.toPrecision(3)}`).join(', ')}` },
    { name: `GPU backend CPU ms per character-frame, crowd of ${CROWD_COUNT} (baked poses + GcsCrowd.update)`, value: many.crowd.perCharacterMs, unit: 'ms',
      goal: `≤ ${GPU_CPU_TARGET_MS} ms`, met: many.crowd.perCharacterMs <= GPU_CPU_TARGET_MS, note: `worst: ${many.name}; ${rows.map((r) => `${r.name} ${r.crowd.perCharacterMs.toPrecision(3)}`).join(', ')}` },
  ];
  return { rows, skipped, targets };
}

/** Table rows for the printed report (header first). */
export function gpuCpuRows(result, ms) {
  const kb = (b) => `${(b / 1024).toFixed(2)} KB`;
  const rows = [['character', 'skins', 'joints', 'path', 'ours ms (one)', 'p95', 'three world ms', 'update() ms', 'uploads (one)', `crowd ×${CROWD_COUNT} ms/char`, 'crowd update() ms/char', 'crowd uploads/char']];
  for (const r of result.rows)
    rows.push([r.name, String(r.skins), String(r.joints), r.path, ms(r.character.oursMs), ms(r.character.oursP95Ms), ms(r.character.threeMs), ms(r.character.wholeMs),
      kb(r.character.bytes), ms(r.crowd.perCharacterMs), ms(r.crowd.updatePerCharacterMs), kb(r.crowd.bytesPerCharacter)]);
  return rows;
}
