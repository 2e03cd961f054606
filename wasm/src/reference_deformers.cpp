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
    d->joints1 = rig.joints1;
    d->weights1 = rig.weights1;
    d->indices = rig.indices;
    d->sourceVertex.resize(rig.vertexCount);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) d->sourceVertex[v] = v;
    d->poses.resize(rig.jointCount);
  } catch (const std::bad_alloc&) {
    delete d;
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while building the skinning deformer");
    return nullptr;
  }
  return d;
}

void SkinningDeformer::deform(const glm::mat4* skin) {
  const ScaleState scale = decomposeAll(skin, jointCount, poses.data());
  skinVertices(skin, scale, restNormals.data(), positions.data(), normals.data());
  if (!tangents.empty()) {
    // Tangents turn like normals: the same skinning of the rest tangents (positions discarded).
    skinVertices(skin, scale, restTangents.data(), tangentPassPositions.data(), turnedTangents.data());
    packTangents();
  }
}

void SkinningDeformer::skinVertices(const glm::mat4* skin, const ScaleState& scale, const float* inNrm, float* outPos,
                                    float* outNrm) const {
  const uint32_t n = vertexCount;
  const bool eight = !joints1.empty();
  if (kind_ == GCS_KIND_LBS) {
    for (uint32_t v = 0; v < n; ++v) {
      const glm::uvec4 j = joints[v];
      const glm::vec4 w = weights[v];
      glm::mat4 m = w[0] * skin[j[0]];
      for (int i = 1; i < 4; ++i)
        if (w[i] > 0.0f) m += w[i] * skin[j[i]];
      if (eight)
        for (int i = 0; i < 4; ++i)
          if (weights1[v][i] > 0.0f) m += weights1[v][i] * skin[joints1[v][i]];
      const float* p = &restPositions[3 * size_t(v)];
      const float* q = inNrm + 3 * size_t(v);
      glm::vec3 rp(m * glm::vec4(p[0], p[1], p[2], 1.0f));
      glm::vec3 rest(q[0], q[1], q[2]);
      // As three.js does: the normal by the blended matrix, then unit length. Where the blend has
      // collapsed (bones scaled to 0), the rest normal turned by the first influence's rotation.
      glm::vec3 rn(m * glm::vec4(rest, 0.0f));
      float len2 = glm::dot(rn, rn);
      if (len2 > 1e-24f && len2 < 1e24f) rn *= 1.0f / std::sqrt(len2);
      else rn = unitOr(rn, poses[j[0]].rotation * rest);
      for (int c = 0; c < 3; ++c) outPos[3 * size_t(v) + c] = rp[c], outNrm[3 * size_t(v) + c] = rn[c];
    }
    return;
  }
  dqsVertices(poses.data(), scale, joints.data(), weights.data(), eight ? joints1.data() : nullptr,
              eight ? weights1.data() : nullptr, restPositions.data(), inNrm, outPos, outNrm, n);
}

// Dual quaternions (Kavan et al. 2007) for the rigid part of each S_j; its scale blended linearly
// and applied first (so rigs with scaled matrices work).
void dqsVertices(const JointPose* poses, const ScaleState& scale, const glm::uvec4* joints, const glm::vec4* weights,
                 const glm::uvec4* joints1, const glm::vec4* weights1, const float* restPositions,
                 const float* restNormals, float* positions, float* normals, uint32_t n) {
  const JointPose* blend[8];
  float w8[8];
  glm::mat4 pm, nm;
  for (uint32_t v = 0; v < n; ++v) {
    const float* p = &restPositions[3 * size_t(v)];
    const float* q = normals ? &restNormals[3 * size_t(v)] : p;  // (not read without normals)
    glm::vec3 rp, rn(0.0f);
    if (scale.uniform) {
      // Every K = s·I: rotate s·x by the blended unit quaternion and translate (no matrices).
      const glm::uvec4 j = joints[v];
      const glm::vec4 wv = weights[v];
      const glm::vec4 pivot = poses[j[0]].real;
      glm::vec4 br(0.0f), bd(0.0f);
      for (int i = 0; i < 4; ++i) {
        if (!(wv[i] > 0.0f)) continue;
        const JointPose& jp = poses[j[i]];
        float sw = glm::dot(jp.real, pivot) < 0.0f ? -wv[i] : wv[i];
        br += sw * jp.real;
        bd += sw * jp.dual;
      }
      if (joints1)
        for (int i = 0; i < 4; ++i) {
          const float w = weights1[v][i];
          if (!(w > 0.0f)) continue;
          const JointPose& jp = poses[joints1[v][i]];
          const float sw = glm::dot(jp.real, pivot) < 0.0f ? -w : w;
          br += sw * jp.real;
          bd += sw * jp.dual;
        }
      const float inv = 1.0f / glm::length(br);
      br *= inv;
      bd *= inv;
      const glm::vec3 u(br), du(bd);
      const glm::vec3 t = 2.0f * (br.w * du - bd.w * u - glm::cross(du, u));
      const glm::vec3 x = scale.s * glm::vec3(p[0], p[1], p[2]), nn(q[0], q[1], q[2]);
      // r·x = x + 2u×(u×x + w·x)
      rp = x + 2.0f * glm::cross(u, glm::cross(u, x) + br.w * x) + t;
      if (normals) rn = nn + 2.0f * glm::cross(u, glm::cross(u, nn) + br.w * nn);
    } else {
      uint32_t k = 0;
      for (int i = 0; i < 4; ++i) {
        if (!(weights[v][i] > 0.0f)) continue;
        blend[k] = &poses[joints[v][i]];
        w8[k++] = weights[v][i];
      }
      if (joints1)
        for (int i = 0; i < 4; ++i) {
          if (!(weights1[v][i] > 0.0f)) continue;
          blend[k] = &poses[joints1[v][i]];
          w8[k++] = weights1[v][i];
        }
      bool renorm = false;
      blendPoses(blend, w8, k, scale, pm, nm, renorm);
      rp = glm::vec3(pm * glm::vec4(p[0], p[1], p[2], 1.0f));
      if (normals) {
        rn = glm::vec3(nm * glm::vec4(q[0], q[1], q[2], 0.0f));
        if (renorm) rn = unitOr(rn, glm::vec3(q[0], q[1], q[2]));  // a normal K has flattened away: the rest one
      }
    }
    for (int c = 0; c < 3; ++c) positions[3 * size_t(v) + c] = rp[c];
    if (normals)
      for (int c = 0; c < 3; ++c) normals[3 * size_t(v) + c] = rn[c];
  }
}

}  // namespace gcs
