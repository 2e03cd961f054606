// What the deformers do to the rest mesh besides skinning (deformer.h): morph targets (base +
// Σ influence · delta, before skinning) and the tangents' handedness (carried after).
#include <cmath>
#include "deformer.h"

namespace gcs {

void Deformer::applyMorphs() {
  if (morphTargetCount == 0 || morphInfluences == morphApplied) return;
  std::vector<float>& rest = *morphableRestPositions();
  std::vector<float>& restN = *morphableRestNormals();
  const size_t n = size_t(vertexCount) * 3;
  for (size_t i = 0; i < n; ++i) rest[i] = morphBasePositions[i];
  const bool normals = !morphNormalDeltas.empty();
  if (normals)
    for (size_t i = 0; i < n; ++i) restN[i] = morphBaseNormals[i];
  for (uint32_t t = 0; t < morphTargetCount; ++t) {
    const float w = morphInfluences[t];
    if (w == 0.0f) continue;
    const float* d = &morphDeltas[t * n];
    for (size_t i = 0; i < n; ++i) rest[i] += w * d[i];
    if (normals) {
      const float* dn = &morphNormalDeltas[t * n];
      for (size_t i = 0; i < n; ++i) restN[i] += w * dn[i];
    }
  }
  if (normals) {  // the kernels expect unit rest normals
    for (uint32_t v = 0; v < vertexCount; ++v) {
      float* q = &restN[3 * size_t(v)];
      float len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      if (len > 1e-20f && std::isfinite(len)) q[0] /= len, q[1] /= len, q[2] /= len;
      else for (int c = 0; c < 3; ++c) q[c] = morphBaseNormals[3 * size_t(v) + c];
    }
  }
  morphApplied = morphInfluences;
}

void Deformer::packTangents() {
  const float* in = turnedTangents.data();
  float* out = tangents.data();
  for (uint32_t v = 0; v < vertexCount; ++v)
    out[4 * v] = in[3 * v], out[4 * v + 1] = in[3 * v + 1], out[4 * v + 2] = in[3 * v + 2], out[4 * v + 3] = tangentSigns[v];
}

}  // namespace gcs
