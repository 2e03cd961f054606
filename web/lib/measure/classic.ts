// The classic model's figures: what it makes of a rig at one setting and at the paper's budget,
// how far it lies off the skin it replaces, its zip bands' triangle shapes, and a rigid rebind of
// a rig (every vertex on its dominant joint) to measure it on.
import type { ClassicDeformer, ClassicReason, Rig, RigInput } from '../index.js';
import { TriangleGrid } from '../surface-distance.js';
import type { FidelityOptions } from './fidelity.js';
import { boundsHeight, meshBorder } from './mesh.js';
import { referenceDqs } from './reference-dqs.js';
import { maxOf, percentile } from './statistics.js';
import { checkList, checkMethods, checkNumberFields, checkObject, checkOptionsObject, checkRigInput } from '../arguments.js';

/** What the classic model makes of a rig at one setting (the paper's Fig. 5 comparison). */
export interface ClassicFigures {
  /** Contours per part at this setting. */
  contours: number;
  /** Rays per contour at this setting. */
  rays: number;
  /** Vertices of the classic model's output mesh. */
  outputVertices: number;
  /** Parts resampled (chain parts, and trunk parts along the spine) and carried. */
  resampled: number;
  /** Trunk parts resampled along the spine. */
  trunk: number;
  /** Parts carried (their own triangles, skinned by DQS). */
  carried: number;
  /** Detail loss, % of the mesh's height (ClassicDeformer.detailLoss). */
  rms: number;
  /** Largest detail loss, % of the mesh's height. */
  max: number;
  /** Welded border edges of the output at rest (equal to the input's: no gap where tubes meet carried skin). */
  border: number;
  /** Ring vertices (contours × rays) of each resampled part, by joint. */
  points: Map<number, number>;
}

/**
 * Builds the classic model at one setting and measures it (disposes it).
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function classicFigures(rig: Rig, contours: number, rays: number): ClassicFigures {
  checkMethods(rig, 'rig', 'classicFigures', ['buildClassic']);
  const d = rig.buildClassic({ contours, rays });
  try {
    const parts = d.parts;
    const loss = d.detailLoss;
    return {
      contours, rays, outputVertices: d.vertexCount, resampled: parts.filter((p) => p.reason === 'resampled').length,
      trunk: parts.filter((p) => p.reason === 'trunk').length, carried: parts.filter((p) => !p.resampled).length,
      rms: loss.rms, max: loss.max, border: meshBorder(d.positions, d.indices).open,
      points: new Map(parts.filter((p) => p.resampled).map((p) => [p.joint, p.vertexCount])),
    };
  } finally {
    d.dispose();
  }
}

/**
 * The classic model at the vertex budget of GCS (which keeps every input vertex): the square
 * setting (contours = rays = s) whose output vertex count is closest to the rig's, by bisection
 * over s in [3, 256] (output size grows with s).
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function classicAtBudget(rig: Rig): ClassicFigures {
  checkMethods(rig, 'rig', 'classicAtBudget', ['buildClassic']);
  let lo = 3, hi = 256;
  const size = (s: number) => {
    const d = rig.buildClassic({ contours: s, rays: s });
    const n = d.vertexCount;
    d.dispose();
    return n;
  };
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (size(mid) <= rig.vertexCount) lo = mid;
    else hi = mid;
  }
  const best = Math.abs(size(lo) - rig.vertexCount) <= Math.abs(size(hi) - rig.vertexCount) ? lo : hi;
  return classicFigures(rig, best, best);
}

/** How far one part of a classic model's output lies from the DQS-posed source surface (% of height). */
export interface OffSurfacePart {
  /** The part's joint. */
  joint: number;
  /** Whether the part is resampled (false: carried). */
  resampled: boolean;
  /** Why it is resampled or carried. */
  reason: ClassicReason;
  /** Output vertices of the part (a shared joint ring counts for both parts). */
  vertices: number;
  /** 99th percentile of its vertices' distances over the frames, % of height. */
  p99: number;
  /** Largest distance, % of height. */
  max: number;
  /** Where the max is: the frame (index into the frames given) and the output vertex. */
  worstFrame: number;
  /** The output vertex of the largest distance. */
  worstVertex: number;
}

/** The classic model against the skin it replaces (docs/method.md §9, "classic off-surface"). */
export interface ClassicOffSurface {
  /** Frames measured. */
  frames: number;
  /** Over every output vertex and frame, % of height. */
  p99: number;
  /** Largest distance over every output vertex and frame, % of height. */
  max: number;
  /** Per part, in the order of `deformer.parts`. */
  parts: OffSurfacePart[];
}

/**
 * Each classic output vertex's distance to the source surface as dual-quaternion skinning poses it
 * (point to nearest triangle of the DQS-posed input mesh), over `frames` (skin matrices J × 16
 * each), in % of `options.height` (default: the rig's bind-pose height): what resampling loses
 * (detail, bulge at the deformer's current setting) and anything that stands off the skin (flaps,
 * cuts, carried parts that do not follow it). Leaves the deformer in the last frame's pose.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function classicOffSurface(input: RigInput, deformer: ClassicDeformer, frames: readonly Float32Array[],
                                  options: FidelityOptions = {}): ClassicOffSurface {
  checkRigInput(input, 'input', 'classicOffSurface');
  checkObject(deformer, 'deformer', 'classicOffSurface');
  checkList(frames, 'frames', 'classicOffSurface');
  checkOptionsObject(options, 'options', 'classicOffSurface');
  const height = options.height ?? boundsHeight(input.positions);
  const nOut = deformer.vertexCount;
  const parts = deformer.parts;
  // Each output vertex's part: ring and carried vertices by the parts' ranges, a cap's vertices
  // by the part of their contour's ring.
  const partOf = new Int32Array(nOut).fill(-1);
  parts.forEach((p, i) => partOf.fill(i, p.firstVertex, p.firstVertex + p.vertexCount));
  const contourOf = deformer.contourOfVertex;
  const partOfContour = new Map<number, number>();
  for (let o = 0; o < nOut; o++) if (contourOf[o] >= 0 && partOf[o] >= 0) partOfContour.set(contourOf[o], partOf[o]);
  for (let o = 0; o < nOut; o++) if (partOf[o] < 0 && contourOf[o] >= 0) partOf[o] = partOfContour.get(contourOf[o]) ?? -1;
  const posed = new Float64Array(input.positions.length);
  const grid = new TriangleGrid();
  const distances = new Float32Array(nOut * frames.length);
  frames.forEach((skin, f) => {
    referenceDqs(input, skin, posed);
    deformer.deform(skin);
    const out = deformer.positions;
    grid.build(posed, input.indices, out);
    for (let o = 0; o < nOut; o++) {
      const d = grid.distance(out[3 * o], out[3 * o + 1], out[3 * o + 2]);
      distances[f * nOut + o] = Number.isNaN(d) ? Infinity : d;
    }
  });
  const scale = 100 / height;
  const byPart = parts.map(() => [] as number[]);
  const worst = parts.map(() => ({ d: -1, frame: 0, vertex: 0 }));
  for (let f = 0; f < frames.length; f++)
    for (let o = 0; o < nOut; o++) {
      const i = partOf[o];
      if (i < 0) continue;
      const d = distances[f * nOut + o];
      byPart[i].push(d);
      if (d > worst[i].d) worst[i] = { d, frame: f, vertex: o };
    }
  return {
    frames: frames.length, p99: percentile(distances, 99) * scale, max: maxOf(distances) * scale,
    parts: parts.map((p, i) => ({
      joint: p.joint, resampled: p.resampled, reason: p.reason, vertices: p.vertexCount,
      p99: byPart[i].length ? percentile(byPart[i], 99) * scale : 0, max: byPart[i].length ? maxOf(byPart[i]) * scale : 0,
      worstFrame: worst[i].frame, worstVertex: worst[i].vertex,
    })),
  };
}

/**
 * A rig of rigid parts made from a skinned one (like Mixamo's X Bot): every vertex bound with
 * weight 1 to its dominant joint (the first of equal largest weights). The classic model's
 * decisions must hold on such a rig too: its skin tears at every joint instead of blending.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function rigidRebind(input: RigInput): RigInput {
  checkRigInput(input, 'input', 'rigidRebind');
  const n = Math.floor(input.positions.length / 3), k = input.influences ?? 4;
  const joints = new Uint32Array(4 * n), weights = new Float32Array(4 * n);
  for (let v = 0; v < n; v++) {
    let best = 0;
    for (let i = 1; i < k; i++) if (input.weights[k * v + i] > input.weights[k * v + best]) best = i;
    joints[4 * v] = input.joints[k * v + best];
    weights[4 * v] = 1;
  }
  return { ...input, joints, weights, influences: 4 };
}

/** The shape of a classic model's zip-band triangles (the bands joining tubes to carried skin). */
export interface BandQuality {
  /** Band triangles: those with both a ring vertex and a carried vertex. */
  triangles: number;
  /** Smallest interior angle (degrees): the minimum, the 1st percentile and the median over triangles. */
  minAngle: number;
  /** 1st percentile of the smallest angle, degrees. */
  minAngleP1: number;
  /** Median of the smallest angle, degrees. */
  minAngleMedian: number;
  /** Triangles with an angle under 5° and under 10°. */
  under5: number;
  /** Triangles with an angle under 10°. */
  under10: number;
  /** Aspect ratio longest edge × perimeter / (4√3 × area): 1 for an equilateral triangle; max, p99, median. */
  aspectMax: number;
  /** 99th percentile of the aspect ratio. */
  aspectP99: number;
  /** Median aspect ratio. */
  aspectMedian: number;
}

/**
 * Minimum angle and aspect ratio of the zip-band triangles of a classic model in its current pose
 * (call it after a deform with identity matrices for the bind pose): long slivers shade as streaks.
 * A band triangle is any triangle that is neither the tubes' (every corner a ring or cap vertex)
 * nor a carried triangle of `input` (every corner a copied input vertex, and the three of them one
 * of the input's triangles): it joins a ring to carried skin, touches a band's own vertices, or
 * runs along a loop.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function classicBandQuality(deformer: ClassicDeformer, input: Pick<RigInput, 'indices'>): BandQuality {
  checkNumberFields(deformer, 'deformer', 'classicBandQuality', ['indices', 'positions']);
  checkNumberFields(input, 'input', 'classicBandQuality', ['indices']);
  const I = deformer.indices, X = deformer.positions, ring = deformer.contourOfVertex, source = deformer.sourceOfVertex;
  const key = (a: number, b: number, c: number) => [a, b, c].sort((x, y) => x - y).join();
  const carried = new Set<string>();
  for (let t = 0; t + 2 < input.indices.length; t += 3) carried.add(key(input.indices[t], input.indices[t + 1], input.indices[t + 2]));
  const angles: number[] = [], aspects: number[] = [];
  const at = (v: number) => [X[3 * v], X[3 * v + 1], X[3 * v + 2]];
  const dist = (p: number[], q: number[]) => Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
  for (let t = 0; t < I.length; t += 3) {
    const v = [I[t], I[t + 1], I[t + 2]];
    if (v.every((x) => ring[x] >= 0)) continue;
    if (v.every((x) => source[x] >= 0) && carried.has(key(source[v[0]], source[v[1]], source[v[2]]))) continue;
    const [a, b, c] = v.map(at);
    const la = dist(b, c), lb = dist(c, a), lc = dist(a, b);
    const s = (la + lb + lc) / 2, area = Math.sqrt(Math.max(0, s * (s - la) * (s - lb) * (s - lc)));
    const angle = (o: number, p: number, q: number) => Math.acos(Math.min(1, Math.max(-1, (p * p + q * q - o * o) / (2 * p * q)))) * 180 / Math.PI;
    angles.push(Math.min(angle(la, lb, lc), angle(lb, lc, la), angle(lc, la, lb)) || 0);
    aspects.push(area > 0 ? Math.max(la, lb, lc) * 2 * s / (4 * Math.sqrt(3) * area) : Infinity);
  }
  const sorted = (a: number[]) => [...a].sort((x, y) => x - y);
  const A = sorted(angles), R = sorted(aspects), n = A.length;
  const q = (s: number[], f: number) => (n ? s[Math.min(n - 1, Math.floor(f * (n - 1)))] : 0);
  return {
    triangles: n, minAngle: n ? A[0] : 0, minAngleP1: q(A, 0.01), minAngleMedian: q(A, 0.5),
    under5: A.filter((x) => x < 5).length, under10: A.filter((x) => x < 10).length,
    aspectMax: n ? R[n - 1] : 0, aspectP99: q(R, 0.99), aspectMedian: q(R, 0.5),
  };
}
