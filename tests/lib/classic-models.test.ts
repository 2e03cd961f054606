// The classic cross-section model on characters: the default human (17,023 vertices; which parts
// resample and why, points per limb, detail loss, a closed output whose seams never open, rebuild
// time printed) and the shared real models (../shared/models) and a ×100 rig: every one builds,
// keeps a closed input closed (no gap, no overlap where tubes meet carried parts), plays its clips
// with finite output and unit normals (on the skin in every clip: classic-motion.test.ts).
import { beforeAll, describe, expect, test } from 'vitest';
import { basename } from 'node:path';
import { initGcsSkin, type GcsSkin, type ClassicDeformer } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { sampleClip } from '../../packages/cli/src/gltf-node.js';
import { coincidentPairs, meshBorder, seamGap } from '../../web/lib/measure.js';
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

/**
 * Plays every clip (frames at 30 fps): non-finite output values, the largest seam gap (vertices
 * that coincide at rest drifting apart: a band's loop leaving its carried triangles, a cap's rim
 * leaving its ring) and the largest |normal length − 1|.
 */
function playAll(mesh: THREE.SkinnedMesh, clips: THREE.AnimationClip[], deformers: ClassicDeformer[], scale = 1): { frames: number; bad: number; gap: number; normalOff: number } {
  let frames = 0, bad = 0, gap = 0, normalOff = 0;
  const pairs = deformers.map((d) => coincidentPairs(d.positions.slice()));
  for (const clip of clips) {
    const count = Math.max(2, Math.min(90, Math.ceil(clip.duration * 30)));
    for (const skin of sampleClip(mesh, clip, count)) {
      if (scale !== 1) scaleSkin(skin, scale);
      deformers.forEach((d, i) => {
        d.deform(skin);
        bad += nonFinite(d.positions) + nonFinite(d.normals);
        gap = Math.max(gap, seamGap(d.positions, pairs[i]));
        const n = d.normals;
        for (let v = 0; v < n.length; v += 3) normalOff = Math.max(normalOff, Math.abs(Math.hypot(n[v], n[v + 1], n[v + 2]) - 1));
      });
      frames++;
    }
  }
  return { frames, bad, gap, normalOff };
}

/** S_j · (×scale): what a cm export's skin matrices carry (Mixamo: ×100). */
function scaleSkin(skin: Float32Array, scale: number): void {
  for (let j = 0; j < skin.length / 16; j++) for (let c = 0; c < 12; c++) skin[16 * j + c] *= scale;
}

/** The welded border of a classic output at rest. */
function border(d: ClassicDeformer): { open: number; overused: number } {
  return meshBorder(d.positions, d.indices);
}

describe('classic cross-sections on the default human', () => {
  test('limbs, spine and pelvis (along the spine) resample; head, hands, feet and the chest (shoulders) are carried, each with its reason; 25 × 20 gives 500 points on the thigh', () => {
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
    console.log(`classic human: ${d.parts.map((p) => `${names[p.joint]} ${p.reason}`).join(', ')}`);
    console.log(`classic human: thigh ${thigh.vertexCount} points, shank ${shank.vertexCount} points, output ${d.vertexCount} vertices / ${d.indices.length / 3} triangles, ${d.sectionCount} contours`);
    console.log(`classic human: detail loss RMS ${loss.rms.toFixed(3)} % / max ${loss.max.toFixed(3)} % of height`);
    for (const limb of ['LeftUpLeg', 'LeftLeg', 'RightUpLeg', 'RightLeg', 'LeftForeArm', 'RightArm', 'RightForeArm', 'Spine'])
      expect(byName(limb).reason).toBe('resampled');
    // The left upper arm's tube stands off its skin at the build's probe poses (p99 just over
    // 1 %; the right one passes): carried, by measurement.
    expect(['resampled', 'off-surface']).toContain(byName('LeftArm').reason);
    // The trunk: the pelvis is resampled along the spine above the crotch, one tube with the spine.
    expect(byName('Hips').reason).toBe('trunk');
    expect(resampled).toContain('Hips');
    for (const end of ['Head', 'LeftHand', 'RightHand', 'LeftFoot', 'RightFoot']) expect(byName(end).reason).toBe('leaf');
    for (const part of ['Chest', 'Head', 'LeftHand', 'LeftFoot']) expect(rigid).toContain(part);
    expect(thigh.vertexCount).toBe(500);
    expect(shank.vertexCount).toBeGreaterThanOrEqual(360);
    expect(shank.vertexCount).toBeLessThanOrEqual(500);
    expect(loss.rms).toBeGreaterThan(0);
    expect(loss.max).toBeLessThan(5);
    // Every output vertex is on a contour, a copy of one input vertex (which the page takes its
    // texture coordinates from) or a band vertex (neither: a point of the input surface between a
    // tube's end ring and the carried skin, our human's hips have rows of them); at the bind pose a
    // copy sits exactly on its source.
    const contourOf = d.contourOfVertex, sourceOf = d.sourceOfVertex;
    let carried = 0, band = 0;
    for (let v = 0; v < d.vertexCount; v++) {
      if (contourOf[v] >= 0) expect(sourceOf[v]).toBe(-1);
      if (contourOf[v] >= 0) continue;
      if (sourceOf[v] < 0) { band++; continue; }
      carried++;
      for (let c = 0; c < 3; c++) expect(d.positions[3 * v + c]).toBe(input.positions[3 * sourceOf[v] + c]);
    }
    expect(carried).toBeGreaterThan(1000);
    expect(band).toBeGreaterThan(0);
    expect(band).toBeLessThan(0.05 * d.vertexCount);
    d.dispose();
    rig.dispose();
  });

  test('the output is a closed mesh at rest and stays closed along every clip: every edge shared by two triangles, no seam opens', () => {
    const human = createHuman();
    const input = rigInputFromSkinnedMesh(human.mesh);
    const rig = gcs.createRig(input);
    const inputBorder = meshBorder(input.positions, input.indices);
    expect(inputBorder).toEqual({ open: 0, overused: 0 }); // the human is closed
    for (const settings of [{ contours: 25, rays: 20, bulge: 0.3 }, { contours: 6, rays: 5, bulge: 2 }, { contours: 60, rays: 64, bulge: 0 }]) {
      const d = rig.buildClassic(settings);
      // Topology is fixed at build: closed at rest is closed in every frame, if no seam opens.
      expect(border(d)).toEqual({ open: 0, overused: 0 });
      const { frames, bad, gap, normalOff } = playAll(human.mesh, human.clips, [d]);
      console.log(`classic human ${settings.contours} × ${settings.rays}: closed, ${frames} frames, seam gap ${gap}, normals off unit ${normalOff.toExponential(1)}`);
      expect(frames).toBeGreaterThan(10);
      expect(bad).toBe(0);
      expect(gap).toBe(0);
      expect(normalOff).toBeLessThan(1e-5);
      d.dispose();
    }
    rig.dispose();
  });

  test('rebuild time for the slider (17,023 vertices, 25 × 20), measured in wasm (printed)', () => {
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
    // Target ≤ 30 ms: a figure, not an assertion (a timed test flakes on a shared machine);
    // `npm run bench` prints it against the target.
    expect(times[0]).toBeGreaterThan(0);
    d.dispose();
    rig.dispose();
  });
});

const { files, reason } = sharedModels();
if (reason) console.log(`classic-models.test: ${reason}`);

describe.skipIf(files.length === 0)('classic cross-sections on the shared models', () => {
  for (const file of files) {
    test(`${basename(file)}: builds, reports why each part is carried, keeps a closed input closed, plays every clip (and ×100) with finite output and unit normals`, async () => {
      const model = await loadGlb(file);
      for (const mesh of model.skinnedMeshes) {
        const input = rigInputFromSkinnedMesh(mesh);
        const rig = gcs.createRig(input);
        const names = mesh.skeleton.bones.map((b, i) => b.name || `#${i}`);
        const d = rig.buildClassic();
        const coarse = rig.buildClassic({ contours: 4, rays: 6, bulge: 2 });
        const loss = d.detailLoss;
        const inputBorder = meshBorder(input.positions, input.indices);
        const reasons = new Map<string, string[]>();
        for (const p of d.parts) reasons.set(p.reason, [...(reasons.get(p.reason) ?? []), names[p.joint]]);
        console.log(`classic ${basename(file)} / ${mesh.name}: ${rig.vertexCount} vertices; ${[...reasons].map(([r, n]) => `${r} ${n.length} [${n.join(', ')}]`).join('; ')}; detail loss RMS ${loss.rms.toFixed(3)} % / max ${loss.max.toFixed(3)} %; input border ${inputBorder.open}, output border ${border(d).open}`);
        expect(d.parts.length).toBeGreaterThan(0);
        expect(Number.isFinite(loss.rms) && Number.isFinite(loss.max)).toBe(true);
        // A resampled part replaces input skin (a tube laid over kept skin would be an overlap).
        if (d.parts.some((p) => p.resampled)) expect(loss.rms).toBeGreaterThan(0);
        // Where tubes meet carried parts the output adds no border and no overlap: a closed
        // input stays closed, an open one keeps exactly its own border.
        for (const m of [d, coarse]) expect(border(m)).toEqual({ open: inputBorder.open, overused: inputBorder.overused });
        for (const scale of [1, 100]) {
          const { bad, gap, normalOff } = playAll(mesh, model.clips, [d, coarse], scale);
          expect(bad).toBe(0);
          expect(gap).toBe(0);
          expect(normalOff).toBeLessThan(1e-5);
        }
        d.dispose();
        coarse.dispose();
        rig.dispose();
      }
    });
  }
});
