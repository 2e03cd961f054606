#include "reference_deformers.h"
#include <cmath>
#include <new>
#include "error.h"
#include "transform.h"

namespace gcs {

float SkinningDeformer::stat(GcsStat which) const {
  switch (which) {
    case GCS_STAT_SECTIONS: return 0.0f;
    case GCS_STAT_PARTS: return 0.0f;
    case GCS_STAT_ADJUSTED_SHARE: return 0.0f;
    case GCS_STAT_ADJUSTED_SECTIONS: return 0.0f;
  }
  return std::nanf("");
}

SkinningDeformer* buildSkinning(const Rig& rig, GcsDeformerKind kind) {
  SkinningDeformer* d = nullptr;
  try {
    d = new SkinningDeformer(kind);
    d->jointCount = rig.jointCount;
    d->allocateOutput(rig.vertexCount);
    d->restPositions.resize(size_t(rig.vertexCount) * 3);
    d->restNormals.resize(size_t(rig.vertexCount) * 3);
    for (uint32_t v = 0; v < rig.vertexCount; ++v)
      for (int c = 0; c < 3; ++c) {
        d->restPositions[3 * v + c] = d->positions[3 * v + c] = rig.positions[v][c];
        d->restNormals[3 * v + c] = d->normals[3 * v + c] = rig.normals[v][c];
      }
    d->joints = rig.joints;
    d->weights = rig.weights;
    d->indices = rig.indices;
    d->sourceVertex.resize(rig.vertexCount);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) d->sourceVertex[v] = v;
    d->real.resize(rig.jointCount);
    d->dual.resize(rig.jointCount);
  } catch (const std::bad_alloc&) {
    delete d;
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while building the skinning deformer");
    return nullptr;
  }
  return d;
}

void SkinningDeformer::deform(const glm::mat4* skin) {
  const uint32_t n = vertexCount;
  if (kind_ == GCS_KIND_LBS) {
    for (uint32_t v = 0; v < n; ++v) {
      const glm::uvec4 j = joints[v];
      const glm::vec4 w = weights[v];
      glm::mat4 m = w[0] * skin[j[0]];
      for (int i = 1; i < 4; ++i)
        if (w[i] > 0.0f) m += w[i] * skin[j[i]];
      const float* p = &restPositions[3 * size_t(v)];
      const float* q = &restNormals[3 * size_t(v)];
      glm::vec3 rp(m * glm::vec4(p[0], p[1], p[2], 1.0f));
      glm::vec3 rn(m * glm::vec4(q[0], q[1], q[2], 0.0f));
      float len = glm::length(rn);
      if (len > 0.0f) rn /= len;
      for (int c = 0; c < 3; ++c) positions[3 * size_t(v) + c] = rp[c], normals[3 * size_t(v) + c] = rn[c];
    }
    return;
  }
  // Dual quaternions (Kavan et al. 2007): per joint, real part r and dual part d = ½ t r.
  for (uint32_t j = 0; j < jointCount; ++j) {
    glm::quat r = rotationOf(skin[j]);
    glm::vec3 t(skin[j][3]);
    glm::quat tq(0.0f, t.x, t.y, t.z);
    glm::quat dq = 0.5f * (tq * r);
    real[j] = glm::vec4(r.x, r.y, r.z, r.w);
    dual[j] = glm::vec4(dq.x, dq.y, dq.z, dq.w);
  }
  for (uint32_t v = 0; v < n; ++v) {
    const glm::uvec4 j = joints[v];
    const glm::vec4 w = weights[v];
    const glm::vec4 pivot = real[j[0]];
    glm::vec4 br(0.0f), bd(0.0f);
    for (int i = 0; i < 4; ++i) {
      if (w[i] <= 0.0f) continue;
      // Antipodality: blend every quaternion in the hemisphere of the first influence.
      float s = glm::dot(real[j[i]], pivot) < 0.0f ? -w[i] : w[i];
      br += s * real[j[i]];
      bd += s * dual[j[i]];
    }
    float len = glm::length(br);
    br /= len;
    bd /= len;
    glm::quat r(br.w, br.x, br.y, br.z), d(bd.w, bd.x, bd.y, bd.z);
    // Translation t = 2 · d · conj(r).
    glm::quat tq = 2.0f * (d * glm::conjugate(r));
    const float* p = &restPositions[3 * size_t(v)];
    const float* q = &restNormals[3 * size_t(v)];
    glm::vec3 rp = r * glm::vec3(p[0], p[1], p[2]) + glm::vec3(tq.x, tq.y, tq.z);
    glm::vec3 rn = r * glm::vec3(q[0], q[1], q[2]);
    for (int c = 0; c < 3; ++c) positions[3 * size_t(v) + c] = rp[c], normals[3 * size_t(v) + c] = rn[c];
  }
}

}  // namespace gcs
