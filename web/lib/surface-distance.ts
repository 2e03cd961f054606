/**
 * Distance from points to a triangle mesh, through a uniform grid of the triangles' boxes: what
 * `classicOffSurface` (gcs-skin/measure) asks for every output vertex of every frame, and the closest
 * point (triangle, barycentrics) from which the classic model's resampled vertices take the source's
 * texture coordinates (`transferSurfaceAttributes`, gcs-skin/three). Rebuilt per frame (`build`),
 * queried per point; the buffers are kept between builds.
 */
export class TriangleGrid {
  private positions: ArrayLike<number> = [];
  private indices: ArrayLike<number> = [];
  private origin = [0, 0, 0];
  private cell = 1;
  private dims = [1, 1, 1];
  private cellStart = new Int32Array(0);
  private cellTriangles = new Int32Array(0);
  private stamp = new Int32Array(0);
  private query = 0;

  /**
   * Indexes the triangles of `positions` (xyz per vertex) / `indices`; `extra` (xyz) are points that
   * will be queried, so that the grid covers them too (a query outside the grid would stop early).
   */
  build(positions: ArrayLike<number>, indices: ArrayLike<number>, extra: ArrayLike<number> = []): void {
    this.positions = positions;
    this.indices = indices;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const p of [positions, extra])
      for (let i = 0; i + 2 < p.length; i += 3)
        for (let c = 0; c < 3; c++) {
          const x = p[i + c];
          if (!Number.isFinite(x)) continue;
          if (x < lo[c]) lo[c] = x;
          if (x > hi[c]) hi[c] = x;
        }
    const triCount = Math.floor(indices.length / 3);
    const size = [0, 1, 2].map((c) => Math.max(hi[c] - lo[c], 0));
    const extent = Math.max(size[0], size[1], size[2], 1e-30);
    // About two triangles per occupied cell on a surface: cells as wide as the mean edge, bounded.
    const cells = Math.max(8, Math.min(128, Math.round(Math.sqrt(triCount) / 2)));
    this.cell = extent / cells;
    this.origin = lo.map((x) => (Number.isFinite(x) ? x : 0));
    this.dims = size.map((s) => Math.max(1, Math.ceil(s / this.cell) + 1));
    const [nx, ny, nz] = this.dims;
    const count = new Int32Array(nx * ny * nz + 1);
    // Each triangle's range of cells (its box), once: x0 y0 z0 x1 y1 z1, x0 = -1 when not finite.
    const range = new Int32Array(6 * triCount);
    for (let t = 0; t < triCount; t++) {
      const a = 3 * indices[3 * t], b = 3 * indices[3 * t + 1], c = 3 * indices[3 * t + 2];
      for (let k = 0; k < 3; k++) {
        const mn = Math.min(positions[a + k], positions[b + k], positions[c + k]);
        const mx = Math.max(positions[a + k], positions[b + k], positions[c + k]);
        if (!Number.isFinite(mn) || !Number.isFinite(mx)) { range[6 * t] = -1; break; }
        range[6 * t + k] = this.clampCell(k, mn);
        range[6 * t + 3 + k] = this.clampCell(k, mx);
      }
    }
    // Two passes over the ranges: count the triangles per cell, then list them (cell by cell).
    for (let pass = 0; pass < 2; pass++) {
      if (pass === 1) {
        for (let i = 0; i < nx * ny * nz; i++) count[i + 1] += count[i];
        this.cellStart = count;
        this.cellTriangles = new Int32Array(count[nx * ny * nz]);
      }
      const cursor = pass === 1 ? count.slice(0, nx * ny * nz) : count;
      for (let t = 0; t < triCount; t++) {
        const r = 6 * t;
        if (range[r] < 0) continue;
        for (let z = range[r + 2]; z <= range[r + 5]; z++)
          for (let y = range[r + 1]; y <= range[r + 4]; y++)
            for (let x = range[r]; x <= range[r + 3]; x++) {
              const cell = (z * ny + y) * nx + x;
              if (pass === 0) count[cell + 1]++;
              else this.cellTriangles[cursor[cell]++] = t;
            }
      }
    }
    if (this.stamp.length < triCount) this.stamp = new Int32Array(triCount);
    this.stamp.fill(0);
    this.query = 0;
  }

  private clampCell(axis: number, x: number): number {
    return Math.min(this.dims[axis] - 1, Math.max(0, Math.floor((x - this.origin[axis]) / this.cell)));
  }

  /** Distance from (x, y, z) to the nearest indexed triangle (Infinity when there is none; NaN in: NaN out). */
  distance(x: number, y: number, z: number): number {
    return this.closest(x, y, z, this.scratch);
  }

  private readonly scratch: ClosestPoint = { triangle: -1, u: 0, v: 0, w: 0 };
  private readonly weights: ClosestPoint = { triangle: -1, u: 0, v: 0, w: 0 };

  /**
   * The nearest indexed triangle to (x, y, z) and the barycentric weights (of its corners a, b, c)
   * of the nearest point on it, written into `hit`; returns the distance (hit.triangle −1 and
   * Infinity when there is no triangle, NaN for a non-finite point).
   */
  closest(x: number, y: number, z: number, hit: ClosestPoint): number {
    hit.triangle = -1;
    if (!Number.isFinite(x) || !Number.isFinite(y) || !Number.isFinite(z)) return NaN;
    const [nx, ny, nz] = this.dims;
    const cx = this.clampCell(0, x), cy = this.clampCell(1, y), cz = this.clampCell(2, z);
    const q = ++this.query;
    let best = Infinity;
    const maxShell = Math.max(nx, ny, nz);
    // How far the point lies inside its own cell: its distance to the nearest face (0 outside).
    const [ox, oy, oz] = this.origin, cell = this.cell;
    const inside = Math.max(0, Math.min(x - (ox + cx * cell), ox + (cx + 1) * cell - x, y - (oy + cy * cell),
      oy + (cy + 1) * cell - y, z - (oz + cz * cell), oz + (cz + 1) * cell - z));
    for (let r = 0; r <= maxShell; r++) {
      // A triangle not seen yet has its box outside the cells scanned (those within r − 1 of the
      // point's): it lies at least (r − 1)·cell plus the point's depth in its own cell away. A
      // point on the surface (the classic model's rings) stops after its own cell.
      if (best <= (r - 1) * cell + inside) break;
      for (let k = cz - r; k <= cz + r; k++) {
        if (k < 0 || k >= nz) continue;
        for (let j = cy - r; j <= cy + r; j++) {
          if (j < 0 || j >= ny) continue;
          const onShellJK = Math.abs(k - cz) === r || Math.abs(j - cy) === r;
          for (let i = cx - r; i <= cx + r; i += onShellJK || r === 0 ? 1 : 2 * r) {
            if (i < 0 || i >= nx) continue;
            const cell = (k * ny + j) * nx + i;
            for (let s = this.cellStart[cell]; s < this.cellStart[cell + 1]; s++) {
              const t = this.cellTriangles[s];
              if (this.stamp[t] === q) continue;
              this.stamp[t] = q;
              const d = closestOnTriangle(this.positions, this.indices, t, x, y, z, this.weights);
              if (d < best) {
                best = d;
                hit.triangle = t; hit.u = this.weights.u; hit.v = this.weights.v; hit.w = this.weights.w;
              }
            }
          }
        }
      }
    }
    return best;
  }
}

/** A point on a triangle mesh: the triangle and the barycentric weights of its corners a, b, c. */
export interface ClosestPoint {
  triangle: number;
  u: number;
  v: number;
  w: number;
}

/**
 * Distance from (px, py, pz) to triangle t of positions P / indices I, in double, and the
 * barycentric weights of the closest point in `out` (by Voronoi regions, Ericson, Real-Time
 * Collision Detection 5.1.5; a degenerate triangle gives its first corner).
 */
export function closestOnTriangle(P: ArrayLike<number>, I: ArrayLike<number>, t: number, px: number, py: number, pz: number,
                                  out: ClosestPoint): number {
  const a = 3 * I[3 * t], b = 3 * I[3 * t + 1], c = 3 * I[3 * t + 2];
  const ax = P[a], ay = P[a + 1], az = P[a + 2];
  const abx = P[b] - ax, aby = P[b + 1] - ay, abz = P[b + 2] - az;
  const acx = P[c] - ax, acy = P[c + 1] - ay, acz = P[c + 2] - az;
  const apx = px - ax, apy = py - ay, apz = pz - az;
  const d1 = abx * apx + aby * apy + abz * apz, d2 = acx * apx + acy * apy + acz * apz;
  let v: number, w: number; // weights of b and c
  if (d1 <= 0 && d2 <= 0) { v = 0; w = 0; }
  else {
    const bpx = px - P[b], bpy = py - P[b + 1], bpz = pz - P[b + 2];
    const d3 = abx * bpx + aby * bpy + abz * bpz, d4 = acx * bpx + acy * bpy + acz * bpz;
    const cpx = px - P[c], cpy = py - P[c + 1], cpz = pz - P[c + 2];
    const d5 = abx * cpx + aby * cpy + abz * cpz, d6 = acx * cpx + acy * cpy + acz * cpz;
    const vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d3 >= 0 && d4 <= d3) { v = 1; w = 0; }
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) { v = d1 / (d1 - d3); w = 0; }
    else if (d6 >= 0 && d5 <= d6) { v = 0; w = 1; }
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) { v = 0; w = d2 / (d2 - d6); }
    else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) { w = (d4 - d3) / (d4 - d3 + (d5 - d6)); v = 1 - w; }
    else {
      const den = va + vb + vc;
      if (Math.abs(den) > 0) { v = vb / den; w = vc / den; }
      else { v = 0; w = 0; }
    }
  }
  out.u = 1 - v - w; out.v = v; out.w = w;
  return Math.hypot(apx - v * abx - w * acx, apy - v * aby - w * acy, apz - v * abz - w * acz);
}
