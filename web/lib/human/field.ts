// Signed distance (approximate) of the body: a smooth union (quadratic smooth-min, C¹) folded
// over each blend group's primitives, then over the groups. Fold steps that cannot matter in a
// region are skipped via a coarse acceleration grid without changing the function; the value
// at a point depends only on the point, which the polygoniser needs for a crack-free surface.
import { BodyModel, GROUP_K, PRIM_ELLIPSOID, TOP_K } from './model.js';

const ACCEL = 0.025;

export class BodyField {
  readonly n: number;
  readonly type: Uint8Array;
  readonly group: Uint8Array;
  readonly bone: Uint8Array;
  readonly P: Float64Array; // 16 params per primitive
  readonly ngroups: number;
  private readonly o: [number, number, number];
  private readonly dims: [number, number, number];
  private readonly lists: (Int32Array | undefined)[];
  private readonly progs: (Int32Array | undefined)[];
  private readonly scratch: Float64Array;

  constructor(model: BodyModel) {
    const prims = model.prims;
    this.n = prims.length;
    this.type = new Uint8Array(prims.map((p) => p.type));
    this.group = new Uint8Array(prims.map((p) => p.group));
    this.bone = new Uint8Array(prims.map((p) => p.bone));
    this.P = new Float64Array(this.n * 16);
    prims.forEach((p, i) => this.P.set(p.p, i * 16));
    this.ngroups = GROUP_K.length;

    const m = 0.1;
    this.o = [model.bboxMin[0] - m, model.bboxMin[1] - m, model.bboxMin[2] - m];
    this.dims = [0, 1, 2].map((a) => Math.ceil((model.bboxMax[a] + m - this.o[a]) / ACCEL)) as [number, number, number];
    const [dx, dy, dz] = this.dims;
    this.lists = new Array(dx * dy * dz);
    this.progs = new Array(dx * dy * dz);
    this.scratch = new Float64Array(this.n);
  }

  /** Primitives that can influence the value somewhere in accel cell c (built on first use). */
  private list(c: number): Int32Array {
    let l = this.lists[c];
    if (l) return l;
    const [dx, dy] = this.dims;
    const i = c % dx, j = Math.floor(c / dx) % dy, k = Math.floor(c / (dx * dy));
    const x = this.o[0] + (i + 0.5) * ACCEL, y = this.o[1] + (j + 0.5) * ACCEL, z = this.o[2] + (k + 0.5) * ACCEL;
    const d = this.scratch;
    let mn = Infinity;
    for (let p = 0; p < this.n; p++) { d[p] = this.prim(p, x, y, z); if (d[p] < mn) mn = d[p]; }
    // a primitive matters where it is within its blend radius of the nearest one; the
    // distances change by at most the half-diagonal across the cell (with slack for the
    // approximate ellipsoid distance)
    const half = (ACCEL * Math.sqrt(3)) / 2;
    const keep: number[] = [];
    for (let p = 0; p < this.n; p++) if (d[p] <= mn + 3 * half + GROUP_K[this.group[p]] + TOP_K) keep.push(p);
    l = Int32Array.from(keep);
    this.lists[c] = l;
    return l;
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

  /**
   * The evaluation program of accel cell c: the smooth union is a fixed left fold per group
   * (primitives in model order), then a fold over the groups. A fold step smin(acc, d) is
   * exactly acc when d ≥ acc + k (or exactly d when acc ≥ d + k), so using interval bounds over
   * the cell, steps that cannot matter are dropped without changing the function: the result
   * is the same C¹ function everywhere, only cheaper. Layout: [nGroups, (group, count, prims…)…].
   */
  private prog(c: number): Int32Array {
    let pr = this.progs[c];
    if (pr) return pr;
    const [dx, dy] = this.dims;
    const i = c % dx, j = Math.floor(c / dx) % dy, k = Math.floor(c / (dx * dy));
    const x = this.o[0] + (i + 0.5) * ACCEL, y = this.o[1] + (j + 0.5) * ACCEL, z = this.o[2] + (k + 0.5) * ACCEL;
    const slack = 1.5 * (ACCEL * Math.sqrt(3)) / 2;
    const groups: { g: number; lo: number; hi: number; prims: number[] }[] = [];
    for (let g = 0; g < this.ngroups; g++) {
      const kg = GROUP_K[g];
      let lo = Infinity, hi = Infinity;
      let kept: number[] = [];
      for (let p = 0; p < this.n; p++) {
        if (this.group[p] !== g) continue;
        const d = this.prim(p, x, y, z), plo = d - slack, phi = d + slack;
        if (kept.length === 0) { kept = [p]; lo = plo; hi = phi; }
        else if (plo >= hi + kg) continue;
        else if (lo >= phi + kg) { kept = [p]; lo = plo; hi = phi; }
        else { kept.push(p); lo = Math.min(lo, plo) - kg / 4; hi = Math.min(hi, phi); }
      }
      if (kept.length) groups.push({ g, lo, hi, prims: kept });
    }
    let kept: typeof groups = [];
    let lo = Infinity, hi = Infinity;
    for (const G of groups) {
      if (kept.length === 0) { kept = [G]; lo = G.lo; hi = G.hi; }
      else if (G.lo >= hi + TOP_K) continue;
      else if (lo >= G.hi + TOP_K) { kept = [G]; lo = G.lo; hi = G.hi; }
      else { kept.push(G); lo = Math.min(lo, G.lo) - TOP_K / 4; hi = Math.min(hi, G.hi); }
    }
    const out = [kept.length];
    for (const G of kept) out.push(G.g, G.prims.length, ...G.prims);
    pr = Int32Array.from(out);
    this.progs[c] = pr;
    return pr;
  }

  /** Signed distance of the body surface (negative inside). */
  eval(x: number, y: number, z: number): number {
    const P = this.prog(this.cell(x, y, z));
    let q = 0;
    const ng = P[q++];
    let top = 0;
    for (let gi = 0; gi < ng; gi++) {
      const g = P[q++], cnt = P[q++], k = GROUP_K[g];
      let acc = this.prim(P[q++], x, y, z);
      for (let r = 1; r < cnt; r++) {
        const d = this.prim(P[q++], x, y, z);
        const h = k - Math.abs(acc - d);
        acc = (acc < d ? acc : d) - (h > 0 ? (h * h) / (4 * k) : 0);
      }
      if (gi === 0) top = acc;
      else {
        const h = TOP_K - Math.abs(top - acc);
        top = (top < acc ? top : acc) - (h > 0 ? (h * h) / (4 * TOP_K) : 0);
      }
    }
    return top;
  }

  /** Distances of the primitives that can matter at a point (written to out[i]); returns their indices. */
  nearDistances(x: number, y: number, z: number, out: Float64Array): Int32Array {
    const L = this.list(this.cell(x, y, z));
    for (let q = 0; q < L.length; q++) out[L[q]] = this.prim(L[q], x, y, z);
    return L;
  }

  /** Per-primitive distances at a point (all primitives), written to out. */
  allDistances(x: number, y: number, z: number, out: Float64Array): void {
    for (let i = 0; i < this.n; i++) out[i] = this.prim(i, x, y, z);
  }
}
