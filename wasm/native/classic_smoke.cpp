// Native smoke test of the classic cross-section model: a three-bone cylinder (radius 0.1, bones
// along +Y at y = 0, 1, 2) is resampled, checked for its radius, for the joint contour on the
// bisector plane under a 90° bend, for the bulge formula, for errors and for the build time.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>
#include "../include/gcs_skin.h"

static int failures = 0;
#define CHECK(cond, ...) do { if (!(cond)) { std::printf("FAIL: " __VA_ARGS__); std::printf("\n"); ++failures; } } while (0)

struct Mesh {
  std::vector<float> pos;
  std::vector<uint32_t> idx, joints;
  std::vector<float> weights;
};

// A closed cylinder (capped), `seg` segments, `rings` rings from y = 0 to y = 3.
static Mesh cylinder(int seg, int rings) {
  Mesh m;
  for (int r = 0; r < rings; ++r) {
    float y = 3.0f * float(r) / float(rings - 1);
    for (int s = 0; s < seg; ++s) {
      float a = 6.2831853f * float(s) / float(seg);
      m.pos.insert(m.pos.end(), {0.1f * std::cos(a), y, 0.1f * std::sin(a)});
      uint32_t j = y < 1.0f ? 0u : y < 2.0f ? 1u : 2u;
      m.joints.insert(m.joints.end(), {j, 0u, 0u, 0u});
      m.weights.insert(m.weights.end(), {1.0f, 0.0f, 0.0f, 0.0f});
    }
  }
  for (int r = 0; r + 1 < rings; ++r)
    for (int s = 0; s < seg; ++s) {
      uint32_t a = uint32_t(r * seg + s), b = uint32_t(r * seg + (s + 1) % seg);
      m.idx.insert(m.idx.end(), {a, b + seg, b, a, a + seg, b + seg});
    }
  return m;
}

int main() {
  Mesh c = cylinder(64, 121);
  int32_t parents[3] = {-1, 0, 1};
  float ibm[48] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                   1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1,
                   1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -2, 0, 1};
  GcsRig* rig = gcs_rig_create(c.pos.data(), nullptr, uint32_t(c.pos.size() / 3), c.idx.data(),
                               uint32_t(c.idx.size()), c.joints.data(), c.weights.data(), 4, parents, ibm, 3);
  if (!rig) { std::printf("rig: %s\n", gcs_last_error_message()); return 1; }
  const uint32_t K = 32, M = 25;
  GcsDeformer* d = gcs_build_classic(rig, M, K, 1.0f);
  if (!d) { std::printf("classic: %s\n", gcs_last_error_message()); return 1; }
  CHECK(gcs_classic_part_count(d) == 3, "3 parts, got %u", gcs_classic_part_count(d));
  const int32_t* parts = gcs_classic_parts(d);
  CHECK(parts[1] == 1 && parts[6] == 1 && parts[11] == 0, "parts 0, 1 resampled, 2 rigid (report: 5 int32 per part)");
  const float* out = gcs_deformer_positions(d);
  // Radii: every ring vertex of part 0 and 1 at 0.1 from the Y axis within 1 %.
  float worst = 0.0f;
  for (int p = 0; p < 2; ++p)
    for (int v = parts[5 * p + 2]; v < parts[5 * p + 2] + parts[5 * p + 3]; ++v)
      worst = std::fmax(worst, std::fabs(std::hypot(out[3 * v], out[3 * v + 2]) - 0.1f) / 0.1f);
  CHECK(worst < 0.01f, "radius error %g", double(worst));
  std::printf("radius error %.4f %%, detail loss rms %.4f %% max %.4f %% of height\n", double(worst) * 100,
              double(gcs_classic_detail_loss(d, 0)), double(gcs_classic_detail_loss(d, 1)));
  // Bend joint 1 by 90° about Z around (0, 1, 0); joint 2 follows.
  float bent[48] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                    0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 1, 1, 0, 1,
                    0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 1, 1, 0, 1};
  CHECK(gcs_deformer_deform(d, bent, 3) == 1, "deform");
  const float nx = -0.70710678f, ny = 0.70710678f;
  int shared = parts[2] + parts[3] - int(K);  // last ring of part 0 = first ring of part 1
  CHECK(shared == parts[7], "shared ring is the first of part 1 (%d vs %d)", shared, parts[7]);
  float planeErr = 0.0f;
  for (int v = shared; v < shared + int(K); ++v)
    planeErr = std::fmax(planeErr, std::fabs(out[3 * v] * nx + (out[3 * v + 1] - 1.0f) * ny));
  CHECK(planeErr < 1e-5f, "joint contour off the bisector plane by %g", double(planeErr));
  // Bulge: mid contour of part 0 (t = 0.5): radius × (1 + b · 0.5 · 1).
  int mid = parts[2] + int(K) * int((M - 1) / 2);
  float r = std::hypot(out[3 * mid], out[3 * mid + 2]);
  CHECK(std::fabs(r / 0.1f - 1.5f) < 0.01f, "bulge radius ratio %g, expected 1.5", double(r / 0.1f));
  for (uint32_t i = 0; i < 3 * gcs_deformer_vertex_count(d); ++i)
    if (!std::isfinite(out[i])) { CHECK(false, "non-finite output"); break; }
  // Errors.
  CHECK(!gcs_build_classic(rig, 1, K, 0) && gcs_last_error_code() == GCS_ERR_OUT_OF_RANGE, "contours 1");
  std::printf("error sentence: %s\n", gcs_last_error_message());
  CHECK(!gcs_build_classic(rig, 10, 1000, 0) && gcs_last_error_code() == GCS_ERR_OUT_OF_RANGE, "rays 1000");
  CHECK(!gcs_classic_set_bulge(d, -1.0f) && gcs_last_error_code() == GCS_ERR_OUT_OF_RANGE, "bulge -1");
  gcs_deformer_destroy(d);
  gcs_rig_destroy(rig);

  // Build time on a denser mesh (~ 17k vertices).
  Mesh big = cylinder(128, 133);
  rig = gcs_rig_create(big.pos.data(), nullptr, uint32_t(big.pos.size() / 3), big.idx.data(),
                       uint32_t(big.idx.size()), big.joints.data(), big.weights.data(), 4, parents, ibm, 3);
  auto t0 = std::chrono::steady_clock::now();
  d = gcs_build_classic(rig, 25, 20, 0.5f);
  auto t1 = std::chrono::steady_clock::now();
  std::printf("build on %u vertices: %.2f ms\n", gcs_rig_vertex_count(rig),
              std::chrono::duration<double, std::milli>(t1 - t0).count());
  gcs_deformer_destroy(d);
  gcs_rig_destroy(rig);
  if (failures) { std::printf("classic smoke: %d failures\n", failures); return 1; }
  std::printf("classic smoke: ok\n");
  return 0;
}
