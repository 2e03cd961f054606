// The GCS per-frame algorithm (docs/method.md §4) in plain JavaScript, for the bench's "same algorithm
// in JS" ratio. It takes the section table from the wasm model (sections(): runs of output
// vertices, part, distal child, alpha, beta) and the rest mesh in output order, and per frame
// computes the relative part motions D_j = S_parent⁻¹ · S_j, each section's
//   M_i = S_parent · D_part^alpha · D_distal^beta
// and transforms its vertices and normals. Non-smooth, no twist spread (the default model).

/** Column-major 4×4 inverse of an affine matrix (rotation/scale + translation). */
function invertAffine(m, o, out) {
  const a = m[o], b = m[o + 1], c = m[o + 2], d = m[o + 4], e = m[o + 5], f = m[o + 6], g = m[o + 8], h = m[o + 9], i = m[o + 10];
  const A = e * i - f * h, B = f * g - d * i, C = d * h - e * g;
  const det = a * A + b * B + c * C;
  const k = 1 / det;
  out[0] = A * k; out[1] = (c * h - b * i) * k; out[2] = (b * f - c * e) * k; out[3] = 0;
  out[4] = B * k; out[5] = (a * i - c * g) * k; out[6] = (c * d - a * f) * k; out[7] = 0;
  out[8] = C * k; out[9] = (b * g - a * h) * k; out[10] = (a * e - b * d) * k; out[11] = 0;
  const tx = m[o + 12], ty = m[o + 13], tz = m[o + 14];
  out[12] = -(out[0] * tx + out[4] * ty + out[8] * tz);
  out[13] = -(out[1] * tx + out[5] * ty + out[9] * tz);
  out[14] = -(out[2] * tx + out[6] * ty + out[10] * tz);
  out[15] = 1;
  return out;
}

/** out = a · b (column-major 4×4; a and b read at offsets ao, bo). out must not alias a or b. */
function mul(a, ao, b, bo, out) {
  for (let c = 0; c < 4; c++) {
    const b0 = b[bo + 4 * c], b1 = b[bo + 4 * c + 1], b2 = b[bo + 4 * c + 2], b3 = b[bo + 4 * c + 3];
    for (let r = 0; r < 4; r++) out[4 * c + r] = a[ao + r] * b0 + a[ao + 4 + r] * b1 + a[ao + 8 + r] * b2 + a[ao + 12 + r] * b3;
  }
  return out;
}

/** Unit quaternion [x, y, z, w] with w ≥ 0 of the rotation part of m (columns normalised). */
function rotationOf(m, q) {
  const l0 = Math.hypot(m[0], m[1], m[2]) || 1, l1 = Math.hypot(m[4], m[5], m[6]) || 1, l2 = Math.hypot(m[8], m[9], m[10]) || 1;
  const m00 = m[0] / l0, m10 = m[1] / l0, m20 = m[2] / l0;
  const m01 = m[4] / l1, m11 = m[5] / l1, m21 = m[6] / l1;
  const m02 = m[8] / l2, m12 = m[9] / l2, m22 = m[10] / l2;
  const tr = m00 + m11 + m22;
  let x, y, z, w;
  if (tr > 0) {
    const s = 0.5 / Math.sqrt(tr + 1);
    w = 0.25 / s; x = (m21 - m12) * s; y = (m02 - m20) * s; z = (m10 - m01) * s;
  } else if (m00 > m11 && m00 > m22) {
    const s = 2 * Math.sqrt(1 + m00 - m11 - m22);
    w = (m21 - m12) / s; x = 0.25 * s; y = (m01 + m10) / s; z = (m02 + m20) / s;
  } else if (m11 > m22) {
    const s = 2 * Math.sqrt(1 + m11 - m00 - m22);
    w = (m02 - m20) / s; x = (m01 + m10) / s; y = 0.25 * s; z = (m12 + m21) / s;
  } else {
    const s = 2 * Math.sqrt(1 + m22 - m00 - m11);
    w = (m10 - m01) / s; x = (m02 + m20) / s; y = (m12 + m21) / s; z = 0.25 * s;
  }
  let n = Math.hypot(x, y, z, w);
  if (w < 0) n = -n;
  q[0] = x / n; q[1] = y / n; q[2] = z / n; q[3] = w / n;
  return q;
}

/**
 * The matrix of D^a: slerp(identity, q, a) about centre c, translation t scaled by a:
 * x ↦ R (x − c) + c + a t.
 */
function fractionMatrix(q, c, t, a, out) {
  let x = q[0], y = q[1], z = q[2], w = q[3];
  if (a === 0) { x = 0; y = 0; z = 0; w = 1; }
  else if (a !== 1) {
    const half = Math.acos(Math.min(1, Math.max(-1, w)));
    const s = Math.sin(half);
    if (s < 1e-6) {
      x *= a; y *= a; z *= a; w = 1;
      const n = Math.hypot(x, y, z, w);
      x /= n; y /= n; z /= n; w /= n;
    } else {
      const k = Math.sin(a * half) / s;
      x *= k; y *= k; z *= k; w = Math.cos(a * half);
    }
  }
  const xx = x * x, yy = y * y, zz = z * z, xy = x * y, xz = x * z, yz = y * z, wx = w * x, wy = w * y, wz = w * z;
  out[0] = 1 - 2 * (yy + zz); out[1] = 2 * (xy + wz); out[2] = 2 * (xz - wy); out[3] = 0;
  out[4] = 2 * (xy - wz); out[5] = 1 - 2 * (xx + zz); out[6] = 2 * (yz + wx); out[7] = 0;
  out[8] = 2 * (xz + wy); out[9] = 2 * (yz - wx); out[10] = 1 - 2 * (xx + yy); out[11] = 0;
  for (let r = 0; r < 3; r++)
    out[12 + r] = c[r] + a * t[r] - (out[r] * c[0] + out[4 + r] * c[1] + out[8 + r] * c[2]);
  out[15] = 1;
  return out;
}

export class JsGcs {
  /**
   * @param {import('../../dist/index.js').GcsDeformer} deformer a built (non-smooth) GCS deformer
   * @param {ArrayLike<number>} parents joint parents (rig input)
   * @param {ArrayLike<number>} inverseBindMatrices J × 16 (rig input)
   */
  constructor(deformer, parents, inverseBindMatrices) {
    const J = parents.length;
    this.J = J;
    const sections = deformer.sections();
    this.sections = sections;
    this.vertexCount = deformer.vertexCount;
    // Rest mesh in output order: the bind-pose deform (exactly the rest mesh for GCS).
    const identity = new Float32Array(J * 16);
    for (let j = 0; j < J; j++) identity[16 * j] = identity[16 * j + 5] = identity[16 * j + 10] = identity[16 * j + 15] = 1;
    deformer.deform(identity);
    this.restPositions = Float32Array.from(deformer.positions);
    this.restNormals = Float32Array.from(deformer.normals);
    this.positions = new Float32Array(this.vertexCount * 3);
    this.normals = new Float32Array(this.vertexCount * 3);
    // Parts (joints that own a section) and their parent parts.
    const isPart = new Uint8Array(J);
    for (const s of sections) isPart[s.part] = 1;
    this.partParent = new Int32Array(J).fill(-1);
    this.partList = [];
    for (let j = 0; j < J; j++) {
      if (!isPart[j]) continue;
      let p = parents[j];
      while (p >= 0 && !isPart[p]) p = parents[p];
      this.partParent[j] = p;
      if (p >= 0) this.partList.push(j);
    }
    // Bind-pose joint centres: the translation of the inverse of each inverse bind matrix.
    this.centres = [];
    const inv = new Float64Array(16);
    for (let j = 0; j < J; j++) {
      invertAffine(inverseBindMatrices, 16 * j, inv);
      this.centres.push([inv[12], inv[13], inv[14]]);
    }
    this.quat = Array.from({ length: J }, () => new Float64Array(4));
    this.trans = Array.from({ length: J }, () => new Float64Array(3));
    this.matrices = new Float64Array(sections.length * 16);
    this.tmpA = new Float64Array(16); this.tmpB = new Float64Array(16); this.tmpC = new Float64Array(16); this.tmpD = new Float64Array(16);
  }

  /** Section transforms of one frame (sectionCount × 16), then every vertex. */
  deform(skin) {
    const { partList, partParent, centres, quat, trans, tmpA, tmpB, tmpC, tmpD, matrices } = this;
    for (const j of partList) {
      invertAffine(skin, 16 * partParent[j], tmpA);
      const d = mul(tmpA, 0, skin, 16 * j, tmpB);
      rotationOf(d, quat[j]);
      const c = centres[j], t = trans[j];
      for (let r = 0; r < 3; r++) t[r] = d[r] * c[0] + d[4 + r] * c[1] + d[8 + r] * c[2] + d[12 + r] - c[r];
    }
    const sections = this.sections;
    for (let i = 0; i < sections.length; i++) {
      const s = sections[i];
      const parent = partParent[s.part];
      let m;
      if (parent < 0) {
        for (let k = 0; k < 16; k++) tmpC[k] = skin[16 * s.part + k];
        m = tmpC;
      } else {
        fractionMatrix(quat[s.part], centres[s.part], trans[s.part], s.alpha, tmpA);
        m = mul(skin, 16 * parent, tmpA, 0, tmpC);
      }
      if (s.distal >= 0 && s.beta > 0) {
        fractionMatrix(quat[s.distal], centres[s.distal], trans[s.distal], s.beta, tmpA);
        m = mul(m, 0, tmpA, 0, tmpD);
      }
      matrices.set(m, 16 * i);
    }
    const rp = this.restPositions, rn = this.restNormals, op = this.positions, on = this.normals;
    for (let i = 0; i < sections.length; i++) {
      const o = 16 * i;
      const m0 = matrices[o], m1 = matrices[o + 1], m2 = matrices[o + 2];
      const m4 = matrices[o + 4], m5 = matrices[o + 5], m6 = matrices[o + 6];
      const m8 = matrices[o + 8], m9 = matrices[o + 9], m10 = matrices[o + 10];
      const m12 = matrices[o + 12], m13 = matrices[o + 13], m14 = matrices[o + 14];
      const end = 3 * (sections[i].first + sections[i].count);
      for (let v = 3 * sections[i].first; v < end; v += 3) {
        const x = rp[v], y = rp[v + 1], z = rp[v + 2];
        op[v] = m0 * x + m4 * y + m8 * z + m12;
        op[v + 1] = m1 * x + m5 * y + m9 * z + m13;
        op[v + 2] = m2 * x + m6 * y + m10 * z + m14;
        const a = rn[v], b = rn[v + 1], c = rn[v + 2];
        on[v] = m0 * a + m4 * b + m8 * c;
        on[v + 1] = m1 * a + m5 * b + m9 * c;
        on[v + 2] = m2 * a + m6 * b + m10 * c;
      }
    }
  }
}
