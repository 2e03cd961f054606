// The classic model resamples the skin into contours × rays, so its vertices are new points with
// no texture coordinates or vertex colours. To draw it with the character's own material, each
// resampled vertex takes the attributes of the closest point of the source surface in the bind
// pose (barycentric interpolation on the closest triangle, found through a uniform grid).
// Where a resampled triangle straddles a UV seam the texture is smeared across it: the resampled
// mesh has no seams to split along.
import * as THREE from 'three';

type AnyAttribute = THREE.BufferAttribute | THREE.InterleavedBufferAttribute;

/** Attributes a material reads that a resampled mesh lacks: uv channels of its textures, vertex colours. */
export function attributesNeeded(material: THREE.Material | THREE.Material[]): string[] {
  const names = new Set<string>();
  for (const m of Array.isArray(material) ? material : [material]) {
    if (!m) continue;
    for (const value of Object.values(m)) {
      const t = value as THREE.Texture;
      if (t?.isTexture && !(t as THREE.CubeTexture).isCubeTexture) names.add(t.channel ? `uv${t.channel}` : 'uv');
    }
    if (m.vertexColors) names.add('color');
  }
  return [...names];
}

/**
 * Adds to `target` (restPositions: its vertices in the source's bind-pose mesh space) the
 * attributes `names` of `source`: a vertex that copies a source vertex (`sourceOf[o] >= 0`: the
 * classic model's carried skin) takes that vertex's values, so its texture seams stay sharp; each
 * resampled vertex takes the values at the closest point of the source's triangles. Attributes the
 * source lacks, or the target has, are skipped. Returns the names added.
 */
export function transferAttributes(source: THREE.BufferGeometry, target: THREE.BufferGeometry, restPositions: ArrayLike<number>, names: string[], sourceOf?: ArrayLike<number>): string[] {
  const attrs = names
    .filter((n) => source.getAttribute(n) && !target.getAttribute(n))
    .map((n) => ({ name: n, attr: source.getAttribute(n) as AnyAttribute }))
    .filter((a) => a.attr.itemSize <= 4);
  if (!attrs.length) return [];
  const pos = source.getAttribute('position') as AnyAttribute;
  const P = new Float32Array(pos.count * 3);
  for (let i = 0; i < pos.count; i++) { P[3 * i] = pos.getX(i); P[3 * i + 1] = pos.getY(i); P[3 * i + 2] = pos.getZ(i); }
  const index = source.index;
  const triCount = Math.floor((index ? index.count : pos.count) / 3);
  const T = new Uint32Array(triCount * 3);
  for (let i = 0; i < T.length; i++) T[i] = index ? index.getX(i) : i;
  const grid = new TriangleGrid(P, T);

  const n = restPositions.length / 3;
  const outs = attrs.map((a) => ({ ...a, out: new Float32Array(n * a.attr.itemSize) }));
  const hit = { tri: -1, u: 0, v: 0, w: 0 };
  for (let o = 0; o < n; o++) {
    const copy = sourceOf ? sourceOf[o] : -1;
    if (copy >= 0) {
      for (const { attr, out } of outs) for (let k = 0; k < attr.itemSize; k++) out[o * attr.itemSize + k] = attr.getComponent(copy, k);
      continue;
    }
    grid.closest(restPositions[3 * o], restPositions[3 * o + 1], restPositions[3 * o + 2], hit);
    if (hit.tri < 0) continue;
    const a = T[3 * hit.tri], b = T[3 * hit.tri + 1], c = T[3 * hit.tri + 2];
    for (const { attr, out } of outs) {
      const size = attr.itemSize;
      for (let k = 0; k < size; k++)
        out[o * size + k] = hit.u * attr.getComponent(a, k) + hit.v * attr.getComponent(b, k) + hit.w * attr.getComponent(c, k);
    }
  }
  for (const { name, attr, out } of outs) target.setAttribute(name, new THREE.BufferAttribute(out, attr.itemSize));
  return outs.map((a) => a.name);
}

/** Triangles bucketed in a uniform grid by their bounding boxes; closest-point queries by growing shells of cells. */
class TriangleGrid {
  private readonly min = [0, 0, 0];
  private readonly dims = [1, 1, 1];
  private readonly cell: number;
  private readonly start: Uint32Array;
  private readonly items: Uint32Array;
  private readonly point = { x: 0, y: 0, z: 0, u: 0, v: 0, w: 0 };

  constructor(private readonly P: Float32Array, private readonly T: Uint32Array) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < P.length; i += 3) for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], P[i + k]); hi[k] = Math.max(hi[k], P[i + k]); }
    const tris = T.length / 3;
    const extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-9);
    // Cells a little larger than a triangle: about tris / 2 cells if the box were a cube.
    const target = Math.max(1, Math.cbrt(tris / 2));
    this.cell = extent / Math.min(128, Math.max(1, Math.round(target)));
    for (let k = 0; k < 3; k++) {
      this.min[k] = lo[k];
      this.dims[k] = Math.max(1, Math.min(256, Math.ceil((hi[k] - lo[k]) / this.cell) + 1));
    }
    const cellCount = this.dims[0] * this.dims[1] * this.dims[2];
    const counts = new Uint32Array(cellCount + 1);
    const range = (t: number, visit: (c: number) => void) => {
      const a = [Infinity, Infinity, Infinity], b = [-Infinity, -Infinity, -Infinity];
      for (let j = 0; j < 3; j++) {
        const v = T[3 * t + j];
        for (let k = 0; k < 3; k++) { a[k] = Math.min(a[k], P[3 * v + k]); b[k] = Math.max(b[k], P[3 * v + k]); }
      }
      const c0 = a.map((x, k) => this.clampCell(x, k)), c1 = b.map((x, k) => this.clampCell(x, k));
      for (let z = c0[2]; z <= c1[2]; z++)
        for (let y = c0[1]; y <= c1[1]; y++)
          for (let x = c0[0]; x <= c1[0]; x++) visit(x + this.dims[0] * (y + this.dims[1] * z));
    };
    for (let t = 0; t < tris; t++) range(t, (c) => { counts[c + 1]++; });
    for (let c = 0; c < cellCount; c++) counts[c + 1] += counts[c];
    this.start = counts.slice();
    const fill = counts.slice();
    this.items = new Uint32Array(counts[cellCount]);
    for (let t = 0; t < tris; t++) range(t, (c) => { this.items[fill[c]++] = t; });
  }

  private clampCell(x: number, k: number): number {
    return Math.max(0, Math.min(this.dims[k] - 1, Math.floor((x - this.min[k]) / this.cell)));
  }

  /** The closest triangle to (x, y, z) and the barycentric weights of the closest point on it. */
  closest(x: number, y: number, z: number, hit: { tri: number; u: number; v: number; w: number }): void {
    const c = [this.clampCell(x, 0), this.clampCell(y, 1), this.clampCell(z, 2)];
    let best = Infinity;
    hit.tri = -1;
    const maxShell = Math.max(...this.dims);
    const seen = new Set<number>();
    for (let s = 0; s <= maxShell; s++) {
      for (let dz = -s; dz <= s; dz++) {
        const cz = c[2] + dz;
        if (cz < 0 || cz >= this.dims[2]) continue;
        for (let dy = -s; dy <= s; dy++) {
          const cy = c[1] + dy;
          if (cy < 0 || cy >= this.dims[1]) continue;
          for (let dx = -s; dx <= s; dx++) {
            if (Math.max(Math.abs(dx), Math.abs(dy), Math.abs(dz)) !== s) continue; // the shell only
            const cx = c[0] + dx;
            if (cx < 0 || cx >= this.dims[0]) continue;
            const cell = cx + this.dims[0] * (cy + this.dims[1] * cz);
            for (let i = this.start[cell]; i < this.start[cell + 1]; i++) {
              const t = this.items[i];
              if (seen.has(t)) continue;
              seen.add(t);
              const d = this.closestOnTriangle(t, x, y, z);
              if (d < best) { best = d; hit.tri = t; hit.u = this.point.u; hit.v = this.point.v; hit.w = this.point.w; }
            }
          }
        }
      }
      // Every triangle not yet seen lies outside the shells 0..s, at least s·cell away.
      if (hit.tri >= 0 && Math.sqrt(best) <= s * this.cell) return;
    }
  }

  /** Squared distance from p to triangle t; the closest point's barycentrics in this.point (Ericson, RTCD 5.1.5). */
  private closestOnTriangle(t: number, px: number, py: number, pz: number): number {
    const P = this.P, T = this.T, q = this.point;
    const a = 3 * T[3 * t], b = 3 * T[3 * t + 1], c = 3 * T[3 * t + 2];
    const ax = P[a], ay = P[a + 1], az = P[a + 2];
    const abx = P[b] - ax, aby = P[b + 1] - ay, abz = P[b + 2] - az;
    const acx = P[c] - ax, acy = P[c + 1] - ay, acz = P[c + 2] - az;
    const apx = px - ax, apy = py - ay, apz = pz - az;
    const d1 = abx * apx + aby * apy + abz * apz, d2 = acx * apx + acy * apy + acz * apz;
    let u: number, v: number, w: number; // weights of a, b, c
    if (d1 <= 0 && d2 <= 0) { u = 1; v = 0; w = 0; }
    else {
      const bpx = px - P[b], bpy = py - P[b + 1], bpz = pz - P[b + 2];
      const d3 = abx * bpx + aby * bpy + abz * bpz, d4 = acx * bpx + acy * bpy + acz * bpz;
      const cpx = px - P[c], cpy = py - P[c + 1], cpz = pz - P[c + 2];
      const d5 = abx * cpx + aby * cpy + abz * cpz, d6 = acx * cpx + acy * cpy + acz * cpz;
      const vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
      if (d3 >= 0 && d4 <= d3) { u = 0; v = 1; w = 0; }
      else if (vc <= 0 && d1 >= 0 && d3 <= 0) { const s = d1 / (d1 - d3); u = 1 - s; v = s; w = 0; }
      else if (d6 >= 0 && d5 <= d6) { u = 0; v = 0; w = 1; }
      else if (vb <= 0 && d2 >= 0 && d6 <= 0) { const s = d2 / (d2 - d6); u = 1 - s; v = 0; w = s; }
      else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) { const s = (d4 - d3) / ((d4 - d3) + (d5 - d6)); u = 0; v = 1 - s; w = s; }
      else {
        const den = va + vb + vc;
        if (!(Math.abs(den) > 0)) { u = 1; v = 0; w = 0; } // degenerate triangle: its first corner
        else { v = vb / den; w = vc / den; u = 1 - v - w; }
      }
    }
    q.u = u; q.v = v; q.w = w;
    const x = ax + v * abx + w * acx - px, y = ay + v * aby + w * acy - py, z = az + v * abz + w * acz - pz;
    return x * x + y * y + z * z;
  }
}
