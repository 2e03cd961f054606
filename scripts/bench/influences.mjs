// node scripts/bench/influences.mjs [--against DIST] [--rounds N]
// What up to 8 influences per vertex cost. On the default human, CesiumMan and Soldier
// (../shared/models; skipped when absent), per method (GCS default and plain, LBS, DQS): median ms
// per deform over clip frames and build ms, and the joint-level GPU table's bytes.
//   --against DIST  A/B: the same figures from another build of the package (e.g. one made before
//                   8 influences: `git archive <commit> | tar -x -C /tmp/old && (cd /tmp/old &&
//                   node scripts/build-lib.mjs)`, DIST = /tmp/old/dist), in alternating child
//                   processes, N rounds (default 5), median of the rounds' medians.
//   Without it: this build's 4-influence characters beside the same characters with their weights
//   spread onto 5–8 joints (each influence onto its joint, parent and first child: the rule of
//   tests/helpers/influences.ts), influences: 8.
// Keep the machine otherwise idle: the figures are medians of short runs.
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseArgs, table } from './common.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const ownDist = resolve(here, '../../dist');
const MODELS = resolve(here, '../../../shared/models');
const METHODS = ['gcs', 'gcs-plain', 'lbs', 'dqs'];

const args = parseArgs(process.argv.slice(2), {
  against: { parse: (s) => resolve(s), default: null },
  rounds: { parse: (s) => Number(s), default: 5 },
  child: { parse: (s) => resolve(s), default: null },
  spread: { type: 'flag', default: false },
});

/** Each influence (j, w) of a vertex that blends joints spread onto j, its parent and first child; 8 largest kept. */
function spread(input) {
  const n = input.positions.length / 3, K = input.influences ?? 4, J = input.parents.length;
  const child = new Int32Array(J).fill(-1);
  for (let j = J - 1; j >= 0; j--) if (input.parents[j] >= 0) child[input.parents[j]] = j;
  const joints = new Uint32Array(8 * n), weights = new Float32Array(8 * n);
  for (let v = 0; v < n; v++) {
    const sum = new Map();
    const add = (j, w) => sum.set(j, (sum.get(j) ?? 0) + w);
    let used = 0;
    for (let k = 0; k < K; k++) if (input.weights[K * v + k] > 0) used++;
    for (let k = 0; k < K; k++) {
      const j = input.joints[K * v + k], w = input.weights[K * v + k];
      if (!(w > 0)) continue;
      if (used === 1) { add(j, w); continue; }
      add(j, 0.55 * w);
      add(input.parents[j] >= 0 ? input.parents[j] : j, 0.3 * w);
      add(child[j] >= 0 ? child[j] : j, 0.15 * w);
    }
    const kept = [...sum].sort((a, b) => b[1] - a[1] || a[0] - b[0]).slice(0, 8);
    const total = kept.reduce((s, [, w]) => s + w, 0);
    kept.forEach(([j, w], k) => { joints[8 * v + k] = j; weights[8 * v + k] = w / total; });
  }
  return { ...input, joints, weights, influences: 8 };
}

/** One process: the figures of one build (`dist`), as JSON on stdout. */
async function measureBuild(dist, withSpread) {
  const { initGcsSkin } = await import(join(dist, 'index.js'));
  const { rigInputFromSkinnedMesh } = await import(join(dist, 'three.js'));
  const { createHuman } = await import(join(dist, 'human/index.js'));
  // The node glTF reader: packages/cli/dist beside dist/ (a build before the CLI's move: dist/cli).
  const reader = existsSync(join(dist, 'cli/gltf-node.js')) ? join(dist, 'cli/gltf-node.js') : join(dist, '../packages/cli/dist/gltf-node.js');
  const { loadGltfFile, sampleClip } = await import(reader);
  const { timeFrames, median } = await import(join(dist, 'measure.js'));
  const gcs = await initGcsSkin();
  const characters = [];
  const human = createHuman();
  characters.push({ name: 'human', mesh: human.mesh, clip: human.clips.find((c) => c.name === 'walk') });
  for (const file of ['CesiumMan.glb', 'Soldier.glb']) {
    const path = join(MODELS, file);
    if (!existsSync(path)) continue;
    const model = await loadGltfFile(path);
    const mesh = model.skinnedMeshes.reduce((a, b) => (a.geometry.getAttribute('position').count >= b.geometry.getAttribute('position').count ? a : b));
    characters.push({ name: file.replace('.glb', ''), mesh, clip: model.clips.find((c) => c.name === 'Run') ?? model.clips[0] });
  }
  const out = {};
  for (const c of characters) {
    const frames = sampleClip(c.mesh, c.clip, 24);
    const base = rigInputFromSkinnedMesh(c.mesh);
    for (const [label, input] of withSpread ? [['4', base], ['8', spread(base)]] : [['4', base]]) {
      const rig = gcs.createRig(input);
      const row = out[`${c.name}/${label}`] = /** @type {Record<string, any>} */ ({ vertices: rig.vertexCount });
      for (const method of METHODS) {
        const builds = [];
        let d;
        for (let i = 0; i < 5; i++) {
          d?.dispose();
          const t0 = performance.now();
          d = method === 'lbs' ? rig.buildLbs() : method === 'dqs' ? rig.buildDqs() : rig.buildGcs({ smooth: method === 'gcs' });
          builds.push(performance.now() - t0);
        }
        const t = timeFrames(frames.length, (f) => d.deform(frames[f]), { minSamples: 200, minMs: 150, maxMs: 600 });
        row[method] = { ms: t.medianMs, buildMs: median(builds) };
        if (method === 'gcs') {
          const table = d.sectionInfluences();
          row.tableBytes = table ? table.length * 4 : 0;
          row.sections = d.sectionCount;
        }
        d.dispose();
      }
      rig.dispose();
    }
  }
  return out;
}

const medianOf = (xs) => { const s = [...xs].sort((a, b) => a - b); return s.length % 2 ? s[(s.length - 1) / 2] : 0.5 * (s[s.length / 2 - 1] + s[s.length / 2]); };

if (args.child) {
  console.log(JSON.stringify(await measureBuild(args.child, args.spread)));
} else if (args.against) {
  const runs = { this: [], other: [] };
  const child = (dist) => JSON.parse(execFileSync(process.execPath, [fileURLToPath(import.meta.url), '--child', dist], { encoding: 'utf8', maxBuffer: 1 << 24 }));
  for (let r = 0; r < args.rounds; r++) {
    // Alternate which goes first: drift of a shared machine falls on both.
    if (r % 2) { runs.other.push(child(args.against)); runs.this.push(child(ownDist)); }
    else { runs.this.push(child(ownDist)); runs.other.push(child(args.against)); }
  }
  // Median and fastest of the rounds' medians: on a shared machine the fastest round is the least disturbed.
  const rows = [['character', 'method', 'ms this', 'ms other', 'ratio', 'fastest this', 'fastest other', 'ratio', 'build ms this', 'build ms other']];
  for (const key of Object.keys(runs.this[0])) {
    for (const method of METHODS) {
      const ms = (list) => list.map((x) => x[key][method].ms);
      const a = medianOf(ms(runs.this)), b = medianOf(ms(runs.other)), fa = Math.min(...ms(runs.this)), fb = Math.min(...ms(runs.other));
      const ba = medianOf(runs.this.map((x) => x[key][method].buildMs)), bb = medianOf(runs.other.map((x) => x[key][method].buildMs));
      rows.push([`${key.split('/')[0]} (${runs.this[0][key].vertices} v)`, method, a.toFixed(4), b.toFixed(4), (a / b).toFixed(3), fa.toFixed(4), fb.toFixed(4), (fa / fb).toFixed(3), ba.toFixed(2), bb.toFixed(2)]);
    }
    const tb = runs.this[0][key].tableBytes, ob = runs.other[0][key].tableBytes;
    rows.push([`${key.split('/')[0]}`, 'GPU table bytes', String(tb), String(ob), (tb / ob).toFixed(3), '', '', '', '', '']);
  }
  console.log(`this build (${ownDist}) against ${args.against}: median and fastest of ${args.rounds} alternating rounds' medians`);
  console.log(table(rows));
} else {
  const r = await measureBuild(ownDist, true);
  const rows = [['character', 'influences', 'method', 'ms per deform', 'build ms', 'GPU table bytes']];
  for (const [key, row] of Object.entries(r)) {
    const [name, k] = key.split('/');
    for (const method of METHODS) rows.push([`${name} (${row.vertices} v)`, k, method, row[method].ms.toFixed(4), row[method].buildMs.toFixed(2), method === 'gcs' ? String(row.tableBytes) : '']);
  }
  console.log('4 influences (the file) and the same weights spread onto 5–8 joints (influences: 8):');
  console.log(table(rows));
}
