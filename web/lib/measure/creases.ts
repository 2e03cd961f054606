// Creases (docs/method.md §9): interior edges whose dihedral angle changes by more than
// CREASE_DEGREES from the rest pose.
import { weldByPosition } from './mesh.js';
import { len3 } from './vectors.js';
import { checkFinite, checkNumberFields, checkNumbers } from '../arguments.js';

/** The crease threshold of docs/method.md §9: a dihedral angle change of more than 20°. */
export const CREASE_DEGREES = 20;

/**
 * The interior edges of a triangle mesh: edges shared by exactly two triangles once vertices at
 * one rest position are welded (so UV seams are not borders). `a`/`b` are the two triangles.
 * Edges of three or more triangles (non-manifold) and border edges are left out. `weld`: the
 * weldByPosition of `rest`, when the caller has it.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function interiorEdges(rest: ArrayLike<number>, indices: ArrayLike<number>,
  weld: ArrayLike<number> = weldByPosition(rest)): {
  /** Per edge, its first triangle. */
  a: Uint32Array;
  /** Per edge, its second triangle. */
  b: Uint32Array;
} {
  checkNumbers(rest, 'rest', 'interiorEdges');
  checkNumbers(indices, 'indices', 'interiorEdges');
  checkNumbers(weld, 'weld', 'interiorEdges');
  const n = Math.floor(rest.length / 3);
  // Edge key → first triangle, or -1 once a third triangle uses it; second triangle beside it.
  const first = new Map<number, number>();
  const second = new Map<number, number>();
  const triCount = Math.floor(indices.length / 3);
  for (let t = 0; t < triCount; t++) {
    for (let e = 0; e < 3; e++) {
      const p = weld[indices[3 * t + e]], q = weld[indices[3 * t + ((e + 1) % 3)]];
      if (p === q) continue;
      const key = Math.min(p, q) * n + Math.max(p, q);
      const t0 = first.get(key);
      if (t0 === undefined) first.set(key, t);
      else if (t0 >= 0 && !second.has(key)) second.set(key, t);
      else { first.set(key, -1); second.delete(key); }
    }
  }
  const a = new Uint32Array(second.size), b = new Uint32Array(second.size);
  let i = 0;
  for (const [key, t1] of second) { a[i] = first.get(key)!; b[i] = t1; i++; }
  return { a, b };
}

/**
 * cos of the angle between the two face normals of each edge; NaN where a face is degenerate.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function dihedralCosines(faceNormals: ArrayLike<number>, edges: { a: Uint32Array; b: Uint32Array }): Float64Array {
  checkNumbers(faceNormals, 'faceNormals', 'dihedralCosines');
  checkNumberFields(edges, 'edges', 'dihedralCosines', ['a', 'b']);
  const out = new Float64Array(edges.a.length);
  for (let i = 0; i < out.length; i++) out[i] = normalCos(faceNormals, edges.a[i], edges.b[i]);
  return out;
}

/**
 * Interior edges whose dihedral angle differs from its rest value by more than CREASE_DEGREES.
 * Edges degenerate at rest are skipped; a face that collapses in the pose (or a non-finite one)
 * counts as a crease.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function countCreases(faceNormals: ArrayLike<number>, edges: { a: Uint32Array; b: Uint32Array },
  restCos: Float64Array, degrees = CREASE_DEGREES, bands = creaseBands(restCos, degrees)): number {
  checkNumbers(faceNormals, 'faceNormals', 'countCreases');
  checkNumberFields(edges, 'edges', 'countCreases', ['a', 'b']);
  checkNumberFields(bands, 'bands', 'countCreases', ['lo', 'hi']);
  let count = 0;
  for (let i = 0; i < restCos.length; i++) {
    if (Number.isNaN(restCos[i])) continue;
    const c = normalCos(faceNormals, edges.a[i], edges.b[i]);
    if (!(c >= bands.lo[i] && c <= bands.hi[i])) count++;
  }
  return count;
}

/**
 * Per edge, the cosines its posed dihedral may take without a crease: the angle within `degrees`
 * of its rest angle a0 is the cosine within [cos(a0 + limit), cos(a0 − limit)] (cos falls on
 * [0, π]), so a frame compares cosines instead of taking an acos per edge.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function creaseBands(restCos: Float64Array, degrees = CREASE_DEGREES): {
  /** Per edge, the lowest cosine without a crease. */
  lo: Float64Array;
  /** Per edge, the highest cosine without a crease. */
  hi: Float64Array;
} {
  checkNumbers(restCos, 'restCos', 'creaseBands');
  checkFinite(degrees, 'degrees', 'creaseBands');
  const limit = degrees * Math.PI / 180;
  const lo = new Float64Array(restCos.length), hi = new Float64Array(restCos.length);
  for (let i = 0; i < restCos.length; i++) {
    const a0 = Math.acos(restCos[i]);
    lo[i] = Math.cos(Math.min(Math.PI, a0 + limit));
    hi[i] = Math.cos(Math.max(0, a0 - limit));
  }
  return { lo, hi };
}

function normalCos(nrm: ArrayLike<number>, s: number, t: number): number {
  const ax = nrm[3 * s], ay = nrm[3 * s + 1], az = nrm[3 * s + 2];
  const bx = nrm[3 * t], by = nrm[3 * t + 1], bz = nrm[3 * t + 2];
  const l = len3(ax, ay, az) * len3(bx, by, bz);
  if (!(l > 0)) return NaN;
  return Math.max(-1, Math.min(1, (ax * bx + ay * by + az * bz) / l));
}
