// Small geometry shared by the classic model's build, its on-skin test and its detail loss.
#pragma once
#include <cmath>
#include <glm/glm.hpp>

namespace gcs {
namespace classic {

constexpr float kPi = 3.14159265358979f;

inline glm::vec3 anyPerpendicular(const glm::vec3& a) {
  glm::vec3 g = std::fabs(a.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(a, g));
}

// The minimal rotation taking unit a to unit b, applied to v.
inline glm::vec3 minRotate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& v) {
  float c = glm::dot(a, b);
  if (c < -0.99999f) {
    glm::vec3 p = anyPerpendicular(a);
    return 2.0f * glm::dot(p, v) * p - v;
  }
  glm::vec3 x = glm::cross(a, b);
  return c * v + glm::cross(x, v) + x * (glm::dot(x, v) / (1.0f + c));
}

// u made perpendicular to unit n and unit length (fallback: any perpendicular).
inline glm::vec3 orthonormal(const glm::vec3& u, const glm::vec3& n) {
  glm::vec3 p = u - glm::dot(u, n) * n;
  float len = glm::length(p);
  return len > 1e-6f ? p / len : anyPerpendicular(n);
}

inline glm::vec3 bisector(const glm::vec3& a, const glm::vec3& b) {
  glm::vec3 s = a + b;
  float len = glm::length(s);
  return len > 1e-6f ? s / len : a;
}

// Closest distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
inline float pointTriangleDistance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return glm::length(ap);
  glm::vec3 bp = p - b;
  float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return glm::length(bp);
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  glm::vec3 cp = p - c;
  float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return glm::length(cp);
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  float denom = 1.0f / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

}  // namespace classic
}  // namespace gcs
