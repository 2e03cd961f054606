// npm run classic [-- --markdown] [--no-models]
// The classic cross-section model on the default human and on every character in ../shared/models
// (skipped with a reason when absent), per skinned mesh: which parts it resamples, the points on
// the thigh and shank at the paper's leg densities (25 contours × 20 rays on the longest bone:
// ≈ 500 on a thigh), the resampling detail loss there and at GCS's vertex budget (GCS keeps every
// input vertex: no loss), and the output's border beside the input's (equal: no gap where tubes
// meet carried skin). Measurement code: web/lib/measure.ts (classicFigures, classicAtBudget).
import { existsSync, readdirSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { initGcsSkin } from '../dist/index.js';
import { rigInputFromSkinnedMesh } from '../dist/three.js';
import { createHuman } from '../dist/human/index.js';
import { loadGltfFile } from '../dist/cli/gltf-node.js';
import { classicAtBudget, classicFigures, meshBorder } from '../dist/measure.js';
import { markdownTable, num, parseArgs, table } from './bench/common.mjs';
import { findBone } from './bench/fidelity.mjs';

let args;
try {
  args = parseArgs(process.argv.slice(2), { markdown: { type: 'flag', default: false }, noModels: { type: 'flag', default: false } });
} catch (e) {
  console.error(`classic: ${e.message}`);
  process.exit(2);
}
if (args.help) {
  console.log('usage: npm run classic -- [--markdown] [--no-models]');
  process.exit(0);
}
const MODELS_DIR = resolve(dirname(fileURLToPath(import.meta.url)), '../../shared/models');
const gcs = await initGcsSkin();

const characters = [{ name: 'default human', meshes: [createHuman().mesh] }];
if (args.noModels) console.error('classic: shared models skipped (--no-models)');
else if (!existsSync(MODELS_DIR)) console.error(`classic: shared models skipped: ${MODELS_DIR} is absent`);
else
  for (const f of readdirSync(MODELS_DIR).filter((x) => /\.glb$/i.test(x)).sort()) {
    const model = await loadGltfFile(join(MODELS_DIR, f));
    characters.push({ name: f, meshes: model.skinnedMeshes });
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
console.log('\nLoss: distance of each input vertex the tubes and bands replace to the resampled surface, % of the mesh\'s height ' +
  '(GCS: 0, it keeps every vertex). GCS budget: the square setting contours = rays whose output is closest to the input\'s vertex ' +
  'count. Border: welded edges used by one triangle, input / output at 25 × 20 and at the budget.');
