/**
 * The GCS vertex stage in TSL, for WebGPURenderer (real WebGPU and its WebGL2 fallback): the same
 * maths as the GLSL chunk (glsl.ts), from the same layout constants (layout.ts), written as node
 * graphs. `gcsPositionNode` is a node material's `positionNode`: it returns the deformed position
 * and turns `normalLocal` (and `tangentLocal` where the geometry has tangents) on the way, where
 * three.js's own skinning does (nodes/accessors/Skinning.js) — after the morph targets, so morphs
 * apply first as on the CPU. Matrices are kept as column triples built at graph time, so the
 * generated shader reads like the GLSL one.
 */
import * as THREE from 'three';
import * as TSL from 'three/tsl';
import type { Node } from 'three/webgpu';
import {
  ALMOST_EQUAL_TRACE, ALMOST_EQUAL_TRACE3, BLEND_ATTRIBUTE, BLEND_THIRD_ATTRIBUTE, COLLAPSED, GPU_TEXELS_PER_JOINT,
  GPU_TEXELS_PER_SECTION, LENGTH_FIX, NEAR_TRACE, NEAR_TRACE3, SECTION_ATTRIBUTE, UNIFORM_SCALE_TOLERANCE, tableTexelsPerSection, type TableSlots,
} from './layout.js';
import type { GpuSections } from './sections.js';

// TSL's node types nest too deeply for these graphs (ints meeting floats, swizzles of sizes):
// nodes are untyped here, and the browser tests check what the graphs compute.
// eslint-disable-next-line @typescript-eslint/no-explicit-any
type N = any;
const {
  abs, attribute, cross, dot, float, Fn, instanceIndex, int, ivec2, length, max, min, normalGeometry, normalLocal, pow,
  positionGeometry, positionLocal, referenceAttribute, select, tangentGeometry, tangentLocal, texture, textureSize,
  transformNormal, uniform, vec3, vec4,
} = TSL as N;
/** A 3×3 matrix as its columns. */
type M3 = [N, N, N];

const mulMV = (m: M3, v: N): N => m[0].mul(v.x).add(m[1].mul(v.y)).add(m[2].mul(v.z));
const mulMM = (a: M3, b: M3): M3 => [mulMV(a, b[0]), mulMV(a, b[1]), mulMV(a, b[2])];
const transpose = (m: M3): M3 => [vec3(m[0].x, m[1].x, m[2].x), vec3(m[0].y, m[1].y, m[2].y), vec3(m[0].z, m[1].z, m[2].z)];
const scale = (m: M3, s: N): M3 => [m[0].mul(s), m[1].mul(s), m[2].mul(s)];
const add = (a: M3, b: M3): M3 => [a[0].add(b[0]), a[1].add(b[1]), a[2].add(b[2])];
/** a + f·(b − a) + g·(c − a), column by column (a lattice cell's three nodes; g = 0 and c = a: a lerp). */
const blend3 = (a: M3, b: M3, c: M3, f: N, g: N): M3 => [0, 1, 2].map((i) => a[i].add(b[i].sub(a[i]).mul(f)).add(c[i].sub(a[i]).mul(g))) as M3;
const trace = (a: M3, b: M3): N => dot(a[0], b[0]).add(dot(a[1], b[1])).add(dot(a[2], b[2]));
const pick = (c: N, a: M3, b: M3): M3 => [select(c, a[0], b[0]), select(c, a[1], b[1]), select(c, a[2], b[2])];
const toVar = (m: M3): M3 => [m[0].toVar(), m[1].toVar(), m[2].toVar()];
const largest = (m: M3): N => { const e = max(max(abs(m[0]), abs(m[1])), abs(m[2])); return max(max(e.x, e.y), e.z); };
const ZERO: () => M3 = () => [vec3(0), vec3(0), vec3(0)];

/** Texel i of a float texture read with integer coordinates (row-major, the texture's width). */
function texel(tex: N, i: N): N {
  const w = int(textureSize(tex).x);
  const y = i.div(w);
  return tex.load(ivec2(i.sub(y.mul(w)), y));
}

/** The rotation matrix of quaternion q (x, y, z, w) scaled by k2 = 2 / |q|² (2 for a unit quaternion). */
function rotation(q: N, k2: N): M3 {
  const xx = q.x.mul(q.x), yy = q.y.mul(q.y), zz = q.z.mul(q.z), xy = q.x.mul(q.y), xz = q.x.mul(q.z), yz = q.y.mul(q.z);
  const wx = q.w.mul(q.x), wy = q.w.mul(q.y), wz = q.w.mul(q.z);
  const one = float(1);
  return [
    vec3(one.sub(k2.mul(yy.add(zz))), k2.mul(xy.add(wz)), k2.mul(xz.sub(wy))),
    vec3(k2.mul(xy.sub(wz)), one.sub(k2.mul(xx.add(zz))), k2.mul(yz.add(wx))),
    vec3(k2.mul(xz.add(wy)), k2.mul(yz.sub(wx)), one.sub(k2.mul(xx.add(yy)))),
  ];
}

/**
 * The CPU's normalMatrix: r when k is a positive uniform scale, else r · cof(k) scaled to entries
 * ≤ 1; r alone when k has collapsed. Also whether the normal is renormalised (1) or not (0).
 */
function normalMatrix(r: M3, k: M3): { n: M3; renorm: N } {
  const s = k[0].x.add(k[1].y).add(k[2].z).div(3).toVar();
  let uniformScale: N = s.greaterThan(0);
  const limit = s.mul(UNIFORM_SCALE_TOLERANCE);
  for (let c = 0; c < 3; c++) for (let i = 0; i < 3; i++) {
    const entry = k[c][['x', 'y', 'z'][i]];
    uniformScale = uniformScale.and(abs(c === i ? entry.sub(s) : entry).lessThanEqual(limit));
  }
  uniformScale = uniformScale.toVar();
  const kbig = largest(k).toVar();
  const a = scale(k, float(1).div(kbig));
  const cof = toVar([cross(a[1], a[2]), cross(a[2], a[0]), cross(a[0], a[1])]);
  const big = largest(cof).toVar();
  const scaled = mulMM(r, scale(cof, float(1).div(big)));
  const keep = uniformScale.or(kbig.greaterThan(COLLAPSED).not()).or(big.greaterThan(COLLAPSED).not());
  return { n: toVar(pick(keep, r, scaled)), renorm: select(uniformScale, float(0), float(1)) };
}

/** One section's transform x ↦ M x + T, its normal matrix N and whether normals renormalise. */
interface SectionBlend { m: M3; t: N; n: M3; renorm: N }

/** The joint-level path's inputs: joint poses (per frame) and the section table (static, `slots` joints per section). */
interface JointInputs { joints: N; table: N; slots: TableSlots; first: N }

/** Joint j's pose: S_j (columns), its translation and rotation quaternion. */
function joint(inputs: JointInputs, j: N): { s: M3; t: N; q: N } {
  const i = inputs.first.add(j.mul(GPU_TEXELS_PER_JOINT)).toVar();
  const r0 = texel(inputs.joints, i).toVar(), r1 = texel(inputs.joints, i.add(1)).toVar(), r2 = texel(inputs.joints, i.add(2)).toVar();
  const q = texel(inputs.joints, i.add(3)).toVar();
  return { s: transpose([r0.xyz, r1.xyz, r2.xyz]), t: vec3(r0.w, r1.w, r2.w), q };
}

/**
 * Section s blended from its joints (the GLSL's gcsSectionBlend): a rigid core is S_j; otherwise
 * the dual-quaternion blend at its weights, K_j = R_jᵀ S_j blended linearly and applied first.
 * Joints past the last (−1) get weight 0, which adds nothing: the GLSL's early break.
 */
function sectionBlend(inputs: JointInputs, s: N): SectionBlend {
  // Per 4 slots, a texel of joints then one of weights (slots 4..7: the third and fourth texels).
  const row = s.mul(tableTexelsPerSection(inputs.slots)).toVar();
  const jointTexels: N[] = [], weightTexels: N[] = [];
  for (let g = 0; g < inputs.slots / 4; g++) {
    jointTexels.push(texel(inputs.table, row.add(2 * g)).toVar());
    weightTexels.push(texel(inputs.table, row.add(2 * g + 1)).toVar());
  }
  const joints = jointTexels[0], weights = weightTexels[0];
  const lanes = ['x', 'y', 'z', 'w'] as const;
  const j0 = joint(inputs, int(joints.x));
  const rigidRotation = rotation(j0.q, float(2));
  const rigidNormal = normalMatrix(rigidRotation, mulMM(transpose(rigidRotation), j0.s));

  const pivot = j0.q;
  let br: N = vec4(0), bd: N = vec4(0);
  let k: M3 = ZERO();
  // The centre of rotation p (w = 1; w = 0: none) and Σ w_i (S_i p − p), where LBS moves it.
  const centre = texel(inputs.table, row.add(tableTexelsPerSection(inputs.slots) - 1)).toVar();
  let moved: N = vec3(0);
  for (let c = 0; c < inputs.slots; c++) {
    const id = jointTexels[c >> 2][lanes[c & 3]];
    const { s: S, t, q } = c === 0 ? j0 : joint(inputs, max(int(id), int(0)));
    const d = vec4(q.w.mul(t).add(cross(t, q.xyz)), dot(t, q.xyz).negate()).mul(0.5);
    const w = c === 0 ? weights.x : select(id.lessThan(0), float(0), weightTexels[c >> 2][lanes[c & 3]]);
    const sw = select(dot(q, pivot).lessThan(0), w.negate(), w);
    br = br.add(q.mul(sw));
    bd = bd.add(d.mul(sw));
    k = add(k, scale(mulMM(transpose(rotation(q, float(2))), S), w));
    moved = moved.add(mulMV(S, centre.xyz).add(t).sub(centre.xyz).mul(w));
  }
  br = br.toVar();
  bd = bd.toVar();
  k = toVar(k);
  const inv2 = float(1).div(dot(br, br)).toVar();
  const t = br.w.mul(bd.xyz).sub(bd.w.mul(br.xyz)).sub(cross(bd.xyz, br.xyz)).mul(inv2.mul(2));
  const rot = toVar(rotation(br, inv2.mul(2)));
  const blended = normalMatrix(rot, k);
  const rigid = joints.y.lessThan(0);
  const m = toVar(mulMM(rot, k));
  // With a centre: turn about it, the centre moved by LBS (M p + T = Σ w_i S_i p).
  const aboutCentre = moved.sub(mulMV(m, centre.xyz).sub(centre.xyz));
  return {
    m: toVar(pick(rigid, j0.s, m)),
    t: select(rigid, j0.t, select(centre.w.greaterThan(0.5), aboutCentre, t)).toVar(),
    n: toVar(pick(rigid, rigidNormal.n, blended.n)),
    renorm: select(rigid, rigidNormal.renorm, blended.renorm).toVar(),
  };
}

/** How one vertex moves: its position, and a function turning its normal (or tangent). */
interface VertexTransform { position(p: N): N; turn(v: N): N }

/** The joint-level path per vertex (the GLSL's JOINT_BASE and gcsTurnJoint). */
function jointVertex(inputs: JointInputs, smooth: boolean): VertexTransform {
  let m: M3, t: N, n: M3, near: N, almostEqual: N, normalise: N;
  if (smooth) {
    const blend = attribute(BLEND_ATTRIBUTE, 'vec3'), third = attribute(BLEND_THIRD_ATTRIBUTE, 'vec2');
    const sa = int(blend.x.add(0.5)).toVar(), sb = int(blend.y.add(0.5)).toVar(), sc = int(third.x.add(0.5)).toVar();
    // A third section (a three-joint lattice cell) is blended in by g; without one, c is a and g is 0.
    const a = sectionBlend(inputs, sa), b = sectionBlend(inputs, sb), c = sectionBlend(inputs, sc);
    const f = blend.z, g = third.y;
    const same = sa.equal(sb), three = sc.notEqual(sa);
    const traceAB = trace(a.n, b.n).toVar();
    const least = min(traceAB, min(trace(a.n, c.n), trace(b.n, c.n)));
    const rotations = a.renorm.lessThan(0.5).and(b.renorm.lessThan(0.5)).and(three.not().or(c.renorm.lessThan(0.5)));
    m = toVar(pick(same, a.m, blend3(a.m, b.m, c.m, f, g)));
    t = select(same, a.t, a.t.add(b.t.sub(a.t).mul(f)).add(c.t.sub(a.t).mul(g))).toVar();
    n = toVar(pick(same, a.n, blend3(a.n, b.n, c.n, f, g)));
    near = same.not().and(rotations).and(select(three, least.greaterThan(NEAR_TRACE3), traceAB.greaterThan(NEAR_TRACE))).toVar();
    almostEqual = near.and(select(three, least.greaterThan(ALMOST_EQUAL_TRACE3), traceAB.greaterThan(ALMOST_EQUAL_TRACE))).toVar();
    normalise = same.not().or(a.renorm.greaterThan(0.5)).toVar();
  } else {
    const a = sectionBlend(inputs, int(attribute(SECTION_ATTRIBUTE, 'float').add(0.5)));
    ({ m, t, n } = a);
    near = null;
    almostEqual = null;
    normalise = a.renorm.greaterThan(0.5);
  }
  return {
    position: (p) => mulMV(m, p).add(t),
    turn: (v) => {
      const x = mulMV(n, v).toVar();
      const e = dot(x, x).sub(1);
      const l = length(x);
      const normalised = select(l.greaterThan(0), x.div(l), v);
      const plain = select(normalise, normalised, x);
      if (!near) return plain;
      const fixed = select(near, x.mul(float(1).add(e.mul(e.mul(LENGTH_FIX[1]).add(LENGTH_FIX[0])))), plain);
      return select(almostEqual, x, fixed);
    },
  };
}

/** The section-level path per vertex (the GLSL's BASE, gcsNormalRows, gcsTurn). */
function sectionVertex(sections: N, first: N, smooth: boolean): VertexTransform {
  const rows = (section: N): [N, N, N] => {
    const i = first.add(section.mul(GPU_TEXELS_PER_SECTION)).toVar();
    return [texel(sections, i).toVar(), texel(sections, i.add(1)).toVar(), texel(sections, i.add(2)).toVar()];
  };
  // Rows of the cofactor matrix, scaled first so no entry overflows; smooth: brought to the CPU's scale.
  const normalRows = (r: [N, N, N], unitScale: boolean): M3 => {
    const big = largest([r[0].xyz, r[1].xyz, r[2].xyz]).toVar();
    const k = select(big.greaterThan(0), float(1).div(big), float(1));
    const a = r[0].xyz.mul(k), b = r[1].xyz.mul(k), c = r[2].xyz.mul(k);
    const n: M3 = toVar([cross(b, c), cross(c, a), cross(a, b)]);
    if (!unitScale) return n;
    const det = abs(dot(a, n[0])).toVar();
    return toVar(scale(n, select(det.greaterThan(COLLAPSED), float(1).div(pow(det, 2 / 3)), float(1))));
  };
  let r: [N, N, N], n: M3;
  if (smooth) {
    const blend = attribute(BLEND_ATTRIBUTE, 'vec3'), third = attribute(BLEND_THIRD_ATTRIBUTE, 'vec2');
    const a = rows(int(blend.x.add(0.5))), b = rows(int(blend.y.add(0.5))), c = rows(int(third.x.add(0.5)));
    const f = blend.z, g = third.y;
    r = [0, 1, 2].map((i) => a[i].add(b[i].sub(a[i]).mul(f)).add(c[i].sub(a[i]).mul(g))) as [N, N, N];
    n = toVar(blend3(normalRows(a, true), normalRows(b, true), normalRows(c, true), f, g));
  } else {
    r = rows(int(attribute(SECTION_ATTRIBUTE, 'float').add(0.5)));
    n = normalRows(r, false);
  }
  return {
    position: (p) => { const h = vec4(p, 1); return vec3(dot(r[0], h), dot(r[1], h), dot(r[2], h)); },
    turn: (v) => {
      const x = vec3(dot(n[0], v), dot(n[1], v), dot(n[2], v)).toVar();
      const l = length(x);
      return select(l.greaterThan(0), x.div(l), v);
    },
  };
}

/**
 * A node material's `positionNode` running GCS from `sections`: the deformed position, with
 * `normalLocal` and `tangentLocal` turned. Single mesh: it reads the morphed position and normal
 * (three.js morphs before positionNode). Crowd (`instanced`): three.js has already placed the
 * instance by then, so it starts from the bind-pose attributes and places the instance itself
 * with the mesh's own `instanceMatrix` (each instance's pose at `instanceIndex`).
 */
export function gcsPositionNode(sections: GpuSections, instanced: boolean): Node {
  const perFrame = texture(sections.texture);
  const base = sections.uniforms.gcsBase, stride = sections.uniforms.gcsStride;
  const baseNode = uniform(base.value, 'int').onObjectUpdate(() => base.value);
  const strideNode = uniform(stride.value, 'int').onObjectUpdate(() => stride.value);
  return Fn((builder: N) => {
    const first = (instanced ? baseNode.add(int(instanceIndex).mul(strideNode)) : baseNode).toVar();
    const vertex = sections.path === 'joints'
      ? jointVertex({ joints: perFrame, table: texture(sections.table as THREE.DataTexture), slots: sections.tableSlots, first }, sections.smooth)
      : sectionVertex(perFrame, first, sections.smooth);
    const placement = instanced ? referenceAttribute('instanceMatrix', 'mat4') : null;
    if (builder.hasGeometryAttribute('normal')) {
      const n = vertex.turn(instanced ? normalGeometry : normalLocal);
      normalLocal.assign(placement ? transformNormal(n, placement) : n);
    }
    if (builder.hasGeometryAttribute('tangent')) {
      const t = vertex.turn(instanced ? tangentGeometry.xyz : tangentLocal);
      tangentLocal.assign(placement ? placement.mul(vec4(t, 0)).xyz : t);
    }
    const p = vertex.position(instanced ? positionGeometry : positionLocal);
    return placement ? placement.mul(vec4(p, 1)).xyz : p;
  })();
}
