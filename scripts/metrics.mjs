// npm run metrics [-- --json] [--markdown] [--no-models] [--vertices N] [--sections N] [--frames N]
// Fidelity per method (docs/method.md §9) on the default human and on every character in
// ../shared/models (skipped with a reason when absent):
// - FidelityProbe (web/lib/measure.ts) over every sampled frame of every clip, on every skinned
//   mesh of the character, in % of the character's height (gltf-node characterHeight): rigid
//   error, distance from an independent DQS (p95, max), flipped triangles beside LBS's, creases
//   (beside the more of LBS's and DQS's), stretched
//   triangles, normals off unit length, non-finite values, seam gap;
// - where the skeleton has human bone names: joint thickness under 90°/135° knee and elbow bends,
//   forearm width under 90°/180° twist, volume ratio under bends (closed meshes), the rest error
//   and flipped triangles over those poses, and the classic model's resampling loss;
// - joints (measureJoints, web/lib/measure/joints.ts): the knees and elbows found from the skeleton's
//   layout, each bent alone to 45°, 90°, 135°: volume change, bulge, collapse, creases, new
//   self-intersecting triangle pairs, per method (largest mesh).
// --markdown prints one fidelity table (rows: character × method) for the README, nothing else;
// --joints-markdown the README's joint table (every knee and elbow at 135°), nothing else;
// --joint-checks the joint targets as pass/fail checks for GCS with centres of rotation, or for
// --candidate METHOD (scripts/bench/joint-checks.mjs), nothing else.
import { existsSync, readdirSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { initGcsSkin } from '../dist/index.js';
import { rigInputFromSkinnedMesh, writeSkinMatrices } from '../dist/three.js';
import { createHuman } from '../dist/human/index.js';
import { characterHeight, loadGltfFile, rootOf, sampleClip } from '../packages/cli/dist/gltf-node.js';
import {
  FidelityProbe, METHODS, METHOD_LABELS, buildMethod, dominantJoints, errorInfo, identitySkin, jointMethods, jointTableRows, measureJoints,
  restOfOutput,
} from '../dist/measure.js';
import { argsOrExit, markdownTable, num, table } from './bench/common.mjs';
import { centresCandidate, clipRows, jointRows } from './bench/joint-checks.mjs';
import {
  bindCentres, findBone, rayThickness, isClosed, minWidth, outputJoints, planeSection, posedCentre,
  rotateBoneWorld, signedVolume, worldPos,
} from './bench/fidelity.mjs';

const positive = (s, flag) => {
  const n = Number(s);
  if (!Number.isInteger(n) || n < 1) throw new Error(`${flag} must be a whole number ≥ 1; got '${s}'`);
  return n;
};
const args = argsOrExit('metrics', {
  json: { type: 'flag', default: false },
  markdown: { type: 'flag', default: false },
  jointsMarkdown: { type: 'flag', default: false },
  jointChecks: { type: 'flag', default: false },
  candidate: { parse: (x) => { if (x !== 'centres' && !METHODS.includes(x)) throw new Error(`--candidate must be centres or one of ${METHODS.join(', ')}; got '${x}'`); return x; }, default: 'centres' },
  noModels: { type: 'flag', default: false },
  vertices: { parse: positive, default: undefined },
  sections: { parse: positive, default: 6 },
  frames: { parse: positive, default: 60 },
}, 'usage: npm run metrics -- [--json] [--markdown] [--joints-markdown] [--joint-checks [--candidate centres|METHOD]] [--no-models] [--vertices N] [--sections N] [--frames N (per clip, default 60)]');
// Progress on stderr whenever stdout carries a document (JSON or the markdown table).
const log = args.json || args.markdown || args.jointsMarkdown ? (...a) => console.error(...a) : (...a) => console.log(...a);
const { sections, frames: framesPerClip } = args;
const MODELS_DIR = resolve(dirname(fileURLToPath(import.meta.url)), '../../shared/models');
const deg = Math.PI / 180;

const gcs = await initGcsSkin();

/** Runs `measure(deformer)` for every method on a rig; { error } where the build or a frame fails. */
function eachMethod(rig, measure) {
  const out = {};
  for (const method of METHODS) {
    let d;
    try {
      d = buildMethod(rig, method, { sections });
      out[method] = measure(d, method);
    } catch (e) {
      out[method] = { error: errorInfo(e) };
    } finally {
      d?.dispose();
    }
  }
  return out;
}

/**
 * Fidelity of a character (all its skinned meshes) per method: FidelityProbe per mesh over every
 * clip's frames, then summed (counts) or maxed (distances) over the meshes. With several meshes
 * the p95 is the largest mesh p95: an upper bound of the p95 over all their vertices.
 */
function fidelityOf(meshes, clips, heights) {
  const perMesh = meshes.map((mesh, i) => {
    const input = rigInputFromSkinnedMesh(mesh);
    const rig = gcs.createRig(input);
    try {
      const sampled = clips.flatMap((clip) => sampleClip(mesh, clip, framesPerClip));
      const frames = sampled.length ? sampled : [identitySkin(rig.jointCount)];
      const height = heights.meshUnits[i] > 0 ? heights.meshUnits[i] : rig.height;
      const probe = new FidelityProbe(input, frames, { height });
      // The classic model's resampling loss, rescaled from its mesh's own height to the character's.
      const lossOf = (d) => ({ rms: d.detailLoss.rms * rig.height / height, max: d.detailLoss.max * rig.height / height,
        resampledParts: d.parts.filter((p) => p.resampled).length });
      return { name: mesh.name, vertices: rig.vertexCount, triangles: input.indices.length / 3, frames: frames.length,
        methods: eachMethod(rig, (d, method) => ({ ...probe.measure(d), ...(method === 'classic' ? { loss: lossOf(d) } : {}) })) };
    } finally {
      rig.dispose();
    }
  });
  const maxOrNull = (xs) => (xs.every((x) => x === null) ? null : Math.max(...xs.filter((x) => x !== null)));
  const sum = (xs) => xs.reduce((a, b) => a + b, 0);
  const methods = {};
  for (const method of METHODS) {
    const fs = perMesh.map((m) => m.methods[method]);
    const failed = fs.find((f) => f.error);
    if (failed) { methods[method] = { error: failed.error }; continue; }
    methods[method] = {
      frames: fs[0].frames, rigidError: maxOrNull(fs.map((f) => f.rigidError)), rigidVertices: sum(fs.map((f) => f.rigidVertices)),
      dqsP95: maxOrNull(fs.map((f) => f.dqsP95)), dqsMax: maxOrNull(fs.map((f) => f.dqsMax)),
      flipped: sum(fs.map((f) => f.flipped)), creases: sum(fs.map((f) => f.creases)), stretched: sum(fs.map((f) => f.stretched)),
      normalOffUnit: Math.max(...fs.map((f) => f.normalOffUnit)), nonFinite: sum(fs.map((f) => f.nonFinite)),
      seamGap: Math.max(...fs.map((f) => f.seamGap)),
      ...(fs[0].loss ? { loss: { rms: Math.max(...fs.map((f) => f.loss.rms)), max: Math.max(...fs.map((f) => f.loss.max)),
        resampledParts: sum(fs.map((f) => f.loss.resampledParts)) } } : {}),
    };
  }
  return { meshes: perMesh, methods };
}

/**
 * The human-specific measures on one mesh whose bones have human names: joint thickness under
 * bends, forearm width under twist, volume ratio, plus the rest error (distance from the rig's
 * positions at the bind pose) and flipped triangles over those poses (FidelityProbe), and the
 * classic model's resampling loss. `height` is the character's height in this mesh's units.
 */
function shapeOf(mesh, height) {
  const input = rigInputFromSkinnedMesh(mesh);
  const rig = gcs.createRig(input);
  const posing = humanPoses(mesh);
  const shape = {
    ...posing, input, dominant: dominantJoints(input), centres: bindCentres(input),
    bindProbe: new FidelityProbe(input, [identitySkin(posing.J)], { height }),
    poseProbe: new FidelityProbe(input, Object.values(posing.poses), { height }),
  };
  const methods = eachMethod(rig, (d, method) => shapeFigures(d, method, shape));
  rig.dispose();
  return { mesh: mesh.name, poses: Object.keys(posing.poses), notes: posing.notes, methods };
}

/**
 * The poses shapeOf measures, as skin-matrix sets from bones (found by their human names) rotated
 * on top of the reference pose: the knee and the elbow bent 90° and 135°, both at once, the
 * forearm twisted 90° and 180°; with what was not measured and why (notes).
 */
function humanPoses(mesh) {
  const bones = mesh.skeleton.bones;
  const root = rootOf(mesh);
  const J = bones.length;
  const rest0 = bones.map((b) => b.quaternion.clone());
  const resetPose = () => { bones.forEach((b, j) => b.quaternion.copy(rest0[j])); root.updateMatrixWorld(true); };
  const skinOf = () => { root.updateMatrixWorld(true); const s = new Float32Array(J * 16); writeSkinMatrices(mesh, s); return s; };
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
  return { J, B, poses, bends, twist, notes };
}

/** shapeOf's figures for one method's deformer `d`: rest error, flips, joint thickness, twist width, volume. */
function shapeFigures(d, method, { input, dominant, centres, B, poses, bends, twist, bindProbe, poseProbe }) {
  const r = {};
  const indices = d.indices;
  const vj = outputJoints(d, dominant);
  const restOut = restOfOutput(d, input.positions);
  // At the bind pose the reference DQS is the rig's own positions: its distance is the rest error.
  r.restError = bindProbe.measure(d).dqsMax;
  r.flippedPoses = poseProbe.measure(d).flipped;
  if (method === 'classic') r.detailLoss = d.detailLoss;
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
  r.triangles = indices.length / 3;
  return r;
}

/** The knees and elbows of one mesh, each bent alone (measureJoints), with the time it took. */
function jointsOf(mesh) {
  const input = rigInputFromSkinnedMesh(mesh);
  const rig = gcs.createRig(input);
  try {
    const t0 = performance.now();
    const m = measureJoints(rig, input, { methods: jointMethods({ sections }), names: mesh.skeleton.bones.map((b) => b.name) });
    return { ...m, mesh: mesh.name, ms: performance.now() - t0 };
  } finally {
    rig.dispose();
  }
}

/** Everything measured on one character: its skinned meshes (the human measures and the joints on the largest). */
function measureCharacter(name, meshes, clips) {
  const heights = characterHeight(meshes);
  const largest = meshes.reduce((a, b) => (b.geometry.getAttribute('position').count > a.geometry.getAttribute('position').count ? b : a));
  const joints = jointsOf(largest);
  if (args.jointsMarkdown) return { name, joints };
  const shape = shapeOf(largest, heights.meshUnits[meshes.indexOf(largest)]);
  const fidelity = fidelityOf(meshes, clips, heights);
  const notes = [...shape.notes];
  if (meshes.length > 1) notes.push(`${meshes.length} skinned meshes: fidelity summed/maxed over all; the bends, twist and volume on the largest ('${largest.name}')`);
  if (!clips.length) notes.push('no animation clip: fidelity over the bind pose only');
  return {
    name, height: heights.world, meshes: fidelity.meshes.map(({ methods, ...m }) => m), clips: clips.map((c) => c.name),
    frames: fidelity.meshes[0].frames, notes, fidelity: fidelity.methods, shape, joints,
  };
}

if (args.jointChecks) {
  await printJointChecks();
  process.exit(0);
}

/**
 * The joint targets for a candidate (GCS with centres of rotation unless --candidate), check by check: the knees and elbows of our
 * human, CesiumMan and Soldier (the Fox held out, printed apart) at 90° and 135°, then every clip
 * of every character.
 */
async function printJointChecks() {
  const candidate = args.candidate === 'centres' ? centresCandidate(sections) : (rig) => buildMethod(rig, args.candidate, { sections });
  console.log(`candidate: ${args.candidate === 'centres' ? 'GCS with centres of rotation' : METHOD_LABELS[args.candidate]}, ${sections} sections\n`);
  const ours = createHuman(args.vertices ? { vertices: args.vertices } : {});
  const characters = [{ name: 'human', meshes: [ours.mesh], clips: ours.clips, counted: true }];
  if (!args.noModels && existsSync(MODELS_DIR))
    for (const f of readdirSync(MODELS_DIR).filter((x) => /\.glb$/i.test(x)).sort()) {
      const model = await loadGltfFile(join(MODELS_DIR, f));
      if (model.skinnedMeshes.length) characters.push({ name: f.replace(/\.glb$/i, ''), meshes: model.skinnedMeshes, clips: model.clips,
        counted: /^(CesiumMan|Soldier)$/.test(f.replace(/\.glb$/i, '')) });
    }
  const f2 = (x) => (Number.isFinite(x) ? x.toFixed(2) : String(x));
  const mark = (c) => `${c.name === 'volume' ? c.value.toFixed(1) : c.name === 'bulge' ? f2(c.value) : c.value} ${c.pass ? '≤' : '>'} ${c.name === 'bulge' || c.name === 'volume' ? f2(c.limit) : c.limit.toFixed(0)}${c.pass ? '' : ' ✗'}`;
  let passed = 0, total = 0, heldPassed = 0, heldTotal = 0;
  const rows = [['character, joint', 'bend', 'bulge p95 (≤ LBS + 0.05)', '|volume %| (≤ |DQS| + 2)', 'creases (≤ 1.1 DQS + 5)', 'new self-x (≤ 1.1 DQS + 5)',
    'GCS / DQS / LBS bulge', 'GCS / DQS / LBS volume']];
  for (const ch of characters) {
    const largest = ch.meshes.reduce((a, b) => (b.geometry.getAttribute('position').count > a.geometry.getAttribute('position').count ? b : a));
    const input = rigInputFromSkinnedMesh(largest);
    const { rows: joints } = jointRows(gcs, input, largest.skeleton.bones.map((b) => b.name), candidate, [90, 135], buildMethod, sections);
    for (const r of joints) {
      const ok = r.checks.filter((c) => c.pass).length;
      if (ch.counted) { passed += ok; total += r.checks.length; } else { heldPassed += ok; heldTotal += r.checks.length; }
      const f = r.figures;
      rows.push([`${ch.name}${ch.counted ? '' : ' (held out)'}, ${r.joint}`, `${r.degrees}°`, ...r.checks.map(mark),
        `${f2(f.gcs.bulgeP95)} / ${f2(f.dqs.bulgeP95)} / ${f2(f.lbs.bulgeP95)}`,
        `${f.gcs.volumeChange.toFixed(1)} / ${f.dqs.volumeChange.toFixed(1)} / ${f.lbs.volumeChange.toFixed(1)}`]);
    }
  }
  console.log(table(rows));
  console.log(`\njoint checks passed: ${passed} of ${total} (human, CesiumMan, Soldier); held out (Fox): ${heldPassed} of ${heldTotal}`);
  const clipTable = [['character, clip', 'flips: candidate / LBS / DQS', 'ratio', 'creases: candidate / LBS / DQS', 'ratio', 'rigid error %', 'normal off unit', 'non-finite']];
  let clipsPassed = 0, clipsTotal = 0;
  for (const ch of characters) {
    const heights = characterHeight(ch.meshes).meshUnits;
    const meshes = ch.meshes.map((mesh) => ({ mesh, input: rigInputFromSkinnedMesh(mesh) }));
    for (const r of clipRows(gcs, meshes, ch.clips, framesPerClip, heights, candidate, buildMethod, sampleClip, sections)) {
      clipsTotal++;
      if (r.pass) clipsPassed++;
      const s = r.sum;
      clipTable.push([`${ch.name}, ${r.clip}`, `${s.candidate.flipped} / ${s.lbs.flipped} / ${s.dqs.flipped}`, `${f2(r.flipRatio)}${r.flipRatio > 1.1 ? ' ✗' : ''}`,
        `${s.candidate.creases} / ${s.lbs.creases} / ${s.dqs.creases}`, `${f2(r.creaseRatio)}${r.creaseRatio > 1.1 ? ' ✗' : ''}`,
        num(r.rigidError, 6), num(r.normalOff, 6), String(r.nonFinite)]);
    }
  }
  console.log(`\n${table(clipTable)}`);
  console.log(`\nclips passed: ${clipsPassed} of ${clipsTotal} (${framesPerClip} frames per clip; flips and creases ≤ 1.1 × the more of LBS and DQS, rigid error ≤ 1e-4 %, normals unit, finite)`);
}

// ---------------------------------------------------------------- characters
const reports = [];
log('metrics: default human…');
const human = createHuman(args.vertices ? { vertices: args.vertices } : {});
reports.push(measureCharacter('default human', [human.mesh], human.clips));
if (args.noModels) log('metrics: shared models skipped (--no-models)');
else if (!existsSync(MODELS_DIR)) log(`metrics: shared models skipped: ${MODELS_DIR} is absent`);
else {
  const files = readdirSync(MODELS_DIR).filter((f) => /\.glb$/i.test(f)).sort();
  if (!files.length) log(`metrics: shared models skipped: no .glb in ${MODELS_DIR}`);
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
    reports.push(measureCharacter(f, model.skinnedMeshes, model.clips));
  }
}

if (args.json) {
  console.log(JSON.stringify({ sections, framesPerClip, methods: METHODS, characters: reports }, null, 2));
  process.exit(0);
}

// ---------------------------------------------------------------- tables
if (args.jointsMarkdown) {
  // README: per character and joint at 135°, bulge p95 / max per method, then the volume changes.
  const methods = reports[0].joints.methods;
  const rows = [['character, joint (135°)', ...methods.map((m) => `bulge p95 / max: ${m.key}`), `volume change %: ${methods.map((m) => m.key).join(' / ')}`]];
  for (const rep of reports) {
    const j = rep.joints;
    const at = j.angles.indexOf(135);
    if (!j.joints.length) rows.push([`${rep.name}: ${j.notes.join('; ') || 'no knee or elbow found'}`, ...methods.map(() => ''), '']);
    for (const joint of j.joints) {
      const f = ({ key }) => ('error' in joint.methods[key] ? null : joint.methods[key][at]);
      rows.push([`${rep.name}, ${joint.hinge.label}`, ...methods.map((m) => (f(m) ? `${num(f(m).bulgeP95, 2)} / ${num(f(m).bulgeMax, 2)}` : 'n/a')),
        methods.map((m) => (f(m) ? f(m).volumeChange.toFixed(1) : 'n/a')).join(' / ')]);
    }
  }
  console.log(markdownTable(rows));
  console.log(`\nEach knee and elbow found from the skeleton's layout, bent alone from the bind pose to 135° about its hinge; ` +
    'GCS at ' + `${sections} sections. Region: the triangles with a vertex weighted on the joint or its parent and nearest (at bind) ` +
    'to the limb\'s bones there. Bulge: distance to the nearest posed bone over the same at bind (p95 / max over the region\'s ' +
    'vertices). Volume: signed cone volumes about the joint centre, posed against bind.');
  process.exit(0);
}

/** One row per method of a character's fidelity; `first` labels the character on its first row. */
function fidelityRows(rep, first) {
  const lbs = rep.fidelity.lbs, dqs = rep.fidelity.dqs;
  const creaseBase = lbs.error || dqs.error ? 0 : Math.max(lbs.creases, dqs.creases);
  return METHODS.map((method, i) => {
    const f = rep.fidelity[method];
    const head = [...first(i), METHOD_LABELS[method]];
    if (f.error) return [...head, 'n/a', 'n/a', 'n/a', 'n/a', 'n/a', 'n/a', 'n/a', 'n/a', 'n/a'];
    const creases = method === 'lbs' || method === 'dqs' || !creaseBase ? String(f.creases) : `${f.creases} (${num(f.creases / creaseBase, 2)}×)`;
    const flipped = method === 'lbs' || lbs.error ? String(f.flipped) : `${f.flipped} (LBS ${lbs.flipped})`;
    const resampled = !f.loss ? 'resampled' : f.loss.resampledParts ? `resampled, loss ${num(f.loss.rms, 2)} / ${num(f.loss.max, 2)}`
      : 'all carried (no part resampled)';
    return [...head, f.rigidError === null ? resampled : num(f.rigidError, 3), f.dqsP95 === null ? 'resampled' : num(f.dqsP95, 3),
      f.dqsMax === null ? 'resampled' : num(f.dqsMax, 3), flipped, creases, String(f.stretched), num(f.normalOffUnit, 3), String(f.nonFinite), num(f.seamGap, 3)];
  });
}
const FIDELITY_HEADER = ['method', 'rigid error %', 'DQS p95 %', 'DQS max %', 'flipped', 'creases', 'stretched', 'normal off unit', 'non-finite', 'seam gap %'];
const describe = (rep) => `${rep.clips.length} clip${rep.clips.length === 1 ? '' : 's'} × ${framesPerClip} frames`;
const failures = reports.flatMap((rep) => METHODS.filter((m) => rep.fidelity[m].error).map((m) => `${rep.name}, ${METHOD_LABELS[m]}: n/a — ${rep.fidelity[m].error.code}: ${rep.fidelity[m].error.message}`));

if (args.markdown) {
  const rows = [['character', ...FIDELITY_HEADER]];
  for (const rep of reports) rows.push(...fidelityRows(rep, (i) => [i === 0 ? `${rep.name} (${describe(rep)})` : '']));
  console.log(markdownTable(rows));
  console.log(`\nEvery clip of each character sampled at ${framesPerClip} frames, GCS at ${sections} sections per part. ` +
    'Distances in % of the character\'s height (bind-pose bounding box of all its skinned meshes, world units); counts summed over frames ' +
    '(and meshes). Rigid error: vertices bound ≥ 0.999 to one joint against S_j·x. DQS: distance from a scale-aware ' +
    'dual-quaternion skinning computed independently in JavaScript. Flipped: triangles whose normal turned against their rest ' +
    'normal carried by their dominant joint, with LBS\'s count over the same frames. Creases: interior edges whose dihedral ' +
    'angle changed by more than 20° from the rest pose, with the ratio to the more of LBS\'s and DQS\'s counts. Stretched: an edge over twice its rest ' +
    'length. "resampled": the classic model has no vertex of the original mesh; "loss": its resampling detail loss, RMS / max ' +
    'distance of the replaced input vertices to the resampled surface (the largest over the meshes).' +
    (reports.some((r) => r.meshes.length > 1) ? ' Characters of several skinned meshes: the p95 is the largest over the meshes (an upper bound).' : ''));
  for (const f of failures) console.log(`\n${f}`);
  process.exit(0);
}

const ratio = (x) => (x === undefined ? 'n/a' : Number.isFinite(x) ? x.toFixed(2) : String(x));
for (const rep of reports) {
  const meshes = rep.meshes.map((m) => `'${m.name}' ${m.vertices} vertices / ${m.triangles} triangles`).join(', ');
  console.log(`\n${rep.name}: ${meshes}; height ${rep.height.toFixed(3)} world units; ${describe(rep)} = ${rep.frames} frames`);
  for (const n of rep.notes) console.log(`  note: ${n}`);
  console.log(table([FIDELITY_HEADER, ...fidelityRows(rep, () => [])]));
  const s = rep.shape;
  const cols = METHODS;
  const get = (f) => cols.map((c) => (s.methods[c].error ? 'n/a' : f(s.methods[c])));
  const rows = [['measure (largest mesh)', ...cols.map((m) => METHOD_LABELS[m])]];
  rows.push(['rest error (% height)', ...get((r) => (r.restError === null ? 'resampled' : num(r.restError, 3)))]);
  rows.push(['resampling loss RMS / max (% own height)', ...get((r) => (r.detailLoss ? `${num(r.detailLoss.rms, 2)} / ${num(r.detailLoss.max, 2)}` : '—'))]);
  for (const [key, label] of [['knee90', 'knee 90° thickness (LBS ≈ 0.71)'], ['knee135', 'knee 135° thickness (LBS ≈ 0.38)'],
    ['elbow90', 'elbow 90° thickness'], ['elbow135', 'elbow 135° thickness'],
    ['twist90', 'forearm twist 90°: min width'], ['twist180', 'forearm twist 180°: min width'],
    ['volume90', 'volume, knee+elbow 90°'], ['volume135', 'volume, knee+elbow 135°']])
    rows.push([label, ...get((r) => (key.startsWith('volume') && !r.closed ? 'open mesh' : ratio(r[key])))]);
  const lbsPoses = s.methods.lbs.error ? undefined : s.methods.lbs.flippedPoses;
  rows.push([`flipped, ${s.poses.length === 1 ? 'reference pose' : `reference + ${s.poses.length - 1} bend/twist poses`}`, ...cols.map((c) => (s.methods[c].error ? 'n/a'
    : c === 'lbs' || lbsPoses === undefined ? String(s.methods[c].flippedPoses) : `${s.methods[c].flippedPoses} (LBS ${lbsPoses})`))]);
  console.log(`\n${table(rows)}`);
  const j = rep.joints;
  console.log(`\njoints of '${j.mesh}' (each bent alone from the bind pose; ${j.ms.toFixed(0)} ms)${j.notes.map((n) => `\n  note: ${n}`).join('')}`);
  if (j.joints.length) console.log(table(jointTableRows(j)));
}
for (const f of failures) console.log(`  ${f}`);
