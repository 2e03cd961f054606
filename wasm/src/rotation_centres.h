// Centres of rotation per weight vector (Le & Hodgins, "Real-time Skeletal Skinning with Optimized
// Centers of Rotation", SIGGRAPH 2016): p*(w) is the average of the bind-pose surface weighted by
// how much its skin weights resemble w,
//   p*(w) = Σ_t sim(w, v_t) a_t c_t / Σ_t sim(w, v_t) a_t,
//   sim(w, v) = Σ_{j<k} w_j w_k v_j v_k exp(−(w_j v_k − w_k v_j)² / σ²),
// over the triangles t (area a_t, centroid c_t, v_t the mean of its corners' weights). A GCS node
// is one weight vector, so its centre is computed once at build time (docs/method.md).
#pragma once
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>
#include <glm/glm.hpp>
#include "rig.h"

namespace gcs {

// The paper's σ: a pair's similarity halves where the weight ratios differ by about 0.08.
constexpr float kCentreSigma = 0.1f;

// The longest lever arm, pivot to centre, in units of the rig's height. The centre moves along the
// chord (linear blend skinning), so a node's shift against DQS grows with its lever arm: it takes
// away the bulge on the outside of the bend and pushes the inside through itself. At 1 % the
// inside stays within about DQS's self-intersections on our characters (docs/method.md).
constexpr float kCentreLever = 0.01f;

// What the integral reads from the surface, grouped by joint pair: sim is a sum over pairs of
// joints, and a triangle adds to pair (j, k) only where both weigh on it. Triangles whose weights
// on the pair fall in one cell of a 1/kCentreCells grid are summed into one term (their moments
// added, their weights averaged by mass): σ is 6 cells wide, and the centres move by under 0.04 %
// of the height on our human (tests/lib/centres.test.ts). Independent of the section count: built
// once per rig (centreSurfaceOf) and kept across rebuilds.
constexpr uint32_t kCentreCells = 64;
struct CentreSurface {
  std::vector<uint64_t> pairs;    // sorted keys j << 32 | k, j < k
  std::vector<uint32_t> first;    // terms of pairs[i]: [first[i], first[i + 1]), a multiple of 4 apart
  // Per term (structure of arrays, 4 lanes at a time): the weights v_j, v_k, and the moments
  // Σ a_t v_j v_k (c_t, 1). Padding terms have zero moments.
  std::vector<float> vj, vk, mx, my, mz, mass;
  // Pair sums already computed, by (pair, w_j, w_k): the section slider rebuilds the same rig over
  // and over, and the nodes of a section count it has seen before cost a lookup. At most
  // memoLimit entries (then it starts afresh), so its memory stays in proportion to the rig.
  struct MemoKey {
    uint32_t pair, wj, wk;  // the weights' bits
    bool operator==(const MemoKey& o) const { return pair == o.pair && wj == o.wj && wk == o.wk; }
  };
  struct MemoHash {
    size_t operator()(const MemoKey& k) const {
      uint64_t h = (uint64_t(k.wj) << 32 | k.wk) * 0x9e3779b97f4a7c15ull ^ k.pair;
      return size_t(h ^ (h >> 29));
    }
  };
  mutable std::unordered_map<MemoKey, glm::vec4, MemoHash> memo;
  size_t memoLimit = 0;
};

// The rig's CentreSurface, built by the first call and cached on the rig; null (the error recorded)
// when its memory cannot be had.
const CentreSurface* centreSurfaceOf(const Rig& rig);

// p* of the blend of `count` joints with weights (summing to 1). Returns false where the integral
// is empty (no triangle weighs on two of the joints) or vanishes: the caller keeps the plain blend.
bool rotationCentre(const CentreSurface& surface, const uint32_t* joints, const float* weights, uint32_t count,
                    glm::vec3& centre);

// The centre a node of `count` joints turns about, false where it keeps the dual-quaternion blend.
// Only a bending pair has one: two joints, one the other's parent. Its centre lies on the line from
// the pivot (the child's joint centre) to p*, at most kCentreLever of the rig's height from the pivot
// (docs/method.md). The per-frame motion t = Σ w_j S_j p − M p is unchanged, so a centre at the
// pivot is the dual-quaternion blend exactly for a child turning about its joint, and the line is a
// smooth hand-over from DQS (lever 0) to the paper's centre (lever |p* − pivot|).
bool nodeCentre(const Rig& rig, const CentreSurface& surface, const uint32_t* joints, const float* weights, uint32_t count,
                glm::vec3& centre);

}  // namespace gcs
