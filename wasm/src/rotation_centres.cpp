#include "rotation_centres.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include "error.h"
#include "memory.h"
#if defined(__wasm_simd128__)
#include <wasm_simd128.h>
#endif

namespace gcs {
namespace {

uint64_t pairKey(uint32_t j, uint32_t k) { return j < k ? uint64_t(j) << 32 | k : uint64_t(k) << 32 | j; }

// One triangle's share of one pair, before the triangles of a cell are summed.
struct RawTerm {
  uint64_t pair;
  uint32_t cell;                // v_j and v_k on the 1/kCentreCells grid
  float vjMass, vkMass;         // v_j and v_k times the mass, for the cell's mean
  glm::vec4 moment;             // mass · (c_t, 1), mass = a_t v_j v_k
  bool operator<(const RawTerm& o) const { return pair != o.pair ? pair < o.pair : cell < o.cell; }
};

// A triangle's mean weights (the union of its corners' joints, each corner's weights / 3).
uint32_t meanWeights(const uint32_t (&corner)[3], const std::vector<uint32_t>& joints, const std::vector<float>& weights,
                     const std::vector<uint8_t>& counts, uint32_t* joint, float* weight) {
  uint32_t n = 0;
  for (uint32_t v : corner)
    for (uint32_t i = 0; i < counts[v]; ++i) {
      const uint32_t j = joints[size_t(v) * kMaxInfluences + i];
      uint32_t s = 0;
      while (s < n && joint[s] != j) ++s;
      if (s == n) joint[n] = j, weight[n] = 0.0f, ++n;
      weight[s] += weights[size_t(v) * kMaxInfluences + i] / 3.0f;
    }
  return n;
}

std::shared_ptr<CentreSurface> buildCentreSurface(const Rig& rig) {
  // Each vertex's weights as the nodes read them (so a node's own vertices are the most similar).
  const uint32_t V = rig.vertexCount;
  const size_t T = rig.indices.size() / 3;
  if (!reserveMemory(uint64_t(V) * (kMaxInfluences * 8 + 1) + uint64_t(T) * 64, "the centres of rotation")) return nullptr;
  std::vector<uint32_t> joints(size_t(V) * kMaxInfluences);
  std::vector<float> weights(size_t(V) * kMaxInfluences);
  std::vector<uint8_t> counts(V);
  for (uint32_t v = 0; v < V; ++v)
    counts[v] = uint8_t(cleanWeights(rig, v, &joints[size_t(v) * kMaxInfluences], &weights[size_t(v) * kMaxInfluences]));
  uint32_t joint[3 * kMaxInfluences];
  float weight[3 * kMaxInfluences];
  // Count first: the raw terms are reserved in one piece (a triangle of n joints has n(n−1)/2 pairs).
  uint64_t rawCount = 0;
  for (size_t t = 0; t < T; ++t) {
    const uint32_t corner[3] = {rig.indices[3 * t], rig.indices[3 * t + 1], rig.indices[3 * t + 2]};
    const uint64_t n = meanWeights(corner, joints, weights, counts, joint, weight);
    rawCount += n * (n - 1) / 2;
  }
  if (!reserveMemory(rawCount * (sizeof(RawTerm) + 2 * 6 * sizeof(float)) * 2, "the centres of rotation")) return nullptr;
  std::vector<RawTerm> raw;
  raw.reserve(size_t(rawCount));
  for (size_t t = 0; t < T; ++t) {
    const uint32_t corner[3] = {rig.indices[3 * t], rig.indices[3 * t + 1], rig.indices[3 * t + 2]};
    const uint32_t n = meanWeights(corner, joints, weights, counts, joint, weight);
    if (n < 2) continue;  // a rigid triangle: no pair weighs on it
    const glm::vec3 pa = rig.positions[corner[0]], pb = rig.positions[corner[1]], pc = rig.positions[corner[2]];
    const float area = 0.5f * glm::length(glm::cross(pb - pa, pc - pa));
    if (!(area > 0.0f) || !std::isfinite(area)) continue;
    const glm::vec3 centroid = (pa + pb + pc) / 3.0f;
    for (uint32_t i = 0; i < n; ++i)
      for (uint32_t k = i + 1; k < n; ++k) {
        const bool ordered = joint[i] < joint[k];
        const float vj = ordered ? weight[i] : weight[k], vk = ordered ? weight[k] : weight[i];
        const float mass = area * vj * vk;
        const auto bin = [](float v) { return std::min(uint32_t(v * float(kCentreCells)), kCentreCells - 1); };
        raw.push_back({pairKey(joint[i], joint[k]), bin(vj) * kCentreCells + bin(vk), vj * mass, vk * mass,
                       glm::vec4(mass * centroid, mass)});
      }
  }
  std::sort(raw.begin(), raw.end());
  auto surface = std::make_shared<CentreSurface>();
  auto push = [&](float vj, float vk, const glm::vec4& m) {
    surface->vj.push_back(vj), surface->vk.push_back(vk);
    surface->mx.push_back(m.x), surface->my.push_back(m.y), surface->mz.push_back(m.z), surface->mass.push_back(m.w);
  };
  for (size_t i = 0; i < raw.size();) {
    if (i == 0 || raw[i].pair != raw[i - 1].pair) {
      while (surface->vj.size() % 4) push(0.0f, 0.0f, glm::vec4(0.0f));
      surface->pairs.push_back(raw[i].pair);
      surface->first.push_back(uint32_t(surface->vj.size()));
    }
    // One cell: moments summed, weights averaged by mass.
    glm::vec4 moment(0.0f);
    float vjMass = 0.0f, vkMass = 0.0f;
    size_t end = i;
    for (; end < raw.size() && raw[end].pair == raw[i].pair && raw[end].cell == raw[i].cell; ++end)
      moment += raw[end].moment, vjMass += raw[end].vjMass, vkMass += raw[end].vkMass;
    if (moment.w > 0.0f) push(vjMass / moment.w, vkMass / moment.w, moment);
    i = end;
  }
  while (surface->vj.size() % 4) push(0.0f, 0.0f, glm::vec4(0.0f));
  surface->first.push_back(uint32_t(surface->vj.size()));
  surface->memoLimit = 4 * size_t(V) + 4096;
  return surface;
}

// e^y for y ≤ 0: 2^n · 2^f with n = round(y·log2 e), |f| ≤ ½, 2^f by its Taylor series to f⁵
// (relative error < 3e-6); y below −80 is taken as −80 (e^−80 ≈ 2e-35: nothing next to the rest).
// The same operations in each lane of the SIMD version.
#if defined(__wasm_simd128__)
inline v128_t expNegative4(v128_t y) {
  const v128_t z = wasm_f32x4_mul(wasm_f32x4_max(y, wasm_f32x4_splat(-80.0f)), wasm_f32x4_splat(1.44269504f));
  const v128_t n = wasm_f32x4_nearest(z), f = wasm_f32x4_sub(z, n);
  v128_t p = wasm_f32x4_splat(0.00133335581f);
  for (float c : {0.00961812911f, 0.0555041087f, 0.240226507f, 0.693147181f, 1.0f})
    p = wasm_f32x4_add(wasm_f32x4_splat(c), wasm_f32x4_mul(f, p));
  const v128_t scale = wasm_i32x4_shl(wasm_i32x4_add(wasm_i32x4_trunc_sat_f32x4(n), wasm_i32x4_splat(127)), 23);
  return wasm_f32x4_mul(p, scale);
}
#else
inline float expNegative(float y) {
  const float z = std::max(y, -80.0f) * 1.44269504f;
  const float n = std::nearbyint(z), f = z - n;
  const float p = 1.0f + f * (0.693147181f + f * (0.240226507f + f * (0.0555041087f + f * (0.00961812911f + f * 0.00133335581f))));
  const int32_t bits = (int32_t(n) + 127) << 23;
  float scale;
  std::memcpy(&scale, &bits, 4);
  return p * scale;
}
#endif

// Σ over one pair's terms of exp(−(w_j v_k − w_k v_j)²/σ²) · moments.
glm::vec4 pairSum(const CentreSurface& s, uint32_t first, uint32_t end, float wj, float wk) {
  const float k = -1.0f / (kCentreSigma * kCentreSigma);
#if defined(__wasm_simd128__)
  const v128_t WJ = wasm_f32x4_splat(wj), WK = wasm_f32x4_splat(wk), K = wasm_f32x4_splat(k);
  v128_t sx = wasm_f32x4_splat(0.0f), sy = sx, sz = sx, sm = sx;
  for (uint32_t t = first; t < end; t += 4) {
    const v128_t x = wasm_f32x4_sub(wasm_f32x4_mul(WJ, wasm_v128_load(&s.vk[t])), wasm_f32x4_mul(WK, wasm_v128_load(&s.vj[t])));
    const v128_t e = expNegative4(wasm_f32x4_mul(K, wasm_f32x4_mul(x, x)));
    sx = wasm_f32x4_add(sx, wasm_f32x4_mul(e, wasm_v128_load(&s.mx[t])));
    sy = wasm_f32x4_add(sy, wasm_f32x4_mul(e, wasm_v128_load(&s.my[t])));
    sz = wasm_f32x4_add(sz, wasm_f32x4_mul(e, wasm_v128_load(&s.mz[t])));
    sm = wasm_f32x4_add(sm, wasm_f32x4_mul(e, wasm_v128_load(&s.mass[t])));
  }
  auto total = [](v128_t v) {
    return wasm_f32x4_extract_lane(v, 0) + wasm_f32x4_extract_lane(v, 1) + wasm_f32x4_extract_lane(v, 2) +
           wasm_f32x4_extract_lane(v, 3);
  };
  return glm::vec4(total(sx), total(sy), total(sz), total(sm));
#else
  glm::vec4 sum[4] = {};
  for (uint32_t t = first; t < end; ++t) {
    const float x = wj * s.vk[t] - wk * s.vj[t];
    const float e = expNegative(k * (x * x));
    sum[t % 4] += e * glm::vec4(s.mx[t], s.my[t], s.mz[t], s.mass[t]);
  }
  return sum[0] + sum[1] + sum[2] + sum[3];
#endif
}

}  // namespace

const CentreSurface* centreSurfaceOf(const Rig& rig) {
  if (!rig.cache.centreSurface) rig.cache.centreSurface = buildCentreSurface(rig);
  return rig.cache.centreSurface.get();
}

bool rotationCentre(const CentreSurface& surface, const uint32_t* joints, const float* weights, uint32_t count,
                    glm::vec3& centre) {
  glm::dvec4 sum(0.0);
  for (uint32_t i = 0; i < count; ++i)
    for (uint32_t k = i + 1; k < count; ++k) {
      const uint64_t pair = pairKey(joints[i], joints[k]);
      auto it = std::lower_bound(surface.pairs.begin(), surface.pairs.end(), pair);
      if (it == surface.pairs.end() || *it != pair) continue;
      const size_t p = size_t(it - surface.pairs.begin());
      const bool ordered = joints[i] < joints[k];
      const float wj = ordered ? weights[i] : weights[k], wk = ordered ? weights[k] : weights[i];
      CentreSurface::MemoKey key{uint32_t(p), 0, 0};
      std::memcpy(&key.wj, &wj, 4);
      std::memcpy(&key.wk, &wk, 4);
      auto memo = surface.memo.find(key);
      if (memo == surface.memo.end()) {
        if (surface.memo.size() >= surface.memoLimit) surface.memo.clear();
        memo = surface.memo.emplace(key, pairSum(surface, surface.first[p], surface.first[p + 1], wj, wk)).first;
      }
      sum += double(wj) * double(wk) * glm::dvec4(memo->second);
    }
  if (!(sum.w > 0.0) || !std::isfinite(sum.w)) return false;
  const glm::dvec3 p = glm::dvec3(sum) / sum.w;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  centre = glm::vec3(p);
  return true;
}


bool nodeCentre(const Rig& rig, const CentreSurface& surface, const uint32_t* joints, const float* weights, uint32_t count,
                glm::vec3& centre) {
  // A bending pair: two joints, one the other's parent. Anything else keeps the dual-quaternion
  // blend (a chain of three or more joints has no single pivot; two unrelated joints do not bend
  // about one another).
  if (count != 2) return false;
  const uint32_t child = rig.parents[joints[1]] == int32_t(joints[0]) ? joints[1]
                         : rig.parents[joints[0]] == int32_t(joints[1]) ? joints[0]
                                                                        : ~0u;
  if (child == ~0u) return false;
  glm::vec3 p;
  if (!rotationCentre(surface, joints, weights, count, p)) return false;
  // The centre on the line from the pivot to p*, at most kCentreLever of the height from the pivot.
  const glm::vec3 pivot = rig.jointCentres[child], lever = p - pivot;
  const float length = glm::length(lever), most = kCentreLever * rig.height;
  centre = length > most ? pivot + lever * (most / length) : p;
  return true;
}

}  // namespace gcs
