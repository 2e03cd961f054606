/**
 * Joints measured one at a time (docs/report-json.md, "Joints"; docs/method.md): a knee or elbow
 * (measure/hinges.ts) bent alone from the bind pose about its hinge, everything else at rest, and
 * its region — the triangles with a vertex weighted on the bent joint or its parent and nearest (at
 * bind) to the limb's bones at the hinge — compared posed against bind:
 * - volume change: the sum of signed cone volumes a·(b×c)/6 about the joint centre (which the bend
 *   leaves in place; a rigid motion about it keeps every cone), % of the bind value;
 * - bulge: each region vertex's distance to the nearest posed bone segment over the same at bind
 *   (p95, max); collapse: the same ratio's p5 and min;
 * - creases (measure's countCreases, over the region's interior edges) and new self-intersecting
 *   triangle pairs (measure/self-intersection.ts).
 * Any deformer can be measured: a method is a name and a build function (JointMethod).
 */
import type { ClassicDeformer, Deformer, Rig, RigInput } from '../index.js';
import { asGiven, GcsError } from '../errors.js';
import { identitySkin } from '../index.js';
import { countCreases, dihedralCosines, interiorEdges } from './creases.js';
import { boundsHeight, weldByPosition } from './mesh.js';
import { METHOD_LABELS, buildMethod, errorInfo, type BuildSettings, type MethodName } from './methods.js';
import { maxOf, percentile } from './statistics.js';
import { findHinges, jointCentres, type BodyFrame, type Hinge, type Vec3 } from './hinges.js';
import { intersectingPairs } from './self-intersection.js';
import { checkFinite, checkList, checkNumberFields, checkNumbers, checkObject, checkOptionsObject, checkRigInput } from '../arguments.js';

/** The bends measured unless told otherwise, degrees. */
export const JOINT_ANGLES: readonly number[] = [45, 90, 135];

/** One joint, one method, one bend angle. */
export interface JointFigures {
  /** The bend angle, degrees. */
  degrees: number;
  /** (posed − bind) / bind of the region's cone volume about the joint centre, %. */
  volumeChange: number;
  /** Distance to the nearest posed bone over the same at bind, over the region's vertices. */
  bulgeP95: number;
  /** Largest bulge ratio over the region's vertices. */
  bulgeMax: number;
  /** 5th percentile of the same ratio (below 1: the skin falls in towards the bone). */
  collapseP5: number;
  /** Smallest ratio. */
  collapseMin: number;
  /** Region edges whose dihedral angle changed by more than 20°. */
  creases: number;
  /** Pairs of region triangles that cross in the pose and did not at bind. */
  newIntersections: number;
}

/** A deformer to measure: `key` names it in JSON, `label` in tables. */
export interface JointMethod {
  /** Its name in JSON (a MethodName, or 'gcs-centres'). */
  key: string;
  /** Its name in tables. */
  label: string;
  /**
   * Builds the deformer on `rig`.
   * @param rig The rig to build on.
   * @returns The deformer (the caller disposes it).
   */
  build(rig: Rig): Deformer;
}

/** The methods the report compares at the joints, built as `buildMethod` builds them. */
export const JOINT_METHOD_NAMES: readonly MethodName[] = ['gcs', 'dqs', 'lbs', 'gcs-plain', 'classic'];

/**
 * The methods measured at the joints: `names` built as `buildMethod` builds them and, with
 * `centres` (default true), GCS with centres of rotation (`centres: true`) right after the default.
 */
export function jointMethods(settings: BuildSettings = {}, names: readonly MethodName[] = JOINT_METHOD_NAMES, centres = true): JointMethod[] {
  const list: JointMethod[] = names.map((m) => ({ key: m, label: METHOD_LABELS[m], build: (rig: Rig) => buildMethod(rig, m, settings) }));
  if (centres) list.splice(names.includes('gcs') ? names.indexOf('gcs') + 1 : 0, 0, CENTRES_METHOD(settings));
  return list;
}

/** GCS with centres of rotation per node (rig.buildGcs's `centres: true`), key 'gcs-centres'. */
export const CENTRES_METHOD = (settings: BuildSettings = {}): JointMethod => ({
  key: 'gcs-centres', label: 'GCS, centres of rotation', build: (rig: Rig) => rig.buildGcs({ sections: settings.sections, centres: true }),
});

/**
 * Skin matrices (J × 16) of the bind pose with `hinge.joint` and everything below it turned by
 * `degrees` about the hinge axis through the joint centre.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function bendSkin(parents: ArrayLike<number>, hinge: Hinge, degrees: number, out?: Float32Array): Float32Array {
  checkNumbers(parents, 'parents', 'bendSkin');
  checkNumberFields(hinge, 'hinge', 'bendSkin', ['centre', 'axis']);
  checkFinite(degrees, 'degrees', 'bendSkin');
  if (out !== undefined && !(out instanceof Float32Array && out.length >= 16 * parents.length))
    throw new GcsError('INVALID_ARGUMENT', `bendSkin: out must be a Float32Array of 16 × ${parents.length} numbers; got ${asGiven(out)}`);
  const J = parents.length;
  const skin = out ?? new Float32Array(16 * J);
  skin.set(identitySkin(J));
  const m = rotationAbout(hinge.centre, hinge.axis, (degrees * Math.PI) / 180);
  for (let k = 0; k < J; k++) if (descends(parents, k, hinge.joint)) skin.set(m, 16 * k);
  return skin;
}

/** Whether joint k is `ancestor` or below it. */
function descends(parents: ArrayLike<number>, k: number, ancestor: number): boolean {
  for (let j = k, steps = 0; j >= 0 && steps <= parents.length; j = parents[j], steps++) if (j === ancestor) return true;
  return false;
}

/** The rigid motion turning by `angle` about the unit `axis` through `centre`, column-major 4×4. */
function rotationAbout(centre: Vec3, axis: Vec3, angle: number): Float64Array {
  const [x, y, z] = axis;
  const c = Math.cos(angle), s = Math.sin(angle), t = 1 - c;
  const m = new Float64Array([
    t * x * x + c, t * x * y + s * z, t * x * z - s * y, 0,
    t * x * y - s * z, t * y * y + c, t * y * z + s * x, 0,
    t * x * z + s * y, t * y * z - s * x, t * z * z + c, 0,
    0, 0, 0, 1,
  ]);
  for (let i = 0; i < 3; i++) m[12 + i] = centre[i] - (m[i] * centre[0] + m[4 + i] * centre[1] + m[8 + i] * centre[2]);
  return m;
}

/**
 * The bones as segments between joint centres (parent to child), plus the bent bone's own segment
 * to its skin's far end when it has no child joint; posed by a set of skin matrices.
 */
class BoneSegments {
  private readonly points: Vec3[] = [];  // per bone: bind start, bind end
  private readonly carriers: number[] = []; // per bone: the joints whose skin matrices move its start and end
  private readonly ends: Float64Array;   // per bone: posed start xyz, end xyz
  /** Per bone: 1 for the limb at the hinge (its parent's bone into the joint, the joint's bones out). */
  readonly limb: Uint8Array;

  constructor(input: RigInput, hinge: Hinge) {
    const centres = jointCentres(input);
    const J = input.parents.length;
    const limb: number[] = [];
    const add = (from: number, to: number, end: Vec3) => {
      this.points.push(centres[from], end);
      this.carriers.push(from, to);
      limb.push(Number((from === hinge.parent && to === hinge.joint) || from === hinge.joint));
    };
    for (let k = 0; k < J; k++) {
      const p = input.parents[k];
      if (p >= 0 && p < J) add(p, k, centres[k]);
    }
    if (!Array.prototype.includes.call(input.parents, hinge.joint)) add(hinge.joint, hinge.joint, hinge.end);
    this.ends = new Float64Array(3 * this.points.length);
    this.limb = Uint8Array.from(limb);
  }

  pose(skin: ArrayLike<number>): Float64Array {
    for (let i = 0; i < this.points.length; i++) {
      const [x, y, z] = this.points[i];
      const m = 16 * this.carriers[i];
      for (let c = 0; c < 3; c++) this.ends[3 * i + c] = skin[m + c] * x + skin[m + 4 + c] * y + skin[m + 8 + c] * z + skin[m + 12 + c];
    }
    return this.ends;
  }
}

/**
 * Distance from a point to the nearest of the posed segments (xyz xyz each); its index in `hit.bone`
 * when asked.
 */
function nearestBone(ends: Float64Array, px: number, py: number, pz: number, hit?: { bone: number }): number {
  let best = Infinity, bone = -1;
  for (let o = 0; o < ends.length; o += 6) {
    const ax = ends[o], ay = ends[o + 1], az = ends[o + 2];
    const dx = ends[o + 3] - ax, dy = ends[o + 4] - ay, dz = ends[o + 5] - az;
    const wx = px - ax, wy = py - ay, wz = pz - az;
    const len2 = dx * dx + dy * dy + dz * dz;
    const f = len2 > 0 ? Math.min(1, Math.max(0, (wx * dx + wy * dy + wz * dz) / len2)) : 0;
    const ex = wx - f * dx, ey = wy - f * dy, ez = wz - f * dz;
    const d2 = ex * ex + ey * ey + ez * ez;
    if (d2 < best) { best = d2; bone = o / 6; }
  }
  if (hit) hit.bone = bone;
  return Math.sqrt(best);
}

/** A joint's region on one output mesh, with what its bind pose gives once. */
class JointRegion {
  private readonly tris: Uint32Array;    // the region's triangles, as a compact index list
  private readonly verts: Uint32Array;   // region vertices with a bone distance at bind
  private readonly restDistance: Float64Array;
  private readonly restVolume: number;
  private readonly edges: { a: Uint32Array; b: Uint32Array };
  private readonly restCos: Float64Array;
  private readonly restPairs: Set<number>;
  private readonly weld: Uint32Array;
  private readonly normals: Float64Array;
  private readonly ratios: Float64Array;
  readonly triangleCount: number;

  /**
   * `weighted`: per vertex, 1 when it has weight on the joint or its parent; of those, the region
   * keeps the vertices nearest (at bind) to one of the limb's bones at the hinge, so skin the parent
   * also carries elsewhere (a shoulder's weight over the chest) stays out. The region's triangles
   * are those with a corner in it. `weld`: weldByPosition(rest), when the caller has it.
   */
  constructor(rest: ArrayLike<number>, indices: ArrayLike<number>, weighted: Uint8Array, private readonly centre: Vec3,
              private readonly bones: BoneSegments, jointCount: number, weld: Uint32Array = weldByPosition(rest)) {
    const ends = bones.pose(identitySkin(jointCount));
    const inRegion = new Uint8Array(weighted.length);
    const verts: number[] = [], dist: number[] = [];
    const size = boundsHeight(rest);
    const hit = { bone: -1 };
    for (let v = 0; v < weighted.length; v++) {
      if (!weighted[v]) continue;
      const d = nearestBone(ends, rest[3 * v], rest[3 * v + 1], rest[3 * v + 2], hit);
      if (!bones.limb[hit.bone]) continue;
      inRegion[v] = 1;
      if (d > 1e-6 * size) { verts.push(v); dist.push(d); }
    }
    const tris: number[] = [];
    for (let t = 0; t + 2 < indices.length; t += 3)
      if (inRegion[indices[t]] || inRegion[indices[t + 1]] || inRegion[indices[t + 2]]) tris.push(indices[t], indices[t + 1], indices[t + 2]);
    this.tris = Uint32Array.from(tris);
    this.triangleCount = tris.length / 3;
    this.verts = Uint32Array.from(verts);
    this.restDistance = Float64Array.from(dist);
    this.ratios = new Float64Array(verts.length);
    this.restVolume = coneVolume(rest, this.tris, centre);
    this.weld = weld;
    this.edges = interiorEdges(rest, this.tris, weld);
    this.normals = new Float64Array(tris.length);
    faceNormals(rest, this.tris, this.normals);
    this.restCos = dihedralCosines(this.normals, this.edges);
    this.restPairs = new Set(intersectingPairs(rest, this.tris, weld));
  }

  figures(posed: ArrayLike<number>, skin: ArrayLike<number>, degrees: number): JointFigures {
    const ends = this.bones.pose(skin);
    for (let i = 0; i < this.verts.length; i++) {
      const v = this.verts[i];
      const d = nearestBone(ends, posed[3 * v], posed[3 * v + 1], posed[3 * v + 2]);
      this.ratios[i] = Number.isNaN(d) ? Infinity : d / this.restDistance[i];
    }
    faceNormals(posed, this.tris, this.normals);
    let newIntersections = 0;
    for (const key of intersectingPairs(posed, this.tris, this.weld)) if (!this.restPairs.has(key)) newIntersections++;
    const volume = coneVolume(posed, this.tris, this.centre);
    return {
      degrees,
      volumeChange: (100 * (volume - this.restVolume)) / this.restVolume,
      bulgeP95: percentile(this.ratios, 95), bulgeMax: maxOf(this.ratios),
      collapseP5: percentile(this.ratios, 5), collapseMin: minOf(this.ratios),
      creases: countCreases(this.normals, this.edges, this.restCos),
      newIntersections,
    };
  }
}

/**
 * Measures deformers at one joint: build it once per rig and hinge, then `measure(deformer)` for
 * each method (the bind-pose side of the rig's own mesh is computed once and shared by every method
 * that keeps the rig's vertices; a resampled model, the classic one, gets its own).
 */
export class JointProbe {
  /** The bend angles measured, degrees. */
  readonly angles: readonly number[];
  private readonly skins: Float32Array[];
  private readonly bones: BoneSegments;
  private readonly rigRegionFlags: Uint8Array;
  private rigRegion: JointRegion | null = null;
  private readonly resampledRegions = new WeakMap<Deformer, JointRegion>();
  private readonly posed: Float64Array;

  /**
   * @param input The rig's input.
   * @param hinge The joint to bend and its axis (from `findHinges`).
   * @param angles Bend angles in degrees (default JOINT_ANGLES).
   * @throws GcsError `INVALID_ARGUMENT` when an angle is not a finite number.
   * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
   */
  constructor(readonly input: RigInput, readonly hinge: Hinge, angles: readonly number[] = JOINT_ANGLES) {
    checkRigInput(input, 'input', 'JointProbe');
    checkObject(hinge, 'hinge', 'JointProbe');
    checkList(angles, 'angles', 'JointProbe');
    const J = input.parents.length;
    if (!(hinge.joint >= 0 && hinge.joint < J && hinge.parent >= 0 && hinge.parent < J))
      throw new GcsError('INVALID_ARGUMENT', `the hinge's joint ${hinge.joint} and parent ${hinge.parent} must be joints of the rig (0 … ${J - 1})`);
    if (!angles.every(Number.isFinite)) throw new GcsError('INVALID_ARGUMENT', 'the bend angles must be finite numbers of degrees');
    this.angles = [...angles];
    this.skins = this.angles.map((a) => bendSkin(input.parents, hinge, a));
    this.bones = new BoneSegments(input, hinge);
    this.rigRegionFlags = weightedOn(input, [hinge.parent, hinge.joint]);
    this.posed = new Float64Array(input.positions.length);
  }

  /** Triangles of the joint's region on the rig's mesh. */
  get regionTriangles(): number {
    return this.region().triangleCount;
  }

  private region(): JointRegion {
    this.rigRegion ??= new JointRegion(this.input.positions, this.input.indices, this.rigRegionFlags, this.hinge.centre, this.bones,
      this.input.parents.length, rigWeld(this.input.positions));
    return this.rigRegion;
  }

  /**
   * The figures at each angle (default: the probe's), in that order. Leaves the deformer in the
   * last bend.
   */
  measure(deformer: Deformer, angles: readonly number[] = this.angles): JointFigures[] {
    if (!angles.every(Number.isFinite)) throw new GcsError('INVALID_ARGUMENT', 'the bend angles must be finite numbers of degrees');
    const skins = angles === this.angles ? this.skins : angles.map((a) => bendSkin(this.input.parents, this.hinge, a));
    const n = Math.floor(this.input.positions.length / 3);
    const source = deformer.sourceVertex ?? (deformer.kind !== 'classic' && deformer.vertexCount === n ? null : undefined);
    if (source === undefined) {
      const region = this.resampledRegion(deformer as ClassicDeformer);
      return angles.map((degrees, i) => {
        deformer.deform(skins[i]);
        return region.figures(deformer.positions, skins[i], degrees);
      });
    }
    const region = this.region();
    if (source) {
      this.posed.fill(NaN); // a rig vertex the deformer does not output shows as non-finite figures, not a stale pose
      const covered = new Uint8Array(n);
      for (const v of source) if (v < n) covered[v] = 1;
      if (covered.some((c, v) => !c && this.rigRegionFlags[v]))
        throw new GcsError('LENGTH_MISMATCH', 'the deformer leaves out vertices of the joint region: measure a deformer built from the same rig');
    }
    return angles.map((degrees, i) => {
      deformer.deform(skins[i]);
      const out = deformer.positions;
      if (source) {
        for (let o = 0; o < source.length; o++) {
          const v = source[o];
          if (v < n) for (let c = 0; c < 3; c++) this.posed[3 * v + c] = out[3 * o + c];
        }
      } else this.posed.set(out);
      return region.figures(this.posed, skins[i], degrees);
    });
  }

  /** A model with its own vertices: its region is its parts of the two joints and the carried skin weighted on them. */
  private resampledRegion(deformer: ClassicDeformer): JointRegion {
    let region = this.resampledRegions.get(deformer);
    if (region) return region;
    const m = deformer.vertexCount;
    const flags = new Uint8Array(m);
    for (const p of deformer.parts ?? [])
      if (p.resampled && (p.joint === this.hinge.joint || p.joint === this.hinge.parent)) flags.fill(1, p.firstVertex, p.firstVertex + p.vertexCount);
    const from = deformer.sourceOfVertex;
    for (let o = 0; o < Math.min(m, from.length); o++) if (from[o] >= 0 && this.rigRegionFlags[from[o]]) flags[o] = 1;
    const { rest, indices, weld } = outputAtRest(deformer);
    region = new JointRegion(rest, indices, flags, this.hinge.centre, this.bones, this.input.parents.length, weld);
    this.resampledRegions.set(deformer, region);
    return region;
  }
}

/** A resampled model's output at the bind pose, its triangles and their weld, once per deformer (every hinge shares them). */
const restOutputs = new WeakMap<Deformer, { rest: Float64Array; indices: Uint32Array; weld: Uint32Array }>();
function outputAtRest(deformer: Deformer): { rest: Float64Array; indices: Uint32Array; weld: Uint32Array } {
  let out = restOutputs.get(deformer);
  if (!out) {
    deformer.deform(identitySkin(deformer.jointCount));
    const rest = Float64Array.from(deformer.positions);
    restOutputs.set(deformer, (out = { rest, indices: deformer.indices, weld: weldByPosition(rest) }));
  }
  return out;
}

/** weldByPosition of a rig's positions, once per array (every hinge of a rig shares it). */
const welds = new WeakMap<object, Uint32Array>();
function rigWeld(positions: ArrayLike<number>): Uint32Array {
  let weld = welds.get(positions);
  if (!weld) welds.set(positions, (weld = weldByPosition(positions)));
  return weld;
}

/** Per vertex: 1 when it has weight on one of `joints`. */
function weightedOn(input: RigInput, joints: number[]): Uint8Array {
  const K = input.influences ?? 4;
  const n = Math.floor(input.positions.length / 3);
  const out = new Uint8Array(n);
  for (let v = 0; v < n; v++)
    for (let i = 0; i < K; i++) if (input.weights[K * v + i] > 0 && joints.includes(input.joints[K * v + i])) out[v] = 1;
  return out;
}

/** What `measureJoints` finds and measures on one rig. */
export interface JointsMeasure {
  /** The bend angles, degrees. */
  angles: number[];
  /** The methods measured, in order. */
  methods: {
    /** The method's key. */
    key: string;
    /** The method's label. */
    label: string;
  }[];
  /** The character's frame (null when hinges were given or none were found). */
  frame: BodyFrame | null;
  /** Why a joint was not found, or a guess was made. */
  notes: string[];
  /** One result per joint. */
  joints: JointResult[];
}

/** One joint's figures, per method and angle. */
export interface JointResult {
  /** The joint. */
  hinge: Hinge;
  /** Triangles of the joint's region (the rig's mesh). */
  regionTriangles: number;
  /** Per method key: the figures at each angle, or why the method could not be built or run. */
  methods: Record<string, JointFigures[] | {
    /** Why the method could not be built or run. */
    error: {
      /** The GcsError code. */
      code: string;
      /** Its sentence. */
      message: string;
    };
  }>;
}

/** Options of `measureJoints`: which methods, angles and joints. */
export interface JointsOptions {
  /** Default: jointMethods() (GCS default, GCS with centres of rotation, DQS, LBS, GCS plain, classic). */
  methods?: readonly JointMethod[];
  /** Default JOINT_ANGLES. */
  angles?: readonly number[];
  /** Joint names (labels only: the joints are found from the skeleton's layout). */
  names?: readonly (string | undefined)[];
  /** Measure these instead of the knees and elbows found. */
  hinges?: readonly Hinge[];
}

/**
 * Finds the knees and elbows of `input` (the rig's input) and measures every method at each.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function measureJoints(rig: Rig, input: RigInput, options: JointsOptions = {}): JointsMeasure {
  checkObject(rig, 'rig', 'measureJoints');
  checkRigInput(input, 'input', 'measureJoints');
  checkOptionsObject(options, 'options', 'measureJoints');
  for (const key of ['hinges', 'angles', 'methods'] as const) if (options[key] !== undefined) checkList(options[key], `options.${key}`, 'measureJoints');
  const search = options.hinges ? { hinges: [...options.hinges], frame: null, notes: [] } : findHinges(input, options.names);
  const angles = [...(options.angles ?? JOINT_ANGLES)];
  const methods = options.methods ?? jointMethods();
  const probes = search.hinges.map((h) => new JointProbe(input, h, angles));
  const joints: JointResult[] = search.hinges.map((hinge) => ({ hinge, regionTriangles: 0, methods: {} }));
  for (const method of methods) {
    let d: Deformer | undefined;
    try {
      d = method.build(rig);
      for (let i = 0; i < probes.length; i++) {
        try {
          joints[i].methods[method.key] = probes[i].measure(d);
        } catch (e) {
          joints[i].methods[method.key] = { error: errorInfo(e) };
        }
      }
    } catch (e) {
      for (const j of joints) j.methods[method.key] = { error: errorInfo(e) };
    } finally {
      d?.dispose();
    }
  }
  probes.forEach((p, i) => { joints[i].regionTriangles = p.regionTriangles; });
  return { angles, methods: methods.map(({ key, label }) => ({ key, label })), frame: search.frame, notes: search.notes, joints };
}

function coneVolume(p: ArrayLike<number>, tris: Uint32Array, c: Vec3): number {
  let v = 0;
  for (let t = 0; t < tris.length; t += 3) {
    const a = 3 * tris[t], b = 3 * tris[t + 1], d = 3 * tris[t + 2];
    const ax = p[a] - c[0], ay = p[a + 1] - c[1], az = p[a + 2] - c[2];
    const bx = p[b] - c[0], by = p[b + 1] - c[1], bz = p[b + 2] - c[2];
    const dx = p[d] - c[0], dy = p[d + 1] - c[1], dz = p[d + 2] - c[2];
    v += ax * (by * dz - bz * dy) + ay * (bz * dx - bx * dz) + az * (bx * dy - by * dx);
  }
  return v / 6;
}

function faceNormals(p: ArrayLike<number>, tris: Uint32Array, out: Float64Array): void {
  for (let t = 0; t < tris.length; t += 3) {
    const a = 3 * tris[t], b = 3 * tris[t + 1], c = 3 * tris[t + 2];
    const ux = p[b] - p[a], uy = p[b + 1] - p[a + 1], uz = p[b + 2] - p[a + 2];
    const vx = p[c] - p[a], vy = p[c + 1] - p[a + 1], vz = p[c + 2] - p[a + 2];
    out[t] = uy * vz - uz * vy; out[t + 1] = uz * vx - ux * vz; out[t + 2] = ux * vy - uy * vx;
  }
}

function minOf(a: Float64Array): number {
  let m = Infinity;
  for (let i = 0; i < a.length; i++) if (a[i] < m) m = a[i];
  return a.length ? m : NaN;
}

/**
 * A compact table of a JointsMeasure (header first; fits 120 columns with two spaces between
 * columns): per joint and method the volume change at every angle, and at `degrees` (default the
 * largest angle) bulge p95 / max, collapse p5 / min, creases and new self-intersecting pairs.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function jointTableRows(m: JointsMeasure, degrees?: number): string[][] {
  checkObject(m, 'm', 'jointTableRows');
  checkList(m.angles, 'm.angles', 'jointTableRows');
  if (degrees === undefined) degrees = Math.max(...m.angles);
  const at = m.angles.indexOf(degrees);
  const f2 = (x: number) => (Number.isFinite(x) ? x.toFixed(2) : String(x));
  const f1 = (x: number) => (Number.isFinite(x) ? (Math.abs(x) < 0.05 ? 0 : x).toFixed(1) : String(x));
  const rows = [['joint', 'method', `volume % ${m.angles.map((a) => `${a}°`).join('/')}`, `bulge p95/max ${degrees}°`,
    `collapse p5/min ${degrees}°`, 'creases', 'new self-x']];
  for (const j of m.joints) {
    m.methods.forEach(({ key }, i) => {
      const r = j.methods[key];
      const head = [i === 0 ? j.hinge.label : '', key];
      if (!r || 'error' in r) { rows.push([...head, `n/a: ${r ? r.error.code : 'not measured'}`, '', '', '', '']); return; }
      const f = r[at];
      rows.push([...head, r.map((x) => f1(x.volumeChange)).join(' / '), f ? `${f2(f.bulgeP95)} / ${f2(f.bulgeMax)}` : 'n/a',
        f ? `${f2(f.collapseP5)} / ${f2(f.collapseMin)}` : 'n/a', f ? String(f.creases) : 'n/a', f ? String(f.newIntersections) : 'n/a']);
    });
  }
  return rows;
}
