// Bounds of a deformed skin without reading its vertices: per frame, a box from the posed bones
// (O(joints), for frustum culling); before a raycast, the exact box of the output positions.
import * as THREE from 'three';
import type { RigInput } from '../index.js';

/** Joints carrying skin and, per joint, the radius of its ball (see boundsFromBones). */
export interface BoneBalls {
  joints: Uint32Array;
  radii: Float32Array;
}

/** Per joint j: its bind position b_j (mesh space, 3 floats) and its balls. */
export interface BoneBounds {
  pivots: Float32Array;
  /** r_j = max |v − b_j| over the vertices weighted to j. */
  own: BoneBalls;
  /** Also counts, for each joint, the vertices of its parent and child joints. */
  near: BoneBalls;
}

/**
 * Per joint carrying skin: b_j (the joint's bind position, mesh space) and r_j = max |v − b_j|
 * over the vertices weighted to j ('own'); 'near' also counts, for each joint, the vertices of
 * its parent and child joints (the paper's criteria and the classic model move a part's skin
 * with its neighbours' transforms). Why this bounds the deformed mesh: see boundsFromBones.
 */
export function boneBounds(input: RigInput, jointCount: number): BoneBounds {
  const J = jointCount;
  const pivots = new Float32Array(3 * J);
  const m = new THREE.Matrix4();
  for (let j = 0; j < J; j++) {
    m.fromArray(input.inverseBindMatrices as ArrayLike<number> as number[], 16 * j).invert();
    pivots[3 * j] = m.elements[12];
    pivots[3 * j + 1] = m.elements[13];
    pivots[3 * j + 2] = m.elements[14];
  }
  const neighbours: number[][] = Array.from({ length: J }, () => []);
  for (let j = 0; j < J; j++) {
    const p = input.parents[j];
    if (p >= 0 && p < J) { neighbours[j].push(p); neighbours[p].push(j); }
  }
  const own = new Float64Array(J).fill(-1), near = new Float64Array(J).fill(-1);
  const P = input.positions, Jt = input.joints, W = input.weights, K = input.influences ?? 4;
  const n = P.length / 3;
  const reach = (r2: Float64Array, j: number, v: number) => {
    const dx = P[3 * v] - pivots[3 * j], dy = P[3 * v + 1] - pivots[3 * j + 1], dz = P[3 * v + 2] - pivots[3 * j + 2];
    const d = dx * dx + dy * dy + dz * dz;
    if (d > r2[j]) r2[j] = d;
  };
  for (let v = 0; v < n; v++) {
    for (let k = 0; k < K; k++) {
      if (!(W[K * v + k] > 0)) continue;
      const j = Jt[K * v + k];
      if (j >= J) continue;
      reach(own, j, v);
      reach(near, j, v);
      for (const q of neighbours[j]) reach(near, q, v);
    }
  }
  const balls = (r2: Float64Array): BoneBalls => {
    const joints: number[] = [];
    const radii = new Float32Array(J);
    for (let j = 0; j < J; j++) if (r2[j] >= 0) { joints.push(j); radii[j] = Math.sqrt(r2[j]) * (1 + 1e-6); }
    return { joints: Uint32Array.from(joints), radii };
  };
  return { pivots, own: balls(own), near: balls(near) };
}

/**
 * The per-frame bounds of the deformed mesh from the skin matrices `skin` (J × 16), written into
 * `box` and `sphere` (no allocation).
 *
 * Each joint j's posed position p_j = S_j b_j and a ball of radius s_j·(k·r_j + grow) (s_j the
 * largest axis scale of S_j; grow = Σ|w_t|·maxDelta_t over the morph influences w_t). LBS moves
 * a vertex to a convex combination of the S_j v, each in its joint's ball, so the box of the balls
 * always holds it. GCS (weights) and DQS blend rigid motions of the vertex's own joints: where
 * those agree at a joint (a connected skeleton) the blend turns about it, so the vertex stays
 * within r_j of that posed joint. The paper's criteria also move a part's skin with its parent's
 * and child's motions, so they use the 'near' radii; the classic model's contours swell by at
 * most 1 + bulge, so it uses the 'near' radii times k = 1 + maxBulge (k = 1 otherwise). Checked
 * on 30 frames of every clip of the default human and the shared test characters (CesiumMan, Fox,
 * RobotExpressive, Soldier), every method and criterion: every vertex inside. The sphere
 * circumscribes the box (generous: culling must never drop a visible mesh; a whole body's sphere
 * came out 1.2–1.5× the exact one, classic about 5×).
 */
export function boundsFromBones(
  skin: Float32Array, pivots: Float32Array, balls: BoneBalls, factor: number, grow: number,
  box: THREE.Box3, sphere: THREE.Sphere,
): void {
  const { joints, radii } = balls;
  let x0 = Infinity, y0 = Infinity, z0 = Infinity, x1 = -Infinity, y1 = -Infinity, z1 = -Infinity;
  // Vector3.applyMatrix4 and Matrix4.getMaxScaleOnAxis written out on the array (the same
  // arithmetic, in the same order): no copy of each matrix into a Matrix4 first.
  for (let i = 0; i < joints.length; i++) {
    const j = joints[i], e = 16 * j;
    const bx = pivots[3 * j], by = pivots[3 * j + 1], bz = pivots[3 * j + 2];
    const w = 1 / (skin[e + 3] * bx + skin[e + 7] * by + skin[e + 11] * bz + skin[e + 15]);
    const px = (skin[e] * bx + skin[e + 4] * by + skin[e + 8] * bz + skin[e + 12]) * w;
    const py = (skin[e + 1] * bx + skin[e + 5] * by + skin[e + 9] * bz + skin[e + 13]) * w;
    const pz = (skin[e + 2] * bx + skin[e + 6] * by + skin[e + 10] * bz + skin[e + 14]) * w;
    const sx = skin[e] * skin[e] + skin[e + 1] * skin[e + 1] + skin[e + 2] * skin[e + 2];
    const sy = skin[e + 4] * skin[e + 4] + skin[e + 5] * skin[e + 5] + skin[e + 6] * skin[e + 6];
    const sz = skin[e + 8] * skin[e + 8] + skin[e + 9] * skin[e + 9] + skin[e + 10] * skin[e + 10];
    const r = (radii[j] * factor + grow) * Math.sqrt(Math.max(sx, sy, sz));
    if (px - r < x0) x0 = px - r;
    if (py - r < y0) y0 = py - r;
    if (pz - r < z0) z0 = pz - r;
    if (px + r > x1) x1 = px + r;
    if (py + r > y1) y1 = py + r;
    if (pz + r > z1) z1 = pz + r;
  }
  setBounds(box, sphere, x0, y0, z0, x1, y1, z1);
}

/** The exact box of `positions` (xyz triples) and the sphere around it. */
export function boundsOfPositions(positions: Float32Array, box: THREE.Box3, sphere: THREE.Sphere): void {
  const a = positions;
  let x0 = Infinity, y0 = Infinity, z0 = Infinity, x1 = -Infinity, y1 = -Infinity, z1 = -Infinity;
  for (let i = 0; i < a.length; i += 3) {
    const x = a[i], y = a[i + 1], z = a[i + 2];
    x0 = x < x0 ? x : x0; x1 = x > x1 ? x : x1;
    y0 = y < y0 ? y : y0; y1 = y > y1 ? y : y1;
    z0 = z < z0 ? z : z0; z1 = z > z1 ? z : z1;
  }
  setBounds(box, sphere, x0, y0, z0, x1, y1, z1);
}

/** Box [x0, x1] × [y0, y1] × [z0, z1] and its circumscribed sphere; empty when inverted (or NaN). */
function setBounds(box: THREE.Box3, sphere: THREE.Sphere, x0: number, y0: number, z0: number, x1: number, y1: number, z1: number): void {
  if (!(x0 <= x1 && y0 <= y1 && z0 <= z1)) {
    box.makeEmpty();
    sphere.makeEmpty();
    return;
  }
  box.min.set(x0, y0, z0);
  box.max.set(x1, y1, z1);
  box.getCenter(sphere.center);
  sphere.radius = 0.5 * Math.sqrt((x1 - x0) ** 2 + (y1 - y0) ** 2 + (z1 - z0) ** 2);
}
