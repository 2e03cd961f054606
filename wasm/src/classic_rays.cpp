#include "classic_rays.h"
#include <algorithm>
#include <cmath>
#include "classic_geometry.h"

namespace gcs {
namespace classic {
namespace {
constexpr float kOutlierFactor = 3.0f;     // a hit farther than 3 × the contour's median is a miss
}  // namespace

// Each triangle crossing the plane is cut into a 2D segment, and only the rays whose angle lies in
// the segment's angular span are tested. The corners are gathered per part by the caller (the rig's
// vertices are scattered, and every contour of the part reads every triangle).
void castContour(const glm::vec3* corners, const uint32_t* triangles, uint32_t count, const glm::vec3& O,
                 const glm::vec3& n, const glm::vec3& u, const glm::vec3& w, uint32_t k, const float* cosT,
                 const float* sinT, float* radius, uint32_t* hitTriangle) {
  const float step = 2.0f * kPi / float(k);
  const float planeD = glm::dot(O, n);
  for (uint32_t ti = 0; ti < count; ++ti) {
    const uint32_t i = triangles[ti];
    const glm::vec3* c = &corners[size_t(i) * 3];
    // Most triangles lie on one side of the plane: sides first, relative positions only if cut.
    float h[3] = {glm::dot(c[0], n) - planeD, glm::dot(c[1], n) - planeD, glm::dot(c[2], n) - planeD};
    bool neg0 = h[0] < 0.0f, neg1 = h[1] < 0.0f, neg2 = h[2] < 0.0f;
    if (neg0 == neg1 && neg1 == neg2) continue;
    glm::vec3 p[3] = {c[0] - O, c[1] - O, c[2] - O};
    glm::vec2 seg[2];
    int s = 0;
    for (int e = 0; e < 3 && s < 2; ++e) {
      int a = e, b = (e + 1) % 3;
      if ((h[a] < 0.0f) == (h[b] < 0.0f)) continue;
      float f = h[a] / (h[a] - h[b]);
      glm::vec3 x = p[a] + f * (p[b] - p[a]);
      seg[s++] = glm::vec2(glm::dot(x, u), glm::dot(x, w));
    }
    if (s < 2) continue;
    glm::vec2 P = seg[0], E = seg[1] - seg[0];
    float aP = std::atan2(P.y, P.x), aQ = std::atan2(seg[1].y, seg[1].x);
    float delta = aQ - aP;
    if (delta > kPi) delta -= 2.0f * kPi;
    if (delta < -kPi) delta += 2.0f * kPi;
    float start = delta >= 0.0f ? aP : aQ, span = std::fabs(delta);
    int r0 = int(std::ceil((start - 1e-5f) / step));
    int r1 = int(std::floor((start + span + 1e-5f) / step));
    if (r1 - r0 >= int(k)) r1 = r0 + int(k) - 1;
    for (int rr = r0; rr <= r1; ++rr) {
      uint32_t r = uint32_t(((rr % int(k)) + int(k)) % int(k));
      glm::vec2 d(cosT[r], sinT[r]);
      float denom = d.x * E.y - d.y * E.x;
      if (std::fabs(denom) < 1e-12f) continue;
      float lambda = (P.x * E.y - P.y * E.x) / denom;
      float mu = (P.x * d.y - P.y * d.x) / denom;
      if (lambda > 0.0f && mu >= -1e-4f && mu <= 1.0001f &&
          (lambda > radius[r] || (lambda == radius[r] && i < hitTriangle[r])))
        radius[r] = lambda, hitTriangle[r] = i;
    }
  }
}

void TriangleSlabs::build(const glm::vec3* corners, uint32_t count, const glm::vec3& o, const glm::vec3& a) {
  origin = o, axis = a, triCount = count;
  triLo.resize(count), triHi.resize(count);
  float hi = -INFINITY;
  lo = INFINITY, rmax = 0.0f;
  for (uint32_t i = 0; i < count; ++i) {
    float s0 = INFINITY, s1 = -INFINITY;
    for (int e = 0; e < 3; ++e) {
      const glm::vec3 d = corners[size_t(i) * 3 + e] - origin;
      const float s = glm::dot(d, axis);
      s0 = std::min(s0, s), s1 = std::max(s1, s);
      const glm::vec3 r = d - s * axis;
      rmax = std::max(rmax, glm::dot(r, r));  // (squared until the end)
    }
    triLo[i] = s0, triHi[i] = s1;
    lo = std::min(lo, s0), hi = std::max(hi, s1);
  }
  rmax = std::sqrt(rmax);
  // (a float margin: the cut test works on other rounded products than these)
  margin = 1e-4f * (std::fabs(lo) + std::fabs(hi) + rmax) + 1e-30f;
  slabCount = std::max<uint32_t>(1, std::min<uint32_t>(256, count / 16));
  width = count && hi > lo ? (hi - lo) / float(slabCount) : 1.0f;
  if (!(std::isfinite(width) && width > 0.0f && std::isfinite(margin))) slabCount = 1, width = 1.0f;
  first.assign(slabCount + 1, 0);
  for (uint32_t i = 0; i < count; ++i)
    for (uint32_t b = slabOf(triLo[i]), e = slabOf(triHi[i]); b <= e; ++b) ++first[b + 1];
  for (uint32_t b = 0; b < slabCount; ++b) first[b + 1] += first[b];
  members.resize(first[slabCount]);
  std::vector<uint32_t> cursor(first.begin(), first.end() - 1);
  for (uint32_t i = 0; i < count; ++i)
    for (uint32_t b = slabOf(triLo[i]), e = slabOf(triHi[i]); b <= e; ++b) members[cursor[b]++] = i;
}

uint32_t TriangleSlabs::slabOf(float s) const {
  const float x = (s - lo) / width;
  if (!(x > 0.0f)) return 0;  // (NaN too: a rig at the edge of float range)
  return x < float(slabCount - 1) ? uint32_t(x) : slabCount - 1;
}

void TriangleSlabs::candidates(const glm::vec3& O, const glm::vec3& n, std::vector<uint32_t>& out) const {
  out.clear();
  const float c = glm::dot(n, axis);
  const float reach = rmax * std::sqrt(std::max(0.0f, 1.0f - c * c)) / c + margin;
  const float s = glm::dot(O - origin, axis), s0 = s - reach, s1 = s + reach;
  // A plane far from perpendicular to the bone, one slab, or figures past float range: every triangle.
  if (!(c > 0.2f) || slabCount == 1 || !std::isfinite(s0) || !std::isfinite(s1)) {
    for (uint32_t i = 0; i < triCount; ++i) out.push_back(i);
    return;
  }
  const uint32_t b0 = slabOf(s0), b1 = slabOf(s1);
  for (uint32_t b = b0; b <= b1; ++b)
    for (uint32_t m = first[b]; m < first[b + 1]; ++m) {
      const uint32_t i = members[m];
      // (a triangle in several slabs is taken from the first of them that the range reads)
      if (std::max(slabOf(triLo[i]), b0) != b || triHi[i] < s0 || triLo[i] > s1) continue;
      out.push_back(i);
    }
}

uint32_t rejectOutliers(float* radius, uint32_t k, std::vector<float>& scratch) {
  scratch.clear();
  for (uint32_t r = 0; r < k; ++r)
    if (radius[r] > 0.0f) scratch.push_back(radius[r]);
  if (scratch.empty()) return 0;
  std::nth_element(scratch.begin(), scratch.begin() + scratch.size() / 2, scratch.end());
  float limit = kOutlierFactor * scratch[scratch.size() / 2];
  uint32_t hits = 0;
  for (uint32_t r = 0; r < k; ++r) {
    if (radius[r] > limit) radius[r] = -1.0f;
    if (radius[r] > 0.0f) ++hits;
  }
  return hits;
}

bool fillMisses(float* radius, uint32_t k) {
  int firstHit = -1;
  for (uint32_t r = 0; r < k; ++r)
    if (radius[r] > 0.0f) { firstHit = int(r); break; }
  if (firstHit < 0) return false;
  for (uint32_t r = 0; r < k; ++r) {
    if (radius[r] > 0.0f) continue;
    int before = 1, after = 1;
    while (radius[(r + k - before) % k] <= 0.0f) ++before;
    while (radius[(r + after) % k] <= 0.0f) ++after;
    float a = radius[(r + k - before) % k], b = radius[(r + after) % k];
    radius[r] = -(a + (b - a) * float(before) / float(before + after));  // negative: filled
  }
  for (uint32_t r = 0; r < k; ++r) radius[r] = std::fabs(radius[r]);
  return true;
}

}  // namespace classic
}  // namespace gcs
