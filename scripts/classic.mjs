// npm run classic [-- --markdown] [--no-models] [--model PATH …]
// The classic cross-section model on the default human and on every character in ../shared/models
// (skipped with a reason when absent), per skinned mesh: which parts it resamples, the points on
// the thigh and shank at the paper's leg densities (25 contours × 20 rays on the longest bone:
// ≈ 500 on a thigh), the resampling detail loss there and at GCS's vertex budget (GCS keeps every
// input vertex: no loss), and the output's border beside the input's (equal: no gap where tubes
// meet carried skin). Then, per mesh, how far the classic output lies from the skin it replaces
// as dual-quaternion skinning poses it (6 frames per clip, bulge at its default 0.3): p99 and max
// over all output vertices and frames, in % of the character's height, and the parts with the
// largest figures. --model PATH (repeatable) adds a .glb from anywhere, e.g. a character whose
// licence keeps it out of ../shared/models. Measurement code: web/lib/measure.ts (classicFigures, classicAtBudget,
// classicOffSurface).
import { existsSync, readdirSync } from 'node:fs';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { initGcsSkin } from '../dist/index.js';
import { rigInputFromSkinnedMesh } from '../dist/three.js';
import { createHuman } from '../dist/human/index.js';
import { characterHeight, loadGltfFile, sampleClip } from '../packages/cli/dist/gltf-node.js';
import { classicAtBudget, classicBandQuality, classicFigures, classicOffSurface, identitySkin, meshBorder, rigidRebind } from '../dist/measure.js';
import { argsOrExit, markdownTable, num, table } from './bench/common.mjs';
import { findBone } from './bench/fidelity.mjs';

const extraModels = [];
const args = argsOrExit('classic', {
  markdown: { type: 'flag', default: false },
  noModels: { type: 'flag', default: false },
  model: { type: 'string', default: extraModels, parse: (v) => (extraModels.push(v), extraModels) },
}, 'usage: npm run classic -- [--markdown] [--no-models] [--model PATH …]');
const MODELS_DIR = resolve(dirname(fileURLToPath(import.meta.url)), '../../shared/models');
const gcs = await initGcsSkin();

const human = createHuman();
const characters = [{ name: 'default human', meshes: [human.mesh], clips: human.clips }];
if (args.noModels) console.error('classic: shared models skipped (--no-models)');
else if (!existsSync(MODELS_DIR)) console.error(`classic: shared models skipped: ${MODELS_DIR} is absent`);
else
  for (const f of readdirSync(MODELS_DIR).filter((x) => /\.glb$/i.test(x)).sort()) {
    const model = await loadGltfFile(join(MODELS_DIR, f));
    characters.push({ name: f, meshes: model.skinnedMeshes, clips: model.clips });
  }
for (const path of args.model) {
  if (!existsSync(path)) {
    console.error(`classic: ${path} not found`);
    process.exit(2);
  }
  const model = await loadGltfFile(path);
  characters.push({ name: basename(path), meshes: model.skinnedMeshes, clips: model.clips });
}

const rows = [['character / mesh', 'input vertices (GCS)', 'resampled + trunk / carried parts', 'thigh / shank points',
  'loss at 25 × 20: RMS / max %', 'output vertices', 'at the GCS budget: setting', 'loss RMS / max %', 'border in / out']];
for (const ch of characters)
  for (const mesh of ch.meshes) {
    const input = rigInputFromSkinnedMesh(mesh);
    const rig = gcs.createRig(input);
    const paper = classicFigures(rig, 25, 20);
    const any = paper.resampled + paper.trunk > 0;
    const budget = any ? classicAtBudget(rig) : null;
    const inBorder = meshBorder(input.positions, input.indices).open;
    // Points on the thigh and the shank where the bones have human names.
    const pointsOf = (name) => paper.points.get(findBone(mesh.skeleton.bones, name));
    const thigh = pointsOf('LeftUpLeg'), shank = pointsOf('LeftLeg');
    rows.push([`${ch.name}${ch.meshes.length > 1 ? ` / ${mesh.name}` : ''}`, String(rig.vertexCount),
      `${paper.resampled} + ${paper.trunk} / ${paper.carried}`, thigh ? `${thigh} / ${shank ?? '—'}` : '—',
      any ? `${num(paper.rms, 2)} / ${num(paper.max, 2)}` : 'nothing resampled', String(paper.outputVertices),
      budget ? `${budget.contours} × ${budget.rays} (${budget.outputVertices})` : '—',
      budget ? `${num(budget.rms, 2)} / ${num(budget.max, 2)}` : '—',
      `${inBorder} / ${paper.border}${budget ? `, ${budget.border}` : ''}`]);
    rig.dispose();
  }
console.log(args.markdown ? markdownTable(rows) : table(rows));

// Off the skin: each classic output vertex's distance to the DQS-posed source surface.
const FRAMES_PER_CLIP = 6;
const off = [['character / mesh', 'frames', 'off-surface p99 %', 'max %', 'worst parts (reason: p99 / max %)', 'carried off-surface',
  'band triangles: min angle ° / under 5° / aspect max']];
for (const ch of characters) {
  const heights = characterHeight(ch.meshes);
  ch.meshes.flatMap((mesh, i) => /** @type {[import('three').SkinnedMesh, number, boolean][]} */ ([[mesh, i, false], [mesh, i, true]])).forEach(([mesh, i, rigid]) => {
    const own = rigInputFromSkinnedMesh(mesh);
    const input = rigid ? rigidRebind(own) : own;  // rigid: a rig of rigid parts, like X Bot
    const rig = gcs.createRig(input);
    const d = rig.buildClassic();
    const sampled = ch.clips.flatMap((clip) => sampleClip(mesh, clip, FRAMES_PER_CLIP));
    const frames = sampled.length ? sampled : [identitySkin(rig.jointCount)];
    const r = classicOffSurface(input, d, frames, { height: heights.meshUnits[i] });
    const name = (j) => mesh.skeleton.bones[j]?.name || `#${j}`;
    const worst = [...r.parts].sort((a, b) => b.max - a.max).filter((p) => p.max > 0.005).slice(0, 3)
      .map((p) => `${name(p.joint)} (${p.reason}: ${num(p.p99, 2)} / ${num(p.max, 2)})`).join(', ');
    const offParts = d.parts.filter((p) => p.reason === 'off-surface').map((p) => name(p.joint));
    d.deform(identitySkin(rig.jointCount));
    const q = classicBandQuality(d, input);
    off.push([`${ch.name}${ch.meshes.length > 1 ? ` / ${mesh.name}` : ''}${rigid ? ' (rigid)' : ''}`, String(frames.length), num(r.p99, 2), num(r.max, 2),
      worst || '— (all carried: on the skin)', offParts.length ? offParts.join(', ') : '—',
      q.triangles ? `${num(q.minAngle, 2)} / ${q.under5} of ${q.triangles} / ${num(q.aspectMax, 1)}` : '—']);
    d.dispose();
    rig.dispose();
  });
}
console.log('');
console.log(args.markdown ? markdownTable(off) : table(off));
console.log('\nLoss: distance of each input vertex the tubes and bands replace to the resampled surface, % of the mesh\'s height ' +
  '(GCS: 0, it keeps every vertex). GCS budget: the square setting contours = rays whose output is closest to the input\'s vertex ' +
  'count. Border: welded edges used by one triangle, input / output at 25 × 20 and at the budget. Off-surface: distance of each ' +
  `output vertex to the source surface as DQS poses it, ${FRAMES_PER_CLIP} frames per clip, bulge 0.3, % of the character's height ` +
  '(targets: p99 ≤ 1, max ≤ 2.5); carried skin moves by DQS of its own weights, so it lies on that surface. (rigid): the same mesh ' +
  'with every vertex bound 100 % to its dominant joint. Band triangles: those of the bands between a tube\'s end ring and carried skin (neither a tube\'s nor a carried input triangle), at the bind pose.');
