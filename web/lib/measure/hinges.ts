/**
 * Knees and elbows found from a skeleton's layout (no names needed) and each one's anatomical
 * hinge: the axis perpendicular to the limb and to the character's forward direction, signed so that
 * a positive bend turns the shin back (knee) or the forearm forward (elbow). docs/report-json.md,
 * "joints", says what is measured at them.
 *
 * How: limbs are chains of joints hanging off one branch joint in mirrored pairs (the two
 * children of the pelvis, of the chest); each limb's hinge is the joint between its two longest
 * consecutive segments (not the clavicle, not the wrist). Up is against the pair that reaches
 * furthest (the legs); the legs are the pair of the lowest branch and the arms the longest other
 * pair above them; forward is perpendicular to up and to the hips' left–right line, on the side
 * where the feet point (the skin of the foot lies ahead of the ankle).
 */
import type { RigInput } from '../index.js';
import { checkList, checkRigInput } from '../arguments.js';

/** A point or vector: x, y, z. */
export type Vec3 = [number, number, number];

/** A knee or elbow found by `findHinges`: its joint and its anatomical hinge axis. */
export interface Hinge {
  /** Which joint it is. */
  kind: 'knee' | 'elbow';
  /** The character's side. */
  side: 'left' | 'right';
  /** 'left knee', …; with the joint's name when names were given. */
  label: string;
  /** The bent joint and its parent (the thigh, the upper arm). */
  joint: number;
  /** The parent joint (the thigh, the upper arm). */
  parent: number;
  /** Bind-pose centre of the joint (mesh space). */
  centre: Vec3;
  /** The far end of the bent bone at bind (its child joint, or its skin's farthest point for a leaf). */
  end: Vec3;
  /** Unit hinge axis (mesh space): bending by a positive angle about it is flexion. */
  axis: Vec3;
}

/** The character's frame in mesh space (unit vectors; left = up × forward). */
export interface BodyFrame {
  /** Up, from the feet to the head. */
  up: Vec3;
  /** Forward, where the feet point. */
  forward: Vec3;
  /** The character's left. */
  left: Vec3;
}

/** What `findHinges` found: the hinges, the body frame and notes on what is missing. */
export interface HingeSearch {
  /** Left knee, right knee, left elbow, right elbow (those found). */
  hinges: Hinge[];
  /** The character's frame; null when no pair of limbs was found. */
  frame: BodyFrame | null;
  /** Why something was not found, or a guess was made. */
  notes: string[];
}

/** A chain of joints from a branch joint's child, following the farthest-reaching child. */
interface Limb {
  branch: number;
  path: number[];
  /** Index in `path` of the hinge (≥ 1), or -1. */
  hinge: number;
  /** The far end of the hinge's bone. */
  end: Vec3;
  /** Summed length of the first segments (what the mirror error is measured against). */
  length: number;
}

const MIRROR_POINTS = 4;   // joints of each limb compared by the mirror test (fingers left out)
const MIRROR_TOLERANCE = 0.2; // largest mirror error, as a fraction of the limb's length

/** What the steps of findHinges read of the rig: joint centres, children, each vertex's dominant joint, reach. */
interface Skeleton {
  input: RigInput;
  centres: Vec3[];
  children: number[][];
  dominant: Int32Array;
  /** Reach of each joint (the longest path down its subtree), -1 until asked (reachOf). */
  reach: Float64Array;
}

/**
 * Finds the knees and elbows of a rig from its skeleton's layout alone (the file's opening comment
 * says how) and each one's hinge axis; `names` (the joints' names, when known) only label them.
 * Returns the hinges found (left knee, right knee, left elbow, right elbow), the character's frame,
 * and notes saying why something was not found or was guessed. Used by measureJoints.
 * @param input The rig (joint centres come from its inverse bind matrices and skin).
 * @param names Joint names, used only in the labels.
 * @returns The hinges found, the body frame, and notes on what was not found or guessed.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function findHinges(input: RigInput, names?: readonly (string | undefined)[]): HingeSearch {
  checkRigInput(input, 'input', 'findHinges');
  if (names !== undefined) checkList(names, 'names', 'findHinges');
  const notes: string[] = [];
  const skeleton = skeletonOf(input);
  const limbs = limbPairs(skeleton, mirroredPairs(skeleton));
  if (limbs.length < 2) {
    notes.push(limbs.length ? 'one mirrored pair of limbs only (legs and arms need two, with skin on this mesh): no knee or elbow found'
      : 'no mirrored pair of limbs in the skeleton: no knee or elbow found');
    return { hinges: [], frame: null, notes };
  }
  const legsAndArms = legsAndArmsOf(skeleton, limbs, notes);
  if (!legsAndArms) return { hinges: [], frame: null, notes };
  const { legs, arms, down } = legsAndArms;
  const frame = bodyFrame(skeleton, legs, down, notes);
  const hinges: Hinge[] = [];
  hingesOfPair(skeleton, legs, 'knee', frame, names, hinges, notes);
  hingesOfPair(skeleton, arms, 'elbow', frame, names, hinges, notes);
  return { hinges, frame, notes };
}

function skeletonOf(input: RigInput): Skeleton {
  const J = input.parents.length;
  const children: number[][] = Array.from({ length: J }, () => []);
  for (let j = 0; j < J; j++) {
    const p = input.parents[j];
    if (p >= 0 && p < J) children[p].push(j);
  }
  return { input, centres: jointCentres(input), children, dominant: dominantJoints(input), reach: new Float64Array(J).fill(-1) };
}

/** The skin point of joint j farthest from its centre (the far end of a leaf bone), or null when j holds no skin. */
function leafTip(s: Skeleton, j: number): Vec3 | null {
  let best = -1, far: Vec3 | null = null;
  const P = s.input.positions;
  for (let v = 0; v < s.dominant.length; v++) {
    if (s.dominant[v] !== j) continue;
    const d = dist([P[3 * v], P[3 * v + 1], P[3 * v + 2]], s.centres[j]);
    if (d > best) { best = d; far = [P[3 * v], P[3 * v + 1], P[3 * v + 2]]; }
  }
  return far;
}

/** Reach of a joint: the longest path down its subtree (children have higher or lower ids: recurse). */
function reachOf(s: Skeleton, j: number): number {
  if (s.reach[j] >= 0) return s.reach[j];
  s.reach[j] = 0; // a cycle in bad input ends here
  let r = 0;
  for (const c of s.children[j]) r = Math.max(r, dist(s.centres[c], s.centres[j]) + reachOf(s, c));
  return (s.reach[j] = r);
}

/** The limb from `root` (a child of `branch`), following the farthest-reaching child, and its hinge. */
function limbOf(s: Skeleton, branch: number, root: number): Limb | null {
  const { centres, children } = s;
  const path = [root];
  const seen = new Set(path);
  for (let j = root; children[j].length;) {
    let next = -1, best = -1;
    for (const c of children[j]) {
      const r = dist(centres[c], centres[j]) + reachOf(s, c);
      if (r > best && !seen.has(c)) { best = r; next = c; }
    }
    if (next < 0) break;
    path.push(next); seen.add(next); j = next;
  }
  // The hinge: the joint (not the limb's root) between its two longest consecutive segments.
  let hinge = -1, score = 0, end: Vec3 | null = null;
  for (let i = 1; i < path.length; i++) {
    const after = i + 1 < path.length ? centres[path[i + 1]] : leafTip(s, path[i]);
    if (!after) continue;
    const d = Math.min(dist(centres[path[i]], centres[path[i - 1]]), dist(after, centres[path[i]]));
    if (d > score) { score = d; hinge = i; end = after; }
  }
  if (hinge < 0 || !end) return null;
  let length = dist(centres[root], centres[branch]);
  for (let i = 1; i < Math.min(path.length, MIRROR_POINTS); i++) length += dist(centres[path[i]], centres[path[i - 1]]);
  return { branch, path, hinge, end, length };
}

/** Mirrored pairs of limbs hanging off one branch joint, the best-mirrored first at each branch. */
function mirroredPairs(s: Skeleton): [Limb, Limb][] {
  const pairs: [Limb, Limb][] = [];
  for (let b = 0; b < s.children.length; b++) {
    if (s.children[b].length < 2) continue;
    const limbs = s.children[b].map((c) => limbOf(s, b, c)).filter((l): l is Limb => l !== null);
    const candidates: { a: Limb; b: Limb; error: number }[] = [];
    for (let i = 0; i < limbs.length; i++)
      for (let k = i + 1; k < limbs.length; k++) {
        const error = mirrorError(limbs[i], limbs[k], s.centres);
        if (error < MIRROR_TOLERANCE) candidates.push({ a: limbs[i], b: limbs[k], error });
      }
    candidates.sort((x, y) => x.error - y.error);
    const used = new Set<Limb>();
    for (const c of candidates) {
      if (used.has(c.a) || used.has(c.b)) continue;
      used.add(c.a); used.add(c.b);
      pairs.push([c.a, c.b]);
    }
  }
  return pairs;
}

/** Limbs, not fingers or ears: each pair as long as a fifth of the skeleton's extent at least, its hinges skinned on this mesh. */
function limbPairs(s: Skeleton, pairs: [Limb, Limb][]): [Limb, Limb][] {
  const lo: Vec3 = [Infinity, Infinity, Infinity], hi: Vec3 = [-Infinity, -Infinity, -Infinity];
  for (const c of s.centres) for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], c[k]); hi[k] = Math.max(hi[k], c[k]); }
  const extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  const skinned = new Set<number>(); // joints with weight on some vertex of this mesh
  for (let i = 0; i < s.input.weights.length; i++) if (s.input.weights[i] > 0) skinned.add(s.input.joints[i]);
  return pairs.filter(([a, b]) => Math.min(a.length, b.length) >= 0.2 * extent &&
    skinned.has(a.path[a.hinge]) && skinned.has(b.path[b.hinge]));
}

/**
 * Up is against the pair whose limbs reach furthest from their roots, taken together (`down`); the
 * legs are the pair of the lowest branch, the arms the longest pair above them and outside them.
 * Null (a note said why) when there is no telling.
 */
function legsAndArmsOf(s: Skeleton, limbs: [Limb, Limb][], notes: string[]): { legs: [Limb, Limb]; arms: [Limb, Limb]; down: Vec3 } | null {
  const { centres } = s;
  const reachVector = ([a, b]: [Limb, Limb]): Vec3 =>
    add(sub(a.end, centres[a.path[0]]), sub(b.end, centres[b.path[0]]));
  const longest = limbs.reduce((x, y) => (norm(reachVector(y)) > norm(reachVector(x)) ? y : x));
  const down = reachVector(longest);
  if (!(norm(down) > 0)) {
    notes.push('the limbs reach nowhere: no knee or elbow found');
    return null;
  }
  const up = scale(down, -1 / norm(down));
  const height = (j: number) => dot(centres[j], up);
  const legs = limbs.reduce((x, y) => (height(y[0].branch) < height(x[0].branch) ? y : x));
  // The arms hang off a branch above the legs' and outside them (not toes, not fingers of a hand).
  const inLegs = (j: number) => legs.some((leg) => leg.path.includes(j));
  const above = limbs.filter((p) => p !== legs && height(p[0].branch) > height(legs[0].branch) && !inLegs(p[0].branch));
  const arms = above.length ? above.reduce((x, y) => (y[0].length + y[1].length > x[0].length + x[1].length ? y : x)) : null;
  if (!arms) {
    // Without a second pair there is no telling legs from arms (nor toes, fingers, ears).
    notes.push('no second pair of limbs above the first: no knee or elbow found');
    return null;
  }
  return { legs, arms, down };
}

/** Forward: perpendicular to up and to the hips' left–right line; the sign from the feet (else the knees). */
function bodyFrame(s: Skeleton, legs: [Limb, Limb], down: Vec3, notes: string[]): BodyFrame {
  const { centres, children, dominant } = s;
  const across = normalize(sub(centres[legs[0].path[0]], centres[legs[1].path[0]]));
  let up = scale(down, -1 / norm(down));
  up = normalize(sub(up, scale(across, dot(up, across))));
  let forward = normalize(cross(across, up));
  let ahead = 0, footSize = 0;
  const subtree = (j: number, out = new Set<number>()): Set<number> => {
    if (out.has(j)) return out;
    out.add(j);
    for (const c of children[j]) subtree(c, out);
    return out;
  };
  for (const leg of legs) {
    const ankle = leg.path[leg.hinge + 1];
    if (ankle === undefined) continue;
    const foot = subtree(ankle);
    const P = s.input.positions;
    let n = 0;
    const sum: Vec3 = [0, 0, 0];
    for (let v = 0; v < dominant.length; v++)
      if (foot.has(dominant[v])) { sum[0] += P[3 * v]; sum[1] += P[3 * v + 1]; sum[2] += P[3 * v + 2]; n++; }
    if (!n) continue;
    const toward = sub(scale(sum, 1 / n), centres[ankle]);
    ahead += dot(toward, forward);
    footSize += norm(toward);
  }
  if (Math.abs(ahead) > 0.1 * footSize) {
    if (ahead < 0) forward = scale(forward, -1);
  } else {
    // No foot to go by: a knee bent at bind stands ahead of its hip–ankle line.
    let knees = 0;
    for (const leg of legs) {
      const hip = centres[leg.path[leg.hinge - 1]], knee = centres[leg.path[leg.hinge]];
      knees += dot(sub(knee, scale(add(hip, leg.end), 0.5)), forward);
    }
    if (knees < 0) forward = scale(forward, -1);
    notes.push(knees !== 0 ? 'forward taken from the knees (no foot skin ahead of the ankles)' : 'forward is a guess: no foot skin and straight knees');
  }
  return { up, forward, left: cross(up, forward) };
}

/** The pair's two hinges, left first, each with its axis signed so that a positive bend is flexion. */
function hingesOfPair(s: Skeleton, pair: [Limb, Limb], kind: Hinge['kind'], frame: BodyFrame,
  names: readonly (string | undefined)[] | undefined, hinges: Hinge[], notes: string[]): void {
  const { centres } = s;
  const { forward, left } = frame;
  const firstIsLeft = dot(sub(centres[pair[0].path[0]], centres[pair[1].path[0]]), left) >= 0;
  const order: [Limb, Hinge['side']][] = firstIsLeft ? [[pair[0], 'left'], [pair[1], 'right']] : [[pair[1], 'left'], [pair[0], 'right']];
  for (const [limb, side] of order) {
    const joint = limb.path[limb.hinge];
    const centre = centres[joint];
    const along = normalize(sub(limb.end, centre));
    // Flexion turns the bone's end toward −forward (knee) or +forward (elbow): axis × along points there.
    const axis = kind === 'knee' ? cross(forward, along) : cross(along, forward);
    const name = names?.[joint];
    if (norm(axis) < 0.3) {
      notes.push(`${side} ${kind}: the bone points along the forward direction, no hinge axis`);
      continue;
    }
    hinges.push({ kind, side, label: `${side} ${kind}${name ? ` (${name})` : ''}`, joint, parent: limb.path[limb.hinge - 1],
      centre, end: limb.end, axis: normalize(axis) });
  }
}

/** Largest distance between one limb's joints mirrored across the plane between the two roots and the other's, over their length. */
function mirrorError(a: Limb, b: Limb, centres: Vec3[]): number {
  const ra = centres[a.path[0]], rb = centres[b.path[0]];
  const gap = sub(ra, rb);
  if (!(norm(gap) > 0)) return Infinity;
  const n = normalize(gap);
  const mid = scale(add(ra, rb), 0.5);
  const count = Math.min(a.path.length, b.path.length, MIRROR_POINTS);
  if (count < 2) return Infinity;
  let worst = 0;
  for (let i = 0; i < count; i++) {
    const p = centres[a.path[i]];
    const mirrored = sub(p, scale(n, 2 * dot(sub(p, mid), n)));
    worst = Math.max(worst, dist(mirrored, centres[b.path[i]]));
  }
  const length = Math.max(a.length, b.length);
  return length > 0 ? worst / length : Infinity;
}

/**
 * Bind-pose centre of every joint (mesh space): the translation of its inverse bind matrix's inverse.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function jointCentres(input: RigInput): Vec3[] {
  checkRigInput(input, 'input', 'jointCentres');
  const J = input.parents.length;
  const M = input.inverseBindMatrices;
  const out: Vec3[] = [];
  for (let j = 0; j < J; j++) {
    const o = 16 * j;
    // IBM = [A | t]: the centre x solves A·x + t = 0.
    const a = [M[o], M[o + 1], M[o + 2], M[o + 4], M[o + 5], M[o + 6], M[o + 8], M[o + 9], M[o + 10]];
    const t: Vec3 = [-M[o + 12], -M[o + 13], -M[o + 14]];
    out.push(solve3(a, t));
  }
  return out;
}

/**
 * The joint of largest weight of each vertex.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function dominantJoints(input: RigInput): Int32Array {
  checkRigInput(input, 'input', 'dominantJoints');
  const K = input.influences ?? 4;
  const n = Math.floor(input.positions.length / 3);
  const out = new Int32Array(n).fill(-1);
  for (let v = 0; v < n; v++) {
    let best = 0;
    for (let i = 0; i < K; i++) if (input.weights[K * v + i] > best) { best = input.weights[K * v + i]; out[v] = input.joints[K * v + i]; }
  }
  return out;
}

/** x with A·x = b (A column-major 3×3, Cramer's rule); the origin when A is singular. */
function solve3(A: number[], b: Vec3): Vec3 {
  const c0: Vec3 = [A[0], A[1], A[2]], c1: Vec3 = [A[3], A[4], A[5]], c2: Vec3 = [A[6], A[7], A[8]];
  const det = dot(c0, cross(c1, c2));
  if (!(Math.abs(det) > 1e-30)) return [0, 0, 0];
  return [dot(b, cross(c1, c2)) / det, dot(c0, cross(b, c2)) / det, dot(c0, cross(c1, b)) / det];
}

const add = (a: Vec3, b: Vec3): Vec3 => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a: Vec3, b: Vec3): Vec3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a: Vec3, s: number): Vec3 => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a: Vec3, b: Vec3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a: Vec3, b: Vec3): Vec3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a: Vec3): number => Math.hypot(a[0], a[1], a[2]);
const dist = (a: Vec3, b: Vec3): number => norm(sub(a, b));
const normalize = (a: Vec3): Vec3 => { const l = norm(a); return l > 0 ? scale(a, 1 / l) : [0, 0, 0]; };
