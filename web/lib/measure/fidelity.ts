// The fidelity probe (docs/method.md §9): a deformer's output, frame by frame, against what the rig
// says — rigid error, distance from the reference DQS, flipped and stretched triangles, creases,
// normals off unit length, non-finite values, the seam gap.
import { GcsError } from '../errors.js';
import { identitySkin, type Deformer, type RigInput } from '../index.js';
import { countCreases, creaseBands, dihedralCosines, interiorEdges, CREASE_DEGREES } from './creases.js';
import { boundsHeight, coincidentPairs, countNonFinite, seamGap } from './mesh.js';
import { referenceDqs, splitSkinMatrix } from './reference-dqs.js';
import { maxOf, percentile } from './statistics.js';
import { dist2, faceNormal, len3 } from './vectors.js';
import { checkOptionsObject, checkRigInput } from '../arguments.js';

/** Fidelity of one method over a set of frames (docs/method.md §9). Distances in % of `height`. */
export interface Fidelity {
  /** Frames measured. */
  frames: number;
  /** Largest distance of a vertex bound ≥ 0.999 to one joint from S_j·x; null: no such vertex or no source map. */
  rigidError: number | null;
  /** Vertices bound ≥ 0.999 to one joint (the rigid error's population). */
  rigidVertices: number;
  /** Distance from the reference DQS over every vertex and frame: 95th percentile and max; null without a source map. */
  dqsP95: number | null;
  /** Largest distance from the reference DQS; null without a source map. */
  dqsMax: number | null;
  /** Triangles whose normal turned against their rest normal carried by their dominant joint, summed over frames. */
  flipped: number;
  /**
   * Creases: interior edges (shared by exactly two triangles, vertices welded by rest position)
   * whose dihedral angle changes by more than 20° from the rest pose, summed over frames. Steps
   * between sections show here long before they flip a triangle (docs/method.md §9).
   */
  creases: number;
  /** Triangles with an edge longer than twice its rest length, summed over frames. */
  stretched: number;
  /** Largest |length − 1| of an output normal. */
  normalOffUnit: number;
  /** NaN or infinite output values (positions and normals), summed over frames. */
  nonFinite: number;
  /** Largest gap between output vertices that coincide at rest. */
  seamGap: number;
}

/** Options of `FidelityProbe` and `classicOffSurface`. */
export interface FidelityOptions {
  /**
   * The character's height in the units of the deformers' OUTPUT (posed mesh space). Default: the
   * rig's own bind-pose height, which is right only when the skin matrices carry no scale (a rig
   * whose S_j are ×100 outputs ×100 positions: pass 100 × that height).
   */
  height?: number;
}

/**
 * Measures deformers against a rig over a fixed set of frames (skin matrices J × 16 each). Build it
 * once per mesh and clip set: it computes the reference DQS of every frame once, then
 * `measure(deformer)` for each method.
 */
export class FidelityProbe {
  /** The height distances are divided by (output units). */
  readonly height: number;
  /** Vertices of the rig. */
  readonly vertexCount: number;
  private readonly reference: Float32Array[] = [];
  private readonly rigid: Int32Array; // per rig vertex: its joint when bound ≥ 0.999, else -1
  private readonly rigidCount: number;
  private readonly dominant: Int32Array; // per rig vertex: the joint of largest weight
  private readonly rotations: Float64Array[] = []; // per frame: J × 9 rotations

  /**
   * @param input The rig, as given to `createRig`.
   * @param frames Skin matrices per frame (J × 16 each).
   * @param options The character's height in output units.
   * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
   */
  constructor(readonly input: RigInput, readonly frames: readonly Float32Array[], options: FidelityOptions = {}) {
    checkRigInput(input, 'input', 'FidelityProbe');
    checkOptionsObject(options, 'options', 'FidelityProbe');
    const n = Math.floor(input.positions.length / 3);
    this.vertexCount = n;
    this.height = options.height ?? boundsHeight(input.positions);
    // Nothing to measure is an error, not NaN figures: no frames, or no height to divide by.
    if (!Array.isArray(frames) || frames.length === 0) throw new GcsError('INVALID_ARGUMENT', 'FidelityProbe needs at least one frame (skin matrices) to measure');
    if (!(this.height > 0 && this.height < Infinity)) throw new GcsError('OUT_OF_RANGE', `FidelityProbe needs a positive, finite height to give distances in % of it; got ${this.height}`);
    this.rigid = new Int32Array(n).fill(-1);
    this.dominant = new Int32Array(n);
    let rigidCount = 0;
    const K = input.influences ?? 4;
    for (let v = 0; v < n; v++) {
      let sum = 0, best = 0;
      for (let i = 0; i < K; i++) sum += Math.max(0, input.weights[K * v + i]);
      for (let i = 1; i < K; i++) if (input.weights[K * v + i] > input.weights[K * v + best]) best = i;
      this.dominant[v] = input.joints[K * v + best];
      let bound = -1;
      for (let i = 0; i < K; i++) {
        const w = input.weights[K * v + i] / sum;
        if (w >= 0.999) bound = input.joints[K * v + i];
      }
      // The same joint listed twice would sum to 1 with neither entry ≥ 0.999: merge.
      if (bound < 0) {
        const j0 = this.dominant[v];
        let w = 0;
        for (let i = 0; i < K; i++) if (input.joints[K * v + i] === j0) w += Math.max(0, input.weights[K * v + i]) / sum;
        if (w >= 0.999) bound = j0;
      }
      this.rigid[v] = bound;
      if (bound >= 0) rigidCount++;
    }
    this.rigidCount = rigidCount;
    const J = input.parents.length;
    for (const skin of frames) {
      const ref = new Float32Array(3 * n); // computed in double, stored in float (memory)
      referenceDqs(input, skin, ref);
      this.reference.push(ref);
      const rot = new Float64Array(9 * J);
      for (let j = 0; j < J; j++) rot.set(splitSkinMatrix(skin, 16 * j).r, 9 * j);
      this.rotations.push(rot);
    }
  }

  /** Deforms `deformer` through every frame and measures it. */
  measure(deformer: Deformer): Fidelity {
    const source = deformer.sourceVertex;
    const nOut = deformer.vertexCount;
    const indices = deformer.indices;
    const P0 = this.input.positions;
    // Rest geometry of the output mesh and the joint that carries each output vertex.
    deformer.deform(identitySkin(deformer.jointCount));
    const rest = Float64Array.from(deformer.positions);
    const jointOf = new Int32Array(nOut).fill(-1);
    if (source) {
      for (let o = 0; o < nOut; o++) {
        const v = source[o];
        if (!(v < this.vertexCount)) throw new GcsError('LENGTH_MISMATCH', `output vertex ${o} comes from rig vertex ${v}, but the probe's rig has ${this.vertexCount}: measure a deformer built from the same rig`);
        jointOf[o] = this.dominant[v];
        for (let c = 0; c < 3; c++) rest[3 * o + c] = P0[3 * v + c];
      }
    } else {
      const parts = (deformer as unknown as { parts?: { joint: number; firstVertex: number; vertexCount: number }[] }).parts;
      if (parts) for (const p of parts) jointOf.fill(p.joint, p.firstVertex, p.firstVertex + p.vertexCount);
    }
    const pairs = coincidentPairs(rest);
    const triCount = Math.floor(indices.length / 3);
    // Per triangle: the joint of largest summed weight over its corners (or of its first corner),
    // its rest normal, its rest edge lengths.
    const triJoint = new Int32Array(triCount).fill(-1);
    const restNormal = new Float64Array(3 * triCount);
    const restEdge = new Float64Array(3 * triCount); // squared
    for (let t = 0; t < triCount; t++) {
      const a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
      triJoint[t] = source ? triangleJoint(this.input, source[a], source[b], source[c]) : jointOf[a];
      faceNormal(rest, a, b, c, restNormal, 3 * t);
      restEdge[3 * t] = dist2(rest, a, b); restEdge[3 * t + 1] = dist2(rest, b, c); restEdge[3 * t + 2] = dist2(rest, c, a);
    }
    const edges = interiorEdges(rest, indices);
    const restCos = dihedralCosines(restNormal, edges);
    const bands = creaseBands(restCos);
    const posedNormal = new Float64Array(3 * triCount);
    const J = this.input.parents.length;
    const scales = new Float64Array(J);
    const scale = 100 / this.height;
    let rigidError = 0, flipped = 0, creases = 0, stretched = 0, normalOff = 0, nonFinite = 0, gap = 0;
    const dqsDistances = source ? new Float32Array(nOut * this.frames.length) : null;
    this.frames.forEach((skin, f) => {
      deformer.deform(skin);
      const pos = deformer.positions, nrm = deformer.normals;
      nonFinite += countNonFinite(pos, nrm);
      gap = Math.max(gap, seamGap(pos, pairs));
      for (let o = 0; o < nOut; o++) {
        const l = len3(nrm[3 * o], nrm[3 * o + 1], nrm[3 * o + 2]);
        const off = Math.abs(l - 1);
        if (!(off <= normalOff)) normalOff = Number.isNaN(off) ? Infinity : off;
      }
      if (source && dqsDistances) {
        const ref = this.reference[f];
        for (let o = 0; o < nOut; o++) {
          const v = source[o];
          const d = len3(pos[3 * o] - ref[3 * v], pos[3 * o + 1] - ref[3 * v + 1], pos[3 * o + 2] - ref[3 * v + 2]);
          dqsDistances[f * nOut + o] = Number.isNaN(d) ? Infinity : d;
          const j = this.rigid[v];
          if (j >= 0) {
            const m = 16 * j;
            const x = P0[3 * v], y = P0[3 * v + 1], z = P0[3 * v + 2];
            const ex = skin[m] * x + skin[m + 4] * y + skin[m + 8] * z + skin[m + 12];
            const ey = skin[m + 1] * x + skin[m + 5] * y + skin[m + 9] * z + skin[m + 13];
            const ez = skin[m + 2] * x + skin[m + 6] * y + skin[m + 10] * z + skin[m + 14];
            const e = len3(pos[3 * o] - ex, pos[3 * o + 1] - ey, pos[3 * o + 2] - ez);
            if (!(e <= rigidError)) rigidError = Number.isNaN(e) ? Infinity : e;
          }
        }
      }
      const rot = this.rotations[f];
      for (let j = 0; j < J; j++) scales[j] = jointScale(skin, j);
      for (let t = 0; t < triCount; t++) {
        const a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
        const j = triJoint[t];
        const rx = restNormal[3 * t], ry = restNormal[3 * t + 1], rz = restNormal[3 * t + 2];
        faceNormal(pos, a, b, c, posedNormal, 3 * t);
        if (j >= 0 && (rx !== 0 || ry !== 0 || rz !== 0)) {
          const r = 9 * j;
          const cx = rot[r] * rx + rot[r + 3] * ry + rot[r + 6] * rz;
          const cy = rot[r + 1] * rx + rot[r + 4] * ry + rot[r + 7] * rz;
          const cz = rot[r + 2] * rx + rot[r + 5] * ry + rot[r + 8] * rz;
          if (cx * posedNormal[3 * t] + cy * posedNormal[3 * t + 1] + cz * posedNormal[3 * t + 2] < 0) flipped++;
        }
        // Stretch is relative to the triangle's own scale change: compare with the rest edge carried
        // by S_j's scale (squared lengths: |e| > 2k|r| ⟺ |e|² > 4k²|r|²).
        const k = j >= 0 ? scales[j] : 1, k4 = 4 * k * k;
        if (dist2(pos, a, b) > k4 * restEdge[3 * t] || dist2(pos, b, c) > k4 * restEdge[3 * t + 1] ||
            dist2(pos, c, a) > k4 * restEdge[3 * t + 2]) stretched++;
      }
      creases += countCreases(posedNormal, edges, restCos, CREASE_DEGREES, bands);
    });
    return {
      frames: this.frames.length,
      rigidError: source && this.rigidCount ? rigidError * scale : null,
      rigidVertices: this.rigidCount,
      dqsP95: dqsDistances ? percentile(dqsDistances, 95) * scale : null,
      dqsMax: dqsDistances ? maxOf(dqsDistances) * scale : null,
      flipped, creases, stretched, normalOffUnit: normalOff, nonFinite, seamGap: gap * scale,
    };
  }
}

function triangleJoint(input: RigInput, a: number, b: number, c: number): number {
  const sum = new Map<number, number>();
  const K = input.influences ?? 4;
  for (const v of [a, b, c])
    for (let i = 0; i < K; i++) {
      const w = input.weights[K * v + i];
      if (w > 0) sum.set(input.joints[K * v + i], (sum.get(input.joints[K * v + i]) ?? 0) + w);
    }
  let best = -1, bw = -Infinity;
  for (const [j, w] of sum) if (w > bw || (w === bw && j < best)) { bw = w; best = j; }
  return best;
}

/** Mean column length of joint j's skin matrix: its scale (1 for a rigid motion). */
function jointScale(skin: ArrayLike<number>, j: number): number {
  const m = 16 * j;
  return (len3(skin[m], skin[m + 1], skin[m + 2]) + len3(skin[m + 4], skin[m + 5], skin[m + 6]) +
    len3(skin[m + 8], skin[m + 9], skin[m + 10])) / 3;
}
