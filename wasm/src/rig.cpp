#include "rig.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include "error.h"

namespace gcs {

size_t firstNonFinite(const float* values, size_t count) {
  uint32_t any = 0;  // a branch-free pass first (vectorised): skin matrices arrive every frame
  for (size_t i = 0; i < count; ++i) {
    uint32_t bits;
    std::memcpy(&bits, values + i, sizeof bits);
    any |= uint32_t((bits & 0x7f800000u) == 0x7f800000u);
  }
  if (!any) return count;
  for (size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i])) return i;
  return count;
}

bool allFinite(const float* values, size_t count) { return firstNonFinite(values, count) == count; }

std::vector<uint32_t> weldByPosition(const Rig& rig, std::vector<uint32_t>& representative) {
  weldRig(rig);
  representative = rig.cache.weldRepresentative;
  return rig.cache.weldGroup;
}

void weldRig(const Rig& rig) {
  if (rig.cache.welded) return;
  std::vector<uint32_t> representative;
  // A sort of the exact position bits, not a hash: O(n log n) for any input (a hash of raw float
  // bits put integer grids of power-of-two sizes into a few buckets: quadratic).
  struct Entry {
    uint32_t x, y, z, v;
    bool operator<(const Entry& o) const {
      if (x != o.x) return x < o.x;
      if (y != o.y) return y < o.y;
      if (z != o.z) return z < o.z;
      return v < o.v;
    }
    bool samePoint(const Entry& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  const uint32_t n = rig.vertexCount;
  std::vector<Entry> entries(n);
  for (uint32_t v = 0; v < n; ++v) {
    glm::vec3 p = rig.positions[v] + glm::vec3(0.0f);  // +0 folds -0 into 0
    Entry& e = entries[v];
    std::memcpy(&e.x, &p.x, 4);
    std::memcpy(&e.y, &p.y, 4);
    std::memcpy(&e.z, &p.z, 4);
    e.v = v;
  }
  std::sort(entries.begin(), entries.end());
  std::vector<uint32_t> runOf(n);
  uint32_t runs = 0;
  for (uint32_t i = 0; i < n; ++i) {
    if (i > 0 && !entries[i].samePoint(entries[i - 1])) ++runs;
    runOf[entries[i].v] = runs;
  }
  // Group ids in order of first appearance, the representative the group's first vertex.
  std::vector<uint32_t> idOfRun(n ? runs + 1 : 0, ~0u);
  std::vector<uint32_t> group(n);
  for (uint32_t v = 0; v < n; ++v) {
    uint32_t& id = idOfRun[runOf[v]];
    if (id == ~0u) {
      id = uint32_t(representative.size());
      representative.push_back(v);
    }
    group[v] = id;
  }
  rig.cache.weldGroup.swap(group);
  rig.cache.weldRepresentative.swap(representative);
  rig.cache.welded = true;  // (after both: a failed allocation leaves no half cache)
}

const WeightGroups& weightGroupsOf(const Rig& rig) {
  if (rig.cache.weightGroups) return *rig.cache.weightGroups;
  weldRig(rig);
  auto groups = std::make_shared<WeightGroups>();
  WeightGroups& w = *groups;
  const size_t G = rig.cache.weldRepresentative.size(), slots = w.slots = rig.influenceSlots;
  w.joint.resize(G * slots);
  w.weight.resize(G * slots);
  w.count.resize(G);
  w.pairOf.assign(G, ~0u);
  std::vector<std::pair<uint64_t, uint32_t>> twoJoints;  // (dominant << 32 | other, group)
  for (size_t g = 0; g < G; ++g) {
    const uint32_t* joint = &w.joint[g * slots];
    const float* weight = &w.weight[g * slots];
    const uint32_t n = w.count[g] = uint8_t(cleanWeights(rig, rig.cache.weldRepresentative[g], &w.joint[g * slots], &w.weight[g * slots]));
    if (n != 2) continue;
    const uint32_t d = weight[1] > weight[0] ? 1 : 0;  // the first of equal weights, as buildWeightNodes
    twoJoints.push_back({uint64_t(joint[d]) << 32 | joint[1 - d], uint32_t(g)});
  }
  std::sort(twoJoints.begin(), twoJoints.end());
  for (size_t i = 0; i < twoJoints.size(); ++i) {
    const uint64_t pair = twoJoints[i].first;
    if (i == 0 || pair != twoJoints[i - 1].first) w.pairs.push_back(glm::uvec2(uint32_t(pair >> 32), uint32_t(pair)));
    w.pairOf[twoJoints[i].second] = uint32_t(w.pairs.size() - 1);
  }
  rig.cache.weightGroups = std::move(groups);
  return *rig.cache.weightGroups;
}

uint32_t Rig::dominantJoint(uint32_t v) const {
  uint32_t best = 0;
  for (uint32_t i = 1; i < influenceSlots; ++i)
    if (weightAt(v, i) > weightAt(v, best)) best = i;
  return jointAt(v, best);
}

void computeNormals(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                    std::vector<glm::vec3>& normals) {
  normals.assign(positions.size(), glm::vec3(0.0f));
  // Scale-free: the cross products grow as the square of the size and their sums' squared
  // lengths as its fourth power, so a mesh far from unit size (a ×1e37 tube overflowed, a ×1e-20
  // one underflowed) has its edges scaled by a power of two near 1 / extent first (exact, so the
  // directions are the same). Ordinary sizes skip it and stay bit-identical.
  float extent = 0.0f;
  for (const glm::vec3& p : positions) extent = std::fmax(extent, std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z))));
  const float scale = extent > 1e6f || (extent > 0.0f && extent < 1e-6f) ? std::ldexp(1.0f, -std::ilogb(extent)) : 1.0f;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const glm::vec3& a = positions[indices[t]];
    const glm::vec3& b = positions[indices[t + 1]];
    const glm::vec3& c = positions[indices[t + 2]];
    // length = 2 · area (× scale²): area weighting for free. Scaled before subtracting: the
    // difference of two coordinates near ±3.4e38 overflows too.
    glm::vec3 n = glm::cross(b * scale - a * scale, c * scale - a * scale);
    normals[indices[t]] += n;
    normals[indices[t + 1]] += n;
    normals[indices[t + 2]] += n;
  }
  for (glm::vec3& n : normals) {
    float len = glm::length(n);
    n = len > 0.0f ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
  }
}

static bool validateParents(const int32_t* parents, uint32_t jointCount) {
  for (uint32_t j = 0; j < jointCount; ++j) {
    int32_t p = parents[j];
    if (p < -1 || p >= int32_t(jointCount) || p == int32_t(j))
      return fail(GCS_ERR_JOINT_OUT_OF_RANGE,
                  "joint %u has parent %d, but parents must be -1 or another joint id below %u",
                  j, p, jointCount);
  }
  // Cycle check: walking up from any joint must reach a root within jointCount steps.
  for (uint32_t j = 0; j < jointCount; ++j) {
    int32_t p = parents[j];
    for (uint32_t steps = 0; p != -1; ++steps) {
      if (steps > jointCount)
        return fail(GCS_ERR_JOINT_OUT_OF_RANGE,
                    "the joint hierarchy has a cycle through joint %u", j);
      p = parents[p];
    }
  }
  return true;
}

bool buildRig(const float* positions, const float* normals, uint32_t vertexCount,
              const uint32_t* indices, uint32_t indexCount, const uint32_t* joints,
              const float* weights, uint32_t influences, const int32_t* parents, const float* inverseBind,
              uint32_t jointCount, Rig& rig) {
  if (influences < 1 || influences > GCS_MAX_INFLUENCES)
    return fail(GCS_ERR_OUT_OF_RANGE, "a vertex has 1 to %d skin influences (joint, weight pairs); got %u",
                GCS_MAX_INFLUENCES, influences);
  if (!positions || !indices || !joints || !weights || !parents || !inverseBind)
    return fail(GCS_ERR_INVALID_ARGUMENT,
                "positions, indices, joints, weights, parents and inverse bind matrices are all required");
  if (vertexCount == 0) return fail(GCS_ERR_NO_SKIN, "the mesh has no vertices");
  if (vertexCount > GCS_MAX_VERTICES)
    return fail(GCS_ERR_OUT_OF_RANGE, "the mesh has %u vertices; at most %u are supported",
                vertexCount, unsigned(GCS_MAX_VERTICES));
  if (jointCount == 0) return fail(GCS_ERR_NO_SKIN, "the skeleton has no joints");
  if (jointCount > GCS_MAX_JOINTS)
    return fail(GCS_ERR_OUT_OF_RANGE, "the skeleton has %u joints; at most %u are supported",
                jointCount, unsigned(GCS_MAX_JOINTS));
  if (indexCount == 0) return fail(GCS_ERR_NO_SKIN, "the mesh has no triangles");
  if (indexCount % 3 != 0)
    return fail(GCS_ERR_LENGTH_MISMATCH,
                "the index count %u is not a multiple of 3 (a triangle list is expected)", indexCount);
  if (!allFinite(positions, size_t(vertexCount) * 3))
    return fail(GCS_ERR_NON_FINITE, "a vertex position is NaN or infinite");
  if (normals && !allFinite(normals, size_t(vertexCount) * 3))
    return fail(GCS_ERR_NON_FINITE, "a vertex normal is NaN or infinite");
  if (!allFinite(inverseBind, size_t(jointCount) * 16))
    return fail(GCS_ERR_NON_FINITE, "an inverse bind matrix contains NaN or infinity");
  for (uint32_t i = 0; i < indexCount; ++i)
    if (indices[i] >= vertexCount)
      return fail(GCS_ERR_INDEX_OUT_OF_RANGE,
                  "triangle index %u (at position %u) is out of range: the mesh has %u vertices",
                  indices[i], i, vertexCount);
  if (!validateParents(parents, jointCount)) return false;

  try {
    rig = Rig();
    rig.vertexCount = vertexCount;
    rig.jointCount = jointCount;
    rig.positions.resize(vertexCount);
    rig.influenceSlots = influences > 4 ? 8 : 4;
    rig.joints.resize(vertexCount);
    rig.weights.resize(vertexCount);
    if (rig.influenceSlots == 8) rig.joints1.resize(vertexCount), rig.weights1.resize(vertexCount);
    for (uint32_t v = 0; v < vertexCount; ++v) {
      rig.positions[v] = glm::vec3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
      float slotWeight[8] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
      uint32_t slotJoint[8] = {0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u};
      float big = 0.0f;
      for (uint32_t i = 0; i < influences; ++i) {
        const float w = weights[size_t(influences) * v + i];
        const uint32_t j = joints[size_t(influences) * v + i];
        if (!std::isfinite(w)) return fail(GCS_ERR_NON_FINITE, "the skin weights of vertex %u are NaN or infinite", v);
        if (w < 0.0f) return fail(GCS_ERR_BAD_WEIGHTS, "vertex %u has a negative skin weight (%g)", v, double(w));
        if (w > 0.0f && j >= jointCount)
          return fail(GCS_ERR_JOINT_OUT_OF_RANGE,
                      "vertex %u is skinned to joint %u, but the skeleton has %u joints", v, j, jointCount);
        slotJoint[i] = w > 0.0f ? j : 0u;  // unused slots point at joint 0 with weight 0
        slotWeight[i] = w;
        big = std::fmax(big, w);
      }
      // Normalise by the largest weight first: weights near FLT_MAX would overflow the sum.
      if (!(big > 0.0f))
        return fail(GCS_ERR_BAD_WEIGHTS, "vertex %u has no skin weight (its weights sum to 0)", v);
      float sum = 0.0f;
      for (float& w : slotWeight) w /= big, sum += w;
      for (float& w : slotWeight) w /= sum;
      rig.joints[v] = glm::uvec4(slotJoint[0], slotJoint[1], slotJoint[2], slotJoint[3]);
      rig.weights[v] = glm::vec4(slotWeight[0], slotWeight[1], slotWeight[2], slotWeight[3]);
      if (rig.influenceSlots == 8) {
        rig.joints1[v] = glm::uvec4(slotJoint[4], slotJoint[5], slotJoint[6], slotJoint[7]);
        rig.weights1[v] = glm::vec4(slotWeight[4], slotWeight[5], slotWeight[6], slotWeight[7]);
      }
    }
    rig.indices.assign(indices, indices + indexCount);
    if (normals) {
      rig.normals.resize(vertexCount);
      for (uint32_t v = 0; v < vertexCount; ++v) {
        glm::vec3 n(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
        float len = glm::length(n);
        rig.normals[v] = len > 0.0f ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
      }
    } else {
      computeNormals(rig.positions, rig.indices, rig.normals);
    }
    rig.parents.assign(parents, parents + jointCount);
    rig.inverseBind.resize(jointCount);
    rig.bind.resize(jointCount);
    rig.jointCentres.resize(jointCount);
    for (uint32_t j = 0; j < jointCount; ++j) {
      glm::mat4 m;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = inverseBind[16 * j + 4 * c + r];
      float det = glm::determinant(m);
      if (!(std::fabs(det) > 1e-12f))
        return fail(GCS_ERR_DEGENERATE, "the inverse bind matrix of joint %u is singular (not invertible): the joint has no bind pose", j);
      rig.inverseBind[j] = m;
      rig.bind[j] = glm::inverse(m);
      rig.jointCentres[j] = glm::vec3(rig.bind[j][3]);
    }
    rig.boundsMin = rig.boundsMax = rig.positions[0];
    for (const glm::vec3& p : rig.positions) {
      rig.boundsMin = glm::min(rig.boundsMin, p);
      rig.boundsMax = glm::max(rig.boundsMax, p);
    }
    glm::vec3 extent = rig.boundsMax - rig.boundsMin;
    rig.height = glm::max(extent.x, glm::max(extent.y, extent.z));
    if (!(rig.height > 0.0f)) return fail(GCS_ERR_DEGENERATE, "all vertices are at the same point");
  } catch (const std::bad_alloc&) {
    return fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while copying the rig (%u vertices)", vertexCount);
  }
  return true;
}

uint32_t cleanWeights(const Rig& rig, uint32_t v, uint32_t* joint, float* weight) {
  uint32_t n = 0;
  float sum = 0.0f;
  for (uint32_t i = 0; i < rig.influenceSlots; ++i) {
    float w = rig.weightAt(v, i);
    if (!(w > 0.0f)) continue;
    uint32_t j = rig.jointAt(v, i), k = 0;
    while (k < n && joint[k] != j) ++k;
    if (k == n) joint[n] = j, weight[n] = 0.0f, ++n;
    weight[k] += w;
  }
  uint32_t kept = 0;
  float biggest = 0.0f;
  for (uint32_t i = 0; i < n; ++i) biggest = std::max(biggest, weight[i]);
  for (uint32_t i = 0; i < n; ++i)
    if (weight[i] >= 0.005f || weight[i] == biggest) joint[kept] = joint[i], weight[kept] = weight[i], sum += weight[i], ++kept;
  for (uint32_t i = 0; i < kept; ++i) weight[i] /= sum;
  return kept;
}

}  // namespace gcs
