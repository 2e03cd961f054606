// Native smoke test of the C API: a two-part bar bent 90°, checked for finiteness, the exact
// rest pose, and the shared section turning by half the joint rotation.
#include <cmath>
#include <cstdio>
#include <vector>
#include "../include/gcs_skin.h"

int main() {
  // A bar along +Y from 0 to 2, 4 vertices per ring, rings every 0.25; joint 1 at y = 1.
  std::vector<float> pos;
  std::vector<uint32_t> idx, joints;
  std::vector<float> weights;
  const int rings = 9;
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < 4; ++k) {
      float a = float(k) * 1.5707963f;
      pos.insert(pos.end(), {0.1f * std::cos(a), 0.25f * float(r), 0.1f * std::sin(a)});
      bool upper = 0.25f * float(r) > 1.0f;
      joints.insert(joints.end(), {upper ? 1u : 0u, 0u, 0u, 0u});
      weights.insert(weights.end(), {1.0f, 0.0f, 0.0f, 0.0f});
    }
  for (int r = 0; r + 1 < rings; ++r)
    for (int k = 0; k < 4; ++k) {
      uint32_t a = uint32_t(r * 4 + k), b = uint32_t(r * 4 + (k + 1) % 4);
      idx.insert(idx.end(), {a, b, a + 4, b, b + 4, a + 4});
    }
  int32_t parents[2] = {-1, 0};
  float ibm[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                   1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
  GcsRig* rig = gcs_rig_create(pos.data(), nullptr, uint32_t(pos.size() / 3), idx.data(),
                               uint32_t(idx.size()), joints.data(), weights.data(), 4, parents, ibm, 2);
  if (!rig) { std::printf("rig: %s\n", gcs_last_error_message()); return 1; }
  const GcsSettings axial{5, GCS_CRITERION_AXIAL, 1.0f, 0, 0, 0};
  GcsDeformer* d = gcs_build_gcs(rig, &axial);
  if (!d) { std::printf("gcs: %s\n", gcs_last_error_message()); return 1; }
  float skin[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                    1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  gcs_deformer_deform(d, skin, 2);
  const float* out = gcs_deformer_positions(d);
  const uint32_t* src = gcs_deformer_source_vertex(d);
  for (uint32_t i = 0; i < gcs_deformer_vertex_count(d); ++i)
    for (int c = 0; c < 3; ++c)
      if (out[3 * i + c] != pos[3 * src[i] + c]) { std::printf("rest pose differs at %u\n", i); return 1; }
  // Bend joint 1 by 90° about Z: S_1 = T(0,1,0) · Rz · T(0,-1,0).
  float bent[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                    0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 1, 1, 0, 1};
  if (!gcs_deformer_deform(d, bent, 2)) { std::printf("deform: %s\n", gcs_last_error_message()); return 1; }
  for (uint32_t i = 0; i < 3 * gcs_deformer_vertex_count(d); ++i)
    if (!std::isfinite(out[i])) { std::printf("non-finite output\n"); return 1; }
  // The weights criterion (the default): every vertex of this bar is bound 100 % to one joint, so
  // every section is a rigid core and the bent bar is exactly S_j · x, part by part.
  const GcsSettings byWeights{5, GCS_CRITERION_WEIGHTS, 1.0f, 0, 0, 1};
  GcsDeformer* w = gcs_build_gcs(rig, &byWeights);
  if (!w) { std::printf("gcs weights: %s\n", gcs_last_error_message()); return 1; }
  if (!gcs_deformer_deform(w, bent, 2)) { std::printf("deform: %s\n", gcs_last_error_message()); return 1; }
  const float* wp = gcs_deformer_positions(w);
  const uint32_t* ws = gcs_deformer_source_vertex(w);
  for (uint32_t i = 0; i < gcs_deformer_vertex_count(w); ++i) {
    const float* x = &pos[3 * ws[i]];
    const float* m = &bent[16 * joints[4 * ws[i]]];
    for (int c = 0; c < 3; ++c) {
      float e = m[c] * x[0] + m[4 + c] * x[1] + m[8 + c] * x[2] + m[12 + c];
      if (std::fabs(wp[3 * i + c] - e) > 1e-6f) { std::printf("weights criterion: vertex %u is not rigid\n", i); return 1; }
    }
  }
  gcs_deformer_destroy(w);
  std::printf("native smoke: %u vertices, %g sections, adjusted share %g — ok\n",
              gcs_deformer_vertex_count(d), double(gcs_deformer_stat(d, GCS_STAT_SECTIONS)),
              double(gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SHARE)));
  gcs_deformer_destroy(d);
  gcs_rig_destroy(rig);
  return 0;
}
