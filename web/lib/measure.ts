/**
 * gcs-skin/measure: the one place where the project measures its deformers (docs/method.md §9). Used by
 * `gcs-skin report`, `npm run metrics`, `npm run bench` and the tests.
 *
 * - Timing: `timeFrames` (median / p95 ms of a per-frame step).
 * - Fidelity: `FidelityProbe` compares a deformer's output, frame by frame, with what the rig says:
 *   rigid error (vertices bound ≥ 0.999 to one joint against S_j·x), distance from a scale-aware
 *   dual-quaternion skinning computed here in JavaScript (independently of the core), flipped and
 *   stretched triangles, normals off unit length, non-finite values and the seam gap. Distances are
 *   in % of the character's height.
 *
 * - Joints: `measureJoints` finds the knees and elbows (`findHinges`) and bends each alone
 *   (`JointProbe`): volume change, bulge and collapse, creases, new self-intersections.
 *
 * Plain TypeScript over typed arrays; no three.js. This file is the entry's face; each job is a room
 * in measure/: statistics, timing, mesh (welding, seams, borders), methods, reference-dqs,
 * fidelity, creases, classic, hinges, joints, self-intersection.
 *
 * @module gcs-skin/measure
 */
export * from './measure/statistics.js';
export * from './measure/timing.js';
export * from './measure/mesh.js';
export * from './measure/methods.js';
export * from './measure/reference-dqs.js';
export * from './measure/fidelity.js';
export * from './measure/creases.js';
export * from './measure/classic.js';
// Knees and elbows bent one at a time (design of the figures: measure/joints.ts).
export * from './measure/hinges.js';
export * from './measure/joints.js';
export { intersectingPairs } from './measure/self-intersection.js';
export { identitySkin } from './index.js';
