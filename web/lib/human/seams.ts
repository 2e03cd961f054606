// UV charts and seams. The surface is cut into charts (connected pieces of the surface inside
// the cells of a 3D grid, box-projected onto their dominant axis and packed into one atlas);
// vertices on chart borders are duplicated, as in any textured game mesh. The cell size is
// chosen so that the number of duplicates matches a target: this is how the default model
// reproduces the paper's 17,023 vertices with 31,235 triangles (a closed genus-0 surface
// has T = 2·V_unique − 4, so its ~1,400 extra vertices must be seam copies).

export interface SeamResult {
  /** for each output vertex, the welded (unique-position) vertex it copies */
  weld: Uint32Array;
  indices: Uint32Array;
  uvs: Float32Array;
  charts: number;
}

function vertexTriangles(idx: Uint32Array, nv: number) {
  const start = new Uint32Array(nv + 1);
  for (let i = 0; i < idx.length; i++) start[idx[i] + 1]++;
  for (let v = 0; v < nv; v++) start[v + 1] += start[v];
  const fill = start.slice(0, nv);
  const list = new Uint32Array(idx.length);
  for (let i = 0; i < idx.length; i++) list[fill[idx[i]]++] = (i / 3) | 0;
  return { start, list };
}

function cellKeys(pos: Float64Array, idx: Uint32Array, size: number): Float64Array {
  const nt = idx.length / 3;
  const keys = new Float64Array(nt);
  for (let t = 0; t < nt; t++) {
    const a = 3 * idx[3 * t], b = 3 * idx[3 * t + 1], c = 3 * idx[3 * t + 2];
    const x = Math.floor((pos[a] + pos[b] + pos[c]) / 3 / size + 0.37);
    const y = Math.floor((pos[a + 1] + pos[b + 1] + pos[c + 1]) / 3 / size + 0.21);
    const z = Math.floor((pos[a + 2] + pos[b + 2] + pos[c + 2]) / 3 / size + 0.43);
    keys[t] = (x + 512) * 1048576 + (y + 512) * 1024 + (z + 512);
  }
  return keys;
}

function countCopies(keys: Float64Array, vt: { start: Uint32Array; list: Uint32Array }, nv: number): number {
  let dup = 0;
  const seen: number[] = [];
  for (let v = 0; v < nv; v++) {
    seen.length = 0;
    for (let q = vt.start[v]; q < vt.start[v + 1]; q++) {
      const k = keys[vt.list[q]];
      if (!seen.includes(k)) seen.push(k);
    }
    dup += seen.length - 1;
  }
  return dup;
}

export function cutSeams(pos: Float64Array, idx: Uint32Array, targetDuplicates: number): SeamResult {
  const nv = pos.length / 3, nt = idx.length / 3;
  const vt = vertexTriangles(idx, nv);
  let keys: Float64Array;
  if (targetDuplicates <= 0) {
    keys = new Float64Array(nt);
  } else {
    // duplicates fall roughly as 1/size: secant steps on log–log, then bisection if needed
    const tol = Math.max(2, 0.01 * targetDuplicates);
    let lo = Math.log(0.005), hi = Math.log(4);
    let x = Math.log(0.3), found = false;
    for (let it = 0; it < 30 && !found; it++) {
      const d = countCopies(cellKeys(pos, idx, Math.exp(x)), vt, nv);
      if (Math.abs(d - targetDuplicates) <= tol) { found = true; break; }
      if (d > targetDuplicates) lo = Math.max(lo, x); else hi = Math.min(hi, x);
      const next = it < 6 && d > 0 ? x + Math.log(d / targetDuplicates) : (lo + hi) / 2;
      x = next > lo && next < hi ? next : (lo + hi) / 2;
    }
    keys = cellKeys(pos, idx, Math.exp(x));
  }

  // charts: connected components of triangles sharing an edge and a cell
  const parent = new Int32Array(nt).map((_, i) => i);
  const find = (a: number): number => { while (parent[a] !== a) { parent[a] = parent[parent[a]]; a = parent[a]; } return a; };
  for (let v = 0; v < nv; v++) {
    const s = vt.start[v], e = vt.start[v + 1];
    for (let p = s; p < e; p++) for (let q = p + 1; q < e; q++) {
      const ta = vt.list[p], tb = vt.list[q];
      if (keys[ta] !== keys[tb]) continue;
      // share an edge? (two common vertices)
      let common = 0;
      for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) if (idx[3 * ta + i] === idx[3 * tb + j]) common++;
      if (common >= 2) { const ra = find(ta), rb = find(tb); if (ra !== rb) parent[ra] = rb; }
    }
  }
  const chartOf = new Int32Array(nt);
  const chartId = new Map<number, number>();
  for (let t = 0; t < nt; t++) {
    const r = find(t);
    let c = chartId.get(r);
    if (c === undefined) { c = chartId.size; chartId.set(r, c); }
    chartOf[t] = c;
  }
  const nc = chartId.size;

  // split vertices per chart
  const weld: number[] = [];
  const out = new Uint32Array(idx.length);
  const local = new Map<number, number>();
  for (let v = 0; v < nv; v++) {
    local.clear();
    for (let q = vt.start[v]; q < vt.start[v + 1]; q++) {
      const t = vt.list[q], c = chartOf[t];
      let nvid = local.get(c);
      if (nvid === undefined) { nvid = weld.length; weld.push(v); local.set(c, nvid); }
      for (let i = 0; i < 3; i++) if (idx[3 * t + i] === v) out[3 * t + i] = nvid;
    }
  }
  const weldArr = Uint32Array.from(weld);
  const nout = weldArr.length;

  // per-chart box projection
  const nrm = new Float64Array(nc * 3);
  for (let t = 0; t < nt; t++) {
    const a = 3 * idx[3 * t], b = 3 * idx[3 * t + 1], c = 3 * idx[3 * t + 2];
    const e1 = [pos[b] - pos[a], pos[b + 1] - pos[a + 1], pos[b + 2] - pos[a + 2]];
    const e2 = [pos[c] - pos[a], pos[c + 1] - pos[a + 1], pos[c + 2] - pos[a + 2]];
    const ch = chartOf[t];
    nrm[3 * ch] += e1[1] * e2[2] - e1[2] * e2[1];
    nrm[3 * ch + 1] += e1[2] * e2[0] - e1[0] * e2[2];
    nrm[3 * ch + 2] += e1[0] * e2[1] - e1[1] * e2[0];
  }
  const chartOfVertex = new Int32Array(nout);
  for (let t = 0; t < nt; t++) for (let i = 0; i < 3; i++) chartOfVertex[out[3 * t + i]] = chartOf[t];
  const uv = new Float64Array(nout * 2);
  const bb = new Float64Array(nc * 4).fill(NaN);
  for (let c = 0; c < nc; c++) { bb[4 * c] = bb[4 * c + 1] = Infinity; bb[4 * c + 2] = bb[4 * c + 3] = -Infinity; }
  for (let v = 0; v < nout; v++) {
    const c = chartOfVertex[v], w = weldArr[v];
    const n = [nrm[3 * c], nrm[3 * c + 1], nrm[3 * c + 2]];
    const ax = Math.abs(n[0]) >= Math.abs(n[1]) && Math.abs(n[0]) >= Math.abs(n[2]) ? 0 : Math.abs(n[1]) >= Math.abs(n[2]) ? 1 : 2;
    const sgn = n[ax] >= 0 ? 1 : -1;
    const p = [pos[3 * w], pos[3 * w + 1], pos[3 * w + 2]];
    let u: number, vv: number;
    if (ax === 0) { u = -sgn * p[2]; vv = p[1]; } else if (ax === 1) { u = p[0]; vv = -sgn * p[2]; } else { u = sgn * p[0]; vv = p[1]; }
    uv[2 * v] = u; uv[2 * v + 1] = vv;
    bb[4 * c] = Math.min(bb[4 * c], u); bb[4 * c + 1] = Math.min(bb[4 * c + 1], vv);
    bb[4 * c + 2] = Math.max(bb[4 * c + 2], u); bb[4 * c + 3] = Math.max(bb[4 * c + 3], vv);
  }
  // shelf packing, tallest first
  const order = Array.from({ length: nc }, (_, c) => c).sort((a, b) => (bb[4 * b + 3] - bb[4 * b + 1]) - (bb[4 * a + 3] - bb[4 * a + 1]));
  let area = 0;
  for (let c = 0; c < nc; c++) area += (bb[4 * c + 2] - bb[4 * c] + 0.01) * (bb[4 * c + 3] - bb[4 * c + 1] + 0.01);
  const width = Math.sqrt(area) * 1.15;
  const off = new Float64Array(nc * 2);
  let x = 0, y = 0, rowH = 0, maxX = 0;
  const pad = 0.005;
  for (const c of order) {
    const w = bb[4 * c + 2] - bb[4 * c] + pad, h = bb[4 * c + 3] - bb[4 * c + 1] + pad;
    if (x + w > width && x > 0) { x = 0; y += rowH; rowH = 0; }
    off[2 * c] = x - bb[4 * c] + pad / 2; off[2 * c + 1] = y - bb[4 * c + 1] + pad / 2;
    x += w; rowH = Math.max(rowH, h); maxX = Math.max(maxX, x);
  }
  const scale = 1 / Math.max(maxX, y + rowH);
  const uvs = new Float32Array(nout * 2);
  for (let v = 0; v < nout; v++) {
    const c = chartOfVertex[v];
    uvs[2 * v] = (uv[2 * v] + off[2 * c]) * scale;
    uvs[2 * v + 1] = (uv[2 * v + 1] + off[2 * c + 1]) * scale;
  }
  return { weld: weldArr, indices: out, uvs, charts: nc };
}
