// Body surface: polygonise the implicit body on a grid that is finer around the joints,
// calibrated so that the vertex count lands on the request, then relax the triangles
// tangentially (projecting back onto the surface) and compute area-weighted normals.
import { BodyField } from './field.js';
import { BodyModel } from './model.js';
import { gridAxis, polygonize } from './polygonize.js';

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
  return polygonize(f, xs, axis(1, model.densify.y), axis(2, model.densify.z));
}

/** Polygonise with about `target` vertices (within ~0.5 %). */
export function polygonizeBody(field: BodyField, model: BodyModel, target: number) {
  // vertices ∝ h0^-2. Calibrate on a cheap coarse run when the target is large.
  let h0 = 0.012 * Math.sqrt(15000 / target);
  if (target > 40000) {
    const hc = 0.012 * Math.sqrt(15000 / 30000);
    const r = run(field, model, hc);
    h0 = hc * Math.sqrt(r.vertexCount / target);
  }
  let best = run(field, model, h0);
  for (let it = 0; it < 8; it++) {
    const err = best.vertexCount / target - 1;
    if (Math.abs(err) < 0.004) break;
    h0 *= Math.sqrt(best.vertexCount / target);
    const r = run(field, model, h0);
    if (Math.abs(r.vertexCount / target - 1) < Math.abs(err)) best = r;
  }
  return best;
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
      // one Newton step back onto f = 0
      const fv = field.eval(px, py, pz);
      gradient(field, px, py, pz, 1e-4, g);
      // stencil sum ≈ 4e·∇f, so the Newton step f·∇f/|∇f|² = f·g·4e/|g|²
      const g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
      if (g2 > 1e-20) {
        const s = (fv * 4e-4) / g2;
        let mx = s * g[0], my = s * g[1], mz = s * g[2];
        const ml = Math.hypot(mx, my, mz), cap = 0.004;
        if (ml > cap) { mx *= cap / ml; my *= cap / ml; mz *= cap / ml; }
        px -= mx; py -= my; pz -= mz;
      }
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
