// One joint bent alone about a hinge through its bind centre (everything else at rest), and what
// that does to the skin around it: bulge (a region vertex's distance to the nearest posed bone
// segment over the same at bind) and volume (signed cone volumes of the region's triangles about
// the joint centre, posed vs bind). A quick check for the centres of rotation; the reported joint
// measurement lives in gcs-skin/measure.
import * as THREE from 'three';
import type { Deformer, RigInput } from '../../web/lib/index.js';

export interface JointBend {
  /** The skin matrices (J × 16) of the bend. */
  skin: Float32Array;
  /** Output-independent: the region's rig vertices and the triangles with a corner in it. */
  region: number[];
  triangles: number[];
  bindDistance: Float32Array;   // per region vertex
  segments: [THREE.Vector3, THREE.Vector3][];  // posed parent→joint and joint→child bones
  centre: THREE.Vector3;
  bindVolume: number;
}

/** Bulge: distance to the posed bones over the same at bind (p95, max); volume change in % (negative: lost). */
export interface BendFigures { bulgeP95: number; bulgeMax: number; volumeChange: number }

function bindCentres(input: RigInput): THREE.Vector3[] {
  const out: THREE.Vector3[] = [];
  for (let j = 0; j < input.parents.length; j++) {
    const ibm = new THREE.Matrix4().fromArray(Array.from(input.inverseBindMatrices).slice(16 * j, 16 * j + 16));
    out.push(new THREE.Vector3().applyMatrix4(ibm.invert()));
  }
  return out;
}

function segmentDistance(p: THREE.Vector3, a: THREE.Vector3, b: THREE.Vector3): number {
  const ab = b.clone().sub(a);
  const u = THREE.MathUtils.clamp(p.clone().sub(a).dot(ab) / ab.lengthSq(), 0, 1);
  return p.distanceTo(a.clone().addScaledVector(ab, u));
}

function coneVolume(positions: ArrayLike<number>, triangles: number[], indices: ArrayLike<number>, c: THREE.Vector3, vertexOf: (v: number) => number): number {
  const a = new THREE.Vector3(), b = new THREE.Vector3(), d = new THREE.Vector3();
  let volume = 0;
  for (const t of triangles) {
    const [i, j, k] = [indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]].map(vertexOf);
    a.fromArray(positions as number[], 3 * i).sub(c);
    b.fromArray(positions as number[], 3 * j).sub(c);
    d.fromArray(positions as number[], 3 * k).sub(c);
    volume += a.dot(b.cross(d)) / 6;
  }
  return volume;
}

/**
 * Bends `joint` by `degrees` about `axis` (through its bind centre); the region is the vertices
 * weighing at least 1 % on both the joint and its parent.
 */
export function bendJoint(input: RigInput, joint: number, axis: THREE.Vector3, degrees: number): JointBend {
  const J = input.parents.length, slots = input.influences ?? 4;
  const centres = bindCentres(input);
  const parent = input.parents[joint];
  const isBelow = (j: number) => { for (let k = j; k >= 0; k = input.parents[k]) if (k === joint) return true; return false; };
  const child = Array.from({ length: J }, (_, j) => j).find((j) => input.parents[j] === joint)!;
  const c = centres[joint];
  const bend = new THREE.Matrix4().makeTranslation(c.x, c.y, c.z)
    .multiply(new THREE.Matrix4().makeRotationAxis(axis.clone().normalize(), THREE.MathUtils.degToRad(degrees)))
    .multiply(new THREE.Matrix4().makeTranslation(-c.x, -c.y, -c.z));
  const skin = new Float32Array(16 * J);
  for (let j = 0; j < J; j++) skin.set((isBelow(j) ? bend : new THREE.Matrix4()).elements, 16 * j);
  const V = input.positions.length / 3;
  const region: number[] = [], inRegion = new Uint8Array(V);
  for (let v = 0; v < V; v++) {
    let wj = 0, wp = 0;
    for (let i = 0; i < slots; i++) {
      if (input.joints[slots * v + i] === joint) wj += input.weights[slots * v + i];
      if (input.joints[slots * v + i] === parent) wp += input.weights[slots * v + i];
    }
    if (wj >= 0.01 && wp >= 0.01) region.push(v), inRegion[v] = 1;
  }
  const triangles: number[] = [];
  for (let t = 0; t < input.indices.length / 3; t++)
    if (inRegion[input.indices[3 * t]] || inRegion[input.indices[3 * t + 1]] || inRegion[input.indices[3 * t + 2]]) triangles.push(t);
  const posedChild = centres[child].clone().applyMatrix4(bend);
  const bindSegments: [THREE.Vector3, THREE.Vector3][] = [[centres[parent], c], [c, centres[child]]];
  const segments: [THREE.Vector3, THREE.Vector3][] = [[centres[parent], c], [c, posedChild]];
  const p = new THREE.Vector3();
  const bindDistance = Float32Array.from(region, (v) => {
    p.fromArray(input.positions as number[], 3 * v);
    return Math.min(...bindSegments.map(([a, b]) => segmentDistance(p, a, b)));
  });
  const bindVolume = coneVolume(input.positions, triangles, input.indices, c, (v) => v);
  return { skin, region, triangles, bindDistance, segments, centre: c, bindVolume };
}

/** Bulge p95/max and volume change (%) of a deformer (output order mapped back by sourceVertex) deformed by the bend. */
export function measureBend(bend: JointBend, input: RigInput, d: Deformer): BendFigures {
  d.deform(bend.skin);
  const source = d.sourceVertex;
  const outputOf = new Uint32Array(input.positions.length / 3);
  if (source) source.forEach((v, o) => { outputOf[v] = o; });
  else outputOf.forEach((_, v) => { outputOf[v] = v; });
  const positions = d.positions;
  const p = new THREE.Vector3();
  const ratios = bend.region.map((v, i) => {
    p.fromArray(positions as unknown as number[], 3 * outputOf[v]);
    return Math.min(...bend.segments.map(([a, b]) => segmentDistance(p, a, b))) / bend.bindDistance[i];
  }).sort((a, b) => a - b);
  const volume = coneVolume(positions, bend.triangles, input.indices, bend.centre, (v) => outputOf[v]);
  return {
    bulgeP95: ratios[Math.floor(0.95 * (ratios.length - 1))],
    bulgeMax: ratios[ratios.length - 1],
    volumeChange: 100 * (volume / bend.bindVolume - 1),  // negative: lost, whichever way the triangles wind
  };
}
