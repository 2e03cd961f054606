// Smooth skin weights. Every primitive of the implicit body belongs to a bone; a vertex's
// distance to a bone is its distance to the nearest primitive of that bone. The nearest bone
// dominates, and bones whose primitives are almost as near (within SIGMA) share the weight
// with a quadratic falloff: this blends across each joint over a band that scales with the
// limb's radius. Only the dominant bone's parent and children may share, so a thigh does not
// pull on the other thigh, nor an arm on the chest; neighbour averaging then smooths the
// borders between dominance regions.
import { BodyField } from './field.js';
import { JOINT_NAMES, JOINT_PARENTS } from './model.js';

const SIGMA = 0.03;

export interface SkinWeights {
  joints: Uint16Array;
  weights: Float32Array;
}

export function computeWeights(field: BodyField, pos: Float64Array, idx: Uint32Array): SkinWeights {
  const nb = JOINT_NAMES.length;
  const nv = pos.length / 3;
  const par = JOINT_PARENTS;
  const near = (a: number, b: number) => a === b || par[a] === b || par[b] === a;
  const allowed = new Uint8Array(nb * nb);
  for (let a = 0; a < nb; a++) for (let b = 0; b < nb; b++) allowed[a * nb + b] = near(a, b) ? 1 : 0;

  const W = new Float32Array(nv * nb);
  const d = new Float64Array(field.n);
  const db = new Float64Array(nb);
  for (let v = 0; v < nv; v++) {
    // primitives beyond their blend radius of the nearest one are culled: their bones get no weight
    const L = field.nearDistances(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], d);
    db.fill(Infinity);
    for (let q = 0; q < L.length; q++) { const i = L[q], b = field.bone[i]; if (d[i] < db[b]) db[b] = d[i]; }
    let dom = 0;
    for (let b = 1; b < nb; b++) if (db[b] < db[dom]) dom = b;
    for (let b = 0; b < nb; b++) {
      if (!allowed[dom * nb + b]) continue;
      const h = 1 - (db[b] - db[dom]) / SIGMA;
      if (h > 0) W[v * nb + b] = h * h;
    }
  }
  // a few passes of neighbour averaging smooth out the seams of the dominance regions
  smooth(W, nb, idx, nv, 3);
  return topFour(W, nb, nv);
}

function smooth(W: Float32Array, nb: number, idx: Uint32Array, nv: number, passes: number): void {
  const acc = new Float32Array(W.length);
  const cnt = new Uint32Array(nv);
  for (let p = 0; p < passes; p++) {
    acc.set(W);
    cnt.fill(1);
    for (let t = 0; t < idx.length; t += 3) {
      for (let e = 0; e < 3; e++) {
        const a = idx[t + e], b = idx[t + ((e + 1) % 3)];
        for (let k = 0; k < nb; k++) { acc[a * nb + k] += W[b * nb + k]; acc[b * nb + k] += W[a * nb + k]; }
        cnt[a]++; cnt[b]++;
      }
    }
    for (let v = 0; v < nv; v++) {
      let s = 0;
      for (let k = 0; k < nb; k++) s += acc[v * nb + k];
      for (let k = 0; k < nb; k++) W[v * nb + k] = acc[v * nb + k] / s;
    }
  }
}

function topFour(W: Float32Array, nb: number, nv: number): SkinWeights {
  const joints = new Uint16Array(nv * 4);
  const weights = new Float32Array(nv * 4);
  const bi = [0, 0, 0, 0], bw = [0, 0, 0, 0];
  for (let v = 0; v < nv; v++) {
    bw.fill(-1); bi.fill(0);
    for (let k = 0; k < nb; k++) {
      const w = W[v * nb + k];
      if (w <= bw[3]) continue;
      let s = 3;
      while (s > 0 && bw[s - 1] < w) { bw[s] = bw[s - 1]; bi[s] = bi[s - 1]; s--; }
      bw[s] = w; bi[s] = k;
    }
    let sum = 0;
    for (let s = 0; s < 4; s++) { if (bw[s] < 1e-3 * bw[0]) bw[s] = 0; sum += bw[s]; }
    for (let s = 0; s < 4; s++) {
      joints[4 * v + s] = bw[s] > 0 ? bi[s] : 0;
      weights[4 * v + s] = bw[s] / sum;
    }
    // make the float32 sum exactly as close to 1 as possible: put the rounding on the largest
    const r = 1 - (weights[4 * v] + weights[4 * v + 1] + weights[4 * v + 2] + weights[4 * v + 3]);
    weights[4 * v] += r;
  }
  return { joints, weights };
}
