/**
 * The GCS vertex stage in TSL, for WebGPURenderer (real WebGPU and its WebGL2 fallback), written as
 * three.js writes its own skinning (nodes/accessors/Skinning.js): the maths in small functions with
 * a layout (`Fn(...).setLayout(...)`, compiled once as shader functions), texel reads in plain
 * accessors, `If` where the GLSL chunk (glsl.ts) branches, both from the same constants
 * (layout.ts). `gcsPositionNode` is a node material's `positionNode`: it returns the deformed
 * position and turns `normalLocal` (and `tangentLocal` where the geometry has tangents) on the way
 * — after the morph targets, so morphs apply first, as on the CPU. The joint-level path's node
 * maths runs in the node pass (node-pass-tsl.ts), once per node and frame; here each vertex reads
 * its 1–3 nodes and blends them.
 *
 * The laid-out functions take values only: a shader function is built once per renderer and
 * reused by every material, so it must not name a texture or uniform of one skin.
 */
import {
  abs, attribute, bool, cross, dot, float, Fn, If, instanceIndex, int, ivec2, length, mat3, min, normalGeometry, normalLocal,
  OnObjectUpdate, positionGeometry, positionLocal, positionPrevious, pow, referenceAttribute, select, step, tangentGeometry, tangentLocal, transformNormal,
  uniform, vec3, vec4,
} from 'three/tsl';
import type { DataTexture, Node, NodeBuilder, TextureNode } from 'three/webgpu';
import {
  ALMOST_EQUAL_TRACE, ALMOST_EQUAL_TRACE3, BLEND_ATTRIBUTE, BLEND_THIRD_ATTRIBUTE, COLLAPSED, DQS_TEXELS_PER_JOINT, INFLUENCE_ATTRIBUTES, WEIGHT_ATTRIBUTES, GPU_NODE_TEXTURES,
  GPU_TEXELS_PER_SECTION, LENGTH_FIX, NEAR_TRACE, NEAR_TRACE3, PREVIOUS_POSITION_ATTRIBUTE, SECTION_ATTRIBUTE,
} from './layout.js';
import { column, gcsNormalTexel, gcsRotation, jointBlend, jointPose, largest, nodeTexels, poseViews, texel, type JointInputs, type PoseViews, type TslNodePass } from './node-pass-tsl.js';
import type { GpuSections } from './sections.js';
import { storedRow, texelView } from './texel-tsl.js';
import { PAGE_WIDTH } from './node-atlas.js';
import { checkObject } from '../arguments.js';

type Bool = Node<'bool'>;
type Int = Node<'int'>;
type Vec3 = Node<'vec3'>;
type Vec4 = Node<'vec4'>;
type Mat3 = Node<'mat3'>;
type Mat4 = Node<'mat4'>;

/** Σ of the entrywise products of two matrices: 1 + 2 cos θ for rotations θ apart. */
const gcsTrace = Fn(([a, b]: [Mat3, Mat3]) =>
  dot(column(a, 0), column(b, 0)).add(dot(column(a, 1), column(b, 1))).add(dot(column(a, 2), column(b, 2))),
).setLayout({ name: 'gcsTrace', type: 'float', inputs: [{ name: 'a', type: 'mat3' }, { name: 'b', type: 'mat3' }] });

/**
 * A normal or tangent as the CPU turns it (joint-level path): blended (smooth) normals are left as
 * they are when both sides are rotations less than 2.8° apart, get the cubic length fix when less
 * than 35° apart, else are normalised (a vanished one keeps its rest direction); unblended ones
 * are normalised only when the scale asks for it.
 */
const gcsTurnJoint = Fn(([v, n, near, almostEqual, normalise]: [Vec3, Mat3, Bool, Bool, Bool]) => {
  const x = n.mul(v).toVar();
  const out = x.toVar();
  If(almostEqual, () => {
    out.assign(x);
  }).ElseIf(near, () => {
    const e = dot(x, x).sub(1);
    out.assign(x.mul(float(1).add(e.mul(float(LENGTH_FIX[0]).add(e.mul(LENGTH_FIX[1]))))));
  }).ElseIf(normalise, () => {
    const l = length(x);
    out.assign(select(l.greaterThan(0), x.div(l), v));
  });
  return out;
}).setLayout({
  name: 'gcsTurnJoint', type: 'vec3',
  inputs: [{ name: 'v', type: 'vec3' }, { name: 'n', type: 'mat3' }, { name: 'near', type: 'bool' }, { name: 'almostEqual', type: 'bool' }, { name: 'normalise', type: 'bool' }],
});

/**
 * Rows of the cofactor matrix of a section's 3×3 part (rows r0..r2), as matrix columns, divided by
 * its largest entry first; `unitScale` (smooth mode, which blends them) also brings them to the
 * CPU's scale: divided by |det|^(2/3), which turns cof(s·R) back into R.
 */
const gcsNormalRows = Fn(([r0, r1, r2, unitScale]: [Vec4, Vec4, Vec4, Bool]) => {
  const big = largest(mat3(r0.xyz, r1.xyz, r2.xyz)).toVar();
  const k = select(big.greaterThan(0), float(1).div(big), float(1));
  const a = r0.xyz.mul(k).toVar(), b = r1.xyz.mul(k).toVar(), c = r2.xyz.mul(k).toVar();
  const n = mat3(cross(b, c), cross(c, a), cross(a, b)).toVar();
  If(unitScale, () => {
    const det = abs(dot(a, column(n, 0))).toVar();
    If(det.greaterThan(COLLAPSED), () => n.assign(n.mul(float(1).div(pow(det, 2 / 3)))));
  });
  return n;
}).setLayout({
  name: 'gcsNormalRows', type: 'mat3',
  inputs: [{ name: 'r0', type: 'vec4' }, { name: 'r1', type: 'vec4' }, { name: 'r2', type: 'vec4' }, { name: 'unitScale', type: 'bool' }],
});

/** A normal or tangent turned by cofactor rows (section-level path), normalised; a vanished one keeps its rest direction. */
const gcsTurn = Fn(([v, rows]: [Vec3, Mat3]) => {
  const x = rows.transpose().mul(v).toVar();
  const l = length(x);
  return select(l.greaterThan(0), x.div(l), v);
}).setLayout({ name: 'gcsTurn', type: 'vec3', inputs: [{ name: 'v', type: 'vec3' }, { name: 'rows', type: 'mat3' }] });

// ------------------------------------------------------------ accessors (texel reads, per skin)

/** How one vertex moves: its position, and a function turning its normal (or tangent). */
interface VertexTransform { position(p: Vec3): Vec3; turn(v: Vec3): Vec3 }

/** One node's transform x ↦ M x + T, its normal matrix N and whether normals renormalise. */
interface Section { m: Mat3; t: Vec3; n: Mat3; renorm: Bool }

/**
 * A node from its four texels as the node pass writes them (the GLSL's gcsNode): the rows of
 * [M | T], and the normal texel n from which N = cof(M·n.x)·n.y; n.w < 0 where normals renormalise.
 */
function decodeNode(r0: Vec4, r1: Vec4, r2: Vec4, n: Vec4): Section {
  const m = mat3(r0.xyz, r1.xyz, r2.xyz).transpose().toVar();
  const a = m.mul(n.x).toVar();
  const a0 = column(a, 0), a1 = column(a, 1), a2 = column(a, 2);
  return { m, t: vec3(r0.w, r1.w, r2.w).toVar(), n: mat3(cross(a1, a2), cross(a2, a0), cross(a0, a1)).mul(n.y).toVar(), renorm: n.w.lessThan(0).toVar() };
}

/** Where a skin's nodes come from: the node pass's textures (one texel per node and target, rows of PAGE_WIDTH), this instance's first node, the page's height. */
interface NodeInputs { nodes: TextureNode[]; first: Int; pageRows: Int }

/** Node s of this instance, read from the node pass's targets. */
function passNode(inputs: NodeInputs, s: Int): Section {
  const i = inputs.first.add(s).toVar();
  const y = i.div(PAGE_WIDTH).toVar();
  const at = ivec2(i.sub(y.mul(PAGE_WIDTH)), storedRow(y, inputs.pageRows)).toVar();
  const [r0, r1, r2, n] = inputs.nodes.map((t) => t.load(at).toVar());
  return decodeNode(r0, r1, r2, n);
}

/** Node s computed here from the joint poses (a velocity pass's previous frame only: the pass holds this frame's). */
function computedNode(inputs: JointInputs, s: Int): Section {
  const texels = nodeTexels(inputs, s);
  return decodeNode(column(texels, 0), column(texels, 1), column(texels, 2), column(texels, 3));
}

/** The joint-level path per vertex (the GLSL's JOINT_BASE): the third section only where there is one. */
function jointVertex(section: (s: Int) => Section, smooth: boolean): VertexTransform {
  if (!smooth) {
    const a = section(int(attribute<'float'>(SECTION_ATTRIBUTE, 'float').add(0.5)));
    return { position: (p) => a.m.mul(p).add(a.t), turn: (v) => gcsTurnJoint(v, a.n, bool(false), bool(false), a.renorm) };
  }
  const blend = attribute<'vec3'>(BLEND_ATTRIBUTE, 'vec3'), third = attribute<'vec2'>(BLEND_THIRD_ATTRIBUTE, 'vec2');
  const sa = int(blend.x.add(0.5)).toVar(), sb = int(blend.y.add(0.5)).toVar(), sc = int(third.x.add(0.5)).toVar();
  const a = section(sa);
  const m = a.m.toVar(), t = a.t.toVar(), n = a.n.toVar();
  const near = bool(false).toVar(), almostEqual = bool(false).toVar(), normalise = a.renorm.toVar();
  If(sb.notEqual(sa), () => {
    const b = section(sb);
    const f = blend.z;
    const trace = gcsTrace(a.n, b.n).toVar();
    m.assign(a.m.add(b.m.sub(a.m).mul(f)));
    t.assign(a.t.add(b.t.sub(a.t).mul(f)));
    n.assign(a.n.add(b.n.sub(a.n).mul(f)));
    If(sc.notEqual(sa), () => {
      // A three-joint lattice cell: + g·(C − A); the least pairwise trace decides the fix.
      const c = section(sc);
      const g = third.y;
      m.addAssign(c.m.sub(a.m).mul(g));
      t.addAssign(c.t.sub(a.t).mul(g));
      n.addAssign(c.n.sub(a.n).mul(g));
      trace.assign(min(trace, min(gcsTrace(a.n, c.n), gcsTrace(b.n, c.n))));
      near.assign(a.renorm.or(b.renorm).or(c.renorm).not().and(trace.greaterThan(NEAR_TRACE3)));
      almostEqual.assign(near.and(trace.greaterThan(ALMOST_EQUAL_TRACE3)));
    }).Else(() => {
      near.assign(a.renorm.or(b.renorm).not().and(trace.greaterThan(NEAR_TRACE)));
      almostEqual.assign(near.and(trace.greaterThan(ALMOST_EQUAL_TRACE)));
    });
    normalise.assign(true);
  });
  return { position: (p) => m.mul(p).add(t), turn: (v) => gcsTurnJoint(v, n, near, almostEqual, normalise) };
}

/** The section-level path per vertex (the GLSL's BASE): rows of each section's affine 3×4, blended. */
function sectionVertex(sections: TextureNode, first: Int, smooth: boolean): VertexTransform {
  const rows = (s: Int): [Vec4, Vec4, Vec4] => {
    const i = first.add(s.mul(GPU_TEXELS_PER_SECTION)).toVar();
    return [texel(sections, i).toVar(), texel(sections, i.add(1)).toVar(), texel(sections, i.add(2)).toVar()];
  };
  let r: [Vec4, Vec4, Vec4], n: Mat3;
  if (smooth) {
    const blend = attribute<'vec3'>(BLEND_ATTRIBUTE, 'vec3'), third = attribute<'vec2'>(BLEND_THIRD_ATTRIBUTE, 'vec2');
    const sa = int(blend.x.add(0.5)).toVar(), sc = int(third.x.add(0.5)).toVar();
    const a = rows(sa), b = rows(int(blend.y.add(0.5)));
    const f = blend.z;
    const lerp = (i: number): Vec4 => a[i].add(b[i].sub(a[i]).mul(f)).toVar();
    r = [lerp(0), lerp(1), lerp(2)];
    const na = gcsNormalRows(a[0], a[1], a[2], bool(true)).toVar();
    n = na.add(gcsNormalRows(b[0], b[1], b[2], bool(true)).sub(na).mul(f)).toVar();
    If(sc.notEqual(sa), () => {
      // A three-joint lattice cell: + g·(C − A).
      const c = rows(sc), g = third.y;
      for (let i = 0; i < 3; i++) r[i].addAssign(c[i].sub(a[i]).mul(g));
      n.addAssign(gcsNormalRows(c[0], c[1], c[2], bool(true)).sub(na).mul(g));
    });
  } else {
    r = rows(int(attribute<'float'>(SECTION_ATTRIBUTE, 'float').add(0.5)));
    n = gcsNormalRows(r[0], r[1], r[2], bool(false)).toVar();
  }
  return {
    position: (p) => { const h = vec4(p, 1); return vec3(dot(r[0], h), dot(r[1], h), dot(r[2], h)); },
    turn: (v) => gcsTurn(v, n),
  };
}

// ------------------------------------------------------------ LBS and DQS per vertex (backend 'gpu', method 'lbs' | 'dqs')

/** LBS normals (the GLSL's gcsTurnLbs): by M, then unit length; where M collapses, by the first influence's rotation q. */
const gcsTurnLbs = Fn(([v, m, q]: [Vec3, Mat3, Vec4]) => {
  const n = m.mul(v).toVar();
  const len2 = dot(n, n).toVar();
  const out = vec3(0).toVar();
  If(len2.greaterThan(1e-24).and(len2.lessThan(1e24)), () => {
    out.assign(n.div(len2.sqrt()));
  }).Else(() => {
    const r = gcsRotation(q, float(2)).mul(v).toVar();
    const l = length(r);
    out.assign(select(l.greaterThan(0), r.div(l), v));
  });
  return out;
}).setLayout({ name: 'gcsTurnLbs', type: 'vec3', inputs: [{ name: 'v', type: 'vec3' }, { name: 'm', type: 'mat3' }, { name: 'q', type: 'vec4' }] });

/**
 * Each vertex blends its own joints (4, or 8 with a second set) from the joint poses, at its own
 * weights (the rig's, as the core normalises them; joint −1 where the weight is 0): LBS as the
 * CPU's (M = Σ w S_j; normals by M, then unit length), DQS through the node maths (jointBlend) with
 * no centre, normals as the joint-level path turns an unblended one. (DQS with a joint pass reads
 * its parts instead, dqsVertex; this is a velocity pass's previous frame.)
 */
function skinVertex(method: 'lbs' | 'dqs', poses: PoseViews, first: Int, slots: 4 | 8): VertexTransform {
  const ids: Vec4[] = [], weights: Vec4[] = [];
  for (let g = 0; g < slots / 4; g++) {
    ids.push(attribute<'vec4'>(INFLUENCE_ATTRIBUTES[g], 'vec4'));
    weights.push(attribute<'vec4'>(WEIGHT_ATTRIBUTES[g], 'vec4'));
  }
  const inputs = { ...poses, first, slots };
  if (method === 'dqs') {
    const texels = jointBlend(inputs, ids, weights, vec4(0)).toVar();
    const node = decodeNode(column(texels, 0), column(texels, 1), column(texels, 2), column(texels, 3));
    return { position: (p) => node.m.mul(p).add(node.t), turn: (v) => gcsTurnJoint(v, node.n, bool(false), bool(false), node.renorm) };
  }
  const lanes = ['x', 'y', 'z', 'w'] as const;
  const r0 = vec4(0).toVar(), r1 = vec4(0).toVar(), r2 = vec4(0).toVar();
  let rest: Vec4 = vec4(0, 0, 0, 1);
  for (let c = 0; c < slots; c++) {
    const id = ids[c >> 2][lanes[c & 3]];
    const w = weights[c >> 2][lanes[c & 3]].mul(step(0, id)).toVar(); // joint −1: weight 0
    const pose = jointPose(inputs, int(id.max(0))).toVar();
    r0.addAssign(column(pose, 0).mul(w));
    r1.addAssign(column(pose, 1).mul(w));
    r2.addAssign(column(pose, 2).mul(w));
    // Where the blend collapses (bones scaled to 0): the first influence's rotation.
    if (c === 0) rest = (select(w.greaterThan(0), column(pose, 3), vec4(0, 0, 0, 1)) as unknown as Vec4).toVar();
  }
  const m = mat3(r0.xyz, r1.xyz, r2.xyz).transpose().toVar(), t = vec3(r0.w, r1.w, r2.w).toVar();
  const q = rest;
  return { position: (p) => m.mul(p).add(t), turn: (v) => gcsTurnLbs(v, m, q) };
}

/**
 * DQS from the joint pass's targets (node-pass-tsl.ts, DQS_TEXELS_PER_JOINT; the GLSL's DQS_BASE):
 * per influence the joint's quaternion, dual part and uniform scale as the pass wrote them, the
 * blend; then M = s·R and the normal by R where every joint of the vertex is a uniform scale (the
 * CPU's quaternion-only path: no scale part read), else the scale parts K_j blended, M = R·K and
 * the normal matrix of gcsNormalTexel(K). `instanceRow`: this instance's row of the targets, in a page `pageRows` high.
 */
function dqsVertex(nodes: TextureNode[], instanceRow: Int, pageRows: Int, slots: 4 | 8): VertexTransform {
  const row = storedRow(instanceRow, pageRows).toVar();
  const lanes = ['x', 'y', 'z', 'w'] as const;
  const ids: Vec4[] = [], weights: Vec4[] = [];
  for (let g = 0; g < slots / 4; g++) {
    ids.push(attribute<'vec4'>(INFLUENCE_ATTRIBUTES[g], 'vec4'));
    weights.push(attribute<'vec4'>(WEIGHT_ATTRIBUTES[g], 'vec4'));
  }
  // Joint j's first texel (one row per instance: no division per joint).
  const at = (c: number, texel = 0) => ivec2(int(ids[c >> 2][lanes[c & 3]].max(0)).mul(DQS_TEXELS_PER_JOINT).add(texel), row);
  // A joint past the last (−1) gets weight 0: it adds nothing (the GLSL's early continue).
  const weight = (c: number) => weights[c >> 2][lanes[c & 3]].mul(step(0, ids[c >> 2][lanes[c & 3]]));
  const pivot = nodes[0].load(at(0)).toVar();
  const br = vec4(0).toVar(), bd = vec4(0).toVar(), s = float(0).toVar(), rigid = bool(true).toVar();
  for (let c = 0; c < slots; c++) {
    const w = weight(c).toVar();
    const first = at(c).toVar();
    const q = nodes[0].load(first).toVar();
    const sw = select(dot(q, pivot).lessThan(0), w.negate(), w);
    br.addAssign(q.mul(sw));
    bd.addAssign(nodes[1].load(first).mul(sw));
    const u = nodes[2].load(first).x.toVar();
    s.addAssign(w.mul(u));
    rigid.assign(rigid.and(u.greaterThan(0).or(w.greaterThan(0).not())));
  }
  const inv2 = float(1).div(dot(br, br)).toVar();
  const t = br.w.mul(bd.xyz).sub(bd.w.mul(br.xyz)).sub(cross(bd.xyz, br.xyz)).mul(inv2.mul(2)).toVar();
  const r = gcsRotation(br, inv2.mul(2)).toVar();
  const m = r.mul(s).toVar(), n = r.toVar(), renorm = bool(false).toVar();
  If(rigid.not(), () => {
    const k = mat3(vec3(0), vec3(0), vec3(0)).toVar();
    for (let c = 0; c < slots; c++) {
      const second = at(c, 1).toVar();
      k.addAssign(mat3(nodes[0].load(second).xyz, nodes[1].load(second).xyz, nodes[2].load(second).xyz).transpose().mul(weight(c)));
    }
    m.assign(r.mul(k));
    const texel = gcsNormalTexel(k).toVar();
    const a = m.mul(texel.x).toVar();
    const a0 = column(a, 0), a1 = column(a, 1), a2 = column(a, 2);
    n.assign(mat3(cross(a1, a2), cross(a2, a0), cross(a0, a1)).mul(texel.y));
    renorm.assign(texel.w.lessThan(0));
  });
  return { position: (p) => m.mul(p).add(t), turn: (v) => gcsTurnJoint(v, n, bool(false), bool(false), renorm) };
}

/** Whether this build writes velocity (three.js asks for previous positions then). */
const needsPreviousData = (builder: NodeBuilder): boolean => (builder as NodeBuilder & { needsPreviousData(): boolean }).needsPreviousData();

/**
 * The CPU backend's `positionNode` on WebGPURenderer: the deformed position as it is (wasm wrote
 * it), and, in a velocity pass, `positionPrevious` from the deformer's previous positions.
 */
export function previousPositionNode(): Node<'vec3'> {
  return Fn((builder: NodeBuilder) => {
    if (needsPreviousData(builder)) positionPrevious.assign(attribute<'vec3'>(PREVIOUS_POSITION_ATTRIBUTE, 'vec3'));
    return positionLocal;
  })();
}

/** What the vertex stage reads of a node pass: this frame's targets (TslNodePass) or the frame before's (its previousViews()). */
type PassViews = Pick<TslNodePass, 'textureNode' | 'pageRows'>;

/** The vertex stage's views of the pass's targets. */
const passTextures = (pass: PassViews): TextureNode[] => Array.from({ length: GPU_NODE_TEXTURES }, (_, i) => pass.textureNode(i));

/**
 * How each vertex moves: path 'sections' from the section transforms; path 'joints' from the node
 * pass's targets (`pass`, `nodeFirst` this instance's first node; DQS's joint pass: its row), or, without one (a velocity
 * pass's previous frame, or a caller that built no pass), from nodes computed here from the joint
 * poses (`poses`, `first` this instance's first joint texel).
 */
function vertexTransform(sections: GpuSections, poses: PoseViews, first: Int, pass: PassViews | null, nodeFirst: Int): VertexTransform {
  if (sections.method === 'dqs' && pass) return dqsVertex(passTextures(pass), nodeFirst, pass.pageRows, sections.tableSlots);
  if (sections.method !== 'gcs') return skinVertex(sections.method, poses, first, sections.tableSlots);
  if (sections.path !== 'joints') return sectionVertex(poses.joints, first, sections.smooth);
  if (pass) {
    const inputs: NodeInputs = { nodes: passTextures(pass), first: nodeFirst, pageRows: pass.pageRows };
    return jointVertex((s) => passNode(inputs, s), sections.smooth);
  }
  const inputs: JointInputs = { ...poses, table: texelView(sections.table as DataTexture), slots: sections.tableSlots, first };
  return jointVertex((s) => computedNode(inputs, s), sections.smooth);
}

/**
 * A node material's `positionNode` running GCS from `sections`: the deformed position, with
 * `normalLocal` and `tangentLocal` turned. Single mesh: it reads the morphed position and normal
 * (three.js morphs before positionNode). Crowd (`instanced`): three.js has already placed the
 * instance by then, so it starts from the bind-pose attributes and places the instance itself
 * with the mesh's own `instanceMatrix` (each instance's pose at `instanceIndex`).
 *
 * Path 'joints': each vertex reads its 1–3 nodes from `pass` (TslNodePass, run once per frame
 * before the draws) and blends them; without a pass it computes them itself (slow: a node per
 * vertex that uses it).
 *
 * Velocity (a render pass whose MRT has `velocity`): `positionPrevious` gets the same vertex under
 * the previous frame's texels (GpuSections.previousTexture), as three.js's skinning does with its
 * previous bone matrices; a crowd places it with the current instance matrix.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function gcsPositionNode(sections: GpuSections, instanced: boolean, pass: TslNodePass | null = null): Node<'vec3'> {
  checkObject(sections, 'sections', 'gcsPositionNode');
  checkObject(sections.uniforms, 'sections.uniforms', 'gcsPositionNode');
  if (pass !== null) checkObject(pass, 'pass', 'gcsPositionNode');
  const poses = poseViews(sections);
  const base = sections.uniforms.gcsBase, stride = sections.uniforms.gcsStride;
  const baseNode = uniform(base.value, 'int').onObjectUpdate(() => base.value);
  const strideNode = uniform(stride.value, 'int').onObjectUpdate(() => stride.value);
  return Fn((builder: NodeBuilder) => {
    const has = (name: string) => builder.geometry?.getAttribute(name) !== undefined;
    const first = (instanced ? baseNode.add(int(instanceIndex).mul(strideNode)) : baseNode).toVar();
    // This instance's first node in the pass's targets (DQS's joint pass: its row).
    const perInstance = sections.method === 'dqs' ? 1 : sections.deformer.sectionCount;
    // (The pass's rows start at its offset in the page it shares with the renderer's other passes.)
    const offset = pass ? pass.offset : int(0);
    const nodeFirst = (instanced ? offset.add(int(instanceIndex).mul(perInstance)) : offset).toVar();
    const vertex = vertexTransform(sections, poses, first, pass, nodeFirst);
    const placement = instanced ? referenceAttribute('instanceMatrix', 'mat4') as unknown as Mat4 : null;
    const place = (p: Vec3): Vec3 => (placement ? placement.mul(vec4(p, 1)).xyz : p);
    if (needsPreviousData(builder)) {
      // With a node pass, the previous frame's nodes are its targets of the run before (no per-vertex node maths).
      if (pass) OnObjectUpdate(({ renderer }) => pass.fillPrevious(renderer));
      const previous = pass ? vertexTransform(sections, poses, first, pass.previousViews(), nodeFirst) : (() => {
        OnObjectUpdate(({ frameId }) => sections.advanceFrame(frameId));
        return vertexTransform(sections, poseViews(sections, true), first, null, nodeFirst);
      })();
      positionPrevious.assign(place(previous.position(instanced ? positionGeometry : positionPrevious)));
    }
    if (has('normal')) {
      const n = vertex.turn(instanced ? normalGeometry : normalLocal);
      normalLocal.assign(placement ? transformNormal(n, placement) : n);
    }
    if (has('tangent')) {
      const t = vertex.turn(instanced ? tangentGeometry.xyz : tangentLocal);
      tangentLocal.assign(placement ? placement.mul(vec4(t, 0)).xyz : t);
    }
    return place(vertex.position(instanced ? positionGeometry : positionLocal));
  })();
}
