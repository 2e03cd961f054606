import { checkNumbers } from '../arguments.js';
/**
 * Pairs of triangles of a mesh that pass through each other: the skin of a bent joint folding into
 * itself. Triangles are binned in a uniform grid by their bounding boxes, and only pairs that share
 * a cell are tested (each pair once: in the first cell of their boxes' overlap), so the cost follows
 * the number of close pairs, not the square of the triangle count. Triangles that share a vertex
 * (after welding) touch by construction and are not tested; coplanar contact is not counted.
 */

/**
 * The crossing pairs, as keys a · T + b (a < b, T = the triangle count), sorted. `weld[v]`: one id
 * for every vertex at one rest position (measure's weldByPosition), so that triangles on either
 * side of a UV seam count as neighbours.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function intersectingPairs(positions: ArrayLike<number>, indices: ArrayLike<number>, weld: ArrayLike<number>): Float64Array {
  checkNumbers(positions, 'positions', 'intersectingPairs');
  checkNumbers(indices, 'indices', 'intersectingPairs');
  checkNumbers(weld, 'weld', 'intersectingPairs');
  const T = Math.floor(indices.length / 3);
  const box = new Float64Array(6 * T);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  const finite = new Uint8Array(T);
  let edgeSum = 0, boxes = 0;
  for (let t = 0; t < T; t++) {
    const a = 3 * indices[3 * t], b = 3 * indices[3 * t + 1], c = 3 * indices[3 * t + 2];
    let ok = true;
    for (let k = 0; k < 3; k++) {
      const mn = Math.min(positions[a + k], positions[b + k], positions[c + k]);
      const mx = Math.max(positions[a + k], positions[b + k], positions[c + k]);
      if (!Number.isFinite(mn) || !Number.isFinite(mx)) ok = false;
      box[6 * t + k] = mn; box[6 * t + 3 + k] = mx;
    }
    if (!ok) continue;
    finite[t] = 1;
    boxes++;
    for (let k = 0; k < 3; k++) {
      lo[k] = Math.min(lo[k], box[6 * t + k]); hi[k] = Math.max(hi[k], box[6 * t + 3 + k]);
      edgeSum += box[6 * t + 3 + k] - box[6 * t + k];
    }
  }
  if (boxes < 2) return new Float64Array(0);
  // Cells about a triangle's mean box side, but no more than four per triangle (a surface fills few
  // of a volume's cells: the empty ones cost memory and a pass).
  let cell = Math.max(edgeSum / (3 * boxes), 1e-30);
  const dimsFor = (s: number) => [0, 1, 2].map((k) => Math.max(1, Math.floor((hi[k] - lo[k]) / s) + 1));
  let dims = dimsFor(cell);
  while (dims[0] * dims[1] * dims[2] > 4 * boxes + 64) { cell *= 1.25; dims = dimsFor(cell); }
  const [nx, ny] = dims;
  const cellOf = (k: number, x: number) => Math.min(dims[k] - 1, Math.floor((x - lo[k]) / cell));
  const range = new Int32Array(6 * T);
  for (let t = 0; t < T; t++) {
    if (!finite[t]) continue;
    for (let k = 0; k < 3; k++) { range[6 * t + k] = cellOf(k, box[6 * t + k]); range[6 * t + 3 + k] = cellOf(k, box[6 * t + 3 + k]); }
  }
  // Each cell's triangles, by counting sort (start offsets, then the triangles in cell order).
  const cellCount = dims[0] * dims[1] * dims[2];
  const start = new Int32Array(cellCount + 1);
  const eachCell = (t: number, visit: (cell: number) => void) => {
    for (let z = range[6 * t + 2]; z <= range[6 * t + 5]; z++)
      for (let y = range[6 * t + 1]; y <= range[6 * t + 4]; y++)
        for (let x = range[6 * t]; x <= range[6 * t + 3]; x++) visit((z * ny + y) * nx + x);
  };
  for (let t = 0; t < T; t++) if (finite[t]) eachCell(t, (cell) => { start[cell + 1]++; });
  for (let i = 0; i < cellCount; i++) start[i + 1] += start[i];
  const members = new Int32Array(start[cellCount]);
  const cursor = start.slice(0, cellCount);
  for (let t = 0; t < T; t++) if (finite[t]) eachCell(t, (cell) => { members[cursor[cell]++] = t; });
  const found: number[] = [];
  for (let cell = 0; cell < cellCount; cell++) {
    const first = start[cell], last = start[cell + 1];
    if (last - first < 2) continue;
    const x = cell % nx, y = Math.floor(cell / nx) % ny, z = Math.floor(cell / (nx * ny));
    for (let i = first; i < last; i++) {
      const s = members[i];
      for (let j = i + 1; j < last; j++) {
        const t = members[j];
        // Test each pair once: in the first cell both boxes cover.
        if (x !== Math.max(range[6 * s], range[6 * t]) || y !== Math.max(range[6 * s + 1], range[6 * t + 1]) ||
            z !== Math.max(range[6 * s + 2], range[6 * t + 2])) continue;
        if (!boxesOverlap(box, s, t) || shareVertex(indices, weld, s, t)) continue;
        if (trianglesCross(positions, indices, s, t)) found.push(s < t ? s * T + t : t * T + s);
      }
    }
  }
  return Float64Array.from(found).sort();
}

function boxesOverlap(box: Float64Array, s: number, t: number): boolean {
  for (let k = 0; k < 3; k++) if (box[6 * s + k] > box[6 * t + 3 + k] || box[6 * t + k] > box[6 * s + 3 + k]) return false;
  return true;
}

function shareVertex(indices: ArrayLike<number>, weld: ArrayLike<number>, s: number, t: number): boolean {
  for (let i = 0; i < 3; i++) {
    const a = weld[indices[3 * s + i]];
    for (let j = 0; j < 3; j++) if (a === weld[indices[3 * t + j]]) return true;
  }
  return false;
}

/**
 * Two non-coplanar triangles cross when an edge of one passes through the other; first the cheap
 * rejection: all corners of one strictly on one side of the other's plane (Möller 1997).
 */
function trianglesCross(P: ArrayLike<number>, I: ArrayLike<number>, s: number, t: number): boolean {
  if (oneSide(P, I, s, t) || oneSide(P, I, t, s)) return false;
  for (let e = 0; e < 3; e++) {
    if (segmentHitsTriangle(P, I[3 * s + e], I[3 * s + ((e + 1) % 3)], I, t)) return true;
    if (segmentHitsTriangle(P, I[3 * t + e], I[3 * t + ((e + 1) % 3)], I, s)) return true;
  }
  return false;
}

/** Whether the corners of triangle s all lie strictly on one side of triangle t's plane. */
function oneSide(P: ArrayLike<number>, I: ArrayLike<number>, s: number, t: number): boolean {
  const a = 3 * I[3 * t], b = 3 * I[3 * t + 1], c = 3 * I[3 * t + 2];
  const ux = P[b] - P[a], uy = P[b + 1] - P[a + 1], uz = P[b + 2] - P[a + 2];
  const vx = P[c] - P[a], vy = P[c + 1] - P[a + 1], vz = P[c + 2] - P[a + 2];
  const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  let above = 0, below = 0;
  for (let k = 0; k < 3; k++) {
    const p = 3 * I[3 * s + k];
    const d = nx * (P[p] - P[a]) + ny * (P[p + 1] - P[a + 1]) + nz * (P[p + 2] - P[a + 2]);
    if (d > 0) above++; else if (d < 0) below++;
  }
  return above === 3 || below === 3;
}

/** Whether the segment from vertex p to vertex q passes through triangle t (Möller–Trumbore, parameter in [0, 1]). */
function segmentHitsTriangle(P: ArrayLike<number>, p: number, q: number, I: ArrayLike<number>, t: number): boolean {
  const a = 3 * I[3 * t], b = 3 * I[3 * t + 1], c = 3 * I[3 * t + 2];
  const ox = P[3 * p], oy = P[3 * p + 1], oz = P[3 * p + 2];
  const dx = P[3 * q] - ox, dy = P[3 * q + 1] - oy, dz = P[3 * q + 2] - oz;
  const e1x = P[b] - P[a], e1y = P[b + 1] - P[a + 1], e1z = P[b + 2] - P[a + 2];
  const e2x = P[c] - P[a], e2y = P[c + 1] - P[a + 1], e2z = P[c + 2] - P[a + 2];
  const hx = dy * e2z - dz * e2y, hy = dz * e2x - dx * e2z, hz = dx * e2y - dy * e2x;
  const det = e1x * hx + e1y * hy + e1z * hz;
  const scale = Math.hypot(e1x, e1y, e1z) * Math.hypot(e2x, e2y, e2z) * Math.hypot(dx, dy, dz);
  if (!(Math.abs(det) > 1e-12 * scale)) return false; // parallel (or degenerate)
  const f = 1 / det;
  const sx = ox - P[a], sy = oy - P[a + 1], sz = oz - P[a + 2];
  const u = f * (sx * hx + sy * hy + sz * hz);
  if (u < 0 || u > 1) return false;
  const qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
  const v = f * (dx * qx + dy * qy + dz * qz);
  if (v < 0 || u + v > 1) return false;
  const h = f * (e2x * qx + e2y * qy + e2z * qz);
  return h >= 0 && h <= 1;
}
