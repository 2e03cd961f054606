// Signed distance (approximate) of the body: an order-independent n-ary smooth union per
// blend group, then between groups. Primitives that cannot influence a region are culled via
// a coarse acceleration grid; the value at a point depends only on the point (deterministic),
// which is what the polygoniser needs for a crack-free surface.
import { BodyModel, GROUP_K, PRIM_ELLIPSOID, TOP_K } from './model.js';

const ACCEL = 0.04;

export class BodyField {
  readonly n: number;
  readonly type: Uint8Array;
  readonly group: Uint8Array;
  readonly bone: Uint8Array;
  readonly P: Float64Array; // 16 params per primitive
  readonly ngroups: number;
  private readonly o: [number, number, number];
  private readonly dims: [number, number, number];
  private readonly cellStart: Int32Array;
  private readonly cellList: Int32Array;
  private readonly dist: Float64Array;
  private readonly gval: Float64Array;
  private readonly gmin: Float64Array;

  constructor(model: BodyModel) {
    const prims = model.prims;
    this.n = prims.length;
    this.type = new Uint8Array(prims.map((p) => p.type));
    this.group = new Uint8Array(prims.map((p) => p.group));
    this.bone = new Uint8Array(prims.map((p) => p.bone));
    this.P = new Float64Array(this.n * 16);
    prims.forEach((p, i) => this.P.set(p.p, i * 16));
    this.ngroups = GROUP_K.length;
    this.dist = new Float64Array(this.n);
    this.gval = new Float64Array(this.ngroups);
    this.gmin = new Float64Array(this.ngroups);

    const m = 0.1;
    this.o = [model.bboxMin[0] - m, model.bboxMin[1] - m, model.bboxMin[2] - m];
    this.dims = [0, 1, 2].map((a) => Math.ceil((model.bboxMax[a] + m - this.o[a]) / ACCEL)) as [number, number, number];
    const [dx, dy, dz] = this.dims;
    const ncell = dx * dy * dz;
    const lists: number[][] = [];
    const all = Array.from({ length: this.n }, (_, i) => i);
    const half = (ACCEL * Math.sqrt(3)) / 2;
    const kmax = Math.max(...GROUP_K) + TOP_K;
    const d = new Float64Array(this.n);
    for (let k = 0; k < dz; k++) for (let j = 0; j < dy; j++) for (let i = 0; i < dx; i++) {
      const x = this.o[0] + (i + 0.5) * ACCEL, y = this.o[1] + (j + 0.5) * ACCEL, z = this.o[2] + (k + 0.5) * ACCEL;
      let mn = Infinity;
      for (const p of all) { d[p] = this.prim(p, x, y, z); if (d[p] < mn) mn = d[p]; }
      // generous margin: the ellipsoid distance is only approximate away from its surface
      const keep = all.filter((p) => d[p] - 2 * half <= mn + 2 * half + 1.5 * kmax);
      lists.push(keep);
    }
    this.cellStart = new Int32Array(ncell + 1);
    let tot = 0;
    for (let c = 0; c < ncell; c++) { this.cellStart[c] = tot; tot += lists[c].length; }
    this.cellStart[ncell] = tot;
    this.cellList = new Int32Array(tot);
    for (let c = 0; c < ncell; c++) this.cellList.set(lists[c], this.cellStart[c]);
  }

  /** Distance to primitive i (approximate for ellipsoids). */
  prim(i: number, x: number, y: number, z: number): number {
    const P = this.P, b = i * 16;
    if (this.type[i] === PRIM_ELLIPSOID) {
      const px = x - P[b], py = y - P[b + 1], pz = z - P[b + 2];
      const lu = px * P[b + 3] + py * P[b + 4] + pz * P[b + 5];
      const lv = px * P[b + 6] + py * P[b + 7] + pz * P[b + 8];
      const lw = px * P[b + 9] + py * P[b + 10] + pz * P[b + 11];
      const ra = P[b + 12], rb = P[b + 13], rc = P[b + 14];
      const k0 = Math.sqrt((lu / ra) ** 2 + (lv / rb) ** 2 + (lw / rc) ** 2);
      const k1 = Math.sqrt((lu / (ra * ra)) ** 2 + (lv / (rb * rb)) ** 2 + (lw / (rc * rc)) ** 2);
      if (k1 < 1e-12) return -Math.min(ra, rb, rc);
      return (k0 * (k0 - 1)) / k1;
    }
    // round cone (Inigo Quilez, exact)
    const ax = P[b], ay = P[b + 1], az = P[b + 2];
    const bax = P[b + 3] - ax, bay = P[b + 4] - ay, baz = P[b + 5] - az;
    const r1 = P[b + 6], r2 = P[b + 7];
    const l2 = bax * bax + bay * bay + baz * baz;
    const rr = r1 - r2;
    const a2 = l2 - rr * rr;
    const il2 = 1 / l2;
    const pax = x - ax, pay = y - ay, paz = z - az;
    const yy = pax * bax + pay * bay + paz * baz;
    const zz = yy - l2;
    const qx = pax * l2 - bax * yy, qy = pay * l2 - bay * yy, qz = paz * l2 - baz * yy;
    const x2 = qx * qx + qy * qy + qz * qz;
    const y2 = yy * yy * l2;
    const z2 = zz * zz * l2;
    const k = Math.sign(rr) * rr * rr * x2;
    if (Math.sign(zz) * a2 * z2 > k) return Math.sqrt(x2 + z2) * il2 - r2;
    if (Math.sign(yy) * a2 * y2 < k) return Math.sqrt(x2 + y2) * il2 - r1;
    return (Math.sqrt(x2 * a2 * il2) + yy * rr) * il2 - r1;
  }

  private cell(x: number, y: number, z: number): number {
    const [dx, dy, dz] = this.dims;
    let i = Math.floor((x - this.o[0]) / ACCEL), j = Math.floor((y - this.o[1]) / ACCEL), k = Math.floor((z - this.o[2]) / ACCEL);
    i = i < 0 ? 0 : i >= dx ? dx - 1 : i;
    j = j < 0 ? 0 : j >= dy ? dy - 1 : j;
    k = k < 0 ? 0 : k >= dz ? dz - 1 : k;
    return i + dx * (j + dy * k);
  }

  /** Signed distance of the body surface (negative inside). */
  eval(x: number, y: number, z: number): number {
    const c = this.cell(x, y, z);
    const s = this.cellStart[c], e = this.cellStart[c + 1];
    const L = this.cellList, dist = this.dist, grp = this.group, gmin = this.gmin, gval = this.gval;
    gmin.fill(Infinity);
    for (let q = s; q < e; q++) {
      const i = L[q];
      const d = this.prim(i, x, y, z);
      dist[i] = d;
      if (d < gmin[grp[i]]) gmin[grp[i]] = d;
    }
    gval.fill(0);
    for (let q = s; q < e; q++) {
      const i = L[q], g = grp[i], k = GROUP_K[g];
      const h = 1 - (dist[i] - gmin[g]) / k;
      if (h > 0) gval[g] += h * h * (k / 4);
    }
    let top = Infinity;
    for (let g = 0; g < this.ngroups; g++) {
      if (gmin[g] === Infinity) continue;
      gval[g] = gmin[g] - (gval[g] - GROUP_K[g] / 4);
      if (gval[g] < top) top = gval[g];
    }
    let acc = 0;
    for (let g = 0; g < this.ngroups; g++) {
      if (gmin[g] === Infinity) continue;
      const h = 1 - (gval[g] - top) / TOP_K;
      if (h > 0) acc += h * h * (TOP_K / 4);
    }
    return top - (acc - TOP_K / 4);
  }

  /** Per-primitive distances at a point (all primitives), written to out. */
  allDistances(x: number, y: number, z: number, out: Float64Array): void {
    for (let i = 0; i < this.n; i++) out[i] = this.prim(i, x, y, z);
  }
}
