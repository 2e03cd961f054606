// Analytic test rigs: a tube of two parts (joint 0 at the origin, joint 1 at `length` along the
// axis, joint 2 at the tip owning no vertices) and the rigid motions that bend or twist it.
import * as THREE from 'three';
import type { RigInput } from '../../web/lib/index.js';

export interface TubeOptions {
  axis?: 'y' | 'x';
  length?: number;   // per part
  radius?: number;
  rings?: number;    // along the whole tube
  segments?: number; // around
  band?: number;     // half-width of the skin-weight blend around the joint (LBS/DQS)
  seam?: boolean;    // duplicate the first column (a UV seam), positions equal
}

export interface Tube {
  input: RigInput;
  ringOf: number[];   // ring index of each vertex
  along: number[];    // coordinate along the axis of each vertex
  axis: THREE.Vector3;
  joint: THREE.Vector3; // centre of joint 1
  rings: number;
  segments: number;
}

export function makeTube(o: TubeOptions = {}): Tube {
  const L = o.length ?? 1, r = o.radius ?? 0.1, rings = o.rings ?? 41, segs = o.segments ?? 12, band = o.band ?? 0.1;
  const axis = o.axis === 'x' ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0);
  const u = o.axis === 'x' ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(1, 0, 0);
  const w = new THREE.Vector3(0, 0, 1);
  const cols = segs + (o.seam ? 1 : 0);
  const positions: number[] = [], joints: number[] = [], weights: number[] = [], ringOf: number[] = [], along: number[] = [];
  for (let i = 0; i < rings; i++) {
    const s = (2 * L * i) / (rings - 1);
    for (let k = 0; k < cols; k++) {
      const a = (2 * Math.PI * (k % segs)) / segs;
      const p = axis.clone().multiplyScalar(s).addScaledVector(u, r * Math.cos(a)).addScaledVector(w, r * Math.sin(a));
      positions.push(p.x, p.y, p.z);
      const t = THREE.MathUtils.clamp((s - (L - band)) / (2 * band), 0, 1);
      const w1 = t * t * (3 - 2 * t);
      joints.push(0, 1, 0, 0);
      weights.push(1 - w1, w1, 0, 0);
      ringOf.push(i);
      along.push(s);
    }
  }
  const indices: number[] = [];
  for (let i = 0; i + 1 < rings; i++)
    for (let k = 0; k < segs; k++) {
      const a = i * cols + k, b = i * cols + (o.seam ? k + 1 : (k + 1) % segs);
      indices.push(a, b, a + cols, b, b + cols, a + cols);
    }
  const joint = axis.clone().multiplyScalar(L);
  const ibm = new Float32Array(48);
  [0, L, 2 * L].forEach((s, j) => {
    const m = new THREE.Matrix4().makeTranslation(axis.x * s, axis.y * s, axis.z * s).invert();
    ibm.set(m.elements, 16 * j);
  });
  return {
    input: { positions: new Float32Array(positions), indices: new Uint32Array(indices), joints: new Uint32Array(joints),
      weights: new Float32Array(weights), parents: new Int32Array([-1, 0, 1]), inverseBindMatrices: ibm },
    ringOf, along, axis, joint, rings, segments: segs,
  };
}

/** The rigid motion rotating by `angle` about `dir` through `centre`. */
export function rotationAbout(centre: THREE.Vector3, dir: THREE.Vector3, angle: number): THREE.Matrix4 {
  const m = new THREE.Matrix4().makeTranslation(centre.x, centre.y, centre.z);
  m.multiply(new THREE.Matrix4().makeRotationAxis(dir.clone().normalize(), angle));
  return m.multiply(new THREE.Matrix4().makeTranslation(-centre.x, -centre.y, -centre.z));
}

/** Skin matrices for the tube: part 0 still, joint 1 (and the tip) moved by `m`. */
export function tubeSkin(m: THREE.Matrix4): Float32Array {
  const out = new Float32Array(48);
  out.set(new THREE.Matrix4().elements, 0);
  out.set(m.elements, 16);
  out.set(m.elements, 32);
  return out;
}

export function maxAbsDiff(a: ArrayLike<number>, b: ArrayLike<number>): number {
  let d = 0;
  for (let i = 0; i < a.length; i++) d = Math.max(d, Math.abs(a[i] - b[i]));
  return d;
}
