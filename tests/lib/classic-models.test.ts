// The classic cross-section model on characters: the default human (17,023 vertices; which parts
// resample, points per limb, detail loss, rebuild time) and the shared real models (../shared/models):
// every one builds and plays its clips with no non-finite value.
import { beforeAll, describe, expect, test } from 'vitest';
import { basename } from 'node:path';
import { initGcsSkin, type GcsSkin, type ClassicDeformer } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { sampleClip } from '../../web/lib/cli/gltf-node.js';
import { loadGlb, sharedModels } from '../helpers/models.js';
import type * as THREE from 'three';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

function nonFinite(a: ArrayLike<number>): number {
  let n = 0;
  for (let i = 0; i < a.length; i++) if (!Number.isFinite(a[i])) n++;
  return n;
}

function describeParts(d: ClassicDeformer, names: string[]): { resampled: string[]; rigid: string[] } {
  const resampled: string[] = [], rigid: string[] = [];
  for (const p of d.parts) (p.resampled ? resampled : rigid).push(names[p.joint] || `#${p.joint}`);
  return { resampled, rigid };
}

/** Plays every clip (frames at 30 fps) and counts non-finite output values. */
function playAll(mesh: THREE.SkinnedMesh, clips: THREE.AnimationClip[], deformers: ClassicDeformer[]): { frames: number; bad: number } {
  let frames = 0, bad = 0;
  for (const clip of clips) {
    const count = Math.max(2, Math.min(90, Math.ceil(clip.duration * 30)));
    for (const skin of sampleClip(mesh, clip, count)) {
      for (const d of deformers) {
        d.deform(skin);
        bad += nonFinite(d.positions) + nonFinite(d.normals);
      }
      frames++;
    }
  }
  return { frames, bad };
}

describe('classic cross-sections on the default human', () => {
  test('limbs and spine resample; head, hands, feet, pelvis, chest are rigid; 25 × 20 gives 500 points on the thigh, the shank by its bone length', () => {
    const human = createHuman();
    const input = rigInputFromSkinnedMesh(human.mesh);
    const rig = gcs.createRig(input);
    expect(Math.abs(rig.vertexCount - 17023)).toBeLessThan(200);
    const names = human.mesh.skeleton.bones.map((b) => b.name);
    const d = rig.buildClassic({ contours: 25, rays: 20, bulge: 0.3 });
    const { resampled, rigid } = describeParts(d, names);
    const byName = (n: string) => d.parts.find((p) => names[p.joint] === n)!;
    const thigh = byName('LeftUpLeg'), shank = byName('LeftLeg');
    const loss = d.detailLoss;
    console.log(`classic human: resampled [${resampled.join(', ')}]; rigid [${rigid.join(', ')}]`);
    console.log(`classic human: thigh ${thigh.vertexCount} points, shank ${shank.vertexCount} points, output ${d.vertexCount} vertices / ${d.indices.length / 3} triangles, ${d.sectionCount} contours`);
    console.log(`classic human: detail loss RMS ${loss.rms.toFixed(3)} % / max ${loss.max.toFixed(3)} % of height`);
    for (const limb of ['LeftUpLeg', 'LeftLeg', 'RightUpLeg', 'RightLeg', 'LeftArm', 'LeftForeArm', 'RightArm', 'RightForeArm'])
      expect(resampled).toContain(limb);
    for (const end of ['Head', 'LeftHand', 'RightHand', 'LeftFoot', 'RightFoot', 'Hips']) expect(rigid).toContain(end);
    expect(thigh.vertexCount).toBe(500);
    expect(shank.vertexCount).toBeGreaterThanOrEqual(360);
    expect(shank.vertexCount).toBeLessThanOrEqual(500);
    expect(loss.rms).toBeGreaterThan(0);
    expect(loss.max).toBeLessThan(5);
    const { frames, bad } = playAll(human.mesh, human.clips, [d]);
    expect(frames).toBeGreaterThan(10);
    expect(bad).toBe(0);
    d.dispose();
    rig.dispose();
  });

  test('rebuild time for the slider (17,023 vertices, 25 × 20), measured in wasm', () => {
    const human = createHuman();
    const rig = gcs.createRig(rigInputFromSkinnedMesh(human.mesh));
    const times: number[] = [];
    for (let i = 0; i < 15; i++) {
      const t0 = performance.now();
      const d = rig.buildClassic({ contours: 25, rays: 20, bulge: 0.3 });
      times.push(performance.now() - t0);
      d.dispose();
    }
    times.sort((a, b) => a - b);
    const median = times[7];
    const t0 = performance.now();
    const d = rig.buildClassic({ contours: 25, rays: 20, bulge: 0.3 });
    const loss = d.detailLoss; // computed on first use
    const lossMs = performance.now() - t0;
    const skin = sampleClip(human.mesh, human.clips.find((c) => c.name === 'run') ?? human.clips[0], 30);
    const f0 = performance.now();
    for (let r = 0; r < 10; r++) for (const s of skin) d.deform(s);
    const frameMs = (performance.now() - f0) / (10 * skin.length);
    console.log(`classic human: rebuild median ${median.toFixed(2)} ms (min ${times[0].toFixed(2)}, max ${times[14].toFixed(2)}) over 15 builds; build + detail loss ${lossMs.toFixed(2)} ms (RMS ${loss.rms.toFixed(3)} %); deform ${frameMs.toFixed(3)} ms/frame`);
    // Target ≤ 30 ms. The fastest build is the least disturbed by other load on the machine.
    expect(times[0]).toBeLessThan(30);
    d.dispose();
    rig.dispose();
  });
});

const { files, reason } = sharedModels();
if (reason) console.log(`classic-models.test: ${reason}`);

describe.skipIf(files.length === 0)('classic cross-sections on the shared models', () => {
  for (const file of files) {
    test(`${basename(file)}: builds, reports its parts, plays every clip with finite output`, async () => {
      const model = await loadGlb(file);
      for (const mesh of model.skinnedMeshes) {
        const rig = gcs.createRig(rigInputFromSkinnedMesh(mesh));
        const names = mesh.skeleton.bones.map((b) => b.name);
        const d = rig.buildClassic();
        const coarse = rig.buildClassic({ contours: 4, rays: 6, bulge: 2 });
        const { resampled, rigid } = describeParts(d, names);
        const loss = d.detailLoss;
        console.log(`classic ${basename(file)} / ${mesh.name}: ${rig.vertexCount} vertices; resampled ${resampled.length} [${resampled.join(', ')}]; rigid ${rigid.length} [${rigid.join(', ')}]; detail loss RMS ${loss.rms.toFixed(3)} % / max ${loss.max.toFixed(3)} %`);
        expect(d.parts.length).toBeGreaterThan(0);
        expect(Number.isFinite(loss.rms) && Number.isFinite(loss.max)).toBe(true);
        expect(nonFinite(d.positions) + nonFinite(d.normals)).toBe(0);
        const { bad } = playAll(mesh, model.clips, [d, coarse]);
        expect(bad).toBe(0);
        d.dispose();
        coarse.dispose();
        rig.dispose();
      }
    });
  }
});
