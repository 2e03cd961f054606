// Helpers for comparing deformed meshes: scaled skin matrices and the worst per-vertex distance.
import * as THREE from 'three';

/** Every skin matrix of a frame premultiplied by a scale about the origin (a scaled character node; ×100: Mixamo). */
export function scaledSkin(skin: Float32Array, sx: number, sy: number, sz: number): Float32Array {
  const out = new Float32Array(skin.length);
  const s = new THREE.Matrix4().makeScale(sx, sy, sz), m = new THREE.Matrix4();
  for (let j = 0; j < skin.length / 16; j++) out.set(m.fromArray(skin, 16 * j).premultiply(s).elements, 16 * j);
  return out;
}

/** The largest distance between corresponding xyz triples of a and b (Infinity on NaN); `normalise`: b's triples made unit first. */
export function maxDistance(a: ArrayLike<number>, b: ArrayLike<number>, normalise = false): number {
  let worst = 0;
  for (let v = 0; v < a.length / 3; v++) {
    let lb = 1;
    if (normalise) lb = Math.hypot(b[3 * v], b[3 * v + 1], b[3 * v + 2]) || 1;
    const d = Math.hypot(a[3 * v] - b[3 * v] / lb, a[3 * v + 1] - b[3 * v + 1] / lb, a[3 * v + 2] - b[3 * v + 2] / lb);
    if (!(d <= worst)) worst = Number.isNaN(d) ? Infinity : d;
  }
  return worst;
}
