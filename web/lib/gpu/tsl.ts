/**
 * The GCS vertex stage in TSL, for WebGPURenderer (real WebGPU and its WebGL2 fallback), written as
 * three.js writes its own skinning (nodes/accessors/Skinning.js): the maths in small functions with
 * a layout (`Fn(...).setLayout(...)`, compiled once as shader functions), texel reads in plain
 * accessors, `If` where the GLSL chunk (glsl.ts) branches, both from the same constants
 * (layout.ts). `gcsPositionNode` is a node material's `positionNode`: it returns the deformed
 * position and turns `normalLocal` (and `tangentLocal` where the geometry has tangents) on the way
 * — after the morph targets, so morphs apply first, as on the CPU.
 *
 * The laid-out functions take values only: a shader function is built once per renderer and
 * reused by every material, so it must not name a texture or uniform of one skin.
 */
import {
  abs, attribute, bool, cross, dot, float, Fn, If, instanceIndex, int, ivec2, length, mat3, mat4, max, min, normalGeometry, normalLocal,
  OnObjectUpdate, positionGeometry, positionLocal, positionPrevious, pow, referenceAttribute, select, step, tangentGeometry, tangentLocal, texture, textureSize, transformNormal,
  uniform, vec3, vec4,
} from 'three/tsl';
import type { DataTexture, Node, NodeBuilder, TextureNode } from 'three/webgpu';
import {
  ALMOST_EQUAL_TRACE, ALMOST_EQUAL_TRACE3, BLEND_ATTRIBUTE, BLEND_THIRD_ATTRIBUTE, COLLAPSED, GPU_TEXELS_PER_JOINT,
  GPU_TEXELS_PER_SECTION, LENGTH_FIX, NEAR_TRACE, NEAR_TRACE3, PREVIOUS_POSITION_ATTRIBUTE, SECTION_ATTRIBUTE, UNIFORM_SCALE_TOLERANCE, tableTexelsPerSection, type TableSlots,
} from './layout.js';
import type { GpuSections } from './sections.js';

type Bool = Node<'bool'>;
type Float = Node<'float'>;
type Int = Node<'int'>;
type Vec3 = Node<'vec3'>;
type Vec4 = Node<'vec4'>;
type Mat3 = Node<'mat3'>;
type Mat4 = Node<'mat4'>;

/** Column c of a matrix (its `[c]`: the typings index arrays, not matrices). */
const column = <T extends Mat3 | Mat4>(m: T, c: number): T extends Mat3 ? Vec3 : Vec4 =>
  (m as unknown as { element(i: number): T extends Mat3 ? Vec3 : Vec4 }).element(c);

/** The largest absolute entry of a 3×3 matrix. */
function largest(m: Mat3): Float {
  const e = max(max(abs(column(m, 0)), abs(column(m, 1))), abs(column(m, 2)));
  return max(max(e.x, e.y), e.z);
}

// ------------------------------------------------------------ shader functions (values in, value out)

/** The rotation matrix of quaternion q (x, y, z, w) scaled by k2 = 2 / |q|² (2 for a unit quaternion). */
const gcsRotation = Fn(([q, k2]: [Vec4, Float]) => {
  const xx = q.x.mul(q.x), yy = q.y.mul(q.y), zz = q.z.mul(q.z), xy = q.x.mul(q.y), xz = q.x.mul(q.z), yz = q.y.mul(q.z);
  const wx = q.w.mul(q.x), wy = q.w.mul(q.y), wz = q.w.mul(q.z);
  return mat3(
    vec3(float(1).sub(k2.mul(yy.add(zz))), k2.mul(xy.add(wz)), k2.mul(xz.sub(wy))),
    vec3(k2.mul(xy.sub(wz)), float(1).sub(k2.mul(xx.add(zz))), k2.mul(yz.add(wx))),
    vec3(k2.mul(xz.add(wy)), k2.mul(yz.sub(wx)), float(1).sub(k2.mul(xx.add(yy)))),
  );
}).setLayout({ name: 'gcsRotation', type: 'mat3', inputs: [{ name: 'q', type: 'vec4' }, { name: 'k2', type: 'float' }] });

/** The CPU's test: k is a positive uniform scale, every entry within UNIFORM_SCALE_TOLERANCE × s of s·I. */
const gcsUniformScale = Fn(([k]: [Mat3]) => {
  const s = column(k, 0).x.add(column(k, 1).y).add(column(k, 2).z).div(3).toVar();
  const deviation = largest(k.sub(mat3(vec3(s, 0, 0), vec3(0, s, 0), vec3(0, 0, s))));
  return s.greaterThan(0).and(deviation.lessThanEqual(s.mul(UNIFORM_SCALE_TOLERANCE)));
}).setLayout({ name: 'gcsUniformScale', type: 'bool', inputs: [{ name: 'k', type: 'mat3' }] });

/**
 * The CPU's normalMatrix: r when k is a positive uniform scale, else r · cof(k) scaled to entries
 * ≤ 1 (k divided by its largest entry first, so ×1e20 scales do not overflow); r alone when k has
 * collapsed.
 */
const gcsNormalMatrix = Fn(([r, k, uniformScale]: [Mat3, Mat3, Bool]) => {
  const n = r.toVar();
  If(uniformScale.not(), () => {
    const kbig = largest(k).toVar();
    If(kbig.greaterThan(COLLAPSED), () => {
      const a = k.mul(float(1).div(kbig)).toVar();
      const a0 = column(a, 0), a1 = column(a, 1), a2 = column(a, 2);
      const cof = mat3(cross(a1, a2), cross(a2, a0), cross(a0, a1)).toVar();
      const big = largest(cof).toVar();
      If(big.greaterThan(COLLAPSED), () => {
        n.assign(r.mul(cof.mul(float(1).div(big))));
      });
    });
  });
  return n;
}).setLayout({ name: 'gcsNormalMatrix', type: 'mat3', inputs: [{ name: 'r', type: 'mat3' }, { name: 'k', type: 'mat3' }, { name: 'uniformScale', type: 'bool' }] });

/** Σ of the entrywise products of two matrices: 1 + 2 cos θ for rotations θ apart. */
const gcsTrace = Fn(([a, b]: [Mat3, Mat3]) =>
  dot(column(a, 0), column(b, 0)).add(dot(column(a, 1), column(b, 1))).add(dot(column(a, 2), column(b, 2))),
).setLayout({ name: 'gcsTrace', type: 'float', inputs: [{ name: 'a', type: 'mat3' }, { name: 'b', type: 'mat3' }] });

/**
 * A section's blended pose, in a joint's texel layout: columns 0–2 the rows of [M | t], column 3
 * the blended rotation quaternion (not normalised). The dual-quaternion blend of `slots` joint
 * poses at their weights (a joint past the last has weight 0: it adds nothing), each joint's scale
 * part K_j = R_jᵀ S_j blended linearly and applied first: M = R·K, the CPU's blendPoses. With a
 * centre of rotation p (`centre`, w = 1; w = 0: none) it turns about p, moved where LBS moves it:
 * t = Σ w_i (S_i p + t_i − p) − (M p − p).
 */
function sectionBlendFunction(slots: TableSlots) {
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
    return mat4(vec4(column(rows, 0), t.x), vec4(column(rows, 1), t.y), vec4(column(rows, 2), t.z), br);
  }).setLayout({ name: `gcsSectionBlend${slots}`, type: 'mat4', inputs });
}
const gcsSectionBlend = { 4: sectionBlendFunction(4), 8: sectionBlendFunction(8) } as const;

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

/** Texel i of a float texture read with integer coordinates (row-major, the texture's width). */
function texel(tex: TextureNode, i: Int): Vec4 {
  const w = int((textureSize(tex) as unknown as Node<'ivec2'>).x);
  const y = i.div(w);
  return tex.load(ivec2(i.sub(y.mul(w)), y));
}

/** How one vertex moves: its position, and a function turning its normal (or tangent). */
interface VertexTransform { position(p: Vec3): Vec3; turn(v: Vec3): Vec3 }

/** The joint-level path's inputs: joint poses (per frame) and the section table (static, `slots` joints per section). */
interface JointInputs { joints: TextureNode; table: TextureNode; slots: TableSlots; first: Int }

/** Joint j's pose as four texels: the rows of S_j (translation in w) and its rotation quaternion. */
function jointPose(inputs: JointInputs, j: Int): Mat4 {
  const i = inputs.first.add(j.mul(GPU_TEXELS_PER_JOINT)).toVar();
  return mat4(texel(inputs.joints, i), texel(inputs.joints, i.add(1)), texel(inputs.joints, i.add(2)), texel(inputs.joints, i.add(3)));
}

/** One section's transform x ↦ M x + T, its normal matrix N and whether normals renormalise. */
interface Section { m: Mat3; t: Vec3; n: Mat3; renorm: Bool }

/**
 * Section s (the GLSL's gcsSectionBlend): a rigid core moves with its joint; otherwise its joints'
 * poses blended (gcsSectionBlend). Its normal matrix from the pose's rotation R and scale part K = Rᵀ M.
 */
function section(inputs: JointInputs, s: Int): Section {
  // Per 4 slots, a texel of joints (−1 past the last) then one of weights; last, the centre.
  const texels = tableTexelsPerSection(inputs.slots);
  const row = s.mul(texels).toVar();
  const joints: Vec4[] = [], weights: Vec4[] = [];
  for (let g = 0; g < inputs.slots / 4; g++) {
    joints.push(texel(inputs.table, row.add(2 * g)).toVar());
    weights.push(texel(inputs.table, row.add(2 * g + 1)).toVar());
  }
  const lanes = ['x', 'y', 'z', 'w'] as const;
  const pose = jointPose(inputs, int(joints[0].x)).toVar();
  If(joints[0].y.greaterThanEqual(0), () => {
    const poses: Mat4[] = [pose];
    for (let c = 1; c < inputs.slots; c++) poses.push(jointPose(inputs, int(max(joints[c >> 2][lanes[c & 3]], 0))));
    // A joint past the last (−1) gets weight 0: it adds nothing (the GLSL's early break).
    const used = weights.map((w, g) => step(vec4(0), joints[g]).mul(w));
    const centre = texel(inputs.table, row.add(texels - 1)); // the last texel: the centre of rotation, or none
    pose.assign(gcsSectionBlend[inputs.slots](...poses, ...used, centre));
  });
  const r0 = column(pose, 0), r1 = column(pose, 1), r2 = column(pose, 2), q = column(pose, 3);
  const m = mat3(r0.xyz, r1.xyz, r2.xyz).transpose().toVar();
  const rotation = gcsRotation(q, float(2).div(dot(q, q))).toVar();
  const k = rotation.transpose().mul(m).toVar();
  const uniformScale = gcsUniformScale(k).toVar();
  return { m, t: vec3(r0.w, r1.w, r2.w).toVar(), n: gcsNormalMatrix(rotation, k, uniformScale).toVar(), renorm: uniformScale.not().toVar() };
}

/** The joint-level path per vertex (the GLSL's JOINT_BASE): the third section only where there is one. */
function jointVertex(inputs: JointInputs, smooth: boolean): VertexTransform {
  if (!smooth) {
    const a = section(inputs, int(attribute<'float'>(SECTION_ATTRIBUTE, 'float').add(0.5)));
    return { position: (p) => a.m.mul(p).add(a.t), turn: (v) => gcsTurnJoint(v, a.n, bool(false), bool(false), a.renorm) };
  }
  const blend = attribute<'vec3'>(BLEND_ATTRIBUTE, 'vec3'), third = attribute<'vec2'>(BLEND_THIRD_ATTRIBUTE, 'vec2');
  const sa = int(blend.x.add(0.5)).toVar(), sb = int(blend.y.add(0.5)).toVar(), sc = int(third.x.add(0.5)).toVar();
  const a = section(inputs, sa);
  const m = a.m.toVar(), t = a.t.toVar(), n = a.n.toVar();
  const near = bool(false).toVar(), almostEqual = bool(false).toVar(), normalise = a.renorm.toVar();
  If(sb.notEqual(sa), () => {
    const b = section(inputs, sb);
    const f = blend.z;
    const trace = gcsTrace(a.n, b.n).toVar();
    m.assign(a.m.add(b.m.sub(a.m).mul(f)));
    t.assign(a.t.add(b.t.sub(a.t).mul(f)));
    n.assign(a.n.add(b.n.sub(a.n).mul(f)));
    If(sc.notEqual(sa), () => {
      // A three-joint lattice cell: + g·(C − A); the least pairwise trace decides the fix.
      const c = section(inputs, sc);
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

/** How each vertex moves under one per-frame texture (joint poses or section transforms). */
function vertexTransform(sections: GpuSections, perFrame: TextureNode, first: Int): VertexTransform {
  return sections.path === 'joints'
    ? jointVertex({ joints: perFrame, table: texture(sections.table as DataTexture), slots: sections.tableSlots, first }, sections.smooth)
    : sectionVertex(perFrame, first, sections.smooth);
}

/**
 * A node material's `positionNode` running GCS from `sections`: the deformed position, with
 * `normalLocal` and `tangentLocal` turned. Single mesh: it reads the morphed position and normal
 * (three.js morphs before positionNode). Crowd (`instanced`): three.js has already placed the
 * instance by then, so it starts from the bind-pose attributes and places the instance itself
 * with the mesh's own `instanceMatrix` (each instance's pose at `instanceIndex`).
 *
 * Velocity (a render pass whose MRT has `velocity`): `positionPrevious` gets the same vertex under
 * the previous frame's texels (GpuSections.previousTexture), as three.js's skinning does with its
 * previous bone matrices; a crowd places it with the current instance matrix.
 */
export function gcsPositionNode(sections: GpuSections, instanced: boolean): Node<'vec3'> {
  const perFrame = texture(sections.texture);
  const base = sections.uniforms.gcsBase, stride = sections.uniforms.gcsStride;
  const baseNode = uniform(base.value, 'int').onObjectUpdate(() => base.value);
  const strideNode = uniform(stride.value, 'int').onObjectUpdate(() => stride.value);
  return Fn((builder: NodeBuilder) => {
    const has = (name: string) => builder.geometry?.getAttribute(name) !== undefined;
    const first = (instanced ? baseNode.add(int(instanceIndex).mul(strideNode)) : baseNode).toVar();
    const vertex = vertexTransform(sections, perFrame, first);
    const placement = instanced ? referenceAttribute('instanceMatrix', 'mat4') as unknown as Mat4 : null;
    const place = (p: Vec3): Vec3 => (placement ? placement.mul(vec4(p, 1)).xyz : p);
    if (needsPreviousData(builder)) {
      OnObjectUpdate(({ frameId }) => sections.advanceFrame(frameId));
      const previous = vertexTransform(sections, texture(sections.previousTexture()), first);
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
