// Small rigid-transform helpers shared by the deformers: fractional rotations about a centre,
// swing/twist split, and the per-vertex 3×4 transform of a run of vertices (SIMD where it pays).
#pragma once
#include <cmath>
#include <cstdint>
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

// Rotation part of an affine matrix as a unit quaternion (columns normalised first so that a
// uniform scale in the rig does not break the conversion).
inline glm::quat rotationOf(const glm::mat4& m) {
  glm::mat3 r(m);
  for (int c = 0; c < 3; ++c) {
    float len = glm::length(r[c]);
    if (len > 0.0f) r[c] /= len;
  }
  return glm::normalize(glm::quat_cast(r));
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

// Transforms `count` interleaved xyz points and normals by one affine matrix m (normals by its
// 3×3 part, assumed a rotation). Output arrays need one spare float after the last vertex.
inline void transformRun(const glm::mat4& m, const float* inPos, const float* inNrm,
                         float* outPos, float* outNrm, uint32_t count) {
#if defined(__wasm_simd128__)
  const v128_t c0 = wasm_v128_load(&m[0][0]);
  const v128_t c1 = wasm_v128_load(&m[1][0]);
  const v128_t c2 = wasm_v128_load(&m[2][0]);
  const v128_t c3 = wasm_v128_load(&m[3][0]);
  for (uint32_t i = 0; i < count; ++i) {
    const float* p = inPos + 3 * i;
    const float* n = inNrm + 3 * i;
    v128_t rp = wasm_f32x4_add(
        wasm_f32x4_add(wasm_f32x4_mul(c0, wasm_v128_load32_splat(p)),
                       wasm_f32x4_mul(c1, wasm_v128_load32_splat(p + 1))),
        wasm_f32x4_add(wasm_f32x4_mul(c2, wasm_v128_load32_splat(p + 2)), c3));
    v128_t rn = wasm_f32x4_add(
        wasm_f32x4_add(wasm_f32x4_mul(c0, wasm_v128_load32_splat(n)),
                       wasm_f32x4_mul(c1, wasm_v128_load32_splat(n + 1))),
        wasm_f32x4_mul(c2, wasm_v128_load32_splat(n + 2)));
    wasm_v128_store(outPos + 3 * i, rp);  // the 4th lane is overwritten by the next vertex
    wasm_v128_store(outNrm + 3 * i, rn);
  }
#else
  for (uint32_t i = 0; i < count; ++i) {
    const float* p = inPos + 3 * i;
    const float* n = inNrm + 3 * i;
    for (int r = 0; r < 3; ++r) {
      outPos[3 * i + r] = m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r];
      outNrm[3 * i + r] = m[0][r] * n[0] + m[1][r] * n[1] + m[2][r] * n[2];
    }
  }
#endif
}

}  // namespace gcs
