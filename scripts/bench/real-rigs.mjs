// Part of `npm run bench`: the default GCS on real characters (../shared/models: Soldier,
// CesiumMan, Fox, RobotExpressive; each skipped with a reason when absent) beside our human, as a
// ratio to a wasm memcpy of the bytes a frame touches (timed frame by frame in turn with it:
// timeInterleaved, so load on the host cancels out), and what makes a rig cost more than another:
//   node pass  the per-frame work before any vertex (joint poses, node transforms), timed alone
//              through gcs_gcs_compute_sections in the same interleaved run;
//   per vertex what is left, in ns per vertex, and as a ratio to the memcpy (the vertex pass alone:
//              the floor of GCS / memcpy whatever the nodes cost);
//   runs       runs of vertices that share their nodes (the kernel loads its matrices once a run),
//              vertices per run, and the shares of vertices that follow one node (rigid or a node
//              of their own), blend two, or blend three (a three-joint lattice cell).
// Every skinned mesh of a file counts (summed), as the demo deforms them all each frame.
import { existsSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { rigInputFromSkinnedMesh } from '../../dist/three.js';
import { loadGltfFile, sampleClip } from '../../packages/cli/dist/gltf-node.js';
import { timeInterleaved } from '../../dist/measure.js';

const MODELS = resolve(dirname(fileURLToPath(import.meta.url)), '../../../shared/models');
export const REAL_RIGS = ['Soldier', 'CesiumMan', 'Fox', 'RobotExpressive'];
export const RATIO_GOAL = 2;

/** Runs and node shares of a smooth GCS deformer, from its per-vertex node tables. */
function runsOf(d) {
  const sec = d.sectionOfVertex(), other = d.blendOther(), third = d.blendThird();
  const V = d.vertexCount;
  let runs = 0, one = 0, two = 0, three = 0;
  for (let i = 0; i < V;) {
    let e = i;
    while (e < V && sec[e] === sec[i] && other[e] === other[i] && third[e] === third[i]) e++;
    runs++;
    if (third[i] !== sec[i]) three += e - i;
    else if (other[i] !== sec[i]) two += e - i;
    else one += e - i;
    i = e;
  }
  return { runs, one, two, three };
}

/** One character's meshes: interleaved default GCS, node pass alone, memcpy; summed over meshes. */
function measureCharacter(gcs, name, meshes, clips, quick) {
  const core = gcs.core;
  const row = { name, meshes: meshes.length, vertices: 0, joints: 0, nodes: 0, runs: 0, one: 0, two: 0, three: 0, gcsMs: 0, nodeMs: 0, memcpyMs: 0 };
  for (const mesh of meshes) {
    const rig = gcs.createRig(rigInputFromSkinnedMesh(mesh));
    const d = rig.buildGcs({});
    const V = d.vertexCount, J = rig.jointCount, S = d.sectionCount;
    const r = runsOf(d);
    const frames = clips.flatMap((c) => sampleClip(mesh, c, quick ? 10 : 30));
    const bytes = V * 24;
    const src = core.gcs_alloc(bytes), dst = core.gcs_alloc(bytes), skinPtr = core.gcs_alloc(J * 64), out = core.gcs_alloc(S * 48 + 16);
    if (!src || !dst || !skinPtr || !out) throw new Error('out of wasm memory for the real-rig bench');
    try {
      const handle = d.live();
      const t = timeInterleaved(frames.length, [
        (f) => d.deform(frames[f]),
        (f) => { gcs.viewF32(skinPtr, J * 16).set(frames[f]); core.gcs_gcs_compute_sections(handle, skinPtr, J, 1, out); },
        () => core.gcs_copy_bytes(dst, src, bytes),
      ], quick ? { minSamples: 60, minMs: 100, maxMs: 400 } : { minSamples: 300, minMs: 500, maxMs: 1500 });
      row.gcsMs += t[0].medianMs;
      row.nodeMs += t[1].medianMs;
      row.memcpyMs += t[2].medianMs;
    } finally {
      for (const p of [src, dst, skinPtr, out]) core.gcs_free(p);
      d.dispose();
      rig.dispose();
    }
    row.vertices += V;
    row.joints = Math.max(row.joints, J);
    row.nodes += S;
    row.runs += r.runs;
    row.one += r.one;
    row.two += r.two;
    row.three += r.three;
  }
  row.ratio = row.gcsMs / row.memcpyMs;
  row.nsPerVertex = (1e6 * Math.max(0, row.gcsMs - row.nodeMs)) / row.vertices;
  row.vertexPassRatio = Math.max(0, row.gcsMs - row.nodeMs) / row.memcpyMs;
  return row;
}

/** The real characters found, loaded once (meshes, clips); `skipped` says which were absent. */
export async function loadRealRigs(log = console.log) {
  const characters = [], skipped = [];
  for (const name of REAL_RIGS) {
    const file = `${MODELS}/${name}.glb`;
    if (!existsSync(file)) { skipped.push(`${name}: not measured (no ${file})`); continue; }
    log(`bench: loading ${name}…`);
    const model = await loadGltfFile(file);
    characters.push({ name, meshes: model.skinnedMeshes, clips: model.clips });
  }
  return { characters, skipped };
}

/** Our human (walk, run) and each loaded character (every clip): one row each. */
export function realRigBench(gcs, human, characters, { quick = false } = {}) {
  const humanClips = human.clips.filter((c) => c.name === 'walk' || c.name === 'run');
  return [measureCharacter(gcs, 'our human', [human.mesh], humanClips, quick),
    ...characters.map((c) => measureCharacter(gcs, c.name, c.meshes, c.clips, quick))];
}

/** Table rows for the printed report (header first). */
export function realRigRows(measured, ms) {
  const pct = (x, n) => `${((100 * x) / n).toFixed(0)} %`;
  const rows = [['character', 'meshes', 'vertices', 'joints', 'nodes', 'vertices/run', '1 / 2 / 3 nodes', 'GCS ms', 'node pass ms', 'ns/vertex after', 'memcpy ms', 'vertex pass / memcpy', 'GCS / memcpy']];
  for (const r of measured)
    rows.push([r.name, String(r.meshes), String(r.vertices), String(r.joints), String(r.nodes), (r.vertices / r.runs).toFixed(1),
      `${pct(r.one, r.vertices)} / ${pct(r.two, r.vertices)} / ${pct(r.three, r.vertices)}`,
      ms(r.gcsMs), `${ms(r.nodeMs)} (${pct(r.nodeMs, r.gcsMs)})`, r.nsPerVertex.toFixed(2), ms(r.memcpyMs), `${r.vertexPassRatio.toFixed(2)}×`, `${r.ratio.toFixed(2)}×`]);
  return rows;
}
