#include "classic_model.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include "classic_geometry.h"
#include "reference_deformers.h"
#include "transform.h"

namespace gcs {

using namespace classic;

float ClassicModel::stat(GcsStat which) const {
  switch (which) {
    case GCS_STAT_SECTIONS: return float(contours.size());
    case GCS_STAT_PARTS: return float(reportJoints.size());
    case GCS_STAT_ADJUSTED_SHARE: return 1.0f;  // every contour is recomputed each frame
    case GCS_STAT_ADJUSTED_SECTIONS: return float(contours.size());
  }
  return std::nanf("");
}

ScaleState ClassicModel::poseRings(const glm::mat4* skin) {
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
  return scale;
}

void ClassicModel::deform(const glm::mat4* skin) {
  const uint32_t k = rays;
  const ScaleState scale = poseRings(skin);
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
