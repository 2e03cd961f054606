#include "classic_model.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <new>
#include <glm/gtc/matrix_transform.hpp>
#include "error.h"
#include "reference_deformers.h"
#include "transform.h"

namespace gcs {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kMinBoneFraction = 0.03f;  // a cylinder-like part is at least 3 % of the height long
constexpr float kMaxMissShare = 0.3f;      // more missing rays than this: carried
constexpr float kOutlierFactor = 3.0f;     // a hit farther than 3 × the contour's median is a miss
constexpr float kMaxExtension = 0.5f;      // a tube end passes a rigid neighbour's joint by ≤ ½ bone
constexpr float kMaxBendCos = 0.70710678f; // a chain continues only while bones turn by ≤ 45°
constexpr float kBranchBehind = 0.25f;     // a root trunk part's branches start before ¼ of its bone
constexpr float kCutMargin = 0.05f;        // a trunk tube ends ¹⁄₂₀ bone short of its branches
constexpr float kMinTrunkSpan = 0.25f;     // … and keeps at least ¼ of its bone
constexpr float kMinTubeSpan = 0.1f;       // a tube between its end loops spans ≥ ⅒ of its bone
constexpr float kBandWidth = 0.02f;        // a tube ends ¹⁄₅₀ bone inside its loop
constexpr uint32_t kProbeContours = 5;     // contours cast to decide whether a part resamples

glm::vec3 anyPerpendicular(const glm::vec3& a) {
  glm::vec3 g = std::fabs(a.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(a, g));
}

// The minimal rotation taking unit a to unit b, applied to v.
glm::vec3 minRotate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& v) {
  float c = glm::dot(a, b);
  if (c < -0.99999f) {
    glm::vec3 p = anyPerpendicular(a);
    return 2.0f * glm::dot(p, v) * p - v;
  }
  glm::vec3 x = glm::cross(a, b);
  return c * v + glm::cross(x, v) + x * (glm::dot(x, v) / (1.0f + c));
}

// u made perpendicular to unit n and unit length (fallback: any perpendicular).
glm::vec3 orthonormal(const glm::vec3& u, const glm::vec3& n) {
  glm::vec3 p = u - glm::dot(u, n) * n;
  float len = glm::length(p);
  return len > 1e-6f ? p / len : anyPerpendicular(n);
}

glm::vec3 bisector(const glm::vec3& a, const glm::vec3& b) {
  glm::vec3 s = a + b;
  float len = glm::length(s);
  return len > 1e-6f ? s / len : a;
}

// Casts the `k` star rays of one contour plane (origin O, normal n, frame u, w) against a triangle
// list: each triangle crossing the plane is cut into a 2D segment, and only the rays whose angle
// lies in the segment's angular span are tested. radius[r] = the outermost hit distance so far
// (−1 before any hit; the caller resets it, so several triangle lists can be cast in turn), and
// hitTriangle[r] the index of the triangle it hit.
// corners: 3 positions per triangle, contiguous (gathered once per part: the rig's vertices are
// scattered, and every contour of the part reads every triangle).
void castContour(const glm::vec3* corners, uint32_t triCount, const glm::vec3& O, const glm::vec3& n,
                 const glm::vec3& u, const glm::vec3& w, uint32_t k, const float* cosT, const float* sinT, float* radius,
                 uint32_t* hitTriangle) {
  const float step = 2.0f * kPi / float(k);
  const float planeD = glm::dot(O, n);
  for (uint32_t i = 0; i < triCount; ++i) {
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
      if (lambda > 0.0f && mu >= -1e-4f && mu <= 1.0001f && lambda > radius[r]) radius[r] = lambda, hitTriangle[r] = i;
    }
  }
}

// Hits farther than kOutlierFactor × the contour's median hit are misses (a ray that slipped past
// the limb and hit a far part of the surface). Returns the number of hits left.
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

// Misses take the radius of their nearest hit neighbours (interpolated by angle). False when the
// contour has no hit at all.
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

// Closest distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
float pointTriangleDistance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
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

}  // namespace

float ClassicModel::stat(GcsStat which) const {
  switch (which) {
    case GCS_STAT_SECTIONS: return float(contours.size());
    case GCS_STAT_PARTS: return float(reportJoints.size());
    case GCS_STAT_ADJUSTED_SHARE: return 1.0f;  // every contour is recomputed each frame
    case GCS_STAT_ADJUSTED_SECTIONS: return float(contours.size());
  }
  return std::nanf("");
}

namespace {

// One build of the model. Parts marked in `forceCarry` (if given) are carried (GCS_CLASSIC_OFF_SURFACE).
// ringTriangle: per ring vertex, the rig triangle its ray hit (T: a filled miss).
ClassicModel* buildOnce(const Rig& rig, uint32_t contourSetting, uint32_t k, float bulge,
                        const std::vector<uint8_t>* forceCarry, std::vector<uint32_t>& ringTriangle) {
  if (contourSetting < GCS_CLASSIC_MIN_CONTOURS || contourSetting > GCS_CLASSIC_MAX_CONTOURS) {
    fail(GCS_ERR_OUT_OF_RANGE, "the contour count must be between %d and %d; got %u",
         GCS_CLASSIC_MIN_CONTOURS, GCS_CLASSIC_MAX_CONTOURS, contourSetting);
    return nullptr;
  }
  if (k < GCS_CLASSIC_MIN_RAYS || k > GCS_CLASSIC_MAX_RAYS) {
    fail(GCS_ERR_OUT_OF_RANGE, "the ray count must be between %d and %d; got %u", GCS_CLASSIC_MIN_RAYS,
         GCS_CLASSIC_MAX_RAYS, k);
    return nullptr;
  }
  if (!(bulge >= 0.0f && bulge <= GCS_CLASSIC_MAX_BULGE)) {
    fail(GCS_ERR_OUT_OF_RANGE, "the bulge must be between 0 and %g; got %g", double(GCS_CLASSIC_MAX_BULGE),
         double(bulge));
    return nullptr;
  }
  ClassicModel* model = nullptr;
  try {
    model = new ClassicModel();
    ClassicModel& m = *model;
    const uint32_t J = rig.jointCount;
    m.jointCount = J;
    m.rays = k;
    m.bulge = bulge;
    m.height = rig.height > 0.0f ? rig.height : 1.0f;
    m.jointCentres = rig.jointCentres;
    m.cosTable.resize(k);
    m.sinTable.resize(k);
    for (uint32_t r = 0; r < k; ++r) {
      double a = 2.0 * 3.14159265358979323846 * double(r) / double(k);
      m.cosTable[r] = float(std::cos(a));
      m.sinTable[r] = float(std::sin(a));
    }

    // 1. Parts by dominant weight (welded), parent part = nearest ancestor that owns vertices.
    std::vector<uint32_t> representative;
    std::vector<uint32_t> group = weldByPosition(rig, representative);
    const uint32_t G = uint32_t(representative.size());
    std::vector<uint32_t> partOf(rig.vertexCount);
    m.parts.assign(J, ClassicPart());
    for (uint32_t j = 0; j < J; ++j) m.parts[j].joint = j;
    for (uint32_t v = 0; v < rig.vertexCount; ++v) {
      partOf[v] = rig.dominantJoint(representative[group[v]]);
      m.parts[partOf[v]].isPart = true;
    }
    std::vector<std::vector<uint32_t>> childParts(J);
    for (uint32_t j = 0; j < J; ++j) {
      if (!m.parts[j].isPart) continue;
      int32_t p = rig.parents[j];
      while (p >= 0 && !m.parts[p].isPart) p = rig.parents[p];
      m.parts[j].parent = p;
      if (p >= 0) childParts[p].push_back(j);
    }

    // 2. Own triangles: triangles with at least one vertex in the part (boundary triangles count
    // for both sides, so the end contours find skin on either side of the weight boundary).
    const uint32_t T = uint32_t(rig.indices.size() / 3);
    std::vector<uint32_t> triFirst(J + 1, 0), triList;
    {
      auto forParts = [&](uint32_t t, auto&& fn) {
        uint32_t a = partOf[rig.indices[3 * t]], b = partOf[rig.indices[3 * t + 1]],
                 c = partOf[rig.indices[3 * t + 2]];
        fn(a);
        if (b != a) fn(b);
        if (c != a && c != b) fn(c);
      };
      for (uint32_t t = 0; t < T; ++t) forParts(t, [&](uint32_t p) { ++triFirst[p + 1]; });
      for (uint32_t j = 0; j < J; ++j) triFirst[j + 1] += triFirst[j];
      triList.resize(triFirst[J]);
      std::vector<uint32_t> cursor(triFirst.begin(), triFirst.end() - 1);
      for (uint32_t t = 0; t < T; ++t) forParts(t, [&](uint32_t p) { triList[cursor[p]++] = t; });
    }

    // 3. Directions of every part (for bends), candidates (chain parts long enough), their axes.
    std::vector<glm::vec3> centroid(J, glm::vec3(0.0f));
    std::vector<uint32_t> ownCount(J, 0);
    for (uint32_t g = 0; g < G; ++g) {
      uint32_t v = representative[g];
      centroid[partOf[v]] += rig.positions[v];
      ++ownCount[partOf[v]];
    }
    const float minBone = kMinBoneFraction * m.height;
    for (uint32_t j = 0; j < J; ++j) {
      ClassicPart& P = m.parts[j];
      if (!P.isPart) continue;
      const glm::vec3 cj = rig.jointCentres[j];
      glm::vec3 dir(0.0f);
      for (uint32_t c : childParts[j]) {
        glm::vec3 d = rig.jointCentres[c] - cj;
        if (glm::length(d) > 1e-6f * m.height) dir += glm::normalize(d);
      }
      if (childParts[j].empty() && ownCount[j]) dir = centroid[j] / float(ownCount[j]) - cj;
      if (glm::length(dir) < 1e-6f * m.height && P.parent >= 0) dir = cj - rig.jointCentres[P.parent];
      P.direction = glm::length(dir) > 1e-6f * m.height ? glm::normalize(dir) : glm::vec3(0, 1, 0);
      if (childParts[j].empty()) {
        P.reason = GCS_CLASSIC_LEAF;
      } else if (childParts[j].size() > 1) {
        P.reason = GCS_CLASSIC_BRANCHING;
      } else {
        P.child = int32_t(childParts[j][0]);
        glm::vec3 bone = rig.jointCentres[P.child] - cj;
        P.length = glm::length(bone);
        if (!(P.length >= minBone)) {
          P.reason = GCS_CLASSIC_TOO_SHORT;
        } else {
          P.candidate = P.resampled = true;
          P.axis = bone / P.length;
        }
      }
    }
    // Trunk parts that branch (pelvis, chest): resampled along the child that continues the trunk,
    // on the side away from the other children (the branches), whose region stays carried.
    // The continuing child: after a resampled-candidate parent, the one child whose own direction
    // turns by at most 45° from the parent's bone (a chest's neck, not its shoulders); with no such
    // parent, the one child whose siblings' joints lie behind a quarter of the bone to it and whose
    // siblings' own directions all point away from its own (a pelvis's spine, the thighs below).
    // branchOf[j][x]: for a split part j, the child of j whose subtree holds part x (−1: none or
    // the continuing child's).
    std::vector<std::vector<int32_t>> branchOf(J);
    for (uint32_t j = 0; j < J; ++j) {
      ClassicPart& P = m.parts[j];
      if (!P.isPart || childParts[j].size() < 2) continue;
      const glm::vec3 cj = rig.jointCentres[j];
      const bool afterTube = P.parent >= 0 && m.parts[P.parent].candidate && !m.parts[P.parent].split;
      int32_t chosen = -1, matches = 0;
      for (uint32_t c : childParts[j]) {
        glm::vec3 bone = rig.jointCentres[c] - cj;
        float len = glm::length(bone);
        if (!(len >= minBone)) continue;
        // The child's own direction (its bone onward): a shoulder's points along the arm.
        const glm::vec3 a = bone / len, own = m.parts[c].direction;
        bool ok;
        if (afterTube) {
          ok = glm::dot(own, m.parts[P.parent].axis) >= kMaxBendCos;
        } else {
          ok = true;
          for (uint32_t o : childParts[j])
            if (o != c && (glm::dot(rig.jointCentres[o] - cj, a) > kBranchBehind * len ||
                           glm::dot(m.parts[o].direction, own) >= 0.0f))
              ok = false;
        }
        if (ok) chosen = int32_t(c), ++matches;
      }
      if (matches != 1) continue;
      branchOf[j].assign(J, -1);
      for (uint32_t x = 0; x < J; ++x) {
        if (!m.parts[x].isPart) continue;
        int32_t y = int32_t(x);
        while (y >= 0 && m.parts[y].parent != int32_t(j)) y = m.parts[y].parent;
        if (y >= 0 && y != chosen) branchOf[j][x] = y;
      }
      glm::vec3 bone = rig.jointCentres[chosen] - cj;
      P.split = afterTube ? 2 : 1;
      P.child = chosen;
      P.length = glm::length(bone);
      P.axis = bone / P.length;
      P.candidate = P.resampled = true;
      P.reason = GCS_CLASSIC_TRUNK;
    }
    float longest = 0.0f;
    for (uint32_t j = 0; j < J; ++j)
      if (m.parts[j].candidate) longest = std::max(longest, m.parts[j].length);
    // Reference directions: parallel-transported down each chain of candidates, so that the
    // contour frames agree at shared contours; a chain starts from +Z (or +Y) projected.
    {
      std::vector<uint8_t> done(J, 0);
      std::vector<uint32_t> stack;
      for (uint32_t j0 = 0; j0 < J; ++j0) {
        if (!m.parts[j0].candidate || done[j0]) continue;
        stack.clear();
        uint32_t j = j0;
        while (true) {  // climb to the first undone candidate ancestor
          stack.push_back(j);
          int32_t p = m.parts[j].parent;
          if (p < 0 || !m.parts[p].candidate || done[p]) break;
          j = uint32_t(p);
        }
        for (size_t s = stack.size(); s-- > 0;) {
          ClassicPart& P = m.parts[stack[s]];
          int32_t p = P.parent;
          if (p >= 0 && m.parts[p].candidate) {
            P.u = orthonormal(minRotate(m.parts[p].axis, P.axis, m.parts[p].u), P.axis);
          } else {
            glm::vec3 g = std::fabs(P.axis.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
            P.u = orthonormal(g, P.axis);
          }
          done[stack[s]] = 1;
        }
      }
    }
    for (uint32_t j = 0; j < J; ++j) {
      ClassicPart& P = m.parts[j];
      if (!P.candidate) continue;
      float share = P.length / longest;
      P.contourCount = std::max<uint32_t>(GCS_CLASSIC_MIN_CONTOURS,
                                          uint32_t(std::lround(double(contourSetting) * share)));
      P.contourCount = std::min(P.contourCount, contourSetting);
    }

    // Which welded vertices the tubes replace. A split trunk part's tube side: its vertices short
    // of its cut, and those of its carried direct branch children (a shoulder's skin down the
    // flank) short of it too; the rest of it is carried. Its cut: 1/20 bone short of the nearest of
    // its (and those children's) vertices that share a triangle with the rest of its branches.
    std::vector<uint32_t> gPart(G);
    for (uint32_t g = 0; g < G; ++g) gPart[g] = partOf[representative[g]];
    auto tOn = [&](const ClassicPart& P, uint32_t v) {
      return glm::dot(rig.positions[v] - rig.jointCentres[P.joint], P.axis) / P.length;
    };
    auto member = [&](uint32_t j, uint32_t x) {  // x is j, or a carried direct branch child of j
      return x == j || (branchOf[j][x] == int32_t(x) && !m.parts[x].resampled);
    };
    auto beforeCut = [&](const ClassicPart& P, uint32_t v) {
      float t = tOn(P, v);
      return P.split == 1 ? t > P.cut : t < P.cut;
    };
    // The part whose tube replaces welded vertex g, or −1 if it is carried (before islands).
    auto baseOwner = [&](uint32_t g) -> int32_t {
      const uint32_t x = gPart[g], v = representative[g];
      const ClassicPart& X = m.parts[x];
      if (X.resampled) return !X.split || beforeCut(X, v) ? int32_t(x) : -1;
      const int32_t p = X.parent;
      if (p >= 0 && m.parts[p].split && m.parts[p].resampled && member(uint32_t(p), x) && beforeCut(m.parts[p], v)) return p;
      return -1;
    };
    auto updateCut = [&](uint32_t j) {  // false: less than kMinTrunkSpan of the bone is left
      ClassicPart& P = m.parts[j];
      float lo = INFINITY, hi = -INFINITY;
      for (uint32_t x = 0; x < J; ++x) {
        if (!m.parts[x].isPart || !member(j, x)) continue;
        for (uint32_t i = triFirst[x]; i < triFirst[x + 1]; ++i) {
          const uint32_t* t = &rig.indices[size_t(triList[i]) * 3];
          bool touches = false;
          for (int e = 0; e < 3; ++e) touches = touches || (branchOf[j][partOf[t[e]]] >= 0 && !member(j, partOf[t[e]]));
          if (!touches) continue;
          for (int e = 0; e < 3; ++e)
            if (member(j, partOf[t[e]])) {
              float tv = tOn(P, t[e]);
              lo = std::min(lo, tv), hi = std::max(hi, tv);
            }
        }
      }
      // (a chest's tube ends by its continuing child's joint; a pelvis's starts at most half a
      // bone before its joint: beyond, its branches are not around it but along it)
      if (P.split == 2) P.cut = std::isfinite(lo) ? std::min(1.0f, lo - kCutMargin) : 1.0f;
      else P.cut = std::isfinite(hi) ? hi + kCutMargin : 0.0f;
      return P.split == 2 ? P.cut >= kMinTrunkSpan : P.cut <= 1.0f - kMinTrunkSpan && P.cut >= -kMaxExtension;
    };
    // Extent of each candidate's tube-side vertices along its bone (for open tube ends).
    auto updateExtents = [&]() {
      for (uint32_t j = 0; j < J; ++j) m.parts[j].ownTMin = 0.0f, m.parts[j].ownTMax = 1.0f;
      for (uint32_t g = 0; g < G; ++g) {
        int32_t o = baseOwner(g);
        if (o < 0) continue;
        ClassicPart& P = m.parts[o];
        float t = tOn(P, representative[g]);
        P.ownTMin = std::max(-kMaxExtension, std::min(P.ownTMin, t));
        P.ownTMax = std::min(1.0f + kMaxExtension, std::max(P.ownTMax, t));
      }
      for (uint32_t j = 0; j < J; ++j) {
        ClassicPart& P = m.parts[j];
        if (P.split == 1) P.ownTMin = P.cut;
        if (P.split == 2) P.ownTMax = P.cut;
      }
    };

    // Triangles over welded vertices, and their edges sorted by (smaller, larger) welded vertex:
    // what the boundary loops between tubes and the carried mesh are traced on.
    struct WeldedEdge {
      uint32_t lo, hi, from, tri;
    };
    // Edges grouped by their smaller welded vertex (a counting sort: linear), each group by the larger.
    std::vector<WeldedEdge> edges;
    {
      std::vector<uint32_t> first(G + 1, 0);
      auto forEdges = [&](auto&& fn) {
        for (uint32_t t = 0; t < T; ++t) {
          uint32_t g[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
          if (g[0] == g[1] || g[1] == g[2] || g[0] == g[2]) continue;
          for (int e = 0; e < 3; ++e) {
            uint32_t a = g[e], b = g[(e + 1) % 3];
            fn(WeldedEdge{std::min(a, b), std::max(a, b), a, t});
          }
        }
      };
      forEdges([&](const WeldedEdge& e) { ++first[e.lo + 1]; });
      for (uint32_t g = 0; g < G; ++g) first[g + 1] += first[g];
      edges.resize(first[G]);
      forEdges([&](const WeldedEdge& e) { edges[first[e.lo]++] = e; });
      for (uint32_t g = G; g > 0; --g) first[g] = first[g - 1];
      first[0] = 0;
      for (uint32_t g = 0; g < G; ++g)  // a vertex has a handful of edges: insertion sort
        for (uint32_t i = first[g] + 1; i < first[g + 1]; ++i)
          for (uint32_t j = i; j > first[g] && edges[j - 1].hi > edges[j].hi; --j) std::swap(edges[j - 1], edges[j]);
    }

    // 4. Which parts are resampled, and where their tubes end. Rays decide (too many misses:
    // carried); then the boundary between the tubes and the carried triangles (those with a
    // carried vertex) is traced: each loop must be one ring around one tube's unshared end, or the
    // part is carried (GCS_CLASSIC_SEAM); that end's contours start just inside the loop.
    // Parts are only ever removed, so this ends.
    std::vector<std::vector<float>> hits(J);
    std::vector<std::vector<uint32_t>> hitTriangles(J);
    std::vector<uint8_t> dirty(J, 0);
    for (uint32_t j = 0; j < J; ++j) dirty[j] = m.parts[j].candidate && !m.parts[j].split;  // trunk parts: once cut
    if (forceCarry)
      for (uint32_t j = 0; j < J; ++j)
        if ((*forceCarry)[j] && m.parts[j].resampled) m.parts[j].resampled = false, m.parts[j].reason = GCS_CLASSIC_OFF_SURFACE;
    std::vector<float> scratch;
    scratch.reserve(k);
    auto endNormals = [&](const ClassicPart& P, glm::vec3& nProx, glm::vec3& nDist) {
      nProx = P.proxShared ? bisector(m.parts[P.parent].axis, P.axis) : P.axis;
      nDist = P.distShared ? bisector(P.axis, m.parts[P.child].axis) : P.axis;
    };
    auto contourFrame = [&](const ClassicPart& P, float t, const glm::vec3& nProx, const glm::vec3& nDist,
                            glm::vec3& centre, glm::vec3& n, glm::vec3& u) {
      centre = rig.jointCentres[P.joint] + t * P.length * P.axis;
      float tc = glm::clamp(t, 0.0f, 1.0f);
      n = glm::normalize((1.0f - tc) * nProx + tc * nDist);
      u = orthonormal(minRotate(P.axis, n, P.u), n);
    };
    // Casts `count` contours of part j evenly over [tLo, tHi] into out (count × k radii): its own
    // triangles; a trunk part's also its continuing child's and its carried branch children's (its
    // tube runs through their skin). Counts the hits left after outliers, and those between joints.
    std::vector<float> probe;
    std::vector<uint32_t> probeTriangles;
    std::vector<glm::vec3> corners;
    std::vector<uint32_t> cornerTriangle;  // the rig triangle of each gathered one
    auto castPart = [&](uint32_t j, uint32_t count, const glm::vec3& nProx, const glm::vec3& nDist,
                        std::vector<float>& out, std::vector<uint32_t>& outTriangles, uint32_t& hitCount,
                        uint32_t& inRangeHits, uint32_t& inRangeRays) {
      const ClassicPart& P = m.parts[j];
      out.assign(size_t(count) * k, -1.0f);  // no hit yet
      outTriangles.assign(size_t(count) * k, 0);
      corners.clear();
      cornerTriangle.clear();
      for (uint32_t x = 0; x < J; ++x) {
        if (x != j && !(P.split && (int32_t(x) == P.child || (m.parts[x].isPart && member(j, x))))) continue;
        for (uint32_t i = triFirst[x]; i < triFirst[x + 1]; ++i) {
          for (int e = 0; e < 3; ++e) corners.push_back(rig.positions[rig.indices[size_t(triList[i]) * 3 + e]]);
          cornerTriangle.push_back(triList[i]);
        }
      }
      const uint32_t triCount = uint32_t(corners.size() / 3);
      for (uint32_t i = 0; i < count; ++i) {
        float t = P.tLo + (P.tHi - P.tLo) * float(i) / float(count - 1);
        glm::vec3 O, n, u;
        contourFrame(P, t, nProx, nDist, O, n, u);
        float* rad = &out[size_t(i) * k];
        uint32_t* tri = &outTriangles[size_t(i) * k];
        castContour(corners.data(), triCount, O, n, u, glm::cross(n, u), k, m.cosTable.data(), m.sinTable.data(), rad, tri);
        for (uint32_t r = 0; r < k; ++r) tri[r] = rad[r] > 0.0f ? cornerTriangle[tri[r]] : 0;
        uint32_t h = rejectOutliers(rad, k, scratch);
        hitCount += h;
        if (t >= -1e-4f && t <= 1.0001f) inRangeHits += h, inRangeRays += k;
      }
    };
    auto shares = [&](const ClassicPart& P) {  // P's distal joint contour is shared with its child
      if (!P.resampled || P.child < 0 || P.split == 2) return false;
      const ClassicPart& C = m.parts[P.child];
      return C.resampled && C.split != 1;
    };
    // A tube's span along its bone: 0 / 1 at a shared joint, just inside its border loop where it
    // meets carried skin, its own vertices' extent at an open end.
    auto spanOf = [](const ClassicPart& P, float& lo, float& hi) {
      lo = P.proxShared ? 0.0f : P.proxLoop >= 0 ? P.loopTLo : P.ownTMin;
      hi = P.distShared ? 1.0f : P.distLoop >= 0 ? P.loopTHi : P.ownTMax;
    };
    auto carry = [&](uint32_t j, uint8_t reason) {
      ClassicPart& P = m.parts[j];
      P.resampled = false;
      P.reason = reason;
      if (P.parent >= 0 && m.parts[P.parent].resampled) dirty[P.parent] = 1;
      if (P.child >= 0 && m.parts[P.child].resampled) dirty[P.child] = 1;
    };
    // Boundary loops: welded vertices in order, the part whose end they close, which end.
    struct Loop {
      std::vector<uint32_t> groups;
      uint32_t part = 0;
      bool distal = false;
    };
    std::vector<Loop> loops;
    std::vector<uint8_t> triCarried(T, 0);
    // Islands (real meshes: a strap or a pouch weighted to another bone, a few vertices of a part
    // inside its neighbour's skin): a tube region cut off from the main region of its part is
    // carried; a carried patch that touches one tube only, lies along its bone and is no bigger
    // than its tube-side skin is replaced by that tube. Either would leave a loop that is no ring
    // around a tube end (a side loop): a gap or an overlap.
    std::vector<int32_t> gOwner(G, -1);
    std::vector<uint32_t> root(G);
    auto find = [&](uint32_t x) {
      while (root[x] != x) x = root[x] = root[root[x]];
      return x;
    };
    auto unite = [&](uint32_t a, uint32_t b) {
      a = find(a), b = find(b);
      if (a != b) root[std::max(a, b)] = std::min(a, b);
    };
    auto owner = [&](uint32_t g) { return gOwner[g]; };
    auto computeOwners = [&]() {
      for (uint32_t g = 0; g < G; ++g) gOwner[g] = baseOwner(g);
      // Skin where two tubes that share no ring touch (a crotch between the thighs) is carried:
      // no tube surface would cover it.
      auto joined = [&](int32_t a, int32_t b) {
        return a == b || (m.parts[a].child == b && m.parts[a].distShared) || (m.parts[b].child == a && m.parts[b].distShared);
      };
      std::vector<uint8_t> apart(G, 0);
      for (uint32_t t = 0; t < T; ++t) {
        uint32_t v[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
        for (int e = 0; e < 3; ++e) {
          int32_t a = gOwner[v[e]], b = gOwner[v[(e + 1) % 3]];
          if (a >= 0 && b >= 0 && !joined(a, b)) apart[v[e]] = apart[v[(e + 1) % 3]] = 1;
        }
      }
      for (uint32_t g = 0; g < G; ++g)
        if (apart[g]) gOwner[g] = -1;
      // Tube regions: welded vertices joined by triangles of three tube-side vertices.
      for (uint32_t g = 0; g < G; ++g) root[g] = g;
      for (uint32_t t = 0; t < T; ++t) {
        uint32_t a = group[rig.indices[3 * t]], b = group[rig.indices[3 * t + 1]], c = group[rig.indices[3 * t + 2]];
        if (gOwner[a] >= 0 && gOwner[b] >= 0 && gOwner[c] >= 0) unite(a, b), unite(b, c);
      }
      std::vector<std::pair<uint32_t, uint32_t>> partRoot;  // (owner, region) per tube vertex
      for (uint32_t g = 0; g < G; ++g)
        if (gOwner[g] >= 0) partRoot.push_back({uint32_t(gOwner[g]), find(g)});
      std::sort(partRoot.begin(), partRoot.end());
      std::vector<uint32_t> mainRegion(J, UINT32_MAX), mainSize(J, 0), tubeSize(J, 0);
      for (size_t i = 0; i < partRoot.size();) {
        size_t e = i;
        while (e < partRoot.size() && partRoot[e] == partRoot[i]) ++e;
        uint32_t part = partRoot[i].first;
        tubeSize[part] += uint32_t(e - i);
        if (e - i > mainSize[part]) mainSize[part] = uint32_t(e - i), mainRegion[part] = partRoot[i].second;
        i = e;
      }
      for (uint32_t g = 0; g < G; ++g)
        if (gOwner[g] >= 0 && find(g) != mainRegion[gOwner[g]]) gOwner[g] = -1;
      // Carried patches: carried welded vertices joined by triangles; the tubes each one touches.
      for (uint32_t g = 0; g < G; ++g) root[g] = g;
      for (uint32_t t = 0; t < T; ++t) {
        uint32_t v[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
        for (int e = 0; e < 3; ++e)
          if (gOwner[v[e]] < 0 && gOwner[v[(e + 1) % 3]] < 0) unite(v[e], v[(e + 1) % 3]);
      }
      std::vector<int32_t> touches(G, -2);  // per patch: −2 none yet, a part, or −1 several
      for (uint32_t t = 0; t < T; ++t) {
        uint32_t v[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
        for (int e = 0; e < 3; ++e) {
          if (gOwner[v[e]] >= 0) continue;
          for (int f = 0; f < 3; ++f) {
            if (gOwner[v[f]] < 0) continue;
            int32_t& tt = touches[find(v[e])];
            tt = tt == -2 || tt == gOwner[v[f]] ? gOwner[v[f]] : -1;
          }
        }
      }
      std::vector<uint32_t> patchSize(G, 0);
      std::vector<float> patchT(G, 0.0f);
      for (uint32_t g = 0; g < G; ++g) {
        if (gOwner[g] >= 0) continue;
        uint32_t r = find(g);
        if (touches[r] < 0) continue;
        ++patchSize[r];
        patchT[r] += tOn(m.parts[touches[r]], representative[g]);
      }
      for (uint32_t g = 0; g < G; ++g) {
        if (gOwner[g] >= 0) continue;
        uint32_t r = find(g);
        if (touches[r] < 0) continue;
        float t = patchT[r] / float(patchSize[r]);
        if (patchSize[r] <= tubeSize[touches[r]] && t > 0.0f && t < 1.0f) gOwner[g] = touches[r];
      }
    };
    for (int round = 0; round < 64; ++round) {
      updateExtents();
      for (int pass = 0; pass < 64; ++pass) {
        bool any = false;
        for (uint32_t j = 0; j < J; ++j) {
          ClassicPart& P = m.parts[j];
          if (!P.resampled || !dirty[j]) continue;
          dirty[j] = 0;
          P.proxShared = P.parent >= 0 && m.parts[P.parent].child == int32_t(j) && shares(m.parts[P.parent]);
          P.distShared = shares(P);
          spanOf(P, P.tLo, P.tHi);
          glm::vec3 nProx, nDist;
          endNormals(P, nProx, nDist);
          // The decision looks at up to kProbeContours contours (the full set is cast once, at the end).
          const uint32_t mm = std::min(P.contourCount, kProbeContours);
          uint32_t hitCount = 0, inRangeHits = 0, inRangeRays = 0;
          castPart(j, mm, nProx, nDist, probe, probeTriangles, hitCount, inRangeHits, inRangeRays);
          // The miss rule looks at the contours between the joints (past a joint, skin of the
          // carried neighbour is expected to be missing); all contours if none lies between them.
          float miss = inRangeRays ? 1.0f - float(inRangeHits) / float(inRangeRays)
                                   : 1.0f - float(hitCount) / float(mm * k);
          if (hitCount == 0 || miss > kMaxMissShare) carry(j, GCS_CLASSIC_RAYS_MISS), any = true;
        }
        if (any) continue;
        // Once the ray tests have settled: a part whose bone turns by more than 45° from its
        // resampled parent's bone is not a continuation of that limb (a foot on a shank): carried.
        for (uint32_t j = 0; j < J; ++j) {
          ClassicPart& P = m.parts[j];
          // (only where it continues its parent's tube: a pelvis's thighs are branches)
          if (!P.resampled || P.parent < 0 || !m.parts[P.parent].resampled || P.split ||
              m.parts[P.parent].child != int32_t(j))
            continue;
          if (glm::dot(P.axis, m.parts[P.parent].axis) >= kMaxBendCos) continue;
          carry(j, GCS_CLASSIC_BENT);
          any = true;
        }
        if (!any) break;
      }

      // Trunk cuts, once the parts around them have settled (a shoulder found carried lets the
      // chest's tube run down its flank); a part whose cut moved is cast again.
      bool recast = false;
      for (uint32_t j = 0; j < J; ++j) {
        ClassicPart& P = m.parts[j];
        if (!P.resampled || !P.split) continue;
        float before = P.cut;
        if (!updateCut(j)) carry(j, GCS_CLASSIC_BRANCHING), recast = true;
        else if (P.cut != before || round == 0) dirty[j] = 1, recast = true;
      }
      if (recast) continue;

      // The carried mesh and its boundary loops with the tubes.
      computeOwners();
      for (uint32_t t = 0; t < T; ++t)
        triCarried[t] = owner(group[rig.indices[3 * t]]) < 0 || owner(group[rig.indices[3 * t + 1]]) < 0 ||
                        owner(group[rig.indices[3 * t + 2]]) < 0;
      // Loop edges: an edge of a carried triangle shared with a tube triangle, directed as in the
      // carried triangle (an edge of the input's own border stays open).
      std::vector<std::pair<uint32_t, uint32_t>> loopEdges;
      for (size_t e0 = 0; e0 < edges.size();) {
        size_t e1 = e0;
        int carriedAt = -1;
        bool tube = false;
        while (e1 < edges.size() && edges[e1].lo == edges[e0].lo && edges[e1].hi == edges[e0].hi) {
          if (triCarried[edges[e1].tri]) { if (carriedAt < 0) carriedAt = int(e1); }
          else tube = true;
          ++e1;
        }
        if (carriedAt >= 0 && tube) {
          const WeldedEdge& e = edges[size_t(carriedAt)];
          loopEdges.push_back({e.from, e.from == e.lo ? e.hi : e.lo});
        }
        e0 = e1;
      }
      std::sort(loopEdges.begin(), loopEdges.end());
      std::vector<uint8_t> used(loopEdges.size(), 0);
      loops.clear();
      std::vector<uint8_t> failed(J, 0);
      for (size_t s = 0; s < loopEdges.size(); ++s) {
        if (used[s]) continue;
        Loop L;
        size_t e = s;
        bool closed = false;
        while (true) {
          used[e] = 1;
          L.groups.push_back(loopEdges[e].first);
          uint32_t next = loopEdges[e].second;
          if (next == loopEdges[s].first) { closed = true; break; }
          auto it = std::lower_bound(loopEdges.begin(), loopEdges.end(), std::make_pair(next, 0u));
          size_t f = size_t(it - loopEdges.begin());
          while (f < loopEdges.size() && loopEdges[f].first == next && used[f]) ++f;
          if (f >= loopEdges.size() || loopEdges[f].first != next) break;
          e = f;
        }
        // The part it closes: most of its vertices'.
        uint32_t best = uint32_t(owner(L.groups[0])), bestCount = 0;
        for (uint32_t g : L.groups) {
          uint32_t c = 0;
          for (uint32_t h : L.groups) c += owner(h) == owner(g);
          if (c > bestCount) best = uint32_t(owner(g)), bestCount = c;
          if (bestCount * 2 > L.groups.size()) break;
        }
        L.part = best;
        ClassicPart& P = m.parts[best];
        if (!closed || !P.resampled) {  // an open chain (it runs into the input's own border)
          if (P.resampled) failed[best] = 1;
          continue;
        }
        const glm::vec3 cj = rig.jointCentres[P.joint];
        float mean = 0.0f;
        for (uint32_t g : L.groups) mean += glm::dot(rig.positions[representative[g]] - cj, P.axis) / P.length;
        mean /= float(L.groups.size());
        L.distal = mean > 0.5f * (P.ownTMin + P.ownTMax);
        // One turn around the bone, seen along it.
        const glm::vec3 w = glm::cross(P.axis, P.u);
        double turn = 0.0;
        float prev = 0.0f;
        for (size_t i = 0; i <= L.groups.size(); ++i) {
          glm::vec3 d = rig.positions[representative[L.groups[i % L.groups.size()]]] - cj;
          float a = std::atan2(glm::dot(d, w), glm::dot(d, P.u));
          if (i) {
            float da = a - prev;
            if (da > kPi) da -= 2.0f * kPi;
            if (da < -kPi) da += 2.0f * kPi;
            turn += da;
          }
          prev = a;
        }
        bool ring = std::fabs(std::fabs(turn) - 2.0 * 3.14159265358979) < 3.14159265358979;
        bool shared = L.distal ? shares(P) : P.proxShared;
        bool taken = false;
        for (const Loop& other : loops)
          if (other.part == best && other.distal == L.distal) taken = true;
        if (!ring || shared || taken) { failed[best] = 1; continue; }
        loops.push_back(std::move(L));
      }
      // A tube that replaces no triangle (every one of its part's triangles has a carried vertex:
      // a coarse part one triangle long) would only be laid over the kept skin: carried.
      std::vector<uint32_t> replaced(J, 0);
      for (uint32_t t = 0; t < T; ++t)
        if (!triCarried[t]) ++replaced[uint32_t(owner(group[rig.indices[3 * t]]))];
      bool any = false;
      for (uint32_t j = 0; j < J; ++j)
        if (failed[j] || (m.parts[j].resampled && replaced[j] == 0)) carry(j, GCS_CLASSIC_SEAM), any = true;
      if (any) continue;
      // Tube ends from the loops: just inside the innermost point of each loop (a flat loop
      // would otherwise leave a band of zero width).
      for (uint32_t j = 0; j < J; ++j) m.parts[j].proxLoop = m.parts[j].distLoop = -1;
      for (size_t l = 0; l < loops.size(); ++l) {
        ClassicPart& P = m.parts[loops[l].part];
        float lo = INFINITY, hi = -INFINITY;
        for (uint32_t g : loops[l].groups) {
          float t = glm::dot(rig.positions[representative[g]] - rig.jointCentres[P.joint], P.axis) / P.length;
          lo = std::min(lo, t), hi = std::max(hi, t);
        }
        if (loops[l].distal) P.distLoop = int32_t(l), P.loopTHi = lo - kBandWidth;
        else P.proxLoop = int32_t(l), P.loopTLo = hi + kBandWidth;
      }
      for (uint32_t j = 0; j < J; ++j) {
        ClassicPart& P = m.parts[j];
        if (!P.resampled) continue;
        float lo, hi;
        spanOf(P, lo, hi);
        // (the ray test is not run again on the final span: the loops only trim the ends of a
        // tube whose rays already hit, and the contours are cast below)
        if (!(hi - lo >= kMinTubeSpan)) carry(j, GCS_CLASSIC_SEAM), any = true;
        else P.tLo = lo, P.tHi = hi;
      }
      if (any) continue;
      bool pending = false;
      for (uint32_t j = 0; j < J; ++j) pending = pending || (m.parts[j].resampled && dirty[j]);
      if (!pending) break;
    }

    // The contours of the parts that stay resampled, cast once at their final span.
    for (uint32_t j = 0; j < J; ++j) {
      const ClassicPart& P = m.parts[j];
      if (!P.resampled) continue;
      glm::vec3 nProx, nDist;
      endNormals(P, nProx, nDist);
      uint32_t hitCount = 0, inRangeHits = 0, inRangeRays = 0;
      castPart(j, P.contourCount, nProx, nDist, hits[j], hitTriangles[j], hitCount, inRangeHits, inRangeRays);
    }

    ringTriangle.clear();
    // 5. Contours. Chains of resampled parts are laid out root → leaf, so that a part's rings are
    // contiguous and a shared contour is the last ring of one part and the first of the next.
    uint32_t vertex = 0;
    for (uint32_t j0 = 0; j0 < J; ++j0) {
      ClassicPart& head = m.parts[j0];
      if (!head.resampled || head.proxShared) continue;
      for (int32_t j = int32_t(j0); j >= 0 && m.parts[j].resampled; j = m.parts[j].distShared ? m.parts[j].child : -1) {
        ClassicPart& P = m.parts[j];
        glm::vec3 nProx, nDist;
        endNormals(P, nProx, nDist);
        const uint32_t mm = P.contourCount;
        P.contours.clear();
        for (uint32_t i = 0; i < mm; ++i) {
          if (i == 0 && P.proxShared) {  // the parent's last contour
            uint32_t id = m.parts[P.parent].contours.back();
            P.contours.push_back(id);
            ClassicContour& c = m.contours[id];
            float* rad = &m.radii[c.radii];
            const float* mine = &hits[j][0];
            for (uint32_t r = 0; r < k; ++r)  // union of both sides
              if (mine[r] > rad[r]) rad[r] = mine[r], ringTriangle[c.first + r] = hitTriangles[j][r];
            c.part = j;
            c.proximal = P.parent;
            c.t = 0.0f;
            continue;
          }
          ClassicContour c;
          c.part = j;
          c.t = P.tLo + (P.tHi - P.tLo) * float(i) / float(mm - 1);
          contourFrame(P, c.t, nProx, nDist, c.centre, c.normal, c.u);
          c.first = vertex;
          vertex += k;
          c.radii = uint32_t(m.radii.size());
          m.radii.insert(m.radii.end(), hits[j].begin() + size_t(i) * k, hits[j].begin() + size_t(i + 1) * k);
          for (uint32_t r = 0; r < k; ++r)
            ringTriangle.push_back(hits[j][size_t(i) * k + r] > 0.0f ? hitTriangles[j][size_t(i) * k + r] : T);
          P.contours.push_back(uint32_t(m.contours.size()));
          m.contours.push_back(c);
        }
        P.first = m.contours[P.contours.front()].first;
        P.count = mm * k;
      }
    }
    m.tubeVertexCount = vertex;
    // Fill misses: from neighbours in the contour, or, for a contour without any hit, from the
    // nearest contour of its part that has hits.
    std::vector<uint8_t> empty(m.contours.size(), 0);
    for (size_t c = 0; c < m.contours.size(); ++c) empty[c] = !fillMisses(&m.radii[m.contours[c].radii], k);
    for (uint32_t j = 0; j < J; ++j) {
      const ClassicPart& P = m.parts[j];
      if (!P.resampled) continue;
      const int n = int(P.contours.size());
      for (int i = 0; i < n; ++i) {
        uint32_t id = P.contours[i];
        if (!empty[id]) continue;
        for (int d = 1; d < n; ++d) {
          int cand[2] = {i - d, i + d};
          int found = -1;
          for (int q : cand)
            if (q >= 0 && q < n && !empty[P.contours[q]]) { found = q; break; }
          if (found >= 0) {
            std::memcpy(&m.radii[m.contours[id].radii], &m.radii[m.contours[P.contours[found]].radii], k * sizeof(float));
            empty[id] = 0;
            break;
          }
        }
      }
    }
    for (size_t c = 0; c < m.contours.size(); ++c)
      if (empty[c]) std::fill(m.radii.begin() + m.contours[c].radii, m.radii.begin() + m.contours[c].radii + k, 0.0f);

    // The skin each contour resamples, as influences: the mean weights of the input vertices of its
    // part and its neighbours that lie around its plane (within half the contour spacing, widened
    // where the mesh is coarse) and no farther from its centre than its rays reached. A ring then
    // moves as that skin does, not as its bone's straight line (a twisting spine, a thigh whose
    // skin the hip's weights bend).
    {
      std::vector<float> sum(J, 0.0f);
      std::vector<uint32_t> touched;
      std::vector<uint32_t> vertexFirst(J + 1, 0), vertexList(rig.vertexCount);  // rig vertices by part
      for (uint32_t v = 0; v < rig.vertexCount; ++v) ++vertexFirst[partOf[v] + 1];
      for (uint32_t j = 0; j < J; ++j) vertexFirst[j + 1] += vertexFirst[j];
      {
        std::vector<uint32_t> cursor(vertexFirst.begin(), vertexFirst.end() - 1);
        for (uint32_t v = 0; v < rig.vertexCount; ++v) vertexList[cursor[partOf[v]]++] = v;
      }
      for (ClassicContour& c : m.contours) {
        const ClassicPart& P = m.parts[c.part];
        auto near = [&](uint32_t x) {
          if (x == uint32_t(c.part) || int32_t(x) == P.child || int32_t(x) == P.parent || (c.proximal >= 0 && int32_t(x) == c.proximal))
            return true;
          return P.split && m.parts[x].isPart && member(c.part, x);
        };
        float reach = 0.0f;
        for (uint32_t r = 0; r < k; ++r) reach = std::max(reach, m.radii[c.radii + r]);
        reach = 1.25f * reach + 1e-6f * m.height;
        float window = 0.5f * P.length * std::max(P.tHi - P.tLo, 1e-3f) / float(std::max<uint32_t>(P.contourCount - 1, 1));
        float total = 0.0f;
        for (int attempt = 0; attempt < 4 && total <= 0.0f; ++attempt, window *= 2.0f) {
          for (uint32_t x0 = 0; x0 < J; ++x0) {
            if (!m.parts[x0].isPart || !near(x0)) continue;
            for (uint32_t i = vertexFirst[x0]; i < vertexFirst[x0 + 1]; ++i) {
            const uint32_t v = vertexList[i];
            glm::vec3 x = rig.positions[v] - c.centre;
            float h = glm::dot(x, c.normal);
            if (std::fabs(h) > window || glm::length(x - h * c.normal) > reach) continue;
            float f = 1.0f - std::fabs(h) / window + 1e-3f;
            for (uint32_t i = 0; i < rig.influenceSlots; ++i) {
              const uint32_t jj = rig.jointAt(v, i);
              if (!(rig.weightAt(v, i) > 0.0f)) continue;
              if (sum[jj] == 0.0f) touched.push_back(jj);
              sum[jj] += f * rig.weightAt(v, i);
            }
            total += f;
            }
          }
        }
        // The four largest, renormalised; none found: the part's own joint.
        c.joints = glm::uvec4(c.part, 0, 0, 0);
        c.weights = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
        std::sort(touched.begin(), touched.end(), [&](uint32_t a, uint32_t b) { return sum[a] > sum[b] || (sum[a] == sum[b] && a < b); });
        float kept = 0.0f;
        for (size_t i = 0; i < touched.size() && i < 4; ++i) kept += sum[touched[i]];
        if (kept > 0.0f)
          for (size_t i = 0; i < 4; ++i) {
            c.joints[int(i)] = i < touched.size() ? touched[i] : 0u;
            c.weights[int(i)] = i < touched.size() ? sum[touched[i]] / kept : 0.0f;
          }
        for (uint32_t jj : touched) sum[jj] = 0.0f;
        touched.clear();
      }
      // A joint contour shared by two tubes takes the mean of its two neighbours' influences (the
      // paper's bisector where the skin is bound hard to each bone; the skin's own blend elsewhere).
      for (const ClassicPart& P : m.parts) {
        if (!P.resampled || !P.proxShared || P.contours.size() < 2) continue;
        const ClassicPart& Q = m.parts[P.parent];
        if (Q.contours.size() < 2) continue;
        ClassicContour& c = m.contours[P.contours.front()];
        for (const ClassicContour* x : {&m.contours[Q.contours[Q.contours.size() - 2]], &m.contours[P.contours[1]]})
          for (int i = 0; i < 4; ++i)
            if (x->weights[i] > 0.0f) {
              if (sum[x->joints[i]] == 0.0f) touched.push_back(x->joints[i]);
              sum[x->joints[i]] += 0.5f * x->weights[i];
            }
        std::sort(touched.begin(), touched.end(), [&](uint32_t a, uint32_t b) { return sum[a] > sum[b] || (sum[a] == sum[b] && a < b); });
        float kept = 0.0f;
        for (size_t i = 0; i < touched.size() && i < 4; ++i) kept += sum[touched[i]];
        for (size_t i = 0; i < 4; ++i) {
          c.joints[int(i)] = i < touched.size() ? touched[i] : 0u;
          c.weights[int(i)] = i < touched.size() ? sum[touched[i]] / kept : 0.0f;
        }
        for (uint32_t jj : touched) sum[jj] = 0.0f;
        touched.clear();
      }
    }

    // Caps: a tube end that meets neither a resampled neighbour nor the carried mesh is closed by a
    // flat fan when the part's input skin has no border (a robot's finger plate); an open input
    // (a sleeve) stays open.
    std::vector<uint8_t> bordered(J, 0);
    for (size_t e0 = 0; e0 < edges.size();) {
      size_t e1 = e0;
      while (e1 < edges.size() && edges[e1].lo == edges[e0].lo && edges[e1].hi == edges[e0].hi) ++e1;
      if (e1 - e0 == 1)
        for (uint32_t g : {edges[e0].lo, edges[e0].hi})
          if (owner(g) >= 0) bordered[owner(g)] = 1;
      e0 = e1;
    }
    for (uint32_t j = 0; j < J; ++j) {
      const ClassicPart& P = m.parts[j];
      if (!P.resampled || bordered[j]) continue;
      if (!P.proxShared && P.proxLoop < 0) {
        m.caps.push_back({P.contours.front(), vertex, -1.0f});
        vertex += k + 1;
      }
      if (!P.distShared && P.distLoop < 0) {
        m.caps.push_back({P.contours.back(), vertex, 1.0f});
        vertex += k + 1;
      }
    }

    // 6. Carried triangles (those with a carried vertex): their vertices are copied and move
    // by dual-quaternion skinning of their own weights; the copies are grouped by part (ranges per part).
    std::vector<int64_t> outputOf(rig.vertexCount, -1);
    for (uint32_t t = 0; t < T; ++t)
      if (triCarried[t])
        for (int e = 0; e < 3; ++e) outputOf[rig.indices[3 * t + e]] = 0;
    std::vector<uint32_t> runCount(J, 0);
    for (uint32_t v = 0; v < rig.vertexCount; ++v)
      if (outputOf[v] == 0) ++runCount[partOf[v]];
    m.carriedFirst = vertex;
    for (uint32_t j = 0; j < J; ++j) {
      m.parts[j].runFirst = vertex;
      m.parts[j].runCount = runCount[j];
      vertex += runCount[j];
    }
    std::vector<int64_t> groupOutput(G, -1);
    {
      std::vector<uint32_t> cursor(J);
      for (uint32_t j = 0; j < J; ++j) cursor[j] = m.parts[j].runFirst;
      for (uint32_t v = 0; v < rig.vertexCount; ++v)
        if (outputOf[v] == 0) groupOutput[group[v]] = outputOf[v] = cursor[partOf[v]]++;
    }
    m.allocateOutput(vertex);
    const uint32_t carried = vertex - m.carriedFirst;
    m.restPositions.assign(size_t(carried) * 3 + 1, 0.0f);
    m.restNormals.assign(size_t(carried) * 3 + 1, 0.0f);
    m.carriedJoints.resize(carried);
    m.carriedWeights.resize(carried);
    const bool eight = rig.influenceSlots == 8;
    if (eight) m.carriedJoints1.resize(carried), m.carriedWeights1.resize(carried);
    m.poses.resize(J);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) {
      if (outputOf[v] < 0) continue;
      m.carriedJoints[size_t(outputOf[v] - m.carriedFirst)] = rig.joints[v];
      m.carriedWeights[size_t(outputOf[v] - m.carriedFirst)] = rig.weights[v];
      if (eight) {
        m.carriedJoints1[size_t(outputOf[v] - m.carriedFirst)] = rig.joints1[v];
        m.carriedWeights1[size_t(outputOf[v] - m.carriedFirst)] = rig.weights1[v];
      }
      size_t o = size_t(outputOf[v] - m.carriedFirst) * 3;
      for (int c = 0; c < 3; ++c) {
        m.restPositions[o + c] = rig.positions[v][c];
        m.restNormals[o + c] = rig.normals[v][c];
      }
    }

    // 7. Triangles: tube quads (outward winding: rays turn from u to w = n × u, counter-clockwise
    // about the contour normal, which points distally), then the bands, then the carried triangles.
    for (uint32_t j = 0; j < J; ++j) {
      const ClassicPart& P = m.parts[j];
      if (!P.resampled) continue;
      for (size_t i = 0; i + 1 < P.contours.size(); ++i) {
        uint32_t a = m.contours[P.contours[i]].first, b = m.contours[P.contours[i + 1]].first;
        for (uint32_t r = 0; r < k; ++r) {
          uint32_t r1 = (r + 1) % k;
          m.indices.insert(m.indices.end(), {a + r, a + r1, b + r1, a + r, b + r1, b + r});
        }
      }
    }
    m.tubeIndexCount = uint32_t(m.indices.size());
    // A band zips an end ring (traversed against the tube's use of its edges: decreasing angle at
    // a proximal end, increasing at a distal one) to its loop (traversed as the carried triangles
    // use its edges, which turns the same way on an outward-wound mesh), always advancing on the
    // side whose next vertex comes first by angle: ring + loop vertices triangles, every edge of
    // both used once, so the seam is closed whatever the two sides' vertex counts.
    std::vector<float> beta;
    std::vector<uint32_t> loopOut;
    for (const Loop& L : loops) {
      const ClassicPart& P = m.parts[L.part];
      const ClassicContour& c = m.contours[L.distal ? P.contours.back() : P.contours.front()];
      const float d = L.distal ? 1.0f : -1.0f;
      const glm::vec3 w = glm::cross(c.normal, c.u);
      const size_t n = L.groups.size();
      auto angleOf = [&](uint32_t g) {
        glm::vec3 x = rig.positions[representative[g]] - c.centre;
        return d * std::atan2(glm::dot(x, w), glm::dot(x, c.u));
      };
      auto wrap = [](float a) {
        while (a > kPi) a -= 2.0f * kPi;
        while (a <= -kPi) a += 2.0f * kPi;
        return a;
      };
      float total = 0.0f;
      for (size_t i = 0; i < n; ++i) total += wrap(angleOf(L.groups[(i + 1) % n]) - angleOf(L.groups[i]));
      loopOut.resize(n);
      for (size_t i = 0; i < n; ++i)  // against the ring's turn (an inward-wound input): walk it backwards
        loopOut[i] = uint32_t(groupOutput[L.groups[total >= 0.0f ? i : n - 1 - i]]);
      size_t start = 0;
      float nearest = INFINITY;
      for (size_t i = 0; i < n; ++i) {
        float a = std::fabs(wrap(angleOf(L.groups[total >= 0.0f ? i : n - 1 - i])));
        if (a < nearest) nearest = a, start = i;
      }
      std::rotate(loopOut.begin(), loopOut.begin() + ptrdiff_t(start), loopOut.end());
      beta.resize(n + 1);
      {
        auto groupAt = [&](size_t i) { size_t s = (start + i) % n; return L.groups[total >= 0.0f ? s : n - 1 - s]; };
        beta[0] = wrap(angleOf(groupAt(0)));
        for (size_t i = 1; i <= n; ++i) beta[i] = beta[i - 1] + wrap(angleOf(groupAt(i % n)) - angleOf(groupAt(i - 1)));
      }
      auto ringAt = [&](uint32_t i) { return c.first + (L.distal ? i % k : (k - i % k) % k); };
      ClassicBand band;
      band.part = L.part;
      band.firstIndex = uint32_t(m.indices.size());
      uint32_t i = 0;
      size_t jj = 0;
      const float step = 2.0f * kPi / float(k);
      while (i < k || jj < n) {
        bool ringStep = jj == n || (i < k && float(i + 1) * step <= beta[jj + 1]);
        if (ringStep) {
          m.indices.insert(m.indices.end(), {ringAt(i), ringAt(i + 1), loopOut[jj % n]});
          ++i;
        } else {
          m.indices.insert(m.indices.end(), {ringAt(i), loopOut[(jj + 1) % n], loopOut[jj % n]});
          ++jj;
        }
      }
      band.indexCount = uint32_t(m.indices.size()) - band.firstIndex;
      m.bands.push_back(band);
    }
    for (const ClassicCap& cap : m.caps) {
      ClassicBand fan;
      fan.part = uint32_t(m.contours[cap.contour].part);
      fan.firstIndex = uint32_t(m.indices.size());
      uint32_t centre = cap.first + k;
      for (uint32_t r = 0; r < k; ++r) {
        uint32_t r1 = (r + 1) % k;
        if (cap.sign > 0.0f) m.indices.insert(m.indices.end(), {centre, cap.first + r, cap.first + r1});
        else m.indices.insert(m.indices.end(), {centre, cap.first + r1, cap.first + r});
      }
      fan.indexCount = uint32_t(m.indices.size()) - fan.firstIndex;
      m.bands.push_back(fan);
    }
    m.bandIndexCount = uint32_t(m.indices.size()) - m.tubeIndexCount;
    for (uint32_t t = 0; t < T; ++t) {
      if (!triCarried[t]) continue;
      for (int e = 0; e < 3; ++e) m.indices.push_back(uint32_t(outputOf[rig.indices[3 * t + e]]));
    }

    // 8. The report (parts in joint order), contours per vertex, and the detail-loss inputs: the
    // input vertices the tubes and bands replace.
    for (uint32_t j = 0; j < J; ++j) {
      const ClassicPart& P = m.parts[j];
      if (!P.isPart) continue;
      m.reportJoints.push_back(j);
      m.report.insert(m.report.end(), {int32_t(j), P.resampled ? 1 : 0, int32_t(P.resampled ? P.first : P.runFirst),
                                       int32_t(P.resampled ? P.count : P.runCount), int32_t(P.reason)});
    }
    m.contourOfVertex.assign(m.vertexCount, -1);
    for (uint32_t c = 0; c < m.contours.size(); ++c)
      for (uint32_t r = 0; r < k; ++r) m.contourOfVertex[m.contours[c].first + r] = int32_t(c);
    for (const ClassicCap& cap : m.caps)
      for (uint32_t r = 0; r <= k; ++r) m.contourOfVertex[cap.first + r] = int32_t(cap.contour);
    m.sourceOfVertex.assign(m.vertexCount, -1);
    for (uint32_t v = 0; v < rig.vertexCount; ++v)
      if (outputOf[v] >= 0) m.sourceOfVertex[size_t(outputOf[v])] = int32_t(v);
    for (uint32_t g = 0; g < G; ++g)
      if (groupOutput[g] < 0 && owner(g) >= 0) {
        m.lossPoints.push_back(rig.positions[representative[g]]);
        m.lossParts.push_back(uint32_t(owner(g)));
      }

    // 9. The bind pose as the initial output (and the bind surface for the detail loss).
    std::vector<glm::mat4> identity(J, glm::mat4(1.0f));
    m.deform(identity.data());
    m.bindPositions.resize(m.vertexCount);
    for (uint32_t o = 0; o < m.vertexCount; ++o)
      m.bindPositions[o] = glm::vec3(m.positions[3 * o], m.positions[3 * o + 1], m.positions[3 * o + 2]);
  } catch (const std::bad_alloc&) {
    delete model;
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while building the classic cross-section model");
    return nullptr;
  }
  return model;
}

// The skin matrices of a probe pose: every joint turned by `angle` about `axis` around its own bind
// centre, on top of its parent's motion (the whole body curled, bent sideways or twisted).
void probeSkin(const Rig& rig, const glm::vec3& axis, float angle, std::vector<glm::mat4>& skin) {
  const uint32_t J = rig.jointCount;
  skin.assign(J, glm::mat4(1.0f));
  std::vector<uint8_t> done(J, 0);
  const glm::mat4 turn = glm::mat4_cast(glm::angleAxis(angle, axis));
  std::function<void(uint32_t)> pose = [&](uint32_t j) {
    if (done[j]) return;
    int32_t p = rig.parents[j];
    glm::mat4 parent(1.0f);
    if (p >= 0 && uint32_t(p) < J) pose(uint32_t(p)), parent = skin[size_t(p)];
    const glm::vec3 c = rig.jointCentres[j];
    skin[j] = parent * glm::translate(glm::mat4(1.0f), c) * turn * glm::translate(glm::mat4(1.0f), -c);
    done[j] = 1;
  };
  for (uint32_t j = 0; j < J; ++j) pose(j);
}

// Which resampled parts stand off the skin they replace (docs/method.md §9's classic off-surface
// target: p99 ≤ 1 %, max ≤ 2.5 % of the height). Per ring vertex: its distance from the point of
// the input surface its ray hit, both posed — the ring by the model (bulge included), the surface
// by dual-quaternion skinning — at probe poses (every joint bent 35° forward,
// backward, to either side, and twisted either way). An end cap must lie on the input's own end (a flat plate): its
// centre within 1 % of the height of the input surface at the bind pose.
std::vector<uint8_t> offSurfaceParts(const Rig& rig, ClassicModel& m, const std::vector<uint32_t>& ringTriangle) {
  const uint32_t J = rig.jointCount, T = uint32_t(rig.indices.size() / 3);
  std::vector<uint8_t> failed(J, 0);
  const float maxOff = 0.025f * m.height, p99Off = 0.01f * m.height;
  // Barycentric coordinates of each ring vertex's hit in the bind pose.
  std::vector<glm::vec3> bary(m.tubeVertexCount, glm::vec3(0.0f));
  for (uint32_t o = 0; o < m.tubeVertexCount; ++o) {
    if (ringTriangle[o] >= T) continue;
    const uint32_t* t = &rig.indices[size_t(ringTriangle[o]) * 3];
    glm::vec3 a = rig.positions[t[0]], e0 = rig.positions[t[1]] - a, e1 = rig.positions[t[2]] - a, x = m.bindPositions[o] - a;
    float d00 = glm::dot(e0, e0), d01 = glm::dot(e0, e1), d11 = glm::dot(e1, e1), d20 = glm::dot(x, e0), d21 = glm::dot(x, e1);
    float den = d00 * d11 - d01 * d01;
    if (!(std::fabs(den) > 0.0f)) { bary[o] = glm::vec3(1.0f, 0.0f, 0.0f); continue; }
    float v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
    bary[o] = glm::vec3(1.0f - v - w, v, w);
  }
  // Caps: the centre of a flat fan must lie on the input's end.
  for (const ClassicCap& cap : m.caps) {
    const glm::vec3 x = m.bindPositions[cap.first + m.rays];
    float best = INFINITY;
    for (uint32_t t = 0; t < T && best > 0.01f * m.height; ++t)
      best = std::min(best, pointTriangleDistance(x, rig.positions[rig.indices[3 * t]], rig.positions[rig.indices[3 * t + 1]],
                                                  rig.positions[rig.indices[3 * t + 2]]));
    if (best > 0.01f * m.height) failed[m.contours[cap.contour].part] = 1;
  }
  constexpr int kProbes = 6;  // in pairs: a left limb and its mirror image get the same verdict
  const glm::vec3 axes[kProbes] = {{1, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {0, 1, 0}};
  const float angles[kProbes] = {0.61f, -0.61f, 0.61f, -0.61f, 0.61f, -0.61f};
  // Only the corners of hit triangles are skinned (a compact copy of them).
  std::vector<int32_t> slot(rig.vertexCount, -1);
  std::vector<uint32_t> cornerOf;
  for (uint32_t o = 0; o < m.tubeVertexCount; ++o)
    if (ringTriangle[o] < T)
      for (int e = 0; e < 3; ++e) {
        uint32_t v = rig.indices[size_t(ringTriangle[o]) * 3 + e];
        if (slot[v] < 0) slot[v] = int32_t(cornerOf.size()), cornerOf.push_back(v);
      }
  const uint32_t C = uint32_t(cornerOf.size());
  std::vector<float> rest(size_t(C) * 3), restNormals(size_t(C) * 3), posed(size_t(C) * 3), posedNormals(size_t(C) * 3);
  const bool eight = rig.influenceSlots == 8;
  std::vector<glm::uvec4> joints(C), joints1(eight ? C : 0);
  std::vector<glm::vec4> weights(C), weights1(eight ? C : 0);
  for (uint32_t i = 0; i < C; ++i) {
    const uint32_t v = cornerOf[i];
    for (int c = 0; c < 3; ++c) rest[3 * i + c] = rig.positions[v][c], restNormals[3 * i + c] = rig.normals[v][c];
    joints[i] = rig.joints[v], weights[i] = rig.weights[v];
    if (eight) joints1[i] = rig.joints1[v], weights1[i] = rig.weights1[v];
  }
  std::vector<glm::mat4> skin;
  std::vector<JointPose> poses(J);
  std::vector<std::vector<float>> distances(J);
  for (int probe = 0; probe < kProbes; ++probe) {  // (at the bind pose each ring vertex is its hit)
    probeSkin(rig, axes[probe], angles[probe], skin);
    m.deform(skin.data());
    const ScaleState scale = decomposeAll(skin.data(), J, poses.data());
    dqsVertices(poses.data(), scale, joints.data(), weights.data(), eight ? joints1.data() : nullptr,
                eight ? weights1.data() : nullptr, rest.data(), restNormals.data(), posed.data(), posedNormals.data(), C);
    for (uint32_t j = 0; j < J; ++j) {
      const ClassicPart& P = m.parts[j];
      if (!P.resampled) continue;
      for (uint32_t o = P.first; o < P.first + P.count; ++o) {
        // (a joint ring shared by two tubes is the method's own joint, the bisector where the skin
        // is bound hard to each bone: that skin folds or opens there under DQS, the ring does not)
        if (ringTriangle[o] >= T || m.contours[size_t(m.contourOfVertex[o])].proximal >= 0) continue;
        const uint32_t* t = &rig.indices[size_t(ringTriangle[o]) * 3];
        glm::vec3 hit(0.0f);
        for (int e = 0; e < 3; ++e) {
          const size_t q = 3 * size_t(slot[t[e]]);
          hit += bary[o][e] * glm::vec3(posed[q], posed[q + 1], posed[q + 2]);
        }
        distances[j].push_back(glm::length(glm::vec3(m.positions[3 * o], m.positions[3 * o + 1], m.positions[3 * o + 2]) - hit));
      }
    }
  }
  for (uint32_t j = 0; j < J; ++j) {
    std::vector<float>& d = distances[j];
    if (d.empty()) continue;
    size_t rank = std::min(d.size() - 1, size_t(std::ceil(0.99 * double(d.size()))) - 1);
    std::nth_element(d.begin(), d.begin() + ptrdiff_t(rank), d.end());
    float p99 = d[rank], worst = *std::max_element(d.begin(), d.end());
    if (worst > maxOff || p99 > p99Off) failed[j] = 1;
  }
  std::vector<glm::mat4> identity(J, glm::mat4(1.0f));
  m.deform(identity.data());
  return failed;
}

}  // namespace

ClassicModel* buildClassic(const Rig& rig, uint32_t contours, uint32_t rays, float bulge) {
  std::vector<uint32_t> ringTriangle;
  ClassicModel* m = buildOnce(rig, contours, rays, bulge, nullptr, ringTriangle);
  std::vector<uint8_t> carried(rig.jointCount, 0);
  // Parts are only ever added to the carried set, so this ends.
  for (uint32_t round = 0; m && round < rig.jointCount; ++round) {
    std::vector<uint8_t> failed;
    try {
      failed = offSurfaceParts(rig, *m, ringTriangle);
    } catch (const std::bad_alloc&) {
      delete m;
      fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while testing the classic model against the skin");
      return nullptr;
    }
    bool any = false;
    for (uint32_t j = 0; j < rig.jointCount; ++j)
      if (failed[j] && !carried[j]) carried[j] = 1, any = true;
    if (!any) break;
    delete m;
    m = buildOnce(rig, contours, rays, bulge, &carried, ringTriangle);
  }
  return m;
}

void ClassicModel::deform(const glm::mat4* skin) {
  const uint32_t J = jointCount;
  const uint32_t k = rays;
  const ScaleState scale = decomposeAll(skin, J, poses.data());
  // Flex of each tube's distal joint (for the bulge): the angle between the child's direction as
  // its own joint turns it and as the part's joint alone would.
  for (uint32_t j = 0; j < J; ++j) {
    ClassicPart& P = parts[j];
    if (!P.resampled) continue;
    const glm::vec3 cd = parts[P.child].direction;
    glm::vec3 straight = poses[j].rotation * cd, actual = poses[P.child].rotation * cd;
    float c = glm::clamp(glm::dot(straight, actual) / (glm::length(straight) * glm::length(actual)), -1.0f, 1.0f);
    P.flex = std::acos(c) / kPi;
  }
  // Contours: each ring moves as one rigid (scaled) section, by the dual-quaternion blend of the
  // weights of the skin it resamples, and swells by the muscle bulge in its own plane.
  const JointPose* blend[4];
  float w4[4];
  glm::mat4 pm, nm;
  for (ClassicContour& c : contours) {
    const ClassicPart& P = parts[c.part];
    uint32_t count = 0;
    for (int i = 0; i < 4; ++i)
      if (c.weights[i] > 0.0f) blend[count] = &poses[c.joints[i]], w4[count++] = c.weights[i];
    bool renormalise = false;
    blendPoses(blend, w4, count, scale, pm, nm, renormalise);
    float tc = glm::clamp(c.t, 0.0f, 1.0f);  // past a joint (or at a shared one): no bulge
    float swell = c.proximal >= 0 ? 1.0f : 1.0f + (P.split ? 0.0f : bulge) * P.flex * std::sin(kPi * tc);
    const glm::vec3 w = glm::cross(c.normal, c.u);
    const float* rad = &radii[c.radii];
    float* out = &positions[size_t(c.first) * 3];
    for (uint32_t r = 0; r < k; ++r) {
      glm::vec3 p(pm * glm::vec4(c.centre + swell * rad[r] * (cosTable[r] * c.u + sinTable[r] * w), 1.0f));
      out[3 * r] = p.x, out[3 * r + 1] = p.y, out[3 * r + 2] = p.z;
    }
    c.posedCentre = glm::vec3(pm * glm::vec4(c.centre, 1.0f));
    c.posedNormal = unitOr(glm::vec3(nm * glm::vec4(c.normal, 0.0f)), glm::vec3(0.0f, 1.0f, 0.0f));
  }
  // Caps: rim copies and the centre, normal along the contour normal (outward).
  for (const ClassicCap& cap : caps) {
    const ClassicContour& c = contours[cap.contour];
    glm::vec3 n = cap.sign * c.posedNormal;
    std::memcpy(&positions[size_t(cap.first) * 3], &positions[size_t(c.first) * 3], size_t(k) * 3 * sizeof(float));
    for (uint32_t r = 0; r <= k; ++r) {
      float* nn = &normals[size_t(cap.first + r) * 3];
      nn[0] = n.x, nn[1] = n.y, nn[2] = n.z;
    }
    float* pc = &positions[size_t(cap.first + k) * 3];
    pc[0] = c.posedCentre.x, pc[1] = c.posedCentre.y, pc[2] = c.posedCentre.z;
  }
  // Carried vertices: dual-quaternion skinning of their own weights, so that carried skin bends
  // with the skin around it (one rigid bone per part left it standing off the skin at every joint
  // it spans) and the bands zipped to it follow.
  if (carriedFirst < vertexCount)
    dqsVertices(poses.data(), scale, carriedJoints.data(), carriedWeights.data(),
                carriedJoints1.empty() ? nullptr : carriedJoints1.data(),
                carriedWeights1.empty() ? nullptr : carriedWeights1.data(), restPositions.data(), restNormals.data(),
                &positions[size_t(carriedFirst) * 3], &normals[size_t(carriedFirst) * 3], vertexCount - carriedFirst);
  // Tube normals: area-weighted from the deformed tube and band triangles (the bands after the
  // carried vertices have moved). Edges are divided by the extent of everything those triangles
  // touch first (tube and carried vertices: a band reaches carried skin that may lie far away): the
  // cross products of a ×1e20 tube overflowed (NaN normals), a ×1e-20 one's underflowed.
  float extent = 0.0f;
  if (tubeVertexCount) {
    glm::vec3 lo(positions[0], positions[1], positions[2]), hi = lo;
    for (uint32_t v = 1; v < vertexCount; ++v) {
      glm::vec3 p(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
      lo = glm::min(lo, p), hi = glm::max(hi, p);
    }
    glm::vec3 e = hi - lo;
    extent = std::fmax(e.x, std::fmax(e.y, e.z));
  }
  if (!(extent > 0.0f)) extent = 1.0f;
  const uint32_t rings = tubeVertexCount;  // ring vertices (caps follow them)
  std::memset(normals.data(), 0, size_t(rings) * 3 * sizeof(float));
  const uint32_t end = tubeIndexCount + bandIndexCount;
  for (uint32_t i = 0; i < end; i += 3) {
    uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
    glm::vec3 pa(positions[3 * a], positions[3 * a + 1], positions[3 * a + 2]);
    glm::vec3 pb(positions[3 * b], positions[3 * b + 1], positions[3 * b + 2]);
    glm::vec3 pc(positions[3 * c], positions[3 * c + 1], positions[3 * c + 2]);
    glm::vec3 f = glm::cross((pb - pa) / extent, (pc - pa) / extent);
    for (uint32_t v : {a, b, c}) {
      if (v >= rings) continue;  // a band's carried vertex (or a cap's) keeps its own normal
      normals[3 * v] += f.x;
      normals[3 * v + 1] += f.y;
      normals[3 * v + 2] += f.z;
    }
  }
  for (uint32_t v = 0; v < rings; ++v) {
    float* nn = &normals[3 * size_t(v)];
    // unitOr scales before squaring: a tiny sum was left unnormalised (its square underflowed to 0).
    glm::vec3 n = unitOr(glm::vec3(nn[0], nn[1], nn[2]), glm::vec3(0.0f, 1.0f, 0.0f));
    nn[0] = n.x, nn[1] = n.y, nn[2] = n.z;
  }
}

float ClassicModel::detailLoss(uint32_t which) const {
  if (which > 1) return std::nanf("");
  if (!lossDone) {
    // For each input vertex the tubes and bands replace, the nearest bind-pose tube triangle among
    // the cells around its own (contour interval ±2, ray sector ±2, following shared contours into
    // the neighbouring part) and its part's band triangles; a vertex farther than 0.5 % of the
    // height from all of those is tested against every tube and band triangle of the model.
    const uint32_t k = rays;
    const float step = 2.0f * kPi / float(k);
    double sum = 0.0;
    float worst = 0.0f;
    auto testCell = [&](const ClassicPart& P, int interval, int sector, float& best, const glm::vec3& x) {
      const ClassicPart* Q = &P;
      int n = int(Q->contours.size());
      if (interval < 0) {
        if (!Q->proxShared) return;
        Q = &parts[Q->parent];
        interval += int(Q->contours.size()) - 1;
        n = int(Q->contours.size());
        if (interval < 0) return;
      } else if (interval > n - 2) {
        if (!Q->distShared) return;
        interval -= n - 1;
        Q = &parts[Q->child];
        n = int(Q->contours.size());
        if (interval > n - 2) return;
      }
      uint32_t a = contours[Q->contours[interval]].first, b = contours[Q->contours[interval + 1]].first;
      uint32_t r = uint32_t(((sector % int(k)) + int(k)) % int(k)), r1 = (r + 1) % k;
      best = std::min(best, pointTriangleDistance(x, bindPositions[a + r], bindPositions[a + r1], bindPositions[b + r1]));
      best = std::min(best, pointTriangleDistance(x, bindPositions[a + r], bindPositions[b + r1], bindPositions[b + r]));
    };
    auto testTriangles = [&](uint32_t first, uint32_t count, float& best, const glm::vec3& x) {
      for (uint32_t t = first; t < first + count; t += 3)
        best = std::min(best, pointTriangleDistance(x, bindPositions[indices[t]], bindPositions[indices[t + 1]],
                                                    bindPositions[indices[t + 2]]));
    };
    for (size_t i = 0; i < lossPoints.size(); ++i) {
      const glm::vec3& x = lossPoints[i];
      const ClassicPart& P = parts[lossParts[i]];
      glm::vec3 rel = x - jointCentres[P.joint];
      float t = glm::dot(rel, P.axis) / P.length;
      int n = int(P.contours.size());
      int interval = int(std::floor((t - P.tLo) / (P.tHi - P.tLo) * float(n - 1)));
      interval = std::max(-n, std::min(2 * n, interval));
      float angle = std::atan2(glm::dot(rel, glm::cross(P.axis, P.u)), glm::dot(rel, P.u));
      if (angle < 0.0f) angle += 2.0f * kPi;
      int sector = int(std::floor(angle / step));
      float best = INFINITY;
      for (int di = -2; di <= 2; ++di)
        for (int dr = -2; dr <= 2; ++dr) testCell(P, interval + di, sector + dr, best, x);
      for (const ClassicBand& band : bands)
        if (band.part == P.joint) testTriangles(band.firstIndex, band.indexCount, best, x);
      if (!std::isfinite(best)) {  // beyond a tube end with no neighbour: the cells at that end
        int last = std::max(0, std::min(n - 2, interval));
        for (int di = -2; di <= 2; ++di)
          for (int dr = -2; dr <= 2; ++dr) testCell(P, last + di, sector + dr, best, x);
      }
      if (best > 5e-3f * height) testTriangles(0, tubeIndexCount + bandIndexCount, best, x);
      sum += double(best) * double(best);
      worst = std::max(worst, best);
    }
    lossRms = lossPoints.empty() ? 0.0f : float(std::sqrt(sum / double(lossPoints.size()))) / height * 100.0f;
    lossMax = worst / height * 100.0f;
    lossDone = true;
  }
  return which == 0 ? lossRms : lossMax;
}

}  // namespace gcs
