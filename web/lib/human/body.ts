// Body surface: polygonise the implicit body on a grid that is finer around the joints,
// calibrated so that the vertex count lands on the request, then relax the triangles
// tangentially (projecting back onto the surface) and compute area-weighted normals.
import { BodyField } from './field.js';
import { BodyModel } from './model.js';
import { gridAxis, largestComponent, polygonize } from './polygonize.js';

export interface WeldedSurface {
  positions: Float64Array;
  indices: Uint32Array;
  normals: Float64Array;
  vertexCount: number;
}

/** Grid spacing along an axis: base spacing h0, finer (down to h0/(1+AMP)) near the given coordinates. */
function spacing(h0: number, centres: number[]): (x: number) => number {
  const AMP = 1.1, W = 0.045;
  return (x: number) => {
    let s = 0;
    for (const c of centres) { const t = (x - c) / W; s += Math.exp(-t * t); }
    return h0 / (1 + AMP * Math.min(1, s));
  };
}

function run(field: BodyField, model: BodyModel, h0: number) {
  const f = (x: number, y: number, z: number) => field.eval(x, y, z);
  const axis = (a: 0 | 1 | 2, cs: number[]) => gridAxis(model.bboxMin[a], model.bboxMax[a], spacing(h0, cs));
  // a small per-axis offset keeps the grid from aligning with the symmetry plane x = 0
  const xs = axis(0, model.densify.x).map((v) => v + 0.000123);
  return largestComponent(polygonize(f, xs, axis(1, model.densify.y), axis(2, model.densify.z)));
}

/**
 * Polygonise with exactly `target` vertices, as one genus-0 piece: calibrate the grid to land
 * a little below the target (the count is a noisy function of the grid spacing), then split
 * the longest edges to make up the difference.
 */
export function polygonizeBody(field: BodyField, model: BodyModel, target: number) {
  // vertices ∝ h0^-2. Calibrate on a cheap coarse run when the target is large.
  const aim = 0.94 * target;
  let h0 = 0.025 * Math.sqrt(15000 / aim);
  if (target > 40000) {
    const hc = 0.025 * Math.sqrt(15000 / 30000);
    const r = run(field, model, hc);
    h0 = hc * Math.sqrt(r.vertexCount / aim);
  }
  const ok = (r: { vertexCount: number }) => r.vertexCount <= target && r.vertexCount >= 0.86 * target;
  // closed and edge-manifold by construction; genus 0 iff V − T/2 = 2 (coarse grids can bridge narrow gaps)
  const sphere = (r: { vertexCount: number; indices: Uint32Array }) => r.vertexCount - r.indices.length / 6 === 2;
  let best: ReturnType<typeof run> | null = null;
  let wiggle = 0;
  for (let it = 0; it < 20 && !best; it++) {
    const r = run(field, model, h0);
    if (sphere(r) && ok(r)) best = r;
    else if (!ok(r) && it < 8) h0 *= Math.sqrt(r.vertexCount / aim);
    else { wiggle++; h0 *= 1 + 0.002 * wiggle * (wiggle % 2 ? 1 : -1); }
  }
  if (!best) throw new Error('human: could not polygonise the body as one closed genus-0 surface');
  return splitToCount(field, best.positions, best.indices, target);
}

/** Split the longest edges (midpoint, projected onto the surface) until there are `target` vertices. */
function splitToCount(field: BodyField, positions: Float64Array, indices: Uint32Array, target: number) {
  let pos = positions, idx = indices;
  let nv = pos.length / 3;
  const g = [0, 0, 0];
  while (nv < target) {
    const need = target - nv;
    const nh = idx.length;
    const len = new Float64Array(nh);
    let cnt = 0;
    for (let h = 0; h < nh; h++) {
      const t = h - (h % 3), a = idx[h], b = idx[t + ((h + 1) % 3)];
      if (a > b) { len[h] = -1; continue; }
      len[h] = Math.hypot(pos[3 * b] - pos[3 * a], pos[3 * b + 1] - pos[3 * a + 1], pos[3 * b + 2] - pos[3 * a + 2]);
      cnt++;
    }
    // length threshold for the ~3·need longest edges, from a sorted sample
    const K = Math.min(cnt, need * 3);
    const stride = Math.max(1, Math.floor(nh / 200000));
    const sample = new Float64Array(Math.ceil(nh / stride));
    let ns = 0;
    for (let h = 0; h < nh; h += stride) if (len[h] > 0) sample[ns++] = len[h];
    const sorted = sample.subarray(0, ns).sort();
    const thr = sorted[Math.max(0, Math.floor(ns * (1 - K / cnt)) - 1)];
    const cand: number[] = [];
    for (let h = 0; h < nh; h++) if (len[h] >= thr && len[h] > 0) cand.push(h);
    cand.sort((p, q) => len[q] - len[p]);
    const M = 4294967296;
    const twinKey = new Map<number, number>(); // key b·M + a → candidate half-edge
    const isEnd = new Uint8Array(nv);
    for (const h of cand) {
      const t = h - (h % 3), b = idx[t + ((h + 1) % 3)];
      twinKey.set(b * M + idx[h], h);
      isEnd[b] = 1;
    }
    const twin = new Map<number, number>();
    for (let h = 0; h < nh; h++) {
      const a = idx[h];
      if (!isEnd[a]) continue;
      const t = h - (h % 3), b = idx[t + ((h + 1) % 3)];
      if (a < b) continue;
      const c = twinKey.get(a * M + b);
      if (c !== undefined) twin.set(c, h);
    }
    const used = new Uint8Array(nh / 3);
    const newPos: number[] = [];
    const newTri: number[] = [];
    const out = Uint32Array.from(idx);
    let made = 0;
    for (const h of cand) {
      if (made >= need) break;
      const u = twin.get(h);
      if (u === undefined) continue;
      const t = (h / 3) | 0, s = (u / 3) | 0;
      if (used[t] || used[s]) continue;
      used[t] = used[s] = 1;
      const a = idx[h], b = idx[3 * t + ((h + 1) % 3)], c = idx[3 * t + ((h + 2) % 3)];
      const d = idx[3 * s + ((u + 2) % 3)];
      const m = nv + made;
      let x = (pos[3 * a] + pos[3 * b]) / 2, y = (pos[3 * a + 1] + pos[3 * b + 1]) / 2, z = (pos[3 * a + 2] + pos[3 * b + 2]) / 2;
      for (let k = 0; k < 3; k++) {
        const fv = field.eval(x, y, z);
        gradient(field, x, y, z, 1e-4, g);
        const g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (g2 < 1e-20) break;
        const sc = Math.min(1, 0.004 / Math.abs((fv * 4e-4) / Math.sqrt(g2) || 1e-9)) * (fv * 4e-4) / g2;
        x -= sc * g[0]; y -= sc * g[1]; z -= sc * g[2];
      }
      newPos.push(x, y, z);
      // (a,b,c) → (a,m,c) + (m,b,c);  twin (b,a,d) → (b,m,d) + (m,a,d)
      out[3 * t] = a; out[3 * t + 1] = m; out[3 * t + 2] = c;
      newTri.push(m, b, c);
      out[3 * s] = b; out[3 * s + 1] = m; out[3 * s + 2] = d;
      newTri.push(m, a, d);
      made++;
    }
    const np = new Float64Array(pos.length + newPos.length);
    np.set(pos); np.set(newPos, pos.length);
    const ni = new Uint32Array(out.length + newTri.length);
    ni.set(out); ni.set(newTri, out.length);
    pos = np; idx = ni; nv += made;
    if (made === 0) break;
  }
  return { positions: pos, indices: idx, vertexCount: nv };
}

function gradient(field: BodyField, x: number, y: number, z: number, e: number, out: number[]): void {
  const a = field.eval(x + e, y - e, z - e), b = field.eval(x - e, y - e, z + e);
  const c = field.eval(x - e, y + e, z - e), d = field.eval(x + e, y + e, z + e);
  out[0] = a - b - c + d;
  out[1] = -a - b + c + d;
  out[2] = -a + b - c + d;
}

/** Tangential Laplacian relaxation + projection onto the implicit surface. */
export function relax(field: BodyField, pos: Float64Array, idx: Uint32Array, iterations: number): void {
  const nv = pos.length / 3;
  const acc = new Float64Array(nv * 3);
  const cnt = new Uint32Array(nv);
  const g = [0, 0, 0];
  for (let it = 0; it < iterations; it++) {
    acc.fill(0); cnt.fill(0);
    for (let t = 0; t < idx.length; t += 3) {
      for (let e = 0; e < 3; e++) {
        const a = idx[t + e], b = idx[t + ((e + 1) % 3)];
        acc[3 * a] += pos[3 * b]; acc[3 * a + 1] += pos[3 * b + 1]; acc[3 * a + 2] += pos[3 * b + 2]; cnt[a]++;
        acc[3 * b] += pos[3 * a]; acc[3 * b + 1] += pos[3 * a + 1]; acc[3 * b + 2] += pos[3 * a + 2]; cnt[b]++;
      }
    }
    for (let v = 0; v < nv; v++) {
      const x = pos[3 * v], y = pos[3 * v + 1], z = pos[3 * v + 2];
      let dx = acc[3 * v] / cnt[v] - x, dy = acc[3 * v + 1] / cnt[v] - y, dz = acc[3 * v + 2] / cnt[v] - z;
      gradient(field, x, y, z, 1e-4, g);
      const gl = Math.hypot(g[0], g[1], g[2]) || 1;
      const nx = g[0] / gl, ny = g[1] / gl, nz = g[2] / gl;
      const dn = dx * nx + dy * ny + dz * nz;
      dx -= dn * nx; dy -= dn * ny; dz -= dn * nz;
      let px = x + 0.5 * dx, py = y + 0.5 * dy, pz = z + 0.5 * dz;
      // back onto f = 0 along the normal (|∇f| ≈ gl / 4e; the stencil sums 4 samples at offset e)
      const fv = field.eval(px, py, pz);
      let m = (fv * 4e-4) / gl;
      if (m > 0.004) m = 0.004; else if (m < -0.004) m = -0.004;
      px -= m * nx; py -= m * ny; pz -= m * nz;
      pos[3 * v] = px; pos[3 * v + 1] = py; pos[3 * v + 2] = pz;
    }
  }
}

export function vertexNormals(pos: Float64Array, idx: Uint32Array): Float64Array {
  const n = new Float64Array(pos.length);
  for (let t = 0; t < idx.length; t += 3) {
    const a = 3 * idx[t], b = 3 * idx[t + 1], c = 3 * idx[t + 2];
    const e1x = pos[b] - pos[a], e1y = pos[b + 1] - pos[a + 1], e1z = pos[b + 2] - pos[a + 2];
    const e2x = pos[c] - pos[a], e2y = pos[c + 1] - pos[a + 1], e2z = pos[c + 2] - pos[a + 2];
    const nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x; // 2·area·normal
    for (const v of [a, b, c]) { n[v] += nx; n[v + 1] += ny; n[v + 2] += nz; }
  }
  for (let v = 0; v < n.length; v += 3) {
    const l = Math.hypot(n[v], n[v + 1], n[v + 2]) || 1;
    n[v] /= l; n[v + 1] /= l; n[v + 2] /= l;
  }
  return n;
}
