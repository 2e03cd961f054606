// Small rigid-transform helpers shared by the deformers: fractional rotations about a centre,
// swing/twist split, and the per-vertex 3×4 transform of a run of vertices (SIMD where it pays).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#if defined(__wasm_simd128__)
#include <wasm_simd128.h>
#endif

namespace gcs {

// A rigid motion split for interpolation: x ↦ R (x − c) + c + t.
struct Motion {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 centre{0.0f};
  glm::vec3 translation{0.0f};
  float angle = 0.0f;  // rotation angle in radians, in [0, π]
  // acos(w) and its sine, computed once per motion so that each of the many fractions taken of
  // it per frame (one per section) costs one sin and one cos instead of acos + 3 trig calls.
  float half = 0.0f, sinHalf = 0.0f;
};

inline float quatAngle(const glm::quat& q) {
  float w = glm::clamp(std::fabs(q.w), 0.0f, 1.0f);
  return 2.0f * std::acos(w);
}

// The largest |entry| of a 3×3 of finite entries. A comparison, not std::fmax: wasm has no
// instruction with fmax's NaN rule, so each fmax is a libc call (a skin matrix takes 9 per frame).
inline float largestAbs(const glm::mat3& m) {
  float big = 0.0f;
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) {
      const float a = std::fabs(m[c][i]);
      big = a > big ? a : big;
    }
  return big;
}

// Rotation part of an affine matrix as a unit quaternion, robust to any scale in the matrix:
// a uniform scale (Mixamo's ×100), a non-uniform one, a mirror, or a collapse to zero. Columns
// are normalised (after dividing by the largest entry, so tiny scales do not underflow); when they
// are not a proper rotation (a mirror, a collapsed axis) the frame is rebuilt from the two longest
// columns; when every column has collapsed the rotation is the identity.
inline glm::quat rotationOf(const glm::mat4& m) {
  glm::mat3 r(m);
  const float big = largestAbs(r);
  if (!(big > 1e-30f)) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  r /= big;
  float len[3];
  for (int c = 0; c < 3; ++c) len[c] = glm::length(r[c]);
  if (len[0] > 1e-4f && len[1] > 1e-4f && len[2] > 1e-4f) {
    glm::mat3 n(r[0] / len[0], r[1] / len[1], r[2] / len[2]);
    if (glm::determinant(n) > 0.9f) return glm::normalize(glm::quat_cast(n));
  }
  // Rebuild a right-handed frame from the longest column a and the next longest b.
  int a = 0;
  for (int c = 1; c < 3; ++c)
    if (len[c] > len[a]) a = c;
  int b = (a + 1) % 3, other = (a + 2) % 3;
  if (len[other] > len[b]) std::swap(b, other);
  glm::mat3 n(1.0f);
  n[a] = r[a] / len[a];
  glm::vec3 vb = r[b] - glm::dot(r[b], n[a]) * n[a];
  float lb = glm::length(vb);
  if (!(lb > 1e-4f)) {  // b collapsed or parallel to a: any axis perpendicular to a
    glm::vec3 helper = std::fabs(n[a].x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    vb = glm::cross(n[a], helper);
    lb = glm::length(vb);
  }
  n[b] = vb / lb;
  n[other] = glm::cross(n[(other + 1) % 3], n[(other + 2) % 3]);
  return glm::normalize(glm::quat_cast(n));
}

// A vector of unit length in the direction of v, or `fallback` when v has (nearly) vanished.
// Divides by the largest component first so tiny vectors do not underflow.
inline glm::vec3 unitOr(const glm::vec3& v, const glm::vec3& fallback) {
  float big = std::fmax(std::fabs(v.x), std::fmax(std::fabs(v.y), std::fabs(v.z)));
  if (!(big > 0.0f) || !std::isfinite(big)) return fallback;  // denormal components still divide exactly
  glm::vec3 u = v / big;
  return u / glm::length(u);
}

// The cofactor matrix of k (det(k) · k^-T when k is invertible): what maps normals through k.
inline glm::mat3 cofactor(const glm::mat3& k) {
  return glm::mat3(glm::cross(k[1], k[2]), glm::cross(k[2], k[0]), glm::cross(k[0], k[1]));
}

// A skin matrix split as S = [R·K | t]: rotation R, the remaining scale/shear K = Rᵀ·S₃ₓ₃, and the
// translation t; R and t also as a unit dual quaternion for blending (Kavan et al. 2007), and the
// matrix that carries its normals (see normalMatrix).
struct JointPose {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 translation{0.0f};
  glm::mat3 scale{1.0f};      // K
  glm::vec4 real{0.0f, 0.0f, 0.0f, 1.0f}, dual{0.0f};  // (x, y, z, w)
  glm::mat4 normal{1.0f};     // 3×3 in a mat4, 4th row and column 0 (SIMD lane 4 stays 0)
  bool renormalise = false;
};

// What the scale parts of one frame's poses have in common: blends take shortcuts when every K is
// the same matrix (`same`), and more when that matrix is s·I, s > 0 (`uniform`).
struct ScaleState {
  bool same = true;
  bool uniform = true;
  float s = 1.0f;
};

// True when k is s·I with s > 0 up to a relative 1e-4: then normals need only the rotation.
inline bool isUniformScale(const glm::mat3& k) {
  float s = (k[0][0] + k[1][1] + k[2][2]) / 3.0f;
  if (!(s > 0.0f)) return false;
  float tol = 1e-4f * s;
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i)
      if (std::fabs(k[c][i] - (c == i ? s : 0.0f)) > tol) return false;
  return true;
}

// The matrix that carries normals for the affine map x ↦ R·K·x + t: R when K is a positive
// uniform scale (then unit normals stay unit); otherwise R·cof(K) divided by its largest entry, so
// the caller must renormalise (`renormalise` is set); R alone when K has collapsed entirely.
inline glm::mat3 normalMatrix(const glm::mat3& r, const glm::mat3& k, bool& renormalise) {
  if (isUniformScale(k)) {
    renormalise = false;
    return r;
  }
  // Scale k to entries ≤ 1 first: the cofactor multiplies entries pairwise (×1e20 would overflow).
  const float kbig = largestAbs(k);
  renormalise = true;
  if (!(kbig > 1e-30f)) return r;
  glm::mat3 c = cofactor(k / kbig);
  const float big = largestAbs(c);
  if (!(big > 1e-30f)) return r;  // every direction collapsed: keep the rotated rest normal
  return r * (c / big);
}

inline glm::mat3 normalMatrix(const glm::quat& rotation, const glm::mat3& k, bool& renormalise) {
  return normalMatrix(glm::mat3_cast(rotation), k, renormalise);
}

// The rotation, scale and normal matrix of a skin matrix whose 3×3 is c·R, R a rotation and c > 0
// (a rig without scale animation, Mixamo's ×100 included: nearly every joint of every frame): its
// Gram matrix SᵀS is c²·I, so R = S/c and K = c·I without rotationOf's normalisations and the
// product Rᵀ·S. False (out untouched) when SᵀS differs from c²·I by more than 2e-6·c² (K then
// differs from c·I by about 1e-6·c, well inside decomposeEach's 1e-5 for a uniform frame), for a
// mirror, and for c² outside [1e-12, 1e12] (the general path keeps tiny and huge scales in range).
inline bool similarityPart(const glm::mat4& s, JointPose& out) {
  const glm::vec3 a(s[0]), b(s[1]), c(s[2]);
  const float aa = glm::dot(a, a), bb = glm::dot(b, b), cc = glm::dot(c, c);
  const float c2 = (aa + bb + cc) * (1.0f / 3.0f);
  if (!(c2 >= 1e-12f && c2 <= 1e12f)) return false;
  const float tol = 2e-6f * c2;
  if (std::fabs(aa - c2) > tol || std::fabs(bb - c2) > tol || std::fabs(cc - c2) > tol ||
      std::fabs(glm::dot(a, b)) > tol || std::fabs(glm::dot(a, c)) > tol || std::fabs(glm::dot(b, c)) > tol ||
      !(glm::dot(glm::cross(a, b), c) > 0.0f))
    return false;
  const float k = std::sqrt(c2), inv = 1.0f / k;
  const glm::mat3 rm(a * inv, b * inv, c * inv);
  out.rotation = glm::normalize(glm::quat_cast(rm));
  out.scale = glm::mat3(k);
  out.normal = glm::mat4(rm);  // orthonormal within 1e-6: normals stay unit
  out.renormalise = false;
  return true;
}

inline void decompose(const glm::mat4& s, JointPose& out) {
  if (!similarityPart(s, out)) {
    out.rotation = rotationOf(s);
    const glm::mat3 rm = glm::mat3_cast(out.rotation);
    out.scale = glm::transpose(rm) * glm::mat3(s);
    out.normal = glm::mat4(normalMatrix(rm, out.scale, out.renormalise));
  }
  out.normal[3][3] = 0.0f;
  out.translation = glm::vec3(s[3]);
  const glm::quat r = out.rotation;
  const glm::quat d = 0.5f * (glm::quat(0.0f, out.translation.x, out.translation.y, out.translation.z) * r);
  out.real = glm::vec4(r.x, r.y, r.z, r.w);
  out.dual = glm::vec4(d.x, d.y, d.z, d.w);
}

// Decomposes the skin matrices of the joints jointAt(0 … count−1) and tells what their scales have
// in common. `uniform` holds when every K_j is s·I up to a relative 1e-5 (float rounding of Rᵀ·S
// makes exact equality rare on animated rigs), all with the same s; s is then exact when the first
// joint's K is exactly uniform (the bind pose: 1).
template <class JointAt>
inline ScaleState decomposeEach(const glm::mat4* skin, uint32_t count, JointAt jointAt, JointPose* poses) {
  ScaleState st;
  if (count == 0) return st;
  const uint32_t first = jointAt(0);
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t j = jointAt(k);
    decompose(skin[j], poses[j]);
    if (st.same && k > 0 && poses[j].scale != poses[first].scale) st.same = false;
  }
  const glm::mat3& k0 = poses[first].scale;
  const float s0 = (k0[0][0] + k0[1][1] + k0[2][2]) / 3.0f;
  st.uniform = s0 > 0.0f;
  const float tol = 1e-5f * s0;
  for (uint32_t n = 0; n < count && st.uniform; ++n) {
    const glm::mat3& k = poses[jointAt(n)].scale;
    for (int c = 0; c < 3 && st.uniform; ++c)
      for (int i = 0; i < 3; ++i)
        if (std::fabs(k[c][i] - (c == i ? s0 : 0.0f)) > tol) {
          st.uniform = false;
          break;
        }
  }
  st.s = st.uniform ? s0 : 1.0f;
  if (st.uniform && k0[0][0] == k0[1][1] && k0[1][1] == k0[2][2]) st.s = k0[0][0];
  return st;
}

// Every joint 0 … count−1 (decomposeEach).
inline ScaleState decomposeAll(const glm::mat4* skin, uint32_t count, JointPose* poses) {
  return decomposeEach(skin, count, [](uint32_t k) { return k; }, poses);
}

// Only the listed joints (a mesh's own, on a skeleton shared by several meshes: decomposeEach).
inline ScaleState decomposeJoints(const glm::mat4* skin, const uint32_t* joints, uint32_t count, JointPose* poses) {
  return decomposeEach(skin, count, [joints](uint32_t k) { return joints[k]; }, poses);
}

// True when every scale is the same s·I with s in [1e-6, 1e6]: the fast uniform path (normal
// matrices as position matrices over s, rotation traces over s², the cubic's 1/s⁵) stays within
// float range there; ×1e20 or ×1e-20 rigs take the general path.
inline bool moderateUniform(const ScaleState& st) { return st.uniform && st.s >= 1e-6f && st.s <= 1e6f; }

// The blend of joint poses with weights w_i (Σ w_i = 1), as dual-quaternion skinning does it:
// rotation and translation by the normalised linear blend of the dual quaternions (each taken in
// the hemisphere of the first), scale/shear by the linear blend of the K_i, applied first.
// Writes the position matrix [R·K | t] and the normal matrix (see normalMatrix).
inline void blendPoses(const JointPose* const* poses, const float* w, uint32_t count, const ScaleState& scale,
                       glm::mat4& position, glm::mat4& normal, bool& renormalise) {
  const glm::vec4 pivot = poses[0]->real;
  glm::vec4 br(0.0f), bd(0.0f);
  for (uint32_t i = 0; i < count; ++i) {
    float s = glm::dot(poses[i]->real, pivot) < 0.0f ? -w[i] : w[i];
    br += s * poses[i]->real;
    bd += s * poses[i]->dual;
  }
  // Unit quaternion r = br/|br| as a matrix, and t = 2·(bd·conj(br))/|br|² (its vector part), without
  // normalising br and bd first. |br| ≥ the largest weight: the quaternions share a hemisphere.
  const float inv2 = 1.0f / glm::dot(br, br);
  const glm::vec3 rv(br), dv(bd);
  const glm::vec3 tv = (2.0f * inv2) * (br.w * dv - bd.w * rv - glm::cross(dv, rv));
  const float xx = br.x * br.x, yy = br.y * br.y, zz = br.z * br.z, xy = br.x * br.y, xz = br.x * br.z,
              yz = br.y * br.z, wx = br.w * br.x, wy = br.w * br.y, wz = br.w * br.z, k2 = 2.0f * inv2;
  glm::mat3 rot(1.0f - k2 * (yy + zz), k2 * (xy + wz), k2 * (xz - wy),
                k2 * (xy - wz), 1.0f - k2 * (xx + zz), k2 * (yz + wx),
                k2 * (xz + wy), k2 * (yz - wx), 1.0f - k2 * (xx + yy));
  glm::mat3 rk;
  if (scale.uniform) {  // the common case (every K = s·I): no per-section scale work
    rk = scale.s * rot;
    renormalise = false;
    normal = glm::mat4(rot);
  } else {
    glm::mat3 k(0.0f);
    if (scale.same) k = poses[0]->scale;
    else
      for (uint32_t i = 0; i < count; ++i) k += w[i] * poses[i]->scale;
    rk = rot * k;
    normal = glm::mat4(normalMatrix(glm::normalize(glm::quat(br.w, br.x, br.y, br.z)), k, renormalise));
  }
  normal[3] = glm::vec4(0.0f);
  position = glm::mat4(glm::vec4(rk[0], 0.0f), glm::vec4(rk[1], 0.0f), glm::vec4(rk[2], 0.0f),
                       glm::vec4(tv.x, tv.y, tv.z, 1.0f));
}

inline Motion motionAbout(const glm::mat4& d, const glm::vec3& centre) {
  Motion m;
  m.rotation = rotationOf(d);
  if (m.rotation.w < 0.0f) m.rotation = -m.rotation;  // shortest arc
  m.centre = centre;
  m.translation = glm::vec3(d * glm::vec4(centre, 1.0f)) - centre;
  m.angle = quatAngle(m.rotation);
  m.half = std::acos(glm::clamp(m.rotation.w, -1.0f, 1.0f));
  m.sinHalf = std::sin(m.half);
  return m;
}

// slerp(identity, q, a) for a unit quaternion q with w ≥ 0.
inline glm::quat fractionOf(const glm::quat& q, float a) {
  if (a == 1.0f) return q;
  if (a == 0.0f) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  float w = glm::clamp(q.w, -1.0f, 1.0f);
  float half = std::acos(w);
  float s = std::sin(half);
  if (s < 1e-6f) return glm::normalize(glm::quat(1.0f, a * q.x, a * q.y, a * q.z));
  float k = std::sin(a * half) / s;
  return glm::quat(std::cos(a * half), k * q.x, k * q.y, k * q.z);
}

// fractionOf(q, a) with half = acos(clamp(q.w)) and s = sin(half) precomputed (same result).
inline glm::quat fractionOf(const glm::quat& q, float half, float s, float a) {
  if (a == 1.0f) return q;
  if (a == 0.0f) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  if (s < 1e-6f) return glm::normalize(glm::quat(1.0f, a * q.x, a * q.y, a * q.z));
  float k = std::sin(a * half) / s;
  return glm::quat(std::cos(a * half), k * q.x, k * q.y, k * q.z);
}

// The matrix of x ↦ R (x − c) + c + t.
inline glm::mat4 matrixOf(const glm::quat& r, const glm::vec3& centre, const glm::vec3& t) {
  glm::mat4 m = glm::mat4_cast(r);
  m[3] = glm::vec4(centre + t - glm::vec3(m * glm::vec4(centre, 0.0f)), 1.0f);
  return m;
}

// D^a: the fraction a of a motion (slerped rotation about its centre, scaled translation).
inline glm::mat4 fractionMatrix(const Motion& m, float a) {
  return matrixOf(fractionOf(m.rotation, m.half, m.sinHalf, a), m.centre, a * m.translation);
}

// Splits q = swing · twist, twist about the unit axis (bind space).
inline void swingTwist(const glm::quat& q, const glm::vec3& axis, glm::quat& swing, glm::quat& twist) {
  glm::vec3 v(q.x, q.y, q.z);
  glm::vec3 p = glm::dot(v, axis) * axis;
  glm::quat t(q.w, p.x, p.y, p.z);
  float len = glm::length(t);
  twist = len > 1e-8f ? t / len : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  if (twist.w < 0.0f) twist = -twist;
  swing = q * glm::conjugate(twist);
}

#if defined(__wasm_simd128__)
// The 4×4 transpose of rows a, b, c, d (lane k of the result i is lane i of row k).
inline void transpose4(v128_t& a, v128_t& b, v128_t& c, v128_t& d) {
  const v128_t ab0 = wasm_i32x4_shuffle(a, b, 0, 4, 1, 5), ab1 = wasm_i32x4_shuffle(a, b, 2, 6, 3, 7);
  const v128_t cd0 = wasm_i32x4_shuffle(c, d, 0, 4, 1, 5), cd1 = wasm_i32x4_shuffle(c, d, 2, 6, 3, 7);
  a = wasm_i32x4_shuffle(ab0, cd0, 0, 1, 4, 5), b = wasm_i32x4_shuffle(ab0, cd0, 2, 3, 6, 7);
  c = wasm_i32x4_shuffle(ab1, cd1, 0, 1, 4, 5), d = wasm_i32x4_shuffle(ab1, cd1, 2, 3, 6, 7);
}
// x·c0 + y·c1 + z·c2 (+ c3) of the 3 floats at p, in one SIMD register (4th lane unused).
inline v128_t affine(v128_t c0, v128_t c1, v128_t c2, v128_t c3, const float* p) {
  return wasm_f32x4_add(wasm_f32x4_add(wasm_f32x4_mul(c0, wasm_v128_load32_splat(p)),
                                       wasm_f32x4_mul(c1, wasm_v128_load32_splat(p + 1))),
                        wasm_f32x4_add(wasm_f32x4_mul(c2, wasm_v128_load32_splat(p + 2)), c3));
}
// c0·n[0] + c1·n[1] + c2·n[2]: a normal turned by a 3×3 held in SIMD columns (their 4th lane 0 for
// affine matrices, so the result's 4th lane is 0 too).
inline v128_t linear3(v128_t c0, v128_t c1, v128_t c2, const float* n) {
  return wasm_f32x4_add(wasm_f32x4_add(wasm_f32x4_mul(c0, wasm_v128_load32_splat(n)),
                                       wasm_f32x4_mul(c1, wasm_v128_load32_splat(n + 1))),
                        wasm_f32x4_mul(c2, wasm_v128_load32_splat(n + 2)));
}
// v divided by the length of its xyz lanes (lane 4 must be 0, as normal matrices make it); a zero
// vector stays zero. All in SIMD: no lane extraction. Divided by its largest component first, so
// that tiny vectors (a normal through a 1e-20 scale) do not underflow when squared.
inline v128_t normalise3(v128_t v) {
  v128_t a = wasm_f32x4_abs(v);
  v128_t m = wasm_f32x4_max(a, wasm_i32x4_shuffle(a, a, 1, 0, 3, 2));
  m = wasm_f32x4_max(m, wasm_i32x4_shuffle(m, m, 2, 3, 0, 1));
  v = wasm_f32x4_div(v, wasm_f32x4_max(m, wasm_f32x4_splat(1e-45f)));  // denormals too
  v128_t sq = wasm_f32x4_mul(v, v);
  v128_t t = wasm_f32x4_add(sq, wasm_i32x4_shuffle(sq, sq, 1, 0, 3, 2));
  v128_t sum = wasm_f32x4_add(t, wasm_i32x4_shuffle(t, t, 2, 3, 0, 1));
  return wasm_f32x4_div(v, wasm_f32x4_sqrt(wasm_f32x4_max(sum, wasm_f32x4_splat(1e-30f))));
}
// v (4th lane 0) scaled to unit length when it is already near unit (a blend of rotations less than
// 35° apart): 1/sqrt(1 + e) ≈ 1 − e/2 + 3e²/8 with e = |v|² − 1 (error ≤ 3e-4 there), no square root
// or division. The constants are passed in so that loops keep them in registers.
inline v128_t nearUnit(v128_t v, v128_t one, v128_t minusHalf, v128_t threeEighths) {
  v128_t sq = wasm_f32x4_mul(v, v);
  v128_t s2 = wasm_f32x4_add(sq, wasm_i32x4_shuffle(sq, sq, 1, 0, 3, 2));
  v128_t e = wasm_f32x4_sub(wasm_f32x4_add(s2, wasm_i32x4_shuffle(s2, s2, 2, 3, 0, 1)), one);
  return wasm_f32x4_mul(v, wasm_f32x4_add(one, wasm_f32x4_mul(e, wasm_f32x4_add(minusHalf, wasm_f32x4_mul(threeEighths, e)))));
}
#endif

// A normal the transform has annihilated (a flattening scale maps some directions to 0) keeps
// its rest direction, so that every output normal is unit.
inline void keepUnit(float* out, const float* rest) {
  if (out[0] == 0.0f && out[1] == 0.0f && out[2] == 0.0f) out[0] = rest[0], out[1] = rest[1], out[2] = rest[2];
}

inline void normaliseInPlace(float* n) {
  glm::vec3 v = unitOr(glm::vec3(n[0], n[1], n[2]), glm::vec3(n[0], n[1], n[2]));
  n[0] = v.x, n[1] = v.y, n[2] = v.z;
}

// Transforms `count` interleaved xyz points by the affine matrix m and their normals by the 3×3
// matrix nm (see normalMatrix), renormalising the normals when Renormalise. Output arrays need one
// spare float after the last vertex (the SIMD path stores 4 lanes per vertex).
template <bool Renormalise>
inline void transformRunT(const glm::mat4& m, const glm::mat4& nm, const float* inPos, const float* inNrm,
                          float* outPos, float* outNrm, uint32_t count) {
#if defined(__wasm_simd128__)
  const v128_t c0 = wasm_v128_load(&m[0][0]), c1 = wasm_v128_load(&m[1][0]);
  const v128_t c2 = wasm_v128_load(&m[2][0]), c3 = wasm_v128_load(&m[3][0]);
  const v128_t n0 = wasm_v128_load(&nm[0][0]), n1 = wasm_v128_load(&nm[1][0]), n2 = wasm_v128_load(&nm[2][0]);
  const v128_t zero = wasm_f32x4_splat(0.0f);
  for (uint32_t i = 0; i < count; ++i) {
    wasm_v128_store(outPos + 3 * i, affine(c0, c1, c2, c3, inPos + 3 * i));  // lane 4 spills into the next vertex
    v128_t rn = affine(n0, n1, n2, zero, inNrm + 3 * i);
    wasm_v128_store(outNrm + 3 * i, Renormalise ? normalise3(rn) : rn);
    if (Renormalise) keepUnit(outNrm + 3 * i, inNrm + 3 * i);
  }
#else
  for (uint32_t i = 0; i < count; ++i) {
    const float* p = inPos + 3 * i;
    const float* n = inNrm + 3 * i;
    for (int r = 0; r < 3; ++r) {
      outPos[3 * i + r] = m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r];
      outNrm[3 * i + r] = nm[0][r] * n[0] + nm[1][r] * n[1] + nm[2][r] * n[2];
    }
    if (Renormalise) normaliseInPlace(outNrm + 3 * i), keepUnit(outNrm + 3 * i, n);
  }
#endif
}

inline void transformRun(const glm::mat4& m, const glm::mat4& nm, bool renormalise, const float* inPos,
                         const float* inNrm, float* outPos, float* outNrm, uint32_t count) {
  if (renormalise) transformRunT<true>(m, nm, inPos, inNrm, outPos, outNrm, count);
  else transformRunT<false>(m, nm, inPos, inNrm, outPos, outNrm, count);
}

// A run of vertices under one transform m = s·R (a uniform frame): positions by m, normals by m's
// 3×3 over s (= R, so they stay unit). Five loop constants instead of transformRunT's seven.
inline void transformRunUniform(const glm::mat4& m, float invS, const float* inPos, const float* inNrm, float* outPos,
                                float* outNrm, uint32_t count) {
#if defined(__wasm_simd128__)
  const v128_t c0 = wasm_v128_load(&m[0][0]), c1 = wasm_v128_load(&m[1][0]);
  const v128_t c2 = wasm_v128_load(&m[2][0]), c3 = wasm_v128_load(&m[3][0]);
  const v128_t s0 = wasm_f32x4_splat(invS);
  for (uint32_t i = 0; i < count; ++i) {
    const float* n = inNrm + 3 * i;
    const v128_t rn = linear3(c0, c1, c2, n);
    wasm_v128_store(outPos + 3 * i, affine(c0, c1, c2, c3, inPos + 3 * i));  // lane 4 spills into the next vertex
    wasm_v128_store(outNrm + 3 * i, wasm_f32x4_mul(rn, s0));
  }
#else
  transformRunT<false>(m, invS * m, inPos, inNrm, outPos, outNrm, count);
#endif
}

// How a blended normal's length is restored: exactly (sqrt and division), by a cubic approximation
// of 1/sqrt around 1 (both normal matrices rotations less than 35° apart: error ≤ 3e-4), or not at
// all (rotations less than 2.8° apart: the blend's length falls short of 1 by at most
// (1 − cos θ)/4 ≤ 3e-4, the cubic's own bound, so the fix would change nothing visible).
enum class NormalFix { Exact, Cubic, None };

constexpr float kNearTrace = 1.0f + 2.0f * 0.82f;            // trace of Ra^T Rb = 1 + 2 cos θ: θ < 35°
constexpr float kAlmostEqualTrace = 1.0f + 2.0f * 0.9988f;   // θ < 2.8°
// Three rotations pairwise θ apart: a convex blend of three unit vectors lies within a cap of
// radius θ/√3 (Jung), so it falls short of 1 by at most 1 − cos(θ/√3) ≈ (1 − cos θ)/3: under 3e-4
// for θ < 2.4° (no fix), and its length² stays above 0.93 for θ < 25° (the cubic errs < 1.5e-4).
constexpr float kAlmostEqualTrace3 = 1.0f + 2.0f * 0.9991f;  // θ < 2.4°
constexpr float kNearTrace3 = 1.0f + 2.0f * 0.9063f;         // θ < 25°

// The fix for a blend of three rotations, from the least of their three pairwise traces.
inline NormalFix rotationBlendFix3(float leastTrace) {
  return leastTrace > kAlmostEqualTrace3 ? NormalFix::None : leastTrace > kNearTrace3 ? NormalFix::Cubic : NormalFix::Exact;
}

// The trace of na^T nb (3×3 parts): 1 + 2 cos θ when both are rotations θ apart. Once per blend run:
// in SIMD, as the 4th lane of an affine matrix's columns is 0.
inline float rotationTrace(const glm::mat4& na, const glm::mat4& nb) {
#if defined(__wasm_simd128__)
  v128_t p = wasm_f32x4_mul(wasm_v128_load(&na[0][0]), wasm_v128_load(&nb[0][0]));
  p = wasm_f32x4_add(p, wasm_f32x4_mul(wasm_v128_load(&na[1][0]), wasm_v128_load(&nb[1][0])));
  p = wasm_f32x4_add(p, wasm_f32x4_mul(wasm_v128_load(&na[2][0]), wasm_v128_load(&nb[2][0])));
  p = wasm_f32x4_add(p, wasm_i32x4_shuffle(p, p, 1, 0, 3, 2));
  p = wasm_f32x4_add(p, wasm_i32x4_shuffle(p, p, 2, 3, 0, 1));
  return wasm_f32x4_extract_lane(p, 0);
#else
  return glm::dot(glm::vec3(na[0]), glm::vec3(nb[0])) + glm::dot(glm::vec3(na[1]), glm::vec3(nb[1])) +
         glm::dot(glm::vec3(na[2]), glm::vec3(nb[2]));
#endif
}

// The least pairwise trace of three normal matrices (a three-node blend's fix: rotationBlendFix3).
inline float leastRotationTrace(const glm::mat4& na, const glm::mat4& nb, const glm::mat4& nc) {
  return std::min({rotationTrace(na, nb), rotationTrace(na, nc), rotationTrace(nb, nc)});
}

// The fix for a blend of two normal matrices that are rotations (trace: rotationTrace).
inline NormalFix rotationBlendFix(float trace) {
  return trace > kAlmostEqualTrace ? NormalFix::None : trace > kNearTrace ? NormalFix::Cubic : NormalFix::Exact;
}

// Smooth mode, a run of vertices that all blend transform A with the same transform B: vertex i
// takes lerp(A, B, f[i]) for its position and normal, the normal's length restored as Fix says.
template <NormalFix Fix>
inline void blendRunT(const glm::mat4& pa, const glm::mat4& na, const glm::mat4& pb, const glm::mat4& nb,
                      const float* f, const float* inPos, const float* inNrm, float* outPos, float* outNrm,
                      uint32_t count) {
#if defined(__wasm_simd128__)
  const v128_t a0 = wasm_v128_load(&pa[0][0]), a1 = wasm_v128_load(&pa[1][0]);
  const v128_t a2 = wasm_v128_load(&pa[2][0]), a3 = wasm_v128_load(&pa[3][0]);
  const v128_t d0 = wasm_f32x4_sub(wasm_v128_load(&pb[0][0]), a0), d1 = wasm_f32x4_sub(wasm_v128_load(&pb[1][0]), a1);
  const v128_t d2 = wasm_f32x4_sub(wasm_v128_load(&pb[2][0]), a2), d3 = wasm_f32x4_sub(wasm_v128_load(&pb[3][0]), a3);
  const v128_t m0 = wasm_v128_load(&na[0][0]), m1 = wasm_v128_load(&na[1][0]), m2 = wasm_v128_load(&na[2][0]);
  const v128_t e0 = wasm_f32x4_sub(wasm_v128_load(&nb[0][0]), m0), e1 = wasm_f32x4_sub(wasm_v128_load(&nb[1][0]), m1);
  const v128_t e2 = wasm_f32x4_sub(wasm_v128_load(&nb[2][0]), m2);
  const v128_t zero = wasm_f32x4_splat(0.0f);
  const v128_t one = wasm_f32x4_splat(1.0f), half = wasm_f32x4_splat(-0.5f), c38 = wasm_f32x4_splat(0.375f);
  for (uint32_t i = 0; i < count; ++i) {
    const v128_t t = wasm_v128_load32_splat(f + i);
    const v128_t c0 = wasm_f32x4_add(a0, wasm_f32x4_mul(t, d0)), c1 = wasm_f32x4_add(a1, wasm_f32x4_mul(t, d1));
    const v128_t c2 = wasm_f32x4_add(a2, wasm_f32x4_mul(t, d2)), c3 = wasm_f32x4_add(a3, wasm_f32x4_mul(t, d3));
    const v128_t n0 = wasm_f32x4_add(m0, wasm_f32x4_mul(t, e0)), n1 = wasm_f32x4_add(m1, wasm_f32x4_mul(t, e1));
    const v128_t n2 = wasm_f32x4_add(m2, wasm_f32x4_mul(t, e2));
    wasm_v128_store(outPos + 3 * i, affine(c0, c1, c2, c3, inPos + 3 * i));
    v128_t rn = affine(n0, n1, n2, zero, inNrm + 3 * i);
    if (Fix == NormalFix::None) {
      wasm_v128_store(outNrm + 3 * i, rn);
    } else if (Fix == NormalFix::Cubic) {
      wasm_v128_store(outNrm + 3 * i, nearUnit(rn, one, half, c38));
    } else {
      wasm_v128_store(outNrm + 3 * i, normalise3(rn));
      keepUnit(outNrm + 3 * i, inNrm + 3 * i);
    }
  }
#else
  for (uint32_t i = 0; i < count; ++i) {
    const float t = f[i];
    const float* p = inPos + 3 * i;
    const float* n = inNrm + 3 * i;
    for (int r = 0; r < 3; ++r) {
      float v = 0.0f, w = 0.0f;
      for (int c = 0; c < 3; ++c) {
        v += (pa[c][r] + t * (pb[c][r] - pa[c][r])) * p[c];
        w += (na[c][r] + t * (nb[c][r] - na[c][r])) * n[c];
      }
      outPos[3 * i + r] = v + pa[3][r] + t * (pb[3][r] - pa[3][r]);
      outNrm[3 * i + r] = w;
    }
    if (Fix != NormalFix::None) normaliseInPlace(outNrm + 3 * i), keepUnit(outNrm + 3 * i, n);
  }
#endif
}

#if defined(__wasm_simd128__)
// Stores a blended normal v of a uniform frame (v = s × a blend of rotations) with its length
// restored as Fix says: times 1/s (None); times 1/|v| for |v|² near s², invS·(1 − e/2 + 3e²/8) with
// e = |v|²/s² − 1, as a polynomial in |v|² (Cubic: three constants, so that a kernel's live values
// fit the registers); or normalised exactly (a vanished one keeps its rest direction). UnitScale:
// s is exactly 1 (rigs in metres), so None stores v as it is.
template <NormalFix Fix, bool UnitScale = false>
struct UniformNormalStore {
  v128_t p0, p1, p2;
  explicit UniformNormalStore(float invS) {
    const float k = invS * invS;
    p0 = wasm_f32x4_splat(Fix == NormalFix::Cubic ? 1.875f * invS : invS);
    p1 = wasm_f32x4_splat(-1.25f * invS * k);
    p2 = wasm_f32x4_splat(0.375f * invS * k * k);
  }
  void operator()(float* out, v128_t v, const float* rest) const {
    if (Fix == NormalFix::None) {
      wasm_v128_store(out, UnitScale ? v : wasm_f32x4_mul(v, p0));
    } else if (Fix == NormalFix::Cubic) {
      v128_t sq = wasm_f32x4_mul(v, v);
      sq = wasm_f32x4_add(sq, wasm_i32x4_shuffle(sq, sq, 1, 0, 3, 2));
      sq = wasm_f32x4_add(sq, wasm_i32x4_shuffle(sq, sq, 2, 3, 0, 1));
      wasm_v128_store(out, wasm_f32x4_mul(v, wasm_f32x4_add(p0, wasm_f32x4_mul(sq, wasm_f32x4_add(p1, wasm_f32x4_mul(p2, sq))))));
    } else {
      wasm_v128_store(out, normalise3(v));
      keepUnit(out, rest);
    }
  }
};
#endif

// Smooth mode when every joint's scale is the same uniform s (the common case: then a section's
// normal matrix is its position matrix's 3×3 divided by s): one lerp of the position matrices serves
// the normals too (stored by UniformNormalStore: the cubic fix has the 1/s folded in): eleven
// loop constants (8 matrix columns, 3 coefficients) instead of blendRunT's 18, so no spills. Same
// results as blendRunT on the normal matrices up to rounding.
template <NormalFix Fix, bool UnitScale = false>
inline void blendRunUniformT(const glm::mat4& pa, const glm::mat4& pb, float invS, const float* f, const float* inPos,
                             const float* inNrm, float* outPos, float* outNrm, uint32_t count) {
#if defined(__wasm_simd128__)
  const v128_t a0 = wasm_v128_load(&pa[0][0]), a1 = wasm_v128_load(&pa[1][0]);
  const v128_t a2 = wasm_v128_load(&pa[2][0]), a3 = wasm_v128_load(&pa[3][0]);
  const v128_t d0 = wasm_f32x4_sub(wasm_v128_load(&pb[0][0]), a0), d1 = wasm_f32x4_sub(wasm_v128_load(&pb[1][0]), a1);
  const v128_t d2 = wasm_f32x4_sub(wasm_v128_load(&pb[2][0]), a2), d3 = wasm_f32x4_sub(wasm_v128_load(&pb[3][0]), a3);
  const UniformNormalStore<Fix, UnitScale> storeNormal(invS);
  for (uint32_t i = 0; i < count; ++i) {
    const v128_t t = wasm_v128_load32_splat(f + i);
    const v128_t c0 = wasm_f32x4_add(a0, wasm_f32x4_mul(t, d0)), c1 = wasm_f32x4_add(a1, wasm_f32x4_mul(t, d1));
    const v128_t c2 = wasm_f32x4_add(a2, wasm_f32x4_mul(t, d2));
    const float* n = inNrm + 3 * i;
    const v128_t rn = linear3(c0, c1, c2, n);
    wasm_v128_store(outPos + 3 * i, affine(c0, c1, c2, wasm_f32x4_add(a3, wasm_f32x4_mul(t, d3)), inPos + 3 * i));
    storeNormal(outNrm + 3 * i, rn, n);
  }
#else
  // Without SIMD: the general kernel, with the normal matrices the position matrices over s.
  blendRunT<Fix == NormalFix::None ? NormalFix::None : NormalFix::Exact>(pa, invS * pa, pb, invS * pb, f, inPos, inNrm,
                                                                         outPos, outNrm, count);
#endif
}

// Smooth mode, a run of vertices that blend three transforms (positions pa/pb/pc, normals na/nb/nc)
// by f and g: M = A + f·(B − A) + g·(C − A), normals likewise, their length restored as `fix` says
// (a vanished normal keeps its rest direction). Scalar: for frames with non-uniform scales only.
inline void blendRun3(const glm::mat4& pa, const glm::mat4& na, const glm::mat4& pb, const glm::mat4& nb,
                      const glm::mat4& pc, const glm::mat4& nc, NormalFix fix, const float* f, const float* g,
                      const float* inPos, const float* inNrm, float* outPos, float* outNrm, uint32_t count) {
  for (uint32_t i = 0; i < count; ++i) {
    const glm::mat4 m = pa + f[i] * (pb - pa) + g[i] * (pc - pa);
    const glm::mat3 nm = glm::mat3(na + f[i] * (nb - na) + g[i] * (nc - na));
    const float* p = inPos + 3 * i;
    const float* n = inNrm + 3 * i;
    const glm::vec3 q = glm::vec3(m * glm::vec4(p[0], p[1], p[2], 1.0f));
    glm::vec3 r = nm * glm::vec3(n[0], n[1], n[2]);
    if (fix == NormalFix::Cubic) {
      const float e = glm::dot(r, r) - 1.0f;
      r *= 1.0f + e * (-0.5f + 0.375f * e);
    }
    for (int k = 0; k < 3; ++k) outPos[3 * i + k] = q[k], outNrm[3 * i + k] = r[k];
    if (fix == NormalFix::Exact) normaliseInPlace(outNrm + 3 * i), keepUnit(outNrm + 3 * i, n);
  }
}

// Smooth mode, a run of vertices that blend three transforms A, B, C (a three-joint lattice cell)
// when every scale is the same uniform s: vertex i takes A + f[i]·(B − A) + g[i]·(C − A) for its
// position and, over s, its normal, whose length is restored as Fix says (rotationBlendFix3).
template <NormalFix Fix, bool UnitScale = false>
inline void blendRun3UniformT(const glm::mat4& pa, const glm::mat4& pb, const glm::mat4& pc, float invS,
                              const float* f, const float* g, const float* inPos, const float* inNrm, float* outPos,
                              float* outNrm, uint32_t count) {
#if defined(__wasm_simd128__)
  v128_t a[4], d[4], e[4];
  for (int c = 0; c < 4; ++c) {
    a[c] = wasm_v128_load(&pa[c][0]);
    d[c] = wasm_f32x4_sub(wasm_v128_load(&pb[c][0]), a[c]);
    e[c] = wasm_f32x4_sub(wasm_v128_load(&pc[c][0]), a[c]);
  }
  const UniformNormalStore<Fix, UnitScale> storeNormal(invS);
  for (uint32_t i = 0; i < count; ++i) {
    const v128_t t = wasm_v128_load32_splat(f + i), u = wasm_v128_load32_splat(g + i);
    v128_t c[4];
    for (int k = 0; k < 4; ++k) c[k] = wasm_f32x4_add(wasm_f32x4_add(a[k], wasm_f32x4_mul(t, d[k])), wasm_f32x4_mul(u, e[k]));
    const float* n = inNrm + 3 * i;
    const v128_t rn = linear3(c[0], c[1], c[2], n);
    wasm_v128_store(outPos + 3 * i, affine(c[0], c[1], c[2], c[3], inPos + 3 * i));
    storeNormal(outNrm + 3 * i, rn, n);
  }
#else
  blendRun3(pa, invS * pa, pb, invS * pb, pc, invS * pc, Fix, f, g, inPos, inNrm, outPos, outNrm, count);
#endif
}

// Calls kernel(fix, unit) with both as compile-time constants (std::integral_constant), so each
// uniform blend kernel is instantiated for the fixes it can meet: unit (s exactly 1) only matters
// for NormalFix::None, the one fix without a 1/s folded into its constants.
template <class Kernel>
inline void withUniformFix(NormalFix fix, bool unitScale, Kernel kernel) {
  using None = std::integral_constant<NormalFix, NormalFix::None>;
  if (fix == NormalFix::None && unitScale) kernel(None{}, std::true_type{});
  else if (fix == NormalFix::None) kernel(None{}, std::false_type{});
  else if (fix == NormalFix::Cubic) kernel(std::integral_constant<NormalFix, NormalFix::Cubic>{}, std::false_type{});
  else kernel(std::integral_constant<NormalFix, NormalFix::Exact>{}, std::false_type{});
}

// Chooses the kernel: a rotation blend's fix (rotationBlendFix) when neither normal matrix is
// flagged for renormalisation, else the exact one.
inline void blendRun(const glm::mat4& pa, const glm::mat4& na, bool renormA, const glm::mat4& pb, const glm::mat4& nb,
                     bool renormB, const float* f, const float* inPos, const float* inNrm, float* outPos,
                     float* outNrm, uint32_t count) {
  const NormalFix fix = renormA || renormB ? NormalFix::Exact : rotationBlendFix(rotationTrace(na, nb));
  if (fix == NormalFix::None) blendRunT<NormalFix::None>(pa, na, pb, nb, f, inPos, inNrm, outPos, outNrm, count);
  else if (fix == NormalFix::Cubic) blendRunT<NormalFix::Cubic>(pa, na, pb, nb, f, inPos, inNrm, outPos, outNrm, count);
  else blendRunT<NormalFix::Exact>(pa, na, pb, nb, f, inPos, inNrm, outPos, outNrm, count);
}

}  // namespace gcs
