/** @module gcs-skin/human */
// gcs-skin/human: a default human character (one closed skinned surface, 19 joints, idle /
// walk / run clips), generated procedurally. See createHuman().
import * as THREE from 'three';
import { asGiven, GcsError } from '../errors.js';
import { polygonizeBody, relax, vertexNormals } from './body.js';
import { makeClips } from './clips.js';
import { BodyField } from './field.js';
import { buildBodyModel, JOINT_NAMES, JOINT_PARENTS, Pose } from './model.js';
import { cutSeams } from './seams.js';
import { computeWeights } from './weights.js';

export { JOINT_NAMES, JOINT_PARENTS } from './model.js';
export type { Pose } from './model.js';
export { humanToGlb } from './gltf.js';

/** Vertex count of the default human (the paper's model: 17,023; the mesh comes out within 1 %). */
export const DEFAULT_VERTICES = 17023;
/** standing height, metres (feet on y = 0, top of the head at y = HEIGHT) */
export const HEIGHT = 1.75;
/** Fewest vertices `createHuman` takes. */
export const MIN_VERTICES = 2000;
/** Most vertices `createHuman` takes. */
export const MAX_VERTICES = 2000000;
/** Share of vertices that are distinct positions when seams are on (paper's model: 15,620 of 17,023). */
export const WELDED_FRACTION = 15620 / 17023;

/** Options of `createHuman` and `createHumanData`. */
export interface HumanOptions {
  /** total vertex count (default 17,023); 2,000 … 2,000,000 */
  vertices?: number;
  /** bind pose: arms down ('stand', default) or 'tpose' */
  pose?: Pose;
  /**
   * cut UV seams (duplicated vertices on chart borders), default true: this is what gives the
   * paper's ratio of ~1.84 triangles per vertex. With false, the mesh is one welded closed
   * surface: triangles = 2·vertices − 4.
   */
  seams?: boolean;
}

/** The human as plain arrays (glTF conventions), before any three.js object is made. */
export interface HumanData {
  /** The bind pose it was built in. */
  pose: Pose;
  /** xyz per vertex, metres */
  positions: Float32Array;
  /** xyz unit normal per vertex. */
  normals: Float32Array;
  /** uv per vertex (the charts cut along the seams). */
  uvs: Float32Array;
  /** Triangle list. */
  indices: Uint32Array;
  /** 4 joint indices per vertex */
  joints: Uint16Array;
  /** 4 weights per vertex, sum 1 */
  weights: Float32Array;
  /** for each vertex, the index of its welded vertex: vertices with equal weld share one position (seam copies) */
  weld: Uint32Array;
  /** Number of distinct welded vertices (positions). */
  weldedCount: number;
  /** Joint names, in joint order (JOINT_NAMES). */
  jointNames: string[];
  /** Parent joint per joint, -1 for the root. */
  parents: number[];
  /** bind-pose joint positions, world (xyz per joint) */
  jointPositions: Float32Array;
  /** column-major 4×4 per joint (world → joint), as in glTF */
  inverseBindMatrices: Float32Array;
  /** Height of the bind-pose mesh, metres. */
  height: number;
  /** How the build went: its time and the number of UV charts. */
  stats: {
    /** Build time, ms. */
    buildMs: number;
    /** Number of UV charts. */
    charts: number;
  };
}

/** The human as three.js objects: the skinned mesh, its clips and the raw data. */
export interface Human {
  /** The skinned mesh, its bones under it, bound. */
  mesh: THREE.SkinnedMesh;
  /** The 'idle', 'walk' and 'run' clips. */
  clips: THREE.AnimationClip[];
  /** Standing height, metres. */
  height: number;
  /** The arrays the mesh was made from. */
  data: HumanData;
}

function validate(options: HumanOptions): { vertices: number; pose: Pose; seams: boolean } {
  if (options === null || typeof options !== 'object' || Array.isArray(options))
    throw new GcsError('INVALID_ARGUMENT', `the human's options must be an object ({ vertices, pose, seams }); got ${asGiven(options)}`);
  const vertices = options.vertices ?? DEFAULT_VERTICES;
  if (typeof vertices !== 'number' || !Number.isFinite(vertices) || vertices < MIN_VERTICES || vertices > MAX_VERTICES) {
    throw new GcsError('OUT_OF_RANGE', `vertices must be a number from ${MIN_VERTICES} to ${MAX_VERTICES} (got ${asGiven(vertices)}).`);
  }
  const pose = options.pose ?? 'stand';
  if (pose !== 'stand' && pose !== 'tpose') {
    throw new GcsError('OUT_OF_RANGE', `pose must be 'stand' or 'tpose' (got ${asGiven(pose)}).`);
  }
  const seams = options.seams ?? true;
  if (typeof seams !== 'boolean') throw new GcsError('INVALID_ARGUMENT', `seams must be true or false (got ${asGiven(seams)}).`);
  return { vertices: Math.round(vertices), pose, seams };
}

/** humanFromData's input: what createHumanData returns (or a copy of it), checked by shape before use. */
function checkHumanData(data: HumanData): void {
  const arrays: [keyof HumanData, number][] = [['positions', 3], ['normals', 3], ['uvs', 2], ['joints', 4], ['weights', 4]];
  if (data === null || typeof data !== 'object')
    throw new GcsError('INVALID_ARGUMENT', `humanFromData takes what createHumanData returns; got ${asGiven(data)}`);
  const count = ArrayBuffer.isView(data.positions) ? (data.positions as Float32Array).length / 3 : -1;
  for (const [key, size] of arrays) {
    const a = data[key] as ArrayLike<number>;
    if (!ArrayBuffer.isView(a) || a.length !== size * count || !Number.isInteger(count))
      throw new GcsError('INVALID_ARGUMENT', `humanFromData: ${key} must be a typed array of ${size} numbers per vertex, as createHumanData returns`);
  }
  const joints = data.jointNames, parents = data.parents, jp = data.jointPositions;
  if (!ArrayBuffer.isView(data.indices) || !Array.isArray(joints) || !Array.isArray(parents) || parents.length !== joints.length
    || !ArrayBuffer.isView(jp) || (jp as Float32Array).length !== 3 * joints.length || parents.filter((p) => p === -1).length !== 1
    || !(data.pose === 'stand' || data.pose === 'tpose') || typeof data.height !== 'number')
    throw new GcsError('INVALID_ARGUMENT', 'humanFromData: the data is not what createHumanData returns (indices, jointNames, parents with one root, jointPositions, pose, height)');
  parents.forEach((p, j) => {
    if (!Number.isInteger(p) || p < -1 || p >= parents.length || p === j)
      throw new GcsError('JOINT_OUT_OF_RANGE', `humanFromData: joint ${j}'s parent ${asGiven(p)} is not a joint of the human`);
  });
}

/** Generate the raw arrays of the character (no three.js objects). */
export function createHumanData(options: HumanOptions = {}): HumanData {
  const t0 = performance.now();
  const { vertices, pose, seams } = validate(options);
  const model = buildBodyModel(pose);
  const field = new BodyField(model);
  const welded = seams ? Math.round(vertices * WELDED_FRACTION) : vertices;
  const poly = polygonizeBody(field, model, welded);
  relax(field, poly.positions, poly.indices, welded > 200000 ? 2 : 3);
  const wn = vertexNormals(poly.positions, poly.indices);
  const sw = computeWeights(field, poly.positions, poly.indices);
  const cut = cutSeams(poly.positions, poly.indices, seams ? vertices - poly.vertexCount : 0);

  // feet on y = 0, scaled to HEIGHT
  let minY = Infinity, maxY = -Infinity;
  for (let v = 1; v < poly.positions.length; v += 3) { minY = Math.min(minY, poly.positions[v]); maxY = Math.max(maxY, poly.positions[v]); }
  const s = HEIGHT / (maxY - minY);
  const n = cut.weld.length;
  const positions = new Float32Array(3 * n), normals = new Float32Array(3 * n);
  const joints = new Uint16Array(4 * n), weights = new Float32Array(4 * n);
  for (let v = 0; v < n; v++) {
    const w = cut.weld[v];
    positions[3 * v] = s * poly.positions[3 * w];
    positions[3 * v + 1] = s * (poly.positions[3 * w + 1] - minY);
    positions[3 * v + 2] = s * poly.positions[3 * w + 2];
    normals.set(wn.subarray(3 * w, 3 * w + 3), 3 * v);
    joints.set(sw.joints.subarray(4 * w, 4 * w + 4), 4 * v);
    weights.set(sw.weights.subarray(4 * w, 4 * w + 4), 4 * v);
  }
  const nj = JOINT_NAMES.length;
  const jointPositions = new Float32Array(3 * nj);
  const inverseBindMatrices = new Float32Array(16 * nj);
  for (let j = 0; j < nj; j++) {
    const q = model.joints[j];
    const p = [s * q[0], s * (q[1] - minY), s * q[2]];
    jointPositions.set(p, 3 * j);
    // bind rotations are identity: the inverse bind matrix is a translation
    inverseBindMatrices.set([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -p[0], -p[1], -p[2], 1], 16 * j);
  }
  return {
    pose, positions, normals, uvs: cut.uvs, indices: cut.indices, joints, weights, weld: cut.weld,
    weldedCount: poly.vertexCount, jointNames: [...JOINT_NAMES], parents: [...JOINT_PARENTS],
    jointPositions, inverseBindMatrices, height: HEIGHT,
    stats: { buildMs: performance.now() - t0, charts: cut.charts },
  };
}

/** Build the three.js objects from raw data. */
export function humanFromData(data: HumanData): Human {
  checkHumanData(data);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(data.positions, 3));
  g.setAttribute('normal', new THREE.BufferAttribute(data.normals, 3));
  g.setAttribute('uv', new THREE.BufferAttribute(data.uvs, 2));
  g.setAttribute('skinIndex', new THREE.BufferAttribute(data.joints, 4));
  g.setAttribute('skinWeight', new THREE.BufferAttribute(data.weights, 4));
  g.setIndex(new THREE.BufferAttribute(data.indices, 1));
  g.computeBoundingBox();
  g.computeBoundingSphere();

  const bones = data.jointNames.map((name) => { const b = new THREE.Bone(); b.name = name; return b; });
  const jp = data.jointPositions;
  data.parents.forEach((p, j) => {
    if (p >= 0) {
      bones[j].position.set(jp[3 * j] - jp[3 * p], jp[3 * j + 1] - jp[3 * p + 1], jp[3 * j + 2] - jp[3 * p + 2]);
      bones[p].add(bones[j]);
    } else {
      bones[j].position.set(jp[3 * j], jp[3 * j + 1], jp[3 * j + 2]);
    }
  });
  const material = new THREE.MeshStandardMaterial({ color: 0xc8a088, roughness: 0.65, metalness: 0 });
  const mesh = new THREE.SkinnedMesh(g, material);
  mesh.name = 'Human';
  const root = bones[data.parents.indexOf(-1)];
  mesh.add(root);
  mesh.updateMatrixWorld(true);
  const skeleton = new THREE.Skeleton(bones);
  mesh.bind(skeleton);
  const hips = root.position;
  const clips = makeClips(data.pose, [hips.x, hips.y, hips.z]);
  return { mesh, clips, height: data.height, data };
}

/**
 * Create the default human: a THREE.SkinnedMesh (bones under the mesh, bound) and its
 * 'idle', 'walk' and 'run' clips. Throws GcsError on bad options (OUT_OF_RANGE, INVALID_ARGUMENT).
 */
export function createHuman(options: HumanOptions = {}): Human {
  return humanFromData(createHumanData(options));
}
