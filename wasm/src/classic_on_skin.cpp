#include "classic_on_skin.h"
#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include "classic_geometry.h"
#include "reference_deformers.h"
#include "transform.h"

namespace gcs {

using namespace classic;

namespace {

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

}  // namespace

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
  std::vector<float> rest(size_t(C) * 3), posed(size_t(C) * 3);
  const bool eight = rig.influenceSlots == 8;
  std::vector<glm::uvec4> joints(C), joints1(eight ? C : 0);
  std::vector<glm::vec4> weights(C), weights1(eight ? C : 0);
  for (uint32_t i = 0; i < C; ++i) {
    const uint32_t v = cornerOf[i];
    for (int c = 0; c < 3; ++c) rest[3 * i + c] = rig.positions[v][c];
    joints[i] = rig.joints[v], weights[i] = rig.weights[v];
    if (eight) joints1[i] = rig.joints1[v], weights1[i] = rig.weights1[v];
  }
  std::vector<glm::mat4> skin;
  std::vector<std::vector<float>> distances(J);
  for (int probe = 0; probe < kProbes; ++probe) {  // (at the bind pose each ring vertex is its hit)
    probeSkin(rig, axes[probe], angles[probe], skin);
    const ScaleState scale = m.poseRings(skin.data());  // (the rings only: the rest is not tested)
    dqsVertices(m.poses.data(), scale, joints.data(), weights.data(), eight ? joints1.data() : nullptr,
                eight ? weights1.data() : nullptr, rest.data(), nullptr, posed.data(), nullptr, C);
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
  m.poseRings(identity.data());
  return failed;
}

}  // namespace gcs
