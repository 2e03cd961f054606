/**
 * The joint and node passes for WebGPURenderer (joint-level path and GPU DQS; real WebGPU and its
 * WebGL2 fallback): once per frame, each joint's parts and every node's transform and normal texel
 * from the joint poses, for every instance in one draw, into four float targets that the vertex
 * stage reads (tsl.ts) — the TSL twin of node-pass.ts, in the same texel layout (layout.ts,
 * GPU_NODE_TEXTURES).
 *
 * A render-to-texture pass (a mesh whose fragments are its texels, written through `mrt()`), not
 * a compute node: on the WebGL2 fallback three.js runs compute through transform feedback into
 * vertex buffers, which the vertex stage could only read as storage attributes; a render target
 * runs the same way on both backends and is read with `textureLoad`, as the GLSL path reads it.
 *
 * The maths lives here once, as small laid-out functions (like three.js's Skinning.js): the joint
 * pass (`gcsDqsJointTexels`: each joint's quaternion, dual part, uniform scale and scale part, once
 * per joint and frame; GPU DQS's only pass) and the node pass that blends those parts
 * (`nodeTexelsFromParts`), as glsl.ts's; `nodeTexels` computes a node from the joint poses alone
 * for a vertex stage built without a pass. Every pass a renderer draws shares its targets
 * (node-atlas.ts, `TslNodePage`): one render of the joint passes and one of the node passes a frame.
 */
import * as THREE from 'three/webgpu';
import {
  abs, bitAnd, bitOr, bool, cross, dot, float, floatBitsToUint, Fn, If, int, ivec2, mat3, mat4, max, min, mix, mrt, positionGeometry, screenCoordinate, select, shiftLeft, sqrt, step, textureSize, uint, uniform, vec3, vec4,
} from 'three/tsl';
import type { DataTexture, Node, TextureNode } from 'three/webgpu';
import {
  COLLAPSED, DQS_TEXELS_PER_JOINT, GPU_NODE_TEXTURES, GPU_TEXELS_PER_JOINT, RIGID_JOINT_TOLERANCE, UNIFORM_SCALE_TOLERANCE, tableTexelsPerSection, type TableSlots,
} from './layout.js';
import { FLOAT_TARGET_EXTENSION, NodePass } from './node-pass.js';
import { NodePage, PagedPass, PAGE_TARGET_OPTIONS, PAGE_WIDTH, type PageMember, type PassKind } from './node-atlas.js';
import type { GpuSections } from './sections.js';
import { storedRow, texelView } from './texel-tsl.js';

type Bool = Node<'bool'>;
type Float = Node<'float'>;
type Int = Node<'int'>;
type Vec4 = Node<'vec4'>;
type Mat3 = Node<'mat3'>;
type Mat4 = Node<'mat4'>;

/** Names of the four targets, in GPU_NODE_TEXTURES order: the rows of [M | T], then the normal texel. */
const OUTPUTS = ['gcsRow0', 'gcsRow1', 'gcsRow2', 'gcsNormal'] as const;

/** Column c of a matrix (its `[c]`: the typings index arrays, not matrices). */
export const column = <T extends Mat3 | Mat4>(m: T, c: number): T extends Mat3 ? Node<'vec3'> : Vec4 =>
  (m as unknown as { element(i: number): T extends Mat3 ? Node<'vec3'> : Vec4 }).element(c);

/** The largest absolute entry of a 3×3 matrix. */
export function largest(m: Mat3): Float {
  const e = max(max(abs(column(m, 0)), abs(column(m, 1))), abs(column(m, 2)));
  return max(max(e.x, e.y), e.z);
}

/** Texel i of a float data texture read with integer coordinates (row-major, the texture's width; a texelView: no row flip). */
export function texel(tex: TextureNode, i: Int): Vec4 {
  const w = int((textureSize(tex) as unknown as Node<'ivec2'>).x);
  const y = i.div(w);
  return tex.load(ivec2(i.sub(y.mul(w)), y));
}

// ------------------------------------------------------------ shader functions (values in, value out)

/** The rotation matrix of quaternion q (x, y, z, w) scaled by k2 = 2 / |q|² (2 for a unit quaternion). */
export const gcsRotation = Fn(([q, k2]: [Vec4, Float]) => {
  const xx = q.x.mul(q.x), yy = q.y.mul(q.y), zz = q.z.mul(q.z), xy = q.x.mul(q.y), xz = q.x.mul(q.z), yz = q.y.mul(q.z);
  const wx = q.w.mul(q.x), wy = q.w.mul(q.y), wz = q.w.mul(q.z);
  return mat3(
    vec3(float(1).sub(k2.mul(yy.add(zz))), k2.mul(xy.add(wz)), k2.mul(xz.sub(wy))),
    vec3(k2.mul(xy.sub(wz)), float(1).sub(k2.mul(xx.add(zz))), k2.mul(yz.add(wx))),
    vec3(k2.mul(xz.add(wy)), k2.mul(yz.sub(wx)), float(1).sub(k2.mul(xx.add(yy)))),
  );
}).setLayout({ name: 'gcsRotation', type: 'mat3', inputs: [{ name: 'q', type: 'vec4' }, { name: 'k2', type: 'float' }] });

/**
 * The CPU's normalMatrix as one texel (x, y, 0, flag), from which the vertex stage takes
 * N = cof(M·x)·y (M = R·K, cof(R) = R), the GLSL's gcsNormalTexel: (1/s, 1, 0, 0) when K is a
 * positive uniform scale s·I (every entry within UNIFORM_SCALE_TOLERANCE × s); else
 * (1/kbig, 1/big, 0, −1), R·cof(K/kbig)/big with entries ≤ 1, normals renormalised; a collapsed
 * K gives (0, 0, 0, −1): N = 0, the normal keeps its rest direction.
 */
export const gcsNormalTexel = Fn(([k]: [Mat3]) => {
  const s = column(k, 0).x.add(column(k, 1).y).add(column(k, 2).z).div(3).toVar();
  const deviation = largest(k.sub(mat3(vec3(s, 0, 0), vec3(0, s, 0), vec3(0, 0, s))));
  const out = vec4(0, 0, 0, -1).toVar();
  If(s.greaterThan(0).and(deviation.lessThanEqual(s.mul(UNIFORM_SCALE_TOLERANCE))), () => {
    out.assign(vec4(float(1).div(s), 1, 0, 0));
  }).Else(() => {
    const kbig = largest(k).toVar();
    If(kbig.greaterThan(COLLAPSED), () => {
      const a = k.mul(float(1).div(kbig)).toVar();
      const a0 = column(a, 0), a1 = column(a, 1), a2 = column(a, 2);
      const big = largest(mat3(cross(a1, a2), cross(a2, a0), cross(a0, a1))).toVar();
      If(big.greaterThan(COLLAPSED), () => out.assign(vec4(float(1).div(kbig), float(1).div(big), 0, -1)));
    });
  });
  return out;
}).setLayout({ name: 'gcsNormalTexel', type: 'vec4', inputs: [{ name: 'k', type: 'mat3' }] });

/**
 * A node's four texels (matrix columns: the rows of [M | T], then the normal texel) from up to
 * `slots` joint poses at their weights (a joint past the last has weight 0: it adds nothing): the
 * dual-quaternion blend, each joint's scale part K_j = R_jᵀ S_j blended linearly and applied
 * first, M = R·K, the CPU's blendPoses. With a centre of rotation p (`centre`, w = 1; w = 0:
 * none) it turns about p, moved where LBS moves it: T = Σ w_i (S_i p + t_i − p) − (M p − p).
 * Each pose: columns 0–2 the rows of [S_j | t_j], column 3 its rotation quaternion.
 */
function nodeBlendFunction(slots: TableSlots) {
  const lanes = ['x', 'y', 'z', 'w'] as const;
  const inputs = [
    ...Array.from({ length: slots }, (_, c) => ({ name: `p${c}`, type: 'mat4' })),
    ...Array.from({ length: slots / 4 }, (_, g) => ({ name: `w${g}`, type: 'vec4' })),
    { name: 'centre', type: 'vec4' },
  ];
  return Fn((args: Node[]) => {
    const all = [...args]; // TSL hands the parameters as an iterable proxy
    const poses = all.slice(0, slots) as Mat4[], weights = all.slice(slots, slots + slots / 4) as Vec4[];
    const centre = all[slots + slots / 4] as Vec4;
    const pivot = column(poses[0], 3);
    const br = vec4(0).toVar(), bd = vec4(0).toVar();
    const k = mat3(vec3(0), vec3(0), vec3(0)).toVar();
    const moved = vec3(0).toVar();
    for (let c = 0; c < slots; c++) {
      const p = poses[c], w = weights[c >> 2][lanes[c & 3]];
      const r0 = column(p, 0), r1 = column(p, 1), r2 = column(p, 2), q = column(p, 3);
      const s = mat3(r0.xyz, r1.xyz, r2.xyz).transpose(), t = vec3(r0.w, r1.w, r2.w);
      const d = vec4(q.w.mul(t).add(cross(t, q.xyz)), dot(t, q.xyz).negate()).mul(0.5);
      const sw = select(dot(q, pivot).lessThan(0), w.negate(), w);
      br.addAssign(q.mul(sw));
      bd.addAssign(d.mul(sw));
      k.addAssign(gcsRotation(q, float(2)).transpose().mul(s).mul(w));
      moved.addAssign(s.mul(centre.xyz).add(t).sub(centre.xyz).mul(w));
    }
    const inv2 = float(1).div(dot(br, br)).toVar();
    const t = br.w.mul(bd.xyz).sub(bd.w.mul(br.xyz)).sub(cross(bd.xyz, br.xyz)).mul(inv2.mul(2)).toVar();
    const m = gcsRotation(br, inv2.mul(2)).mul(k).toVar();
    If(centre.w.greaterThan(0.5), () => {
      t.assign(moved.sub(m.mul(centre.xyz).sub(centre.xyz)));
    });
    const rows = m.transpose().toVar();
    return mat4(vec4(column(rows, 0), t.x), vec4(column(rows, 1), t.y), vec4(column(rows, 2), t.z), gcsNormalTexel(k));
  }).setLayout({ name: `gcsNodeBlend${slots}`, type: 'mat4', inputs });
}
const gcsNodeBlend = { 4: nodeBlendFunction(4), 8: nodeBlendFunction(8) } as const;

/**
 * s where k is a positive uniform scale s·I within RIGID_JOINT_TOLERANCE × s (the CPU's test for a
 * uniform frame, per joint; s exactly the diagonal where its entries are equal), else 0: the
 * GLSL's gcsRigidScale.
 */
const gcsRigidScale = Fn(([k]: [Mat3]) => {
  const diagonal = vec3(column(k, 0).x, column(k, 1).y, column(k, 2).z).toVar();
  const s = diagonal.x.add(diagonal.y).add(diagonal.z).div(3).toVar();
  const deviation = largest(k.sub(mat3(vec3(s, 0, 0), vec3(0, s, 0), vec3(0, 0, s))));
  const out = float(0).toVar();
  If(s.greaterThan(0).and(deviation.lessThanEqual(s.mul(RIGID_JOINT_TOLERANCE))), () => {
    out.assign(select(diagonal.x.equal(diagonal.y).and(diagonal.y.equal(diagonal.z)), diagonal.x, s));
  });
  return out;
}).setLayout({ name: 'gcsRigidScale', type: 'float', inputs: [{ name: 'k', type: 'mat3' }] });

/**
 * DQS's joint pass: one of a joint's two texels (DQS_TEXELS_PER_JOINT) in the four targets, from
 * its pose (columns 0–2 the rows of [S | t], column 3 its quaternion q): the first (q, its dual
 * part ½ (0, t)·q, (u, 0, 0, 0), 0), u = gcsRigidScale(K); the second (the rows of K = Rᵀ S, 0).
 * The GLSL's DQS_PASS_FRAGMENT.
 */
const gcsDqsJointTexels = Fn(([pose, second]: [Mat4, Bool]) => {
  const r0 = column(pose, 0), r1 = column(pose, 1), r2 = column(pose, 2), q = column(pose, 3);
  const t = vec3(r0.w, r1.w, r2.w);
  const k = gcsRotation(q, float(2)).transpose().mul(mat3(r0.xyz, r1.xyz, r2.xyz).transpose()).toVar();
  const out = mat4(vec4(0), vec4(0), vec4(0), vec4(0)).toVar();
  If(second, () => {
    const rows = k.transpose();
    out.assign(mat4(vec4(column(rows, 0), 0), vec4(column(rows, 1), 0), vec4(column(rows, 2), 0), vec4(0)));
  }).Else(() => {
    const dual = vec4(q.w.mul(t).add(cross(t, q.xyz)), dot(t, q.xyz).negate()).mul(0.5);
    out.assign(mat4(q, dual, vec4(gcsRigidScale(k), 0, 0, 0), vec4(0)));
  });
  return out;
}).setLayout({ name: 'gcsDqsJointTexels', type: 'mat4', inputs: [{ name: 'pose', type: 'mat4' }, { name: 'second', type: 'bool' }] });

// ------------------------------------------------------------ accessors (texel reads, per skin)

/**
 * The joint poses as the maths reads them: the full format's texture, and where the skin has one
 * (GCS and DQS on path 'joints') the compact twin with the uniform saying the frame is compact (1).
 */
export interface PoseViews { joints: TextureNode; compact: { texture: TextureNode; format: Int } | null }

/** This frame's joint poses (`previous`: the frame before's, for velocity) as PoseViews. */
export function poseViews(sections: GpuSections, previous = false): PoseViews {
  const joints = texelView(previous ? sections.previousTexture() : sections.texture);
  const twin = sections.compactPoses(previous);
  if (!twin) return { joints, compact: null };
  const format = uniform(twin.format.value, 'int').onObjectUpdate(() => twin.format.value) as unknown as Int;
  return { joints, compact: { texture: texelView(twin.texture), format } };
}

/** The node maths' inputs: joint poses (per frame) and the section table (static, `slots` joints per section). */
export interface JointInputs extends PoseViews { table: TextureNode; slots: TableSlots; first: Int }

/**
 * Joint j's pose as four texels: the rows of S_j (translation in w) and its rotation quaternion.
 * Where the texture has a compact twin (GpuSections.compactTexture: GCS and DQS), a frame whose
 * poses are compact (one uniform for the frame) reads those instead: the GLSL's gcsJoint.
 */
export function jointPose(inputs: Omit<JointInputs, 'table'>, j: Int): Mat4 {
  const i = inputs.first.add(j.mul(GPU_TEXELS_PER_JOINT)).toVar();
  const full = () => mat4(texel(inputs.joints, i), texel(inputs.joints, i.add(1)), texel(inputs.joints, i.add(2)), texel(inputs.joints, i.add(3)));
  const compact = inputs.compact;
  if (!compact) return full();
  const pose = mat4(vec4(0), vec4(0), vec4(0), vec4(0)).toVar();
  If(compact.format.equal(1), () => {
    const g = i.div(GPU_TEXELS_PER_JOINT).toVar(), first = g.mul(3).div(2).toVar(); // 6 floats from lane 0 (g even) or 2 (odd)
    pose.assign(gcsCompactPose(texel(compact.texture, first), texel(compact.texture, first.add(1)), g.bitAnd(1).equal(1)));
  }).Else(() => { pose.assign(full()); });
  return pose;
}

/**
 * A joint's pose from its compact floats (texels a, b; from a's lane 2 where `odd`): the smallest
 * three of q, the dropped one's index in the lowest bits of the first two, then t; S = R(q). The
 * same mat4 as the full format's four texels.
 */
const gcsCompactPose = Fn(([a, b, odd]: [Vec4, Vec4, Bool]) => {
  const c = select(odd, vec3(a.z, a.w, b.x), a.xyz).toVar();
  const t = select(odd, b.yzw, vec3(a.w, b.x, b.y)).toVar();
  const lowest = (v: Float) => bitAnd(floatBitsToUint(v) as unknown as Node<'uint'>, uint(1));
  const dropped = int(bitOr(lowest(c.x), shiftLeft(lowest(c.y), uint(1)))).toVar();
  const d = sqrt(max(float(1).sub(dot(c, c)), 0)).toVar();
  const q = vec4(c, d).toVar();
  If(dropped.equal(0), () => { q.assign(vec4(d, c)); })
    .ElseIf(dropped.equal(1), () => { q.assign(vec4(c.x, d, c.y, c.z)); })
    .ElseIf(dropped.equal(2), () => { q.assign(vec4(c.x, c.y, d, c.z)); });
  const rows = gcsRotation(q, float(2)).transpose().toVar();
  return mat4(vec4(column(rows, 0), t.x), vec4(column(rows, 1), t.y), vec4(column(rows, 2), t.z), q);
}).setLayout({ name: 'gcsCompactPose', type: 'mat4', inputs: [{ name: 'a', type: 'vec4' }, { name: 'b', type: 'vec4' }, { name: 'odd', type: 'bool' }] });

/**
 * Section s's row of the table: per 4 slots a texel of joints (−1 past the last) then one of
 * weights; last, its centre of rotation (w = 0: none).
 */
function sectionRow(inputs: JointInputs, s: Int): { joints: Vec4[]; weights: Vec4[]; centre: () => Vec4 } {
  const texels = tableTexelsPerSection(inputs.slots);
  const row = s.mul(texels).toVar();
  const joints: Vec4[] = [], weights: Vec4[] = [];
  for (let g = 0; g < inputs.slots / 4; g++) {
    joints.push(texel(inputs.table, row.add(2 * g)).toVar());
    weights.push(texel(inputs.table, row.add(2 * g + 1)).toVar());
  }
  return { joints, weights, centre: () => texel(inputs.table, row.add(texels - 1)) };
}

/**
 * Node s's four texels from the joint poses alone (for a vertex stage built without a pass, which
 * then computes a node per vertex that uses it): a rigid core is its joint's pose (normal texel from
 * K = Rᵀ S); otherwise its joints' poses blended (gcsNodeBlend). The pass blends the joint pass's
 * parts instead (nodeTexelsFromParts): the same node up to rounding.
 */
export function nodeTexels(inputs: JointInputs, s: Int): Mat4 {
  const { joints, weights, centre } = sectionRow(inputs, s);
  const pose = jointPose(inputs, int(joints[0].x)).toVar();
  const out = mat4(pose).toVar();
  If(joints[0].y.greaterThanEqual(0), () => {
    out.assign(jointBlend(inputs, joints, weights, centre(), pose));
  }).Else(() => {
    const r0 = column(pose, 0), r1 = column(pose, 1), r2 = column(pose, 2), q = column(pose, 3);
    const k = gcsRotation(q, float(2)).transpose().mul(mat3(r0.xyz, r1.xyz, r2.xyz).transpose());
    out.assign(mat4(r0, r1, r2, gcsNormalTexel(k)));
  });
  return out;
}

const LANES = ['x', 'y', 'z', 'w'] as const;

/**
 * The blend of joints `ids` (per 4 slots a vec4; −1 past the last) at `weights`, about `centre`
 * (w = 0: none), as a node's four texels (gcsNodeBlend): the section table's joints in the pass,
 * a vertex's own joints for DQS. `first`: the first joint's pose when already read.
 */
export function jointBlend(inputs: Omit<JointInputs, 'table'>, ids: Vec4[], weights: Vec4[], centre: Vec4, first?: Mat4): Mat4 {
  const poses: Mat4[] = [first ?? jointPose(inputs, int(max(ids[0].x, 0)))];
  for (let c = 1; c < inputs.slots; c++) poses.push(jointPose(inputs, int(max(ids[c >> 2][LANES[c & 3]], 0))));
  // A joint past the last (−1) gets weight 0: it adds nothing (the GLSL's early break).
  const used = weights.map((w, g) => step(vec4(0), ids[g]).mul(w));
  return gcsNodeBlend[inputs.slots](...poses, ...used, centre);
}

/** The node pass's inputs: the joint poses (a rigid core, a centre's LBS motion), the table, and the joint pass's parts (its targets 0–2, this instance's row). */
export interface PartsInputs extends JointInputs { parts: TextureNode[]; row: Int }

/**
 * Node s's four texels from its joints' parts as the joint pass wrote them once per joint and frame
 * (the GLSL's gcsSectionBlend and gcsBlend): a rigid core is its joint's pose (normal texel from its
 * K); otherwise the dual-quaternion blend of the parts: M = s·R where every joint is a uniform
 * scale (normal texel (1/s, 1, 0, 0)), else M = R·K with K = Σ w K_j; with a centre of rotation
 * (w = 1) turned about it, the centre moved by LBS.
 */
export function nodeTexelsFromParts(inputs: PartsInputs, s: Int): Mat4 {
  const { joints: ids, weights, centre: centreOf } = sectionRow(inputs, s);
  const [p0, p1, p2] = inputs.parts;
  const first = (c: number) => ivec2(int(max(ids[c >> 2][LANES[c & 3]], 0)).mul(DQS_TEXELS_PER_JOINT), inputs.row);
  const scale = (c: number): Mat3 => {
    const k = first(c).add(ivec2(1, 0)).toVar();
    return mat3(p0.load(k).xyz, p1.load(k).xyz, p2.load(k).xyz).transpose();
  };
  const out = mat4(vec4(0), vec4(0), vec4(0), vec4(0)).toVar();
  If(ids[0].y.lessThan(0), () => {
    const pose = jointPose(inputs, int(ids[0].x));
    out.assign(mat4(column(pose, 0), column(pose, 1), column(pose, 2), gcsNormalTexel(scale(0))));
  }).Else(() => {
    // A joint past the last (−1) gets weight 0: it adds nothing (the GLSL's continue).
    const weight = (c: number) => weights[c >> 2][LANES[c & 3]].mul(step(0, ids[c >> 2][LANES[c & 3]]));
    const pivot = p0.load(first(0)).toVar();
    const br = vec4(0).toVar(), bd = vec4(0).toVar(), sum = float(0).toVar(), rigid = bool(true).toVar();
    for (let c = 0; c < inputs.slots; c++) {
      const w = weight(c).toVar(), where = first(c).toVar();
      const q = p0.load(where).toVar();
      const sw = select(dot(q, pivot).lessThan(0), w.negate(), w);
      br.addAssign(q.mul(sw));
      bd.addAssign(p1.load(where).mul(sw));
      const u = p2.load(where).x.toVar();
      sum.addAssign(w.mul(u));
      rigid.assign(rigid.and(u.greaterThan(0).or(w.greaterThan(0).not())));
    }
    const inv2 = float(1).div(dot(br, br)).toVar();
    const t = br.w.mul(bd.xyz).sub(bd.w.mul(br.xyz)).sub(cross(bd.xyz, br.xyz)).mul(inv2.mul(2)).toVar();
    const r = gcsRotation(br, inv2.mul(2)).toVar();
    const m = r.mul(sum).toVar(), n = vec4(float(1).div(sum), 1, 0, 0).toVar();
    If(rigid.not(), () => {
      const k = mat3(vec3(0), vec3(0), vec3(0)).toVar();
      for (let c = 0; c < inputs.slots; c++) k.addAssign(scale(c).mul(weight(c)));
      m.assign(r.mul(k));
      n.assign(gcsNormalTexel(k));
    });
    const centre = centreOf();
    If(centre.w.greaterThan(0.5), () => {
      const moved = vec3(0).toVar(); // Σ w_i (S_i p − p): where LBS moves the centre p
      for (let c = 0; c < inputs.slots; c++) {
        const pose = jointPose(inputs, int(max(ids[c >> 2][LANES[c & 3]], 0)));
        const r0 = column(pose, 0), r1 = column(pose, 1), r2 = column(pose, 2);
        const sj = mat3(r0.xyz, r1.xyz, r2.xyz).transpose(), tj = vec3(r0.w, r1.w, r2.w);
        moved.addAssign(sj.mul(centre.xyz).add(tj).sub(centre.xyz).mul(weight(c)));
      }
      t.assign(moved.sub(m.mul(centre.xyz).sub(centre.xyz)));
    });
    const rows = m.transpose().toVar();
    out.assign(mat4(vec4(column(rows, 0), t.x), vec4(column(rows, 1), t.y), vec4(column(rows, 2), t.z), n));
  });
  return out;
}

/** Whether `renderer` draws through WebGL2 without float render targets (the pass cannot run there). */
function noFloatTargets(renderer: unknown): boolean {
  const backend = (renderer as { backend?: { isWebGLBackend?: boolean; extensions?: { has(name: string): boolean } } })?.backend;
  return backend?.isWebGLBackend === true && backend.extensions?.has(FLOAT_TARGET_EXTENSION) === false;
}

/** A page of node passes for WebGPURenderer (node-atlas.ts), with the previous frame's texels for velocity. */
export class TslNodePage extends NodePage<THREE.RenderTarget> {
  /**
   * Velocity: the targets as the frame before left them (copied on the GPU once per frame, before
   * the frame's first run), made on first use (previousTextures).
   */
  private previous: { target: THREE.RenderTarget; filled: boolean } | null = null;
  /** The renderer's frame (info.frame) whose copy was made. */
  private keptFrame = -1;
  /** Members placed since the last copy: their previous rows are computed after their first run (no motion). */
  private readonly unfilled = new Set<PageMember>();

  constructor(width: number, rows: number) {
    super(width, rows, (w, h) => {
      const target = new THREE.RenderTarget(w, h, PAGE_TARGET_OPTIONS);
      target.textures.forEach((t, i) => { t.name = OUTPUTS[i]; });
      return target;
    });
  }

  /** The previous frame's textures (made on first use; until a frame has passed they show this frame's). */
  previousTextures(): THREE.Texture[] {
    if (!this.previous) this.previous = { target: this.target.clone(), filled: false };
    return this.previous.target.textures;
  }

  override add(member: PageMember): boolean {
    if (!super.add(member)) return false;
    this.unfilled.add(member);
    return true;
  }

  protected override grow(height: number): void {
    super.grow(height);
    this.previous?.target.setSize(this.width, height);
    if (this.previous) this.previous.filled = false;
  }

  /**
   * At each draw of a member, before any run: once per frame the texels become the previous
   * frame's (a frame drawn again without an update: no motion).
   */
  beginFrame(renderer: THREE.WebGPURenderer): void {
    const previous = this.previous, frame = renderer.info.frame;
    if (!previous || frame === this.keptFrame) return;
    this.keptFrame = frame;
    if (previous.filled) this.copy(renderer);
  }

  /** The stale members' run; members new to the page run once more into the previous targets (no motion rather than unwritten texels). */
  override run(renderer: object): void {
    const r = renderer as THREE.WebGPURenderer, previous = this.previous;
    super.run(renderer);
    if (!previous) { this.unfilled.clear(); return; }
    if (!previous.filled) { this.copy(r); this.unfilled.clear(); return; }
    if (!this.unfilled.size) return;
    for (const { member } of this.members) member.quad.visible = this.unfilled.has(member);
    this.unfilled.clear();
    this.drawInto(r, previous.target);
  }

  /** Velocity, before a draw that reads the previous textures: made after this frame's run, they are filled with it. */
  fillPrevious(renderer: THREE.WebGPURenderer): void {
    if (this.previous && !this.previous.filled) this.copy(renderer);
  }

  /** The targets copied into the previous frame's (four small GPU copies). */
  private copy(renderer: THREE.WebGPURenderer): void {
    const previous = this.previous!;
    this.target.textures.forEach((t, i) => renderer.copyTextureToTexture(t, previous.target.textures[i]));
    previous.filled = true;
  }

  protected override draw(renderer: object): void {
    this.drawInto(renderer as unknown as THREE.WebGPURenderer, this.target);
  }

  /** One render of the visible quads into `into`, restoring the render target, cube face, mip level, MRT and autoClear. */
  private drawInto(r: THREE.WebGPURenderer, into: THREE.RenderTarget): void {
    const target = r.getRenderTarget(), face = r.getActiveCubeFace(), level = r.getActiveMipmapLevel();
    const outputMRT = r.getMRT(), autoClear = r.autoClear;
    r.autoClear = false; // each member writes every texel of its rows
    r.setMRT(null);
    r.setRenderTarget(into);
    r.render(this.scene, this.camera);
    r.setRenderTarget(target, face, level);
    r.setMRT(outputMRT);
    r.autoClear = autoClear;
  }

  override dispose(): void {
    super.dispose();
    this.previous?.target.dispose();
  }
}

/** The page a WebGPURenderer's passes share. */
const makeTslPage = (width: number, rows: number): TslNodePage => new TslNodePage(width, rows);

/**
 * The pass: its rows of the renderer's page (node-atlas.ts) of GPU_NODE_TEXTURES float textures,
 * one texel per node (instance k's node s is node k·sections + s from the pass's first texel,
 * row-major, PAGE_WIDTH wide); for method 'dqs' the joint pass, two texels per joint, one row per
 * instance (DQS_TEXELS_PER_JOINT; gcsDqsJointTexels). Runs at the skin's first draw after
 * `GpuSections.update()` (shadow or colour pass), with every other stale pass of the page in one
 * render: every pass of that frame reads the same texels, and a frame drawn twice computes them once.
 */
export class TslNodePass extends PagedPass<TslNodePage> {
  /** Times the pass has run (once per GpuSections.update() that was drawn). */
  runs = 0;
  /** The mesh that draws this pass's fragments into its page. */
  readonly quad: THREE.Mesh;
  /** The vertex stage's offset into the page: the pass's first texel (GCS) or first row (DQS). */
  readonly offset = uniform(0, 'int');
  /** The page's height in rows: where a backend stores render targets upside down, reads flip rows by it (texel-tsl.ts). */
  readonly pageRows = uniform(1, 'int');
  /** GCS: the joint pass whose parts the node pass reads (drawn first); null for a joint pass. */
  readonly jointPass: TslNodePass | null;
  private readonly material: THREE.NodeMaterial;
  private readonly geometry = new THREE.BufferGeometry();
  /** What the vertex stage reads: one texture node per target. */
  private readonly views: TextureNode[];
  /** Velocity: views of the page's previous frame (made on first use, previousTextureNode). */
  private previousViewNodes: TextureNode[] | null = null;
  /** WebGLRenderer with WebGLNodesHandler: the GLSL pass run instead (made at its first draw). */
  private glsl: NodePass | null = null;
  /** The fragment's numbering: the first row, the page's width, and the quad's corners in clip space. */
  private readonly firstRow = uniform(0, 'int');
  private readonly pageWidth = uniform(PAGE_WIDTH, 'int');
  private readonly rect = uniform(new THREE.Vector4());

  /**
   * @param sections The GPU sections whose joint poses and section table the pass reads.
   * @param kind 'joints': the joint pass (GPU DQS's, and what a GCS node pass reads); 'nodes': the node pass (GCS), with its joint pass.
   */
  constructor(sections: GpuSections, kind: PassKind = sections.method === 'dqs' ? 'joints' : 'nodes') {
    super(sections, kind);
    const writesJoints = kind === 'joints', stride = sections.transforms.texelsPerInstance;
    const S = this.perInstance, nodes = sections.instanceCount * S;
    // One fragment per texel: its node from the fragment's position in the pass's rows (texels past the last repeat the last node).
    const poses = poseViews(sections);
    const table = writesJoints ? null : texelView(sections.table as DataTexture);
    this.jointPass = writesJoints ? null : new TslNodePass(sections, 'joints');
    const parts = this.jointPass;
    const texels = Fn(() => {
      const at = ivec2(screenCoordinate).toVar();
      const row = at.y.sub(this.firstRow).toVar();
      if (writesJoints) {
        const joint = at.x.div(DQS_TEXELS_PER_JOINT).toVar();
        const pose = jointPose({ ...poses, slots: sections.tableSlots, first: row.mul(stride) }, joint);
        return gcsDqsJointTexels(pose, at.x.notEqual(joint.mul(DQS_TEXELS_PER_JOINT)));
      }
      const texel = (min(row.mul(this.pageWidth).add(at.x) as unknown as Float, int(nodes - 1) as unknown as Float) as unknown as Int).toVar();
      const instance = texel.div(S).toVar();
      const inputs: PartsInputs = {
        ...poses, table: table!, slots: sections.tableSlots, first: instance.mul(stride),
        parts: [0, 1, 2].map((i) => parts!.textureNode(i)), row: storedRow(parts!.offset.add(instance), parts!.pageRows),
      };
      return nodeTexelsFromParts(inputs, texel.sub(instance.mul(S)));
    })().toVar() as unknown as Mat4;
    this.material = new THREE.NodeMaterial();
    this.material.name = 'gcsNodePass';
    // Two triangles over the pass's texels (rows counted from the top, as screenCoordinate and textureLoad count them).
    this.material.vertexNode = vec4(mix(this.rect.xy, this.rect.zw, positionGeometry.xy), 0, 1);
    // The fragment is the four outputs (an output struct: no lighting, fog or colour transform).
    this.material.fragmentNode = mrt(Object.fromEntries(OUTPUTS.map((name, i) => [name, column(texels, i)])));
    this.material.depthTest = false;
    this.material.depthWrite = false;
    this.material.blending = THREE.NoBlending;
    this.material.side = THREE.DoubleSide;
    this.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]), 3));
    this.quad = new THREE.Mesh(this.geometry, this.material);
    this.views = OUTPUTS.map(() => texelView(EMPTY));
  }

  /** The page's target this pass draws into (shared with other passes); null before its first draw. */
  get target(): THREE.RenderTarget | null {
    return this.page?.target ?? null;
  }

  /** The vertex stage's view of target i (0–2: rows of [M | T], 3: the normal texel); one node per target, shared by every material. */
  textureNode(i: number): TextureNode {
    return this.views[i];
  }

  /**
   * Velocity: a view of target i as the frame before drew it (the run before this frame's), for a
   * velocity pass's previous positions: the nodes of the previous frame, read as this frame's are,
   * not blended again per vertex. Until a frame has passed, and in a frame drawn without a new run,
   * it shows this frame's (no motion).
   */
  previousTextureNode(i: number): TextureNode {
    this.previousViewNodes ??= OUTPUTS.map((_, t) => texelView(this.page ? this.page.previousTextures()[t] : EMPTY));
    return this.previousViewNodes[i];
  }

  /** The vertex stage's views of the previous frame's targets (previousTextureNode), as textureNode gives this frame's. */
  previousViews(): Pick<TslNodePass, 'textureNode' | 'pageRows'> {
    return { textureNode: (i) => this.previousTextureNode(i), pageRows: this.pageRows };
  }

  /**
   * Writes every node of every instance for the current joint poses, unless already written since
   * the last GpuSections.update(), with every other stale pass of the renderer's page in one
   * render; returns why `renderer` cannot, or null. WebGPURenderer: the page's render (restoring the
   * render target, cube face, mip level and MRT). A WebGLRenderer with three.js's WebGLNodesHandler:
   * the GLSL pass (node-pass.ts) on a page of its own, same layout, whose targets the views then
   * show — while the pass is one row high: the handler's texture reads count rows from the top
   * (WebGPU's convention) and the GLSL pass writes them from the bottom.
   */
  render(renderer: unknown): string | null {
    const r = renderer as THREE.WebGPURenderer & { isWebGLRenderer?: boolean };
    if (r?.isWebGLRenderer) {
      const why = NodePass.unsupported(renderer);
      if (why) return why;
      if (this.rows > 1) return `a WebGLRenderer with WebGLNodesHandler reads the node pass's targets from the other end when they span more than one row (more than ${PAGE_WIDTH} nodes)`;
      this.glsl ??= new NodePass(this.sections, true);
      this.show(this.glsl.target!.textures, null);
      this.offset.value = 0;
      this.pageRows.value = this.glsl.target!.height;
      return this.glsl.render(renderer as unknown as import('three').WebGLRenderer);
    }
    if (noFloatTargets(renderer)) return `this renderer's WebGL2 backend has no ${FLOAT_TARGET_EXTENSION} (float render targets), which the joint-level path's node pass draws into`;
    const why = this.jointPass?.render(renderer) ?? this.seat(r, makeTslPage); // the parts this pass reads, first
    if (why) return why;
    this.page!.beginFrame(r);
    if (this.stale()) this.page!.run(r);
    return null;
  }

  /** Velocity, before each draw that reads previousTextureNode: the page's previous textures filled with this frame's until a frame has passed. */
  fillPrevious(renderer: unknown): void {
    const r = renderer as THREE.WebGPURenderer;
    if (this.page && this.previousViewNodes && r?.isWebGPURenderer) this.page.fillPrevious(r);
  }

  /** @internal The texels hold the current joint poses (one more run). */
  override drawn(): void {
    super.drawn();
    this.runs++;
  }

  /** @internal This pass's rows start at `firstRow` of `page`: its quad, its fragments' numbering and the vertex stage's reads follow. */
  place(page: NodePage, firstRow: number): void {
    const tslPage = page as unknown as TslNodePage;
    const { width, height } = tslPage.target;
    this.firstRow.value = firstRow;
    this.pageWidth.value = width;
    this.rect.value.set(-1, 1 - 2 * firstRow / height, 2 * this.columns / width - 1, 1 - 2 * (firstRow + this.rows) / height);
    this.offset.value = this.kind === 'joints' ? firstRow : firstRow * width;
    this.pageRows.value = height;
    this.show(tslPage.target.textures, this.previousViewNodes ? tslPage.previousTextures() : null);
  }

  /** Points the vertex stage's views at `textures` (the page's, or the GLSL pass's) and the previous views at `previous`. */
  private show(textures: THREE.Texture[], previous: THREE.Texture[] | null): void {
    for (let i = 0; i < this.views.length; i++) if (this.views[i].value !== textures[i]) this.views[i].value = textures[i];
    if (previous && this.previousViewNodes) for (let i = 0; i < previous.length; i++) this.previousViewNodes[i].value = previous[i];
  }

  dispose(): void {
    this.leave(makeTslPage);
    this.material.dispose();
    this.geometry.dispose();
    this.glsl?.dispose();
    this.jointPass?.dispose();
  }
}

/** What a view shows before its pass has a page: one float texel. */
const EMPTY = new THREE.DataTexture(new Float32Array(4), 1, 1, THREE.RGBAFormat, THREE.FloatType);
