// npm run metrics [-- --json] [--markdown] [--no-models] [--vertices N]
// Fidelity per method (design.md §7) on the default human and on the characters in
// ../shared/models (skipped with a reason when absent): rest error, classic detail loss, joint
// thickness under 90°/135° knee and elbow bends, thickness under 90°/180° forearm twist, volume
// ratio under bends (closed meshes), seam gap, non-finite values, flipped triangles.
import { existsSync, readdirSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { initGcsSkin } from '../dist/index.js';
import { rigInputFromSkinnedMesh } from '../dist/three.js';
import { createHuman } from '../dist/human/index.js';
import { loadGltfFile, rootOf, sampleClip, skinMatricesOf } from '../dist/cli/gltf-node.js';
import { coincidentPairs, countNonFinite, errorInfo, identitySkin, restError, restOfOutput, seamGap } from '../dist/cli/measure.js';
import { markdownTable, num, parseArgs, table } from './bench/common.mjs';
import {
  bindCentres, dominantJoints, findBone, rayThickness, flippedTriangles, isClosed, minWidth, outputJoints, planeSection, posedCentre,
  rotateBoneWorld, signedVolume, worldPos,
} from './bench/fidelity.mjs';

let args;
try {
  args = parseArgs(process.argv.slice(2), {
    json: { type: 'flag', default: false },
    markdown: { type: 'flag', default: false },
    noModels: { type: 'flag', default: false },
    vertices: { parse: Number, default: undefined },
    sections: { parse: Number, default: 6 },
  });
} catch (e) {
  console.error(`metrics: ${e.message}`);
  process.exit(2);
}
if (args.help) {
  console.log('usage: npm run metrics -- [--json] [--markdown] [--no-models] [--vertices N] [--sections N]');
  process.exit(0);
}
const log = args.json ? (...a) => console.error(...a) : (...a) => console.log(...a);
const fmtTable = args.markdown ? markdownTable : table;
const sections = args.sections;
const METHODS = [
  { key: 'gcs', label: 'GCS', build: (rig) => rig.buildGcs({ sections }) },
  { key: 'gcs-smooth', label: 'GCS smooth', build: (rig) => rig.buildGcs({ sections, smooth: true }) },
  { key: 'gcs-twist', label: 'GCS twist', build: (rig) => rig.buildGcs({ sections, twistSpread: true }) },
  { key: 'classic', label: 'classic', build: (rig) => rig.buildClassic({}) },
  { key: 'lbs', label: 'LBS', build: (rig) => rig.buildLbs() },
  { key: 'dqs', label: 'DQS', build: (rig) => rig.buildDqs() },
];
const MODELS_DIR = resolve(dirname(fileURLToPath(import.meta.url)), '../../shared/models');
const deg = Math.PI / 180;

const gcs = await initGcsSkin();

/** Fidelity of every method on one skinned mesh. */
function measure(name, mesh, clips) {
  const input = rigInputFromSkinnedMesh(mesh);
  const rig = gcs.createRig(input);
  const height = rig.height;
  const bones = mesh.skeleton.bones;
  const root = rootOf(mesh);
  const J = bones.length;
  const rest0 = bones.map((b) => b.quaternion.clone());
  const resetPose = () => { bones.forEach((b, j) => b.quaternion.copy(rest0[j])); root.updateMatrixWorld(true); };
  const skinOf = () => { root.updateMatrixWorld(true); return skinMatricesOf(mesh, new Float32Array(J * 16)); };
  const dominant = dominantJoints(input);
  const centres = bindCentres(input);
  const meshWorldInv = new THREE.Matrix4().copy(mesh.matrixWorld).invert();
  const toMesh = (v) => v.clone().transformDirection(meshWorldInv);
  const notes = [];

  // Named bones and the body's frame (world, reference pose).
  resetPose();
  const B = Object.fromEntries(['Hips', 'Head', 'Neck', 'Spine', 'LeftUpLeg', 'RightUpLeg', 'LeftLeg', 'LeftFoot', 'LeftArm', 'RightArm', 'LeftForeArm', 'LeftHand']
    .map((n) => [n, findBone(bones, n)]));
  const has = (...names) => names.every((n) => B[n] >= 0);
  let forward = null;
  if (has('Hips', 'LeftUpLeg', 'RightUpLeg') && (B.Head >= 0 || B.Neck >= 0 || B.Spine >= 0)) {
    const left = worldPos(bones[B.LeftUpLeg]).sub(worldPos(bones[B.RightUpLeg])).normalize();
    const top = bones[B.Head >= 0 ? B.Head : B.Neck >= 0 ? B.Neck : B.Spine];
    const up = worldPos(top).sub(worldPos(bones[B.Hips])).normalize();
    forward = new THREE.Vector3().crossVectors(left, up).normalize();
  } else notes.push('no Hips/LeftUpLeg/RightUpLeg/Head bones: bends, twist and volume not measured');

  // Poses: each a skin-matrix set from bones rotated on top of the reference pose.
  const poses = { reference: skinOf() };
  const bendSpecs = [
    { key: 'knee', upper: 'LeftUpLeg', joint: 'LeftLeg', child: 'LeftFoot', toward: -1 },
    { key: 'elbow', upper: 'LeftArm', joint: 'LeftForeArm', child: 'LeftHand', toward: +1 },
  ];
  const bends = {};
  if (forward) {
    for (const s of bendSpecs) {
      if (!has(s.upper, s.joint, s.child)) { notes.push(`no ${s.upper}/${s.joint}/${s.child} bones: ${s.key} not measured`); continue; }
      const lower = worldPos(bones[B[s.child]]).sub(worldPos(bones[B[s.joint]])).normalize();
      const axis = new THREE.Vector3().crossVectors(lower, forward.clone().multiplyScalar(s.toward));
      if (axis.length() < 0.2) { notes.push(`${s.key}: the limb points along the bend direction; not measured`); continue; }
      axis.normalize();
      bends[s.key] = { ...s, axisWorld: axis, axisMesh: toMesh(axis).normalize() };
      for (const a of [90, 135]) {
        resetPose();
        rotateBoneWorld(bones, B[s.joint], axis, a * deg);
        poses[`${s.key}${a}`] = skinOf();
      }
    }
    for (const a of [90, 135]) {
      if (!bends.knee || !bends.elbow) break;
      resetPose();
      for (const k of ['knee', 'elbow']) rotateBoneWorld(bones, B[bends[k].joint], bends[k].axisWorld, a * deg);
      poses[`bend${a}`] = skinOf();
    }
  }
  let twist = null;
  if (forward && has('LeftArm', 'LeftForeArm', 'LeftHand')) {
    const axis = worldPos(bones[B.LeftHand]).sub(worldPos(bones[B.LeftForeArm])).normalize();
    twist = { axisMesh: toMesh(axis).normalize() };
    for (const a of [90, 180]) {
      resetPose();
      rotateBoneWorld(bones, B.LeftForeArm, axis, a * deg);
      poses[`twist${a}`] = skinOf();
    }
  }
  resetPose();
  const clipFrames = [];
  for (const clip of clips) clipFrames.push(...sampleClip(mesh, clip, 20));
  resetPose();

  const results = {};
  for (const m of METHODS) {
    let d;
    try {
      d = m.build(rig);
    } catch (e) {
      results[m.key] = { error: errorInfo(e) };
      continue;
    }
    const r = {};
    const indices = d.indices;
    const vj = outputJoints(d, dominant);
    const restOut = restOfOutput(d, input.positions);
    const pairs = coincidentPairs(restOut);
    r.restError = restError(d, input.positions);
    if (m.key === 'classic') r.detailLoss = d.detailLoss;
    const deformed = (skin) => { d.deform(skin); return Float32Array.from(d.positions); };
    const ref = deformed(poses.reference);
    const closed = isClosed(restOut, indices);
    const refVolume = closed ? signedVolume(ref, indices) : null;
    // Joint thickness across the bend, in the bisector plane of the two bones, over the reference pose.
    const thickness = (P, skin, s) => {
      const cj = posedCentre(skin, B[s.joint], centres[B[s.joint]]);
      const cu = posedCentre(skin, B[s.upper], centres[B[s.upper]]);
      const cc = posedCentre(skin, B[s.child], centres[B[s.child]]);
      const u = cj.clone().sub(cu), l = cc.clone().sub(cj);
      const n = u.clone().normalize().add(l.clone().normalize()).normalize();
      const e = new THREE.Vector3().crossVectors(bends[s.key].axisMesh, n).normalize();
      const segments = [];
      planeSection(P, indices, vj, new Set([B[s.upper], B[s.joint]]), cj, n, 0.6 * Math.min(u.length(), l.length()), segments);
      return rayThickness(segments, cj, e, bends[s.key].axisMesh);
    };
    for (const key of Object.keys(bends)) {
      const s = bends[key];
      const t0 = thickness(ref, poses.reference, s);
      for (const a of [90, 135]) {
        const skin = poses[`${key}${a}`];
        r[`${key}${a}`] = thickness(deformed(skin), skin, s) / t0;
      }
    }
    // Twist: narrowest width of the arm's cross-sections from above the elbow to mid-forearm, over rest.
    if (twist) {
      const ce = centres[B.LeftForeArm], ch = centres[B.LeftHand];
      const along = ch.clone().sub(ce);
      const n = twist.axisMesh;
      const u = new THREE.Vector3().crossVectors(n, Math.abs(n.y) < 0.9 ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(1, 0, 0)).normalize();
      const w = new THREE.Vector3().crossVectors(n, u);
      const limb = new Set([B.LeftArm, B.LeftForeArm, B.LeftHand]);
      const ts = [-0.2, -0.1, 0, 0.1, 0.2, 0.35, 0.5];
      const widths = (P, skin) => ts.map((t) => {
        const c = posedCentre(skin, B.LeftArm, ce.clone().addScaledVector(along, t)); // the upper arm stays put under the twist
        return minWidth(planeSection(P, indices, vj, limb, c, n, 0.5 * along.length()), u, w);
      });
      const w0 = widths(ref, poses.reference);
      for (const a of [90, 180]) {
        const skin = poses[`twist${a}`];
        const wa = widths(deformed(skin), skin);
        r[`twist${a}`] = Math.min(...wa.map((x, i) => x / w0[i]).filter(Number.isFinite));
      }
    }
    if (closed) for (const a of [90, 135]) if (poses[`bend${a}`]) r[`volume${a}`] = signedVolume(deformed(poses[`bend${a}`]), indices) / refVolume;
    r.closed = closed;
    // Seam gap, non-finite values, flipped triangles over every pose and clip frame.
    let gap = 0, bad = 0, flipped = 0, flippedClips = 0;
    const posed = Object.values(poses);
    const all = [...posed, ...clipFrames];
    all.forEach((skin, i) => {
      d.deform(skin);
      bad += countNonFinite(d.positions, d.normals);
      gap = Math.max(gap, seamGap(d.positions, pairs));
      const f = flippedTriangles(restOut, d.positions, indices, vj, skin);
      if (i < posed.length) flipped = Math.max(flipped, f);
      else flippedClips = Math.max(flippedClips, f);
    });
    r.seamGap = gap / height;
    r.nonFinite = bad;
    r.flipped = flipped;
    r.flippedClips = flippedClips;
    r.triangles = indices.length / 3;
    r.poses = all.length;
    results[m.key] = r;
    d.dispose();
  }
  rig.dispose();
  return { name, vertices: input.positions.length / 3, triangles: input.indices.length / 3, joints: J, height, notes, poses: Object.keys(poses), clipFrames: clipFrames.length, methods: results };
}

// ---------------------------------------------------------------- models
const reports = [];
log('metrics: default human…');
const human = createHuman(args.vertices ? { vertices: args.vertices } : {});
reports.push(measure('default human', human.mesh, human.clips));
if (args.noModels) log('metrics: shared models skipped (--no-models)');
else if (!existsSync(MODELS_DIR)) log(`metrics: shared models skipped: ${MODELS_DIR} is absent`);
else {
  const files = readdirSync(MODELS_DIR).filter((f) => /\.(glb|gltf)$/i.test(f)).sort();
  if (!files.length) log(`metrics: shared models skipped: no .glb/.gltf in ${MODELS_DIR}`);
  for (const f of files) {
    log(`metrics: ${f}…`);
    let model;
    try {
      model = await loadGltfFile(join(MODELS_DIR, f));
    } catch (e) {
      log(`metrics: ${f} skipped: unreadable (${e.message.split('\n')[0]})`);
      continue;
    }
    if (!model.skinnedMeshes.length) { log(`metrics: ${f} skipped: no skinned mesh`); continue; }
    // The largest skinned mesh (a character may carry small extra skinned meshes: visor, eyes).
    const mesh = model.skinnedMeshes.reduce((a, b) => (b.geometry.getAttribute('position').count > a.geometry.getAttribute('position').count ? b : a));
    const rep = measure(`${f} (${mesh.name || 'mesh'})`, mesh, model.clips);
    if (model.skinnedMeshes.length > 1) rep.notes.push(`${model.skinnedMeshes.length} skinned meshes: measured the largest`);
    reports.push(rep);
  }
}

if (args.json) {
  console.log(JSON.stringify({ sections, models: reports }, null, 2));
  process.exit(0);
}
const ratio = (x) => (x === undefined ? 'n/a' : Number.isFinite(x) ? x.toFixed(2) : String(x));
for (const rep of reports) {
  console.log(`\n${rep.name}: ${rep.vertices} vertices, ${rep.triangles} triangles, ${rep.joints} joints, height ${rep.height.toFixed(3)}; ` +
    `${rep.poses.length} poses + ${rep.clipFrames} clip frames`);
  for (const n of rep.notes) console.log(`  note: ${n}`);
  const cols = METHODS.map((m) => m.key);
  const get = (key, f) => cols.map((c) => (rep.methods[c].error ? 'n/a' : f(rep.methods[c], key)));
  const rows = [['metric', ...METHODS.map((m) => m.label)]];
  rows.push(['rest error (% height)', ...get('restError', (r) => (r.restError === null ? 'resampled' : num((100 * r.restError) / rep.height, 4)))]);
  rows.push(['resampling loss RMS / max (% height)', ...get('', (r) => (r.detailLoss ? `${num(r.detailLoss.rms, 2)} / ${num(r.detailLoss.max, 2)}` : '—'))]);
  for (const [key, label] of [['knee90', 'knee 90° thickness (LBS ≈ 0.71)'], ['knee135', 'knee 135° thickness (LBS ≈ 0.38)'],
    ['elbow90', 'elbow 90° thickness'], ['elbow135', 'elbow 135° thickness'],
    ['twist90', 'forearm twist 90°: min width'], ['twist180', 'forearm twist 180°: min width'],
    ['volume90', 'volume, knee+elbow 90°'], ['volume135', 'volume, knee+elbow 135°']])
    rows.push([label, ...get(key, (r) => (key.startsWith('volume') && !r.closed ? 'open mesh' : ratio(r[key])))]);
  rows.push(['seam gap, max (% height)', ...get('seamGap', (r) => num(100 * r.seamGap, 4))]);
  rows.push(['non-finite values', ...get('nonFinite', (r) => String(r.nonFinite))]);
  rows.push(['flipped triangles, bend/twist poses (max)', ...get('flipped', (r) => `${r.flipped} / ${r.triangles}`)]);
  rows.push(['flipped triangles, clip frames (max)', ...get('flippedClips', (r) => (rep.clipFrames ? `${r.flippedClips} / ${r.triangles}` : 'no clips'))]);
  console.log(fmtTable(rows));
  for (const m of METHODS) if (rep.methods[m.key].error) console.log(`  ${m.label}: n/a — ${rep.methods[m.key].error.code}: ${rep.methods[m.key].error.message}`);
}
