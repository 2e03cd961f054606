// The joint targets as pass/fail checks (npm run metrics -- --joint-checks): a candidate GCS (by
// default `centres: true`) against LBS and DQS, each knee and elbow bent alone to 90° and 135°
// (measureJoints), and every clip of every character played through (FidelityProbe):
// - bulge p95 ≤ LBS's + 0.05; |volume change| ≤ |DQS's| + 2 points;
//   creases and new self-intersecting pairs ≤ 1.1 × DQS's + 5;
// - per clip: flipped triangles and creases ≤ 1.1 × the more of LBS's and DQS's;
//   rigid-bound skin exact (≤ 1e-4 % of the height), unit normals, finite output.
import { FidelityProbe, CENTRES_METHOD, measureJoints } from '../../dist/measure.js';

/** The joint checks' bounds, as the targets state them. */
export const JOINT_TARGETS = { bulge: 0.05, volumePoints: 2, countFactor: 1.1, countSlack: 5, clipFactor: 1.1 };

const KEYS = { candidate: 'candidate', gcs: 'gcs', dqs: 'dqs', lbs: 'lbs' };

/**
 * The four checks of one joint at one angle: { name, value, limit, pass } each.
 * `c`, `dqs`, `lbs`: JointFigures of the candidate and the two references.
 */
export function jointChecks(c, dqs, lbs) {
  const t = JOINT_TARGETS;
  const count = (x) => t.countFactor * x + t.countSlack;
  return [
    { name: 'bulge', value: c.bulgeP95, limit: lbs.bulgeP95 + t.bulge, pass: c.bulgeP95 <= lbs.bulgeP95 + t.bulge },
    { name: 'volume', value: c.volumeChange, limit: Math.abs(dqs.volumeChange) + t.volumePoints,
      pass: Math.abs(c.volumeChange) <= Math.abs(dqs.volumeChange) + t.volumePoints },
    { name: 'creases', value: c.creases, limit: count(dqs.creases), pass: c.creases <= count(dqs.creases) },
    { name: 'self-x', value: c.newIntersections, limit: count(dqs.newIntersections), pass: c.newIntersections <= count(dqs.newIntersections) },
  ];
}

/**
 * Every knee and elbow of one mesh at `angles`: per joint and angle the candidate's, GCS default's,
 * DQS's and LBS's figures and the four checks.
 */
export function jointRows(gcs, input, names, candidate, angles, buildMethod, sections) {
  const rig = gcs.createRig(input);
  try {
    const methods = [
      { key: KEYS.candidate, label: 'candidate', build: candidate },
      { key: KEYS.gcs, label: 'GCS', build: (r) => buildMethod(r, 'gcs', { sections }) },
      { key: KEYS.dqs, label: 'DQS', build: (r) => buildMethod(r, 'dqs', { sections }) },
      { key: KEYS.lbs, label: 'LBS', build: (r) => buildMethod(r, 'lbs', { sections }) },
    ];
    const m = measureJoints(rig, input, { methods, angles, names });
    const rows = [];
    for (const joint of m.joints) {
      const r = joint.methods;
      for (const key of Object.values(KEYS)) if ('error' in r[key]) throw new Error(`${joint.hinge.label}, ${key}: ${r[key].error.message}`);
      angles.forEach((degrees, i) => {
        const f = Object.fromEntries(Object.values(KEYS).map((k) => [k, r[k][i]]));
        rows.push({ joint: joint.hinge.label, degrees, figures: f, checks: jointChecks(f.candidate, f.dqs, f.lbs) });
      });
    }
    return { rows, notes: m.notes };
  } finally {
    rig.dispose();
  }
}

/**
 * Every clip of one character's meshes: per clip the candidate's, LBS's and DQS's flips and
 * creases (summed over the meshes), the candidate's rigid error, normals and finiteness.
 */
export function clipRows(gcs, meshes, clips, frames, heights, candidate, buildMethod, sampleClip, sections) {
  const rows = [];
  for (const clip of clips) {
    const sum = { candidate: { flipped: 0, creases: 0 }, lbs: { flipped: 0, creases: 0 }, dqs: { flipped: 0, creases: 0 } };
    let rigidError = 0, normalOff = 0, nonFinite = 0;
    meshes.forEach((mesh, i) => {
      const input = mesh.input;
      const rig = gcs.createRig(input);
      try {
        const sampled = sampleClip(mesh.mesh, clip, frames);
        const probe = new FidelityProbe(input, sampled, { height: heights[i] > 0 ? heights[i] : rig.height });
        for (const key of ['candidate', 'lbs', 'dqs']) {
          const d = key === 'candidate' ? candidate(rig) : buildMethod(rig, key, { sections });
          try {
            const f = probe.measure(d);
            sum[key].flipped += f.flipped;
            sum[key].creases += f.creases;
            if (key === 'candidate') {
              rigidError = Math.max(rigidError, f.rigidError ?? 0);
              normalOff = Math.max(normalOff, f.normalOffUnit);
              nonFinite += f.nonFinite;
            }
          } finally {
            d.dispose();
          }
        }
      } finally {
        rig.dispose();
      }
    });
    const ratio = (k) => {
      const most = Math.max(sum.lbs[k], sum.dqs[k]);
      return most > 0 ? sum.candidate[k] / most : sum.candidate[k] > 0 ? Infinity : 1;
    };
    rows.push({
      clip: clip.name, sum, flipRatio: ratio('flipped'), creaseRatio: ratio('creases'), rigidError, normalOff, nonFinite,
      pass: ratio('flipped') <= JOINT_TARGETS.clipFactor && ratio('creases') <= JOINT_TARGETS.clipFactor && rigidError <= 1e-4 &&
        normalOff <= 1e-3 && nonFinite === 0,
    });
  }
  return rows;
}

/** The default candidate: GCS with centres of rotation at `sections`. */
export const centresCandidate = (sections) => CENTRES_METHOD({ sections }).build;
