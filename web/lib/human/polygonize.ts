// Marching tetrahedra on a rectilinear (per-axis warped) grid, evaluated only in blocks near
// the surface. The Freudenthal split (6 tetrahedra around the cube diagonal) is translation
// invariant, so neighbouring cells agree on shared faces: the output is a closed,
// edge-manifold, consistently oriented (outward) triangle mesh with shared vertices.

export type ScalarField = (x: number, y: number, z: number) => number;

const TETS: number[][] = [];
// TRI_TABLE[tet*16+mask] = flat list of edges (pairs of cube corners) forming triangles
const TRI_TABLE: number[][] = [];
{
  const perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
  for (const [a, b] of perms) TETS.push([0, 1 << a, (1 << a) | (1 << b), 7]);
  const pos = (c: number) => [c & 1, (c >> 1) & 1, (c >> 2) & 1];
  const mid = (e: number[]) => { const p = pos(e[0]), q = pos(e[1]); return [0, 1, 2].map((i) => (p[i] + q[i]) / 2); };
  for (const tet of TETS) {
    for (let mask = 0; mask < 16; mask++) {
      const ins = [0, 1, 2, 3].filter((i) => mask & (1 << i)).map((i) => tet[i]);
      const out = [0, 1, 2, 3].filter((i) => !(mask & (1 << i))).map((i) => tet[i]);
      const tris: number[][][] = [];
      if (ins.length === 1) tris.push(out.map((o) => [ins[0], o]));
      else if (ins.length === 3) tris.push(ins.map((i) => [i, out[0]]));
      else if (ins.length === 2) {
        const [a, b] = ins, [c, d] = out;
        tris.push([[a, c], [a, d], [b, d]], [[a, c], [b, d], [b, c]]);
      }
      const flat: number[] = [];
      const ci = [0, 0, 0], co = [0, 0, 0];
      for (const i of ins) pos(i).forEach((v, k) => (ci[k] += v / ins.length));
      for (const o of out) pos(o).forEach((v, k) => (co[k] += v / out.length));
      const dir = [0, 1, 2].map((k) => co[k] - ci[k]);
      for (const t of tris) {
        const [p0, p1, p2] = t.map(mid);
        const e1 = [0, 1, 2].map((k) => p1[k] - p0[k]), e2 = [0, 1, 2].map((k) => p2[k] - p0[k]);
        const n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        const dot = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
        const tt = dot < 0 ? [t[0], t[2], t[1]] : t;
        for (const e of tt) flat.push(Math.min(e[0], e[1]), Math.max(e[0], e[1]));
      }
      TRI_TABLE.push(flat);
    }
  }
}

export interface PolyResult {
  positions: Float64Array;
  indices: Uint32Array;
  vertexCount: number;
}

const B = 8;

/** Grid coordinates from a spacing function: x_{i+1} = x_i + h(x_i). */
export function gridAxis(lo: number, hi: number, h: (x: number) => number): Float64Array {
  const xs: number[] = [lo];
  let x = lo;
  while (x < hi) { x += h(x); xs.push(x); }
  return Float64Array.from(xs);
}

export function polygonize(f: ScalarField, xs: Float64Array, ys: Float64Array, zs: Float64Array): PolyResult {
  const nx = xs.length, ny = ys.length, nz = zs.length;
  const cx = nx - 1, cy = ny - 1, cz = nz - 1;
  const bx = Math.ceil(cx / B), by = Math.ceil(cy / B), bz = Math.ceil(cz / B);
  // open-addressing hash: grid-edge key → vertex index
  let hcap = 1 << 16;
  let hkeys = new Float64Array(hcap).fill(-1);
  let hvals = new Int32Array(hcap);
  const slot = (key: number, keys: Float64Array, cap: number) => {
    const lo = key % 4294967296, hi = (key - lo) / 4294967296;
    let h = (Math.imul(lo | 0, 0x9e3779b1) ^ Math.imul(hi | 0, 0x85ebca6b)) & (cap - 1);
    while (keys[h] !== -1 && keys[h] !== key) h = (h + 1) & (cap - 1);
    return h;
  };
  let pos = new Float64Array(3 * 65536);
  let nv = 0;
  let idx = new Uint32Array(6 * 65536);
  let nt = 0;
  const vals = new Float64Array((B + 1) ** 3);
  const S1 = B + 1, S2 = (B + 1) * (B + 1);
  const cornerOff = [0, 1, S1, S1 + 1, S2, S2 + 1, S2 + S1, S2 + S1 + 1];
  const cv = new Float64Array(8);
  const gOff = [0, 1, nx, nx + 1, nx * ny, nx * ny + 1, nx * ny + nx, nx * ny + nx + 1];

  for (let bk = 0; bk < bz; bk++) for (let bj = 0; bj < by; bj++) for (let bi = 0; bi < bx; bi++) {
    const i0 = bi * B, j0 = bj * B, k0 = bk * B;
    const i1 = Math.min(i0 + B, cx), j1 = Math.min(j0 + B, cy), k1 = Math.min(k0 + B, cz);
    const mx = (xs[i0] + xs[i1]) / 2, my = (ys[j0] + ys[j1]) / 2, mz = (zs[k0] + zs[k1]) / 2;
    const hd = 0.5 * Math.hypot(xs[i1] - xs[i0], ys[j1] - ys[j0], zs[k1] - zs[k0]);
    const fc = f(mx, my, mz);
    // no surface in the block if |f| at its centre exceeds the half-diagonal (f is about 1-Lipschitz; 1.5 for slack)
    if (Math.abs(fc) > 1.5 * hd + 0.003) continue;
    // sample block corners
    for (let k = k0; k <= k1; k++) for (let j = j0; j <= j1; j++) for (let i = i0; i <= i1; i++) {
      let v = f(xs[i], ys[j], zs[k]);
      if (v === 0) v = 1e-12;
      vals[(i - i0) + S1 * (j - j0) + S2 * (k - k0)] = v;
    }
    for (let k = k0; k < k1; k++) for (let j = j0; j < j1; j++) for (let i = i0; i < i1; i++) {
      const l = (i - i0) + S1 * (j - j0) + S2 * (k - k0);
      let cmask = 0;
      for (let c = 0; c < 8; c++) { const v = vals[l + cornerOff[c]]; cv[c] = v; if (v < 0) cmask |= 1 << c; }
      if (cmask === 0 || cmask === 255) continue;
      const g = i + nx * (j + ny * k);
      for (let t = 0; t < 6; t++) {
        const tet = TETS[t];
        let m = 0;
        for (let q = 0; q < 4; q++) if (cmask & (1 << tet[q])) m |= 1 << q;
        if (m === 0 || m === 15) continue;
        const tab = TRI_TABLE[t * 16 + m];
        for (let e = 0; e < tab.length; e += 2) {
          const ca = tab[e], cb = tab[e + 1];
          const key = (g + gOff[ca]) * 8 + (ca ^ cb);
          let hs = slot(key, hkeys, hcap);
          let vi: number;
          if (hkeys[hs] === key) vi = hvals[hs];
          else {
            vi = nv++;
            if (2 * nv > hcap) {
              const ok = hkeys, ov = hvals;
              hcap *= 2;
              hkeys = new Float64Array(hcap).fill(-1);
              hvals = new Int32Array(hcap);
              for (let q = 0; q < ok.length; q++) if (ok[q] !== -1) { const z = slot(ok[q], hkeys, hcap); hkeys[z] = ok[q]; hvals[z] = ov[q]; }
              hs = slot(key, hkeys, hcap);
            }
            hkeys[hs] = key; hvals[hs] = vi;
            if (3 * nv > pos.length) { const np = new Float64Array(pos.length * 2); np.set(pos); pos = np; }
            const va = cv[ca], vb = cv[cb];
            let s = va / (va - vb);
            s = s < 0.02 ? 0.02 : s > 0.98 ? 0.98 : s;
            const ax = xs[i + (ca & 1)], ay = ys[j + ((ca >> 1) & 1)], az = zs[k + ((ca >> 2) & 1)];
            const bx2 = xs[i + (cb & 1)], by2 = ys[j + ((cb >> 1) & 1)], bz2 = zs[k + ((cb >> 2) & 1)];
            pos[3 * vi] = ax + s * (bx2 - ax);
            pos[3 * vi + 1] = ay + s * (by2 - ay);
            pos[3 * vi + 2] = az + s * (bz2 - az);
          }
          if (nt >= idx.length) { const ni = new Uint32Array(idx.length * 2); ni.set(idx); idx = ni; }
          idx[nt++] = vi;
        }
      }
    }
  }
  return { positions: pos.slice(0, 3 * nv), indices: idx.slice(0, nt), vertexCount: nv };
}

/** Keep only the largest connected piece (thin parts can leave islands on coarse grids). */
export function largestComponent(r: PolyResult): PolyResult {
  const nv = r.vertexCount, idx = r.indices;
  const par = new Int32Array(nv).map((_, i) => i);
  const find = (a: number): number => { while (par[a] !== a) { par[a] = par[par[a]]; a = par[a]; } return a; };
  for (let t = 0; t < idx.length; t += 3) {
    let a = find(idx[t]), b = find(idx[t + 1]);
    if (a !== b) par[a] = b;
    a = find(idx[t + 1]); b = find(idx[t + 2]);
    if (a !== b) par[a] = b;
  }
  const size = new Int32Array(nv);
  for (let v = 0; v < nv; v++) size[find(v)]++;
  let best = 0;
  for (let v = 0; v < nv; v++) if (size[v] > size[best]) best = v;
  if (size[best] === nv) return r;
  const map = new Int32Array(nv).fill(-1);
  let n = 0;
  const pos = new Float64Array(3 * size[best]);
  for (let v = 0; v < nv; v++) if (find(v) === best) { map[v] = n; pos.set(r.positions.subarray(3 * v, 3 * v + 3), 3 * n); n++; }
  const out: number[] = [];
  for (let t = 0; t < idx.length; t += 3) if (map[idx[t]] >= 0) out.push(map[idx[t]], map[idx[t + 1]], map[idx[t + 2]]);
  return { positions: pos, indices: Uint32Array.from(out), vertexCount: n };
}
