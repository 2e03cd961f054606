// Small measures of a deformer's output mesh: non-finite values, vertices welded at rest and the gap
// a seam opens, the mesh's border, the rest pose in the output order and its error, the bounds.
import { identitySkin, type Deformer } from '../index.js';
import { checkMethods, checkNumbers } from '../arguments.js';

/**
 * Number of NaN or infinite values in the given arrays.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function countNonFinite(...arrays: ArrayLike<number>[]): number {
  for (let k = 0; k < arrays.length; k++) checkNumbers(arrays[k], `array ${k}`, 'countNonFinite');
  let bad = 0;
  for (const a of arrays) for (let i = 0; i < a.length; i++) if (!Number.isFinite(a[i])) bad++;
  return bad;
}

/**
 * Groups of output vertices that coincide at rest (glTF splits vertices along UV and normal
 * seams): pairs [first of group, other member], flattened. `rest` is xyz per output vertex.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function coincidentPairs(rest: ArrayLike<number>): Uint32Array {
  checkNumbers(rest, 'rest', 'coincidentPairs');
  const weld = weldByPosition(rest);
  const pairs: number[] = [];
  for (let v = 0; v < weld.length; v++) if (weld[v] !== v) pairs.push(weld[v], v);
  return Uint32Array.from(pairs);
}

/**
 * For each vertex, the first vertex at exactly its rest position (itself when none comes before).
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function weldByPosition(rest: ArrayLike<number>): Uint32Array {
  checkNumbers(rest, 'rest', 'weldByPosition');
  const n = Math.floor(rest.length / 3);
  const f = new Float32Array(3);
  const u = new Uint32Array(f.buffer);
  const seen = new Map<string, number>();
  const weld = new Uint32Array(n);
  for (let v = 0; v < n; v++) {
    f[0] = rest[3 * v] + 0; f[1] = rest[3 * v + 1] + 0; f[2] = rest[3 * v + 2] + 0; // +0 folds -0
    const key = `${u[0]},${u[1]},${u[2]}`;
    const at = seen.get(key);
    if (at === undefined) seen.set(key, v);
    weld[v] = at ?? v;
  }
  return weld;
}

/**
 * Largest distance between vertices that coincide at rest (0 = no seam opens). NaN counts as infinite.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function seamGap(positions: ArrayLike<number>, pairs: Uint32Array): number {
  checkNumbers(positions, 'positions', 'seamGap');
  checkNumbers(pairs, 'pairs', 'seamGap');
  let gap = 0;
  for (let i = 0; i < pairs.length; i += 2) {
    const a = 3 * pairs[i], b = 3 * pairs[i + 1];
    const dx = positions[a] - positions[b], dy = positions[a + 1] - positions[b + 1], dz = positions[a + 2] - positions[b + 2];
    const d = Math.sqrt(dx * dx + dy * dy + dz * dz);
    if (!(d <= gap)) gap = Number.isNaN(d) ? Infinity : d;
  }
  return gap;
}

/**
 * The border of a triangle mesh (`positions` xyz per vertex) with its coincident vertices welded
 * (coincidentPairs): `open` edges used by one triangle, `overused` edges by more than two (a fold
 * or an overlap glued on). A closed manifold mesh has both 0; a closed input deformed into an
 * output with a gap or a torn seam has open > 0.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function meshBorder(positions: ArrayLike<number>, indices: ArrayLike<number>): {
  /** Edges used by one triangle. */
  open: number;
  /** Edges used by more than two triangles. */
  overused: number;
} {
  checkNumbers(positions, 'positions', 'meshBorder');
  checkNumbers(indices, 'indices', 'meshBorder');
  const vertexCount = Math.floor(positions.length / 3);
  const pairs = coincidentPairs(positions);
  const weld = new Uint32Array(vertexCount);
  for (let v = 0; v < vertexCount; v++) weld[v] = v;
  for (let i = 0; i < pairs.length; i += 2) weld[pairs[i + 1]] = pairs[i];
  const uses = new Map<number, number>();
  for (let t = 0; t + 2 < indices.length; t += 3)
    for (let e = 0; e < 3; e++) {
      const a = weld[indices[t + e]], b = weld[indices[t + ((e + 1) % 3)]];
      if (a === b) continue;
      const key = a < b ? a * vertexCount + b : b * vertexCount + a;
      uses.set(key, (uses.get(key) ?? 0) + 1);
    }
  let open = 0, overused = 0;
  for (const n of uses.values()) {
    if (n === 1) open++;
    else if (n > 2) overused++;
  }
  return { open, overused };
}

/**
 * The rest positions of a deformer's output vertices: the rig's bind-pose positions of their
 * source vertices where the deformer has them, else the output of a bind-pose deform.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function restOfOutput(deformer: Deformer, rigPositions: ArrayLike<number>): Float32Array {
  checkMethods(deformer, 'deformer', 'restOfOutput', ['deform']);
  checkNumbers(rigPositions, 'rigPositions', 'restOfOutput');
  const source = deformer.sourceVertex;
  const nRig = Math.floor(rigPositions.length / 3);
  deformer.deform(identitySkin(deformer.jointCount));
  const out = Float32Array.from(deformer.positions);
  if (source) {
    for (let o = 0; o < source.length; o++) {
      const v = source[o];
      if (v < nRig) for (let c = 0; c < 3; c++) out[3 * o + c] = rigPositions[3 * v + c];
    }
  }
  return out;
}

/**
 * Rest error: the largest distance, over output vertices that come from a rig vertex, between the
 * bind-pose deform and that vertex's original position. null when no output vertex has a source
 * (a resampled model: see the classic detail loss instead).
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function restError(deformer: Deformer, rigPositions: ArrayLike<number>): number | null {
  checkMethods(deformer, 'deformer', 'restError', ['deform']);
  checkNumbers(rigPositions, 'rigPositions', 'restError');
  const source = deformer.sourceVertex;
  if (!source) return null;
  const nRig = Math.floor(rigPositions.length / 3);
  deformer.deform(identitySkin(deformer.jointCount));
  const p = deformer.positions;
  let err = 0, any = false;
  for (let o = 0; o < source.length; o++) {
    const v = source[o];
    if (v >= nRig) continue;
    any = true;
    const dx = p[3 * o] - rigPositions[3 * v], dy = p[3 * o + 1] - rigPositions[3 * v + 1], dz = p[3 * o + 2] - rigPositions[3 * v + 2];
    const d = Math.sqrt(dx * dx + dy * dy + dz * dz);
    if (!(d <= err)) err = Number.isNaN(d) ? Infinity : d;
  }
  return any ? err : null;
}

/**
 * Largest extent of the bounding box of xyz positions.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function boundsHeight(positions: ArrayLike<number>): number {
  checkNumbers(positions, 'positions', 'boundsHeight');
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i + 2 < positions.length; i += 3)
    for (let c = 0; c < 3; c++) { lo[c] = Math.min(lo[c], positions[i + c]); hi[c] = Math.max(hi[c], positions[i + c]); }
  return Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}
