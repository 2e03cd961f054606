// The classic cross-section model in the characters' own motion: every clip of our human and of
// every shared character (../shared/models), and each of them rebound as a rig of rigid parts (every
// vertex 100 % on its dominant joint, like Mixamo's X Bot), stays on the skin it replaces (per clip:
// off-surface p99 ≤ 1 %, max ≤ 2.5 % of the height). The build's outputs are pinned by a digest
// (tests/lib/classic-golden.json): taken before the build was split into steps and made faster
// (the same triangles, reports and deformed vertices, bit for bit), and taken again, on purpose,
// when the zip bands got rows of their own vertices, and for Soldier's body mesh when open tube
// ends began to start where their rays all find skin (GCS_WRITE_CLASSIC_GOLDEN=1 writes it).
import { beforeAll, describe, expect, test } from 'vitest';
import { createHash } from 'node:crypto';
import { existsSync, readFileSync, writeFileSync } from 'node:fs';
import { basename, dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import type * as THREE from 'three';
import { initGcsSkin, type GcsSkin, type ClassicDeformer, type RigInput } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { characterHeight, sampleClip } from '../../packages/cli/src/gltf-node.js';
import { classicBandQuality, classicOffSurface, identitySkin, rigidRebind } from '../../web/lib/measure.js';
import { loadGlb, MODELS_DIR, sharedModels } from '../helpers/models.js';
import { rigidShellFigure, strideFrames } from './classic-stand-ins.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

const FRAMES_PER_CLIP = 12;
const GOLDEN = join(dirname(fileURLToPath(import.meta.url)), 'classic-golden.json');

interface Character { name: string; meshes: THREE.SkinnedMesh[]; clips: THREE.AnimationClip[] }

/** Our human, then the shared characters (only `only`, if given). */
async function characters(only?: string): Promise<Character[]> {
  const human = createHuman();
  const out: Character[] = [{ name: 'human', meshes: [human.mesh], clips: human.clips }];
  for (const file of sharedModels().files) {
    if (only && basename(file, '.glb') !== only) continue;
    const model = await loadGlb(file);
    out.push({ name: basename(file, '.glb'), meshes: model.skinnedMeshes, clips: model.clips });
  }
  return out;
}

/** The meshes of a character as rig inputs: as they are, and rebound rigidly. */
function variants(ch: Character): { label: string; mesh: THREE.SkinnedMesh; index: number; input: RigInput }[] {
  return ch.meshes.flatMap((mesh, index) => {
    const input = rigInputFromSkinnedMesh(mesh);
    const name = `${ch.name}${ch.meshes.length > 1 ? ` / ${mesh.name}` : ''}`;
    return [{ label: name, mesh, index, input }, { label: `${name} (rigid)`, mesh, index, input: rigidRebind(input) }];
  });
}

/** A digest of everything a classic build gives: triangles, report, maps, and the deformed output over frames. */
function digest(d: ClassicDeformer, frames: Float32Array[]): string {
  const h = createHash('sha256');
  const bytes = (a: ArrayLike<number> & { buffer: ArrayBufferLike; byteOffset: number; byteLength: number }) =>
    h.update(new Uint8Array(a.buffer, a.byteOffset, a.byteLength));
  bytes(d.indices);
  bytes(Int32Array.from(d.parts.flatMap((p) => [p.joint, p.resampled ? 1 : 0, p.firstVertex, p.vertexCount])));
  h.update(d.parts.map((p) => p.reason).join());
  bytes(d.contourOfVertex);
  bytes(d.sourceOfVertex);
  for (const skin of [identitySkin(d.jointCount), ...frames]) {
    d.deform(skin);
    bytes(d.positions);
    bytes(d.normals);
  }
  bytes(Float32Array.of(d.detailLoss.rms, d.detailLoss.max));
  return h.digest('hex');
}

describe('classic cross-sections: the same outputs as the pinned build', () => {
  test('human, shared characters and their rigid rebinds: triangles, reports and deformed vertices bit for bit (4 frames per clip)', async () => {
    const found: Record<string, string> = {};
    for (const ch of await characters())
      for (const v of variants(ch)) {
        const rig = gcs.createRig(v.input);
        const d = rig.buildClassic();
        found[v.label] = digest(d, ch.clips.flatMap((clip) => sampleClip(v.mesh, clip, 4)));
        d.dispose();
        rig.dispose();
      }
    if (process.env.GCS_WRITE_CLASSIC_GOLDEN) writeFileSync(GOLDEN, `${JSON.stringify(found, null, 2)}\n`);
    const golden = JSON.parse(readFileSync(GOLDEN, 'utf8')) as Record<string, string>;
    const compared = Object.keys(found).filter((k) => k in golden);
    console.log(`classic golden: ${compared.length} of ${Object.keys(found).length} builds compared`);
    expect(compared.length).toBeGreaterThanOrEqual(2); // at least the human and its rigid rebind
    for (const k of compared) expect(found[k], k).toBe(golden[k]);
  });
});

// One test per character (the measure is the costly part): a build that resamples nothing is
// checked on a few frames per clip (its carried skin is DQS of its own weights).
const onSkin = sharedModels().files.map((f) => basename(f, '.glb'));
describe('classic cross-sections stay on the skin in every clip (distance to the DQS-posed source surface)', () => {
  for (const name of ['human', ...onSkin])
    test(`${name}, as it is and rebound rigidly, every clip (${FRAMES_PER_CLIP} frames): p99 ≤ 1 %, max ≤ 2.5 % of the height`, async () => {
      const ch = name === 'human' ? (await characters())[0] : (await characters(name))[1];
      const rows: string[] = [];
      const heights = characterHeight(ch.meshes);
      for (const v of variants(ch)) {
        const rig = gcs.createRig(v.input);
        const d = rig.buildClassic();
        const resampled = d.parts.filter((p) => p.resampled).length;
        const carriedOff = d.parts.filter((p) => p.reason === 'off-surface').length;
        for (const clip of ch.clips) {
          const frames = sampleClip(v.mesh, clip, resampled ? FRAMES_PER_CLIP : 3);
          const r = classicOffSurface(v.input, d, frames, { height: heights.meshUnits[v.index] });
          rows.push(`${v.label} / ${clip.name || 'clip'}: p99 ${r.p99.toFixed(3)} %, max ${r.max.toFixed(3)} % (${resampled} parts resampled, ${carriedOff} carried off-surface)`);
          expect(r.p99, `${v.label} / ${clip.name}`).toBeLessThanOrEqual(1);
          expect(r.max, `${v.label} / ${clip.name}`).toBeLessThanOrEqual(2.5);
          // Carried skin moves by DQS of its own weights: it lies on the surface (float rounding only).
          for (const p of r.parts) if (!p.resampled) expect(p.max).toBeLessThan(1e-3);
        }
        d.dispose();
        rig.dispose();
      }
      console.log(`classic off-surface per clip:\n  ${rows.join('\n  ')}`);
    }, 180_000);
});

// A rig of separate rigid shells with gaps at the joints (Mixamo's X Bot; the rigid rebinds above
// keep one connected skin, and passed). Before the rules of pieces (a contour reads influences
// only from the pieces of skin its rays hit; tubes share a joint ring only where skin joins them)
// and of open ends (a tube end that meets nothing starts where its rays all find skin), the
// shank's end rings stood in the gap above its slanted shell, blended with the thigh's shell
// around their plane, and left the skin at the bent knee. Measured then (p99 / max %): 0.90 / 2.61,
// 0.97 / 3.42 and 1.03 / 3.42 for the first three shapes below; 17 of 288 shapes of a wider sweep
// failed, none fails now.
const SHELL_SHAPES = [
  // thigh's gap above the knee, shank's start below it (negative: above), dome, slant, knee bend°
  [0.01, -0.03, 0.2, 0.4, 130],
  [0.03, -0.005, 0.4, 1.2, 150],
  [0.015, -0.015, 0.4, 0.8, 150],  // the shells' ends touch at one point
  [0.02, -0.01, 0.2, 0.4, 150],
] as const;
describe('classic cross-sections on a rig of separate rigid shells (a stand-in for X Bot)', () => {
  test(`a stride, ${SHELL_SHAPES.length} shapes of knee (${FRAMES_PER_CLIP} frames): p99 ≤ 1 %, max ≤ 2.5 % of the height`, () => {
    const rows: string[] = [];
    for (const [thighGap, shankStart, dome, slant, knee] of SHELL_SHAPES) {
      const figure = rigidShellFigure(thighGap, shankStart, dome, slant);
      const rig = gcs.createRig(figure.input);
      const d = rig.buildClassic();
      const r = classicOffSurface(figure.input, d, strideFrames(figure, FRAMES_PER_CLIP, knee), {});
      const label = `shells ${thighGap} / ${shankStart} / ${dome} / ${slant}, knee ${knee}°`;
      rows.push(`${label}: p99 ${r.p99.toFixed(3)} %, max ${r.max.toFixed(3)} %; ${r.parts.filter((p) => p.resampled).map((p) => `joint ${p.joint} ${p.p99.toFixed(2)} / ${p.max.toFixed(2)}`).join(', ')}`);
      expect(d.parts.find((p) => p.joint === 4)?.resampled, `${label}: the shank is resampled`).toBe(true);
      expect(r.p99, label).toBeLessThanOrEqual(1);
      expect(r.max, label).toBeLessThanOrEqual(2.5);
      d.dispose();
      rig.dispose();
    }
    console.log(`classic rigid shells:\n  ${rows.join('\n  ')}`);
  });
});

// Mixamo's X Bot itself, when it is on this machine (its licence keeps it out of the repository):
// GCS_XBOT=/path/to/Xbot.glb, or ../shared/models/Xbot.glb (then also measured above).
const XBOT = process.env.GCS_XBOT ?? join(MODELS_DIR, 'Xbot.glb');
describe('classic cross-sections on X Bot (optional)', () => {
  const reason = existsSync(XBOT) ? '' : `skipped: ${XBOT} is absent (set GCS_XBOT to Mixamo's X Bot .glb)`;
  if (reason) console.log(`classic X Bot: ${reason}`);
  test.skipIf(Boolean(reason))(`every mesh, every clip (${FRAMES_PER_CLIP} frames): p99 ≤ 1 %, max ≤ 2.5 % of the height`, async () => {
    const model = await loadGlb(XBOT);
    const heights = characterHeight(model.skinnedMeshes);
    const rows: string[] = [];
    model.skinnedMeshes.forEach((mesh, index) => {
      const input = rigInputFromSkinnedMesh(mesh);
      const rig = gcs.createRig(input);
      const d = rig.buildClassic();
      for (const clip of model.clips) {
        const r = classicOffSurface(input, d, sampleClip(mesh, clip, FRAMES_PER_CLIP), { height: heights.meshUnits[index] });
        rows.push(`${mesh.name} / ${clip.name}: p99 ${r.p99.toFixed(3)} %, max ${r.max.toFixed(3)} %`);
        expect(r.p99, `${mesh.name} / ${clip.name}`).toBeLessThanOrEqual(1);
        expect(r.max, `${mesh.name} / ${clip.name}`).toBeLessThanOrEqual(2.5);
      }
      d.dispose();
      rig.dispose();
    });
    console.log(`classic X Bot off-surface per clip:\n  ${rows.join('\n  ')}`);
  }, 180_000);
});

// The bands between tubes and carried skin: rows of band vertices between the ring and the loop,
// so no long slivers where a loop runs down the bone. A single row of triangles from ring to loop
// (before) failed every bound here: our human 0.03° (251 of 737 triangles under 5°, aspect 1198),
// CesiumMan 0.61° (20 of 331), Soldier 0.30° (17 of 320, aspect 131).
const BAND_MIN_ANGLE = 1.5;    // degrees (measured: 2.04° at least)
const BAND_MAX_ASPECT = 30;    // (measured: 18.0 at most)
const BAND_UNDER_5_SHARE = 0.03;  // of the band triangles (measured: 1.7 % at most)
describe('classic cross-sections: the zip bands between tubes and carried skin', () => {
  test(`band triangles at the bind pose: smallest angle ≥ ${BAND_MIN_ANGLE}°, aspect ≤ ${BAND_MAX_ASPECT}, under 5° ≤ ${BAND_UNDER_5_SHARE * 100} %`, async () => {
    for (const ch of await characters())
      for (const mesh of ch.meshes) {
        const input = rigInputFromSkinnedMesh(mesh);
        const rig = gcs.createRig(input);
        const d = rig.buildClassic();
        d.deform(identitySkin(d.jointCount));
        const q = classicBandQuality(d, input);
        const label = `${ch.name} / ${mesh.name}`;
        console.log(`classic bands ${label}: ${q.triangles} triangles, min angle ${q.minAngle.toFixed(2)}° (p1 ${q.minAngleP1.toFixed(2)}°, median ${q.minAngleMedian.toFixed(1)}°), under 5° ${q.under5}, aspect max ${q.aspectMax.toFixed(1)} (p99 ${q.aspectP99.toFixed(1)}, median ${q.aspectMedian.toFixed(2)})`);
        // A band joins every edge of its ring and its loop: where something is resampled and
        // meets carried skin there are band triangles.
        if (d.parts.some((p) => p.resampled) && d.parts.some((p) => !p.resampled)) expect(q.triangles).toBeGreaterThan(0);
        if (q.triangles) {
          expect(q.minAngle, label).toBeGreaterThanOrEqual(BAND_MIN_ANGLE);
          expect(q.aspectMax, label).toBeLessThanOrEqual(BAND_MAX_ASPECT);
          expect(q.under5 / q.triangles, label).toBeLessThanOrEqual(BAND_UNDER_5_SHARE);
        }
        d.dispose();
        rig.dispose();
      }
  });
});
