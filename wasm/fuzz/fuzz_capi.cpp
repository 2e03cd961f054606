// libFuzzer target over the whole C API (include/gcs_skin.h), built natively with ASan and UBSan:
//   make -C wasm fuzz       (FUZZ_SECONDS=600 by default; new inputs kept in build/fuzz/corpus)
//   make -C wasm fuzz-ci    (replays wasm/fuzz/findings, then 60 s from the seeds in wasm/fuzz/corpus;
//                            fails on any finding)
// Every check below aborts: an abort, a sanitizer report or a leak is a finding. Reproduce one with
// build/fuzz/fuzz_capi FILE; GCS_FUZZ_VERBOSE=1 prints the decoded rig, settings and frames.
//
// An input decodes (FuzzedDataProvider) into a small rig: a tube along a joint chain or tree, or a
// triangle soup; mostly valid, sometimes broken in exactly one documented way (then
// gcs_rig_create must reject it with the documented error code, or accept it where the header
// says the input is fine). A valid rig gets every deformer: GCS with each criterion (fuzzed section
// count, influence width, smooth, twist, centres of rotation), classic, LBS and DQS, plus builds with out-of-range
// settings that must be rejected. The rig is then destroyed (a deformer keeps no pointer to it) and
// the deformers run through fuzzed frames of skin matrices: identity, rigid, uniform and
// non-uniform scales (0.01 … ×1e20, 1e-20), mirrors, shears, collapsed and raw matrices; GCS, LBS
// and DQS sometimes with morph targets (fuzzed influences per frame) and tangents, any deformer
// sometimes keeping its previous positions (each deform's previous = the last one's, bit for bit). Rejected calls
// (bad matrix count, null or non-finite matrices, bad morph targets or influences, bad tangents,
// set_bulge) are mixed in.
//
// Checks: every call reports its outcome through gcs_last_error_code (rejections with the
// documented code and a message); a rejected call changes nothing (output arrays bit-identical
// before and after a rejected deform or set_bulge, the rig still usable after a rejected build);
// output indices < output vertex count, index count a multiple of 3; GCS / LBS / DQS triangles are
// the rig's triangles through gcs_deformer_source_vertex; GCS sections tile the output, and the
// classic part ranges lie inside it; statistics in range; finite output for finite input; the GCS
// rest pose is bit-exact (identity skins give back the rig's positions) for every criterion, and
// welded vertices (same bind position: UV seams) get the same output; a deformer built twice from
// the same rig gives the same bits for the same frame;
// unit normals (|1 − |n|| ≤ 1e-3) where the input normal was unit (or computed by the rig): always
// for LBS and DQS (their contract covers collapsed matrices), for GCS (and classic, when every
// input normal was unit) when every skin matrix of the frame is a rotation times a positive
// diagonal scale (finite, non-degenerate); tangents alike (unit xyz where normals are, finite, the
// handedness w carried bit for bit).
//
// Value bounds: positions |x| ≤ 1e4 (morphed: ≤ 1e4 + 3 targets · influence 10 · 1e4 < 1e6) and
// skin matrix entries |m| ≤ 1e21 (scales up to 1e20 times shears of at most 3), so the exact
// deformed position of every method is below 3·1e21·1e6 + 1e21 ≈ 3e27 < 1e30, far below FLT_MAX:
// a non-finite output can only come from an intermediate overflow (e.g. squaring a 1e20 column to
// take its length), which is avoidable.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#include <fuzzer/FuzzedDataProvider.h>
#include "../include/gcs_skin.h"

namespace {

bool g_verbose = false;
std::string g_context;  // what is being checked (printed with a failure)

[[noreturn]] void failCheck(int line, const char* cond, const char* format, ...) {
  std::fprintf(stderr, "\nFUZZ CHECK FAILED (fuzz_capi.cpp:%d): %s\n  context: %s\n  ", line, cond, g_context.c_str());
  va_list args;
  va_start(args, format);
  std::vfprintf(stderr, format, args);
  va_end(args);
  std::fprintf(stderr, "\n  last error: %d \"%s\"\n", gcs_last_error_code(), gcs_last_error_message());
  std::abort();
}
#define CHECK(cond, ...)                                              \
  do {                                                                \
    if (!(cond)) failCheck(__LINE__, #cond, __VA_ARGS__);             \
  } while (0)

// Exploration only (never set by the make targets): GCS_FUZZ_ALLOW=id,id lets a run go past
// findings already reported, by id, so that it can look for others. Ids: negzero (the GCS rest
// pose turns a -0 coordinate into +0: the values are equal, the bits are not), hugeweights (no
// weights whose sum overflows a float: the rig normalises them to 0), cofactor (scales up to 1e18,
// not 1e20: the normal matrix of a non-uniform or mirrored 1e20 scale overflows), tinynormal (no
// unit-normal check for scales whose axes differ by more than 1e6: a normal of length 1e-22 or
// 1e-30 is normalised from underflowed squares, or not at all). Reproducers: wasm/fuzz/findings.
// gcs_build_gcs with its settings given one by one (the fuzzer picks each).
GcsDeformer* buildGcs(const GcsRig* rig, uint32_t sections, uint32_t criterion, float width, int smooth, int twist, int centres) {
  const GcsSettings settings{sections, criterion, width, smooth, twist, centres};
  return gcs_build_gcs(rig, &settings);
}

bool allowed(const char* id) {
  static const char* list = std::getenv("GCS_FUZZ_ALLOW");
  if (!list) return false;
  const size_t n = std::strlen(id);
  for (const char* p = std::strstr(list, id); p; p = std::strstr(p + 1, id))
    if ((p == list || p[-1] == ',') && (p[n] == '\0' || p[n] == ',')) return true;
  return false;
}

void log(const char* format, ...) {
  if (!g_verbose) return;
  va_list args;
  va_start(args, format);
  std::vfprintf(stderr, format, args);
  va_end(args);
}

constexpr float kMaxCoord = 1e4f;

// ------------------------------------------------------------------------------------------ rig

struct RigInput {
  uint32_t vertexCount = 0, indexCount = 0, jointCount = 0;
  std::vector<float> positions, normals;
  bool withNormals = false;
  std::vector<uint32_t> indices, joints;
  std::vector<float> weights;
  std::vector<int32_t> parents;
  std::vector<float> inverseBind;
  std::vector<uint8_t> unitNormal;  // per vertex: its normal was given unit, or computed by the rig
  bool allUnit = true;
  const char* generator = "";
  std::vector<uint32_t> weldOrder;  // vertices sorted by position (welded ones adjacent)
  bool samePosition(uint32_t u, uint32_t v) const {
    for (int c = 0; c < 3; ++c)
      if (!(positions[3 * size_t(u) + c] == positions[3 * size_t(v) + c])) return false;
    return true;
  }
  void sortForWelds() {
    weldOrder.resize(vertexCount);
    for (uint32_t v = 0; v < vertexCount; ++v) weldOrder[v] = v;
    std::sort(weldOrder.begin(), weldOrder.end(), [&](uint32_t u, uint32_t v) {
      for (int c = 0; c < 3; ++c) {
        const float a = positions[3 * size_t(u) + c], b = positions[3 * size_t(v) + c];
        if (a != b) return a < b;
      }
      return u < v;
    });
  }
};

double unitValue(FuzzedDataProvider& f) { return double(f.ConsumeIntegralInRange<int>(-1000, 1000)) / 1000.0; }

// A rotation (column-major 3×3, doubles) from a fuzzed quaternion; the identity when it is zero.
void fuzzRotation(FuzzedDataProvider& f, double r[9]) {
  double x = unitValue(f), y = unitValue(f), z = unitValue(f), w = unitValue(f);
  double n = std::sqrt(x * x + y * y + z * z + w * w);
  if (n < 1e-3) x = y = z = 0.0, w = 1.0, n = 1.0;
  x /= n, y /= n, z /= n, w /= n;
  const double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z),     2 * (x * z - w * y),
                       2 * (x * y - w * z),     1 - 2 * (x * x + z * z), 2 * (y * z + w * x),
                       2 * (x * z + w * y),     2 * (y * z - w * x),     1 - 2 * (x * x + y * y)};
  std::memcpy(r, m, sizeof m);
}

void identity3(double r[9]) {
  for (int i = 0; i < 9; ++i) r[i] = (i % 4 == 0) ? 1.0 : 0.0;
}

// The inverse bind matrix of a joint at centre c with bind rotation r and uniform scale s:
// B = T(c)·R·s, B⁻¹ = [Rᵀ/s | −Rᵀc/s].
void inverseBindOf(const double c[3], const double r[9], double s, float* out) {
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) out[4 * col + row] = float(r[3 * row + col] / s);  // Rᵀ/s
  for (int row = 0; row < 3; ++row) {
    double t = 0.0;
    for (int k = 0; k < 3; ++k) t += r[3 * row + k] * c[k];
    out[12 + row] = float(-t / s);
  }
  out[3] = out[7] = out[11] = 0.0f;
  out[15] = 1.0f;
}

void fuzzInverseBinds(FuzzedDataProvider& f, RigInput& in, const std::vector<double>& centres) {
  in.inverseBind.assign(size_t(in.jointCount) * 16, 0.0f);
  const int mode = f.ConsumeIntegralInRange<int>(0, 7);  // 0-4: translation only; 5, 6: rotated; 7: scaled too
  for (uint32_t j = 0; j < in.jointCount; ++j) {
    double r[9];
    identity3(r);
    double s = 1.0;
    if (mode >= 5) fuzzRotation(f, r);
    if (mode == 7) {
      static const double scales[] = {1.0, 0.01, 100.0, 0.5, 2.0};
      s = f.PickValueInArray(scales);
    }
    inverseBindOf(&centres[3 * j], r, s, &in.inverseBind[16 * size_t(j)]);
  }
}

// Normals: null (computed by the rig), unit, or arbitrary finite (0, tiny, huge components).
void fuzzNormals(FuzzedDataProvider& f, RigInput& in) {
  const int mode = f.ConsumeIntegralInRange<int>(0, 5);
  in.unitNormal.assign(in.vertexCount, 1);
  in.allUnit = true;
  if (mode <= 1) {  // null: computed, unit
    in.withNormals = false;
    return;
  }
  in.withNormals = true;
  in.normals.assign(size_t(in.vertexCount) * 3, 0.0f);
  for (uint32_t v = 0; v < in.vertexCount; ++v) {
    float* n = &in.normals[3 * size_t(v)];
    if (mode <= 3 || f.ConsumeIntegralInRange<int>(0, 3) > 0) {
      double x = unitValue(f), y = unitValue(f), z = unitValue(f);
      double len = std::sqrt(x * x + y * y + z * z);
      if (len < 1e-3) x = 0.0, y = 1.0, z = 0.0, len = 1.0;
      n[0] = float(x / len), n[1] = float(y / len), n[2] = float(z / len);
    } else {
      static const float mags[] = {0.0f, 1e-30f, 1e-20f, 1e-3f, 1.0f, 3.0f, 1e20f, 1e30f};
      for (int c = 0; c < 3; ++c) n[c] = f.PickValueInArray(mags) * (f.ConsumeBool() ? -1.0f : 1.0f);
      in.unitNormal[v] = 0;
      in.allUnit = false;
    }
  }
}

// Skin weights of one vertex: up to four (joint, weight) slots, unused slots pointing anywhere
// with weight 0 (valid: a joint id is only checked where its weight is > 0).
void setWeights(RigInput& in, uint32_t v, const uint32_t* joint, const float* weight) {
  for (int i = 0; i < 4; ++i) in.joints[4 * size_t(v) + i] = joint[i], in.weights[4 * size_t(v) + i] = weight[i];
}

// Parents: a chain, a tree (parent id below the child), a reversed chain (parent id above), or
// several roots.
void fuzzParents(FuzzedDataProvider& f, RigInput& in) {
  const uint32_t J = in.jointCount;
  in.parents.assign(J, -1);
  const int topology = f.ConsumeIntegralInRange<int>(0, 3);
  for (uint32_t j = 0; j < J; ++j) {
    if (topology == 0) in.parents[j] = int32_t(j) - 1;
    else if (topology == 1) in.parents[j] = j == 0 ? -1 : f.ConsumeIntegralInRange<int32_t>(-1, int32_t(j) - 1);
    else if (topology == 2) in.parents[j] = j + 1 < J ? int32_t(j) + 1 : -1;
    else in.parents[j] = f.ConsumeBool() || j == 0 ? -1 : f.ConsumeIntegralInRange<int32_t>(0, int32_t(j) - 1);
  }
}

// Joint centres: each joint at its parent's centre plus a bone (mostly along +Y, bent by a fuzzed
// amount, sometimes of zero length).
std::vector<double> fuzzCentres(FuzzedDataProvider& f, const RigInput& in, double scale) {
  const uint32_t J = in.jointCount;
  std::vector<double> c(size_t(J) * 3, 0.0);
  std::vector<uint8_t> done(J, 0);
  static const double bends[] = {0.0, 0.0, 0.3, 1.0, 3.0};
  const double bend = f.PickValueInArray(bends);
  for (uint32_t pass = 0; pass <= J; ++pass)
    for (uint32_t j = 0; j < J; ++j) {
      if (done[j]) continue;
      int32_t p = in.parents[j];
      if (p >= 0 && !done[p]) continue;
      double dir[3] = {bend * unitValue(f), 1.0, bend * unitValue(f)};
      double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
      double bone = f.ConsumeIntegralInRange<int>(0, 15) == 0 ? 0.0 : scale * 0.2 * f.ConsumeIntegralInRange<int>(1, 8);
      for (int k = 0; k < 3; ++k) c[3 * j + k] = (p >= 0 ? c[3 * size_t(p) + k] : scale * 0.1 * unitValue(f)) + bone * dir[k] / len;
      done[j] = 1;
    }
  return c;
}

// A tube per joint, from its centre to its first child's centre (or along its bone past a leaf),
// rings of `seg` vertices, weights ramping into the child and the parent near the ends.
void makeTube(FuzzedDataProvider& f, RigInput& in) {
  in.generator = "tube";
  in.jointCount = f.ConsumeIntegralInRange<uint32_t>(1, 6);
  fuzzParents(f, in);
  static const double scales[] = {1.0, 1.0, 0.01, 100.0, 1000.0};
  const double scale = f.PickValueInArray(scales);
  std::vector<double> centres = fuzzCentres(f, in, scale);
  const uint32_t J = in.jointCount;
  const uint32_t seg = f.ConsumeIntegralInRange<uint32_t>(3, 8);
  const uint32_t rings = f.ConsumeIntegralInRange<uint32_t>(2, 5);
  const int profile = f.ConsumeIntegralInRange<int>(0, 3);  // 0 hard, 1 ramp, 2 even split at the joint, 3 fuzzed
  const bool caps = f.ConsumeBool();
  const double radius = scale * 0.02 * f.ConsumeIntegralInRange<int>(1, 10);
  std::vector<int32_t> firstChild(J, -1);
  for (uint32_t j = J; j-- > 0;)
    if (in.parents[j] >= 0) firstChild[in.parents[j]] = int32_t(j);
  const uint32_t perJoint = rings * seg + (caps ? 1 : 0);
  in.vertexCount = J * perJoint;
  in.positions.assign(size_t(in.vertexCount) * 3, 0.0f);
  in.joints.assign(size_t(in.vertexCount) * 4, 0);
  in.weights.assign(size_t(in.vertexCount) * 4, 0.0f);
  for (uint32_t j = 0; j < J; ++j) {
    const double* a = &centres[3 * j];
    double b[3];
    int32_t child = firstChild[j];
    if (child >= 0) {
      for (int k = 0; k < 3; ++k) b[k] = centres[3 * size_t(child) + k];
    } else {
      int32_t p = in.parents[j];
      double d[3] = {0.0, scale * 0.5, 0.0};
      if (p >= 0)
        for (int k = 0; k < 3; ++k) d[k] = a[k] - centres[3 * size_t(p) + k];
      for (int k = 0; k < 3; ++k) b[k] = a[k] + d[k];
    }
    double axis[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double len = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    if (len < 1e-9) axis[0] = 0.0, axis[1] = 1.0, axis[2] = 0.0;
    else
      for (double& x : axis) x /= len;
    double u[3] = {axis[1], -axis[0], 0.0};
    if (std::fabs(axis[2]) > 0.9) u[0] = 0.0, u[1] = axis[2], u[2] = -axis[1];
    double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double& x : u) x /= ul;
    double w[3] = {axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2], axis[0] * u[1] - axis[1] * u[0]};
    const uint32_t base = j * perJoint;
    for (uint32_t r = 0; r < rings; ++r) {
      const double t = double(r) / double(rings - 1);
      for (uint32_t s = 0; s < seg; ++s) {
        const uint32_t v = base + r * seg + s;
        const double ang = 2.0 * 3.14159265358979 * double(s) / double(seg);
        const double jitter = f.ConsumeIntegralInRange<int>(0, 7) == 0 ? 0.3 * unitValue(f) : 0.0;
        for (int k = 0; k < 3; ++k)
          in.positions[3 * size_t(v) + k] =
              float(a[k] + t * (b[k] - a[k]) + radius * (1.0 + jitter) * (std::cos(ang) * u[k] + std::sin(ang) * w[k]));
        uint32_t jt[4] = {j, child >= 0 ? uint32_t(child) : j, in.parents[j] >= 0 ? uint32_t(in.parents[j]) : j,
                          f.ConsumeIntegral<uint32_t>()};
        float wt[4] = {1.0f, 0.0f, 0.0f, 0.0f};
        if (profile == 1) {
          wt[1] = t > 0.5 ? float(t - 0.5) : 0.0f;
          wt[2] = t < 0.5 ? float(0.5 - t) : 0.0f;
        } else if (profile == 2) {
          if (r == rings - 1 && child >= 0) wt[0] = wt[1] = 0.5f;
        } else if (profile == 3) {
          for (int i = 0; i < 3; ++i) wt[i] = float(f.ConsumeIntegralInRange<int>(0, 8)) / 8.0f;
          if (!(wt[0] + wt[1] + wt[2] > 0.0f)) wt[0] = 1.0f;
        }
        setWeights(in, v, jt, wt);
      }
    }
    if (caps) {
      const uint32_t v = base + rings * seg;
      for (int k = 0; k < 3; ++k) in.positions[3 * size_t(v) + k] = float(b[k]);
      uint32_t jt[4] = {j, 0, 0, 0};
      float wt[4] = {1.0f, 0.0f, 0.0f, 0.0f};
      setWeights(in, v, jt, wt);
    }
    for (uint32_t r = 0; r + 1 < rings; ++r)
      for (uint32_t s = 0; s < seg; ++s) {
        uint32_t p0 = base + r * seg + s, p1 = base + r * seg + (s + 1) % seg;
        in.indices.insert(in.indices.end(), {p0, p1, p1 + seg, p0, p1 + seg, p0 + seg});
      }
    if (caps)
      for (uint32_t s = 0; s < seg; ++s)
        in.indices.insert(in.indices.end(), {base + (rings - 1) * seg + s, base + (rings - 1) * seg + (s + 1) % seg,
                                             base + rings * seg});
  }
  fuzzInverseBinds(f, in, centres);
}

// A triangle soup: a few vertices on a coarse grid, random triangles, random weights.
void makeSoup(FuzzedDataProvider& f, RigInput& in) {
  in.generator = "soup";
  in.vertexCount = f.ConsumeIntegralInRange<uint32_t>(1, 40);
  in.jointCount = f.ConsumeIntegralInRange<uint32_t>(1, 8);
  fuzzParents(f, in);
  static const float scales[] = {1.0f, 0.01f, 100.0f, kMaxCoord / 127.0f * 127.0f};
  const float scale = f.PickValueInArray(scales);
  in.positions.resize(size_t(in.vertexCount) * 3);
  for (float& x : in.positions) x = float(f.ConsumeIntegralInRange<int>(-127, 127)) / 127.0f * scale;
  const uint32_t T = f.ConsumeIntegralInRange<uint32_t>(1, 48);
  for (uint32_t i = 0; i < 3 * T; ++i) in.indices.push_back(f.ConsumeIntegralInRange<uint32_t>(0, in.vertexCount - 1));
  in.joints.assign(size_t(in.vertexCount) * 4, 0);
  in.weights.assign(size_t(in.vertexCount) * 4, 0.0f);
  for (uint32_t v = 0; v < in.vertexCount; ++v) {
    uint32_t jt[4];
    float wt[4];
    for (int i = 0; i < 4; ++i) {
      jt[i] = f.ConsumeIntegralInRange<uint32_t>(0, in.jointCount - 1);
      int q = f.ConsumeIntegralInRange<int>(-3, 16);
      wt[i] = q <= 0 ? 0.0f : float(q) / 16.0f;
    }
    if (!(wt[0] + wt[1] + wt[2] + wt[3] > 0.0f)) wt[0] = 1.0f;
    setWeights(in, v, jt, wt);
  }
  std::vector<double> centres(size_t(in.jointCount) * 3);
  for (double& c : centres) c = double(f.ConsumeIntegralInRange<int>(-127, 127)) / 127.0 * scale;
  fuzzInverseBinds(f, in, centres);
}

// Tweaks the header allows (the rig must still be accepted): -0 coordinates, the same joint twice
// in a vertex, an unused slot pointing at a joint out of range, tiny or huge (finite) weights.
void fuzzValidTweaks(FuzzedDataProvider& f, RigInput& in) {
  const int tweak = f.ConsumeIntegralInRange<int>(0, 7);
  if (in.vertexCount == 0) return;
  const uint32_t v = f.ConsumeIntegralInRange<uint32_t>(0, in.vertexCount - 1);
  switch (tweak) {
    case 0:  // -0 for every zero coordinate (a mirror plane in a glTF)
      for (float& x : in.positions)
        if (x == 0.0f) x = -0.0f;
      break;
    case 1:  // a -0 coordinate on one vertex
      in.positions[3 * size_t(v) + f.ConsumeIntegralInRange<int>(0, 2)] = -0.0f;
      break;
    case 2:  // the same joint listed twice
      in.joints[4 * size_t(v) + 1] = in.joints[4 * size_t(v)];
      in.weights[4 * size_t(v) + 1] = 0.5f;
      break;
    case 3:  // an unused slot (weight 0) naming a joint out of range
      for (int i = 3; i >= 0; --i)
        if (in.weights[4 * size_t(v) + i] == 0.0f) {
          in.joints[4 * size_t(v) + i] = in.jointCount + f.ConsumeIntegral<uint16_t>();
          break;
        }
      break;
    case 4: {  // tiny or huge (finite) weights: they are normalised on copy
      static const float mult[] = {1e-30f, 1e-40f, 1e30f, 1e38f, FLT_MAX};
      float m = f.PickValueInArray(mult);
      if (m > 1e30f && allowed("hugeweights")) m = 1e30f;
      const bool all = f.ConsumeBool();
      for (uint32_t u = all ? 0 : v; u < (all ? in.vertexCount : v + 1); ++u)
        for (int i = 0; i < 4; ++i) {
          float& w = in.weights[4 * size_t(u) + i];
          w = w > 0.0f ? (m == FLT_MAX ? FLT_MAX : w * m) : 0.0f;
        }
      break;
    }
    case 5: {  // UV seams: copies of a few vertices at the same position (own normal and weights),
               // some triangles re-pointed to the copies
      const uint32_t copies = f.ConsumeIntegralInRange<uint32_t>(1, 4);
      for (uint32_t c = 0; c < copies; ++c) {
        const uint32_t src = f.ConsumeIntegralInRange<uint32_t>(0, in.vertexCount - 1), dst = in.vertexCount++;
        for (int k = 0; k < 3; ++k) in.positions.push_back(in.positions[3 * size_t(src) + k]);
        for (int k = 0; k < 4; ++k) in.joints.push_back(in.joints[4 * size_t(src) + k]);
        for (int k = 0; k < 4; ++k) in.weights.push_back(in.weights[4 * size_t(src) + k]);
        if (f.ConsumeBool()) {  // other weights on the copy
          in.weights[4 * size_t(dst)] += 0.25f;
          in.joints[4 * size_t(dst) + 3] = f.ConsumeIntegralInRange<uint32_t>(0, in.jointCount - 1);
          in.weights[4 * size_t(dst) + 3] = 0.5f;
        }
        for (uint32_t& i : in.indices)
          if (i == src && f.ConsumeBool()) i = dst;
      }
      break;
    }
    default:
      break;
  }
}

// One deliberate break; returns the error code the header promises for it (GCS_OK: none).
GcsError fuzzBreak(FuzzedDataProvider& f, RigInput& in, const float*& pos, const float*& nrm, const uint32_t*& idx,
                   const uint32_t*& jts, const float*& wts, const int32_t*& par, const float*& ibm,
                   uint32_t& vertexCount, uint32_t& indexCount, uint32_t& jointCount, uint32_t& influences) {
  const int kind = f.ConsumeIntegralInRange<int>(0, 20);
  const uint32_t v = f.ConsumeIntegralInRange<uint32_t>(0, in.vertexCount - 1);
  const uint32_t j = f.ConsumeIntegralInRange<uint32_t>(0, in.jointCount - 1);
  static const float nonFinite[] = {NAN, INFINITY, -INFINITY};
  log("break %d (v %u, j %u)\n", kind, v, j);
  switch (kind) {
    case 0: pos = nullptr; return GCS_ERR_INVALID_ARGUMENT;
    case 1: {
      switch (f.ConsumeIntegralInRange<int>(0, 4)) {
        case 0: idx = nullptr; break;
        case 1: jts = nullptr; break;
        case 2: wts = nullptr; break;
        case 3: par = nullptr; break;
        default: ibm = nullptr; break;
      }
      return GCS_ERR_INVALID_ARGUMENT;
    }
    case 2: vertexCount = 0; return GCS_ERR_NO_SKIN;
    case 3: jointCount = 0; return GCS_ERR_NO_SKIN;
    case 4: indexCount = 0; return GCS_ERR_NO_SKIN;
    case 5: indexCount -= f.ConsumeIntegralInRange<uint32_t>(1, 2); return indexCount ? GCS_ERR_LENGTH_MISMATCH : GCS_ERR_NO_SKIN;
    case 6: vertexCount = GCS_MAX_VERTICES + 1; return GCS_ERR_OUT_OF_RANGE;
    case 7: jointCount = GCS_MAX_JOINTS + 1; return GCS_ERR_OUT_OF_RANGE;
    case 8: in.positions[3 * size_t(v) + f.ConsumeIntegralInRange<int>(0, 2)] = f.PickValueInArray(nonFinite); return GCS_ERR_NON_FINITE;
    case 9:
      if (!nrm) return GCS_OK;
      in.normals[3 * size_t(v) + f.ConsumeIntegralInRange<int>(0, 2)] = f.PickValueInArray(nonFinite);
      return GCS_ERR_NON_FINITE;
    case 10: in.inverseBind[16 * size_t(j) + f.ConsumeIntegralInRange<int>(0, 15)] = f.PickValueInArray(nonFinite); return GCS_ERR_NON_FINITE;
    case 11:
      in.indices[f.ConsumeIntegralInRange<uint32_t>(0, indexCount - 1)] = in.vertexCount + f.ConsumeIntegral<uint16_t>();
      return GCS_ERR_INDEX_OUT_OF_RANGE;
    case 12: {
      static const int32_t bad[] = {-2, INT32_MIN};
      const int c = f.ConsumeIntegralInRange<int>(0, 2);
      in.parents[j] = c == 0 ? int32_t(j) : c == 1 ? int32_t(in.jointCount + f.ConsumeIntegral<uint8_t>()) : f.PickValueInArray(bad);
      return GCS_ERR_JOINT_OUT_OF_RANGE;
    }
    case 13: {  // a cycle: j's parent becomes one of its descendants (or itself through a 2-cycle)
      if (in.jointCount < 2) return GCS_OK;
      uint32_t a = j, b = (j + 1) % in.jointCount;
      in.parents[a] = int32_t(b);
      in.parents[b] = int32_t(a);
      return GCS_ERR_JOINT_OUT_OF_RANGE;
    }
    case 14: in.weights[4 * size_t(v) + f.ConsumeIntegralInRange<int>(0, 3)] = -0.25f; return GCS_ERR_BAD_WEIGHTS;
    case 15:
      for (int i = 0; i < 4; ++i) in.weights[4 * size_t(v) + i] = 0.0f;
      return GCS_ERR_BAD_WEIGHTS;
    case 16: in.weights[4 * size_t(v) + f.ConsumeIntegralInRange<int>(0, 3)] = f.PickValueInArray(nonFinite); return GCS_ERR_NON_FINITE;
    case 17: {
      int i = f.ConsumeIntegralInRange<int>(0, 3);
      in.joints[4 * size_t(v) + i] = in.jointCount + f.ConsumeIntegral<uint16_t>();
      in.weights[4 * size_t(v) + i] = 0.5f;
      return GCS_ERR_JOINT_OUT_OF_RANGE;
    }
    case 18:
      for (int i = 0; i < 16; ++i) in.inverseBind[16 * size_t(j) + i] = i == 15 ? f.ConsumeIntegralInRange<int>(0, 1) : 0.0f;
      return GCS_ERR_DEGENERATE;  // finite but not invertible
    case 19: influences = f.ConsumeBool() ? 0 : GCS_MAX_INFLUENCES + 1 + f.ConsumeIntegral<uint8_t>(); return GCS_ERR_OUT_OF_RANGE;
    default:
      for (uint32_t u = 0; u < in.vertexCount; ++u)
        for (int c = 0; c < 3; ++c) in.positions[3 * size_t(u) + c] = in.positions[c];
      return GCS_ERR_DEGENERATE;
  }
}

// ------------------------------------------------------------------------------------------ frames

// Skin matrix magnitudes: 1e±20 included (see the bounds at the top).
double fuzzScale(FuzzedDataProvider& f) {
  static const double s[] = {1.0, 100.0, 0.01, 1e20, 1e-20, 1e10, 1e-10, 0.0 /* random */};
  double v = f.PickValueInArray(s);
  if (v > 1e18 && allowed("cofactor")) v = 1e18;
  return v == 0.0 ? 0.25 + 0.25 * f.ConsumeIntegralInRange<int>(0, 12) : v;
}

// One skin matrix (16 floats). Returns true when it is "nice": a rotation times a positive
// diagonal scale plus a translation (finite and non-degenerate).
bool fuzzMatrix(FuzzedDataProvider& f, float* out, float coordScale) {
  const int kind = f.ConsumeIntegralInRange<int>(0, 10);
  double r[9], k[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, t[3] = {0, 0, 0};
  identity3(r);
  bool nice = true;
  if (kind >= 1 && kind != 7) fuzzRotation(f, r);
  if (kind >= 1 && kind != 7) {
    static const double tmag[] = {0.0, 1.0, 1.0, 1e20, 1e-20};
    const double m = f.PickValueInArray(tmag);  // 1: within the model's size
    for (double& x : t) x = m * unitValue(f) * (m == 1.0 ? double(coordScale) : 1.0);
  }
  switch (kind) {
    case 2: {  // uniform scale
      const double s = fuzzScale(f);
      k[0] = k[4] = k[8] = s;
      break;
    }
    case 3: {  // non-uniform positive scale
      k[0] = fuzzScale(f), k[4] = fuzzScale(f), k[8] = fuzzScale(f);
      const double hi = std::fmax(k[0], std::fmax(k[4], k[8])), lo = std::fmin(k[0], std::fmin(k[4], k[8]));
      if (hi > 1e6 * lo && allowed("tinynormal")) nice = false;
      break;
    }
    case 4: {  // mirror
      const double s = fuzzScale(f);
      k[0] = -s, k[4] = f.ConsumeBool() ? -s : s, k[8] = f.ConsumeBool() ? -s : s;
      nice = false;
      break;
    }
    case 5: {  // shear
      const double s = fuzzScale(f);
      k[3] = 2.0 * unitValue(f), k[6] = 2.0 * unitValue(f), k[7] = 2.0 * unitValue(f);
      for (double& x : k) x *= s;
      nice = false;
      break;
    }
    case 6: {  // collapsed: zero, or flattened to a line or a plane
      const int z = f.ConsumeIntegralInRange<int>(0, 7);
      for (int a = 0; a < 3; ++a)
        if (z & (1 << a)) k[4 * a] = 0.0;
      if (z == 0) k[0] = k[4] = k[8] = 0.0;
      nice = false;
      break;
    }
    case 7: {  // raw entries, the bottom row too
      static const double mag[] = {0.0, 1e-20, 1.0, 10.0, 1e20};
      const double cap = allowed("cofactor") ? 1e18 : 1e20;
      for (int i = 0; i < 16; ++i) out[i] = float(std::fmin(f.PickValueInArray(mag), cap) * unitValue(f));
      if (f.ConsumeBool()) out[3] = out[7] = out[11] = 0.0f, out[15] = 1.0f;
      return false;
    }
    case 8: {  // tiny or huge everything (a cm/km rig): rotation and translation ×s
      const double s = fuzzScale(f);
      k[0] = k[4] = k[8] = s;
      for (double& x : t) x *= s;
      break;
    }
    default:
      break;
  }
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) {
      double v = 0.0;
      for (int i = 0; i < 3; ++i) v += r[3 * i + row] * k[3 * c + i];
      out[4 * c + row] = float(v);
    }
  for (int row = 0; row < 3; ++row) out[12 + row] = float(t[row]);
  out[3] = out[7] = out[11] = 0.0f;
  out[15] = 1.0f;
  return nice;
}

struct Frame {
  std::vector<float> skin;
  bool nice = true;
  bool identity = false;
};

Frame fuzzFrame(FuzzedDataProvider& f, uint32_t J, float coordScale) {
  Frame fr;
  fr.skin.assign(size_t(J) * 16, 0.0f);
  const int mode = f.ConsumeIntegralInRange<int>(0, 3);  // 0: one matrix for all joints; else per joint
  for (uint32_t j = 0; j < J; ++j) {
    if (mode == 0 && j > 0) {
      std::memcpy(&fr.skin[16 * size_t(j)], &fr.skin[0], 16 * sizeof(float));
      continue;
    }
    fr.nice = fuzzMatrix(f, &fr.skin[16 * size_t(j)], coordScale) && fr.nice;
  }
  if (g_verbose)
    for (uint32_t j = 0; j < J; ++j) {
      log("frame%s: joint %u skin", fr.nice ? " (nice)" : "", j);
      for (int k = 0; k < 16; ++k) log(" %.9g", double(fr.skin[16 * size_t(j) + k]));
      log("\n");
    }
  // A composed matrix can overflow float while being built here: the frame must be finite input
  // (non-finite input is the rejection path, fuzzed apart), so such entries become 0.
  for (float& x : fr.skin)
    if (!std::isfinite(x)) x = 0.0f, fr.nice = false;
  return fr;
}

Frame identityFrame(uint32_t J) {
  Frame fr;
  fr.identity = true;
  fr.skin.assign(size_t(J) * 16, 0.0f);
  for (uint32_t j = 0; j < J; ++j)
    for (int i = 0; i < 4; ++i) fr.skin[16 * size_t(j) + 5 * i] = 1.0f;
  return fr;
}

// ------------------------------------------------------------------------------------------ deformers

struct Built {
  GcsDeformer* d = nullptr;
  uint32_t kind = 0;
  std::string label;
  float* positions = nullptr;
  float* normals = nullptr;
  bool keepPrevious = false;        // keep_previous_positions: positions alternate between two arrays
  float* tangents = nullptr;        // set_tangents: the output, and the w of each rig vertex
  std::vector<float> tangentW;
  uint32_t vertexCount = 0;
  uint32_t sections = 0;  // GCS
  std::vector<uint32_t> outputOf;  // GCS, LBS, DQS: the output vertex of each rig vertex
  uint32_t a = 0, c = 0;           // build settings (GCS: sections, criterion; classic: contours, rays)
  float w = 0.0f;                  // GCS: influence width; classic: bulge
  int smooth = 0, twist = 0, centres = 0;
  GcsDeformer* rebuild(const GcsRig* rig) const {
    switch (kind) {
      case GCS_KIND_GCS: return buildGcs(rig, a, c, w, smooth, twist, centres);
      case GCS_KIND_CLASSIC: return gcs_build_classic(rig, a, c, w);
      case GCS_KIND_LBS: return gcs_build_lbs(rig);
      default: return gcs_build_dqs(rig);
    }
  }
};

void checkOk(const char* what) {
  CHECK(gcs_last_error_code() == GCS_OK, "%s succeeded but the error code is not GCS_OK", what);
  CHECK(gcs_last_error_message()[0] == '\0', "%s succeeded but the error message is not empty", what);
}

void checkRejected(const char* what, bool (*expected)(int)) {
  const int code = gcs_last_error_code();
  CHECK(code != GCS_OK, "%s was rejected with GCS_OK", what);
  CHECK(expected(code), "%s was rejected with an unexpected code %d", what, code);
  CHECK(gcs_last_error_message()[0] != '\0', "%s was rejected without a message", what);
}

bool finiteArray(const float* a, size_t n, size_t& bad) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(a[i])) {
      bad = i;
      return false;
    }
  return true;
}

// Structure checks of a freshly built deformer against its rig.
void checkStructure(Built& b, const RigInput& in) {
  GcsDeformer* d = b.d;
  const uint32_t N = gcs_deformer_vertex_count(d);
  b.vertexCount = N;
  b.positions = gcs_deformer_positions(d);
  b.normals = gcs_deformer_normals(d);
  CHECK(gcs_deformer_kind(d) == b.kind, "kind %u, expected %u", gcs_deformer_kind(d), b.kind);
  CHECK(N > 0, "no output vertices");
  CHECK(b.positions && b.normals, "null output arrays");
  const uint32_t I = gcs_deformer_index_count(d);
  const uint32_t* idx = gcs_deformer_indices(d);
  CHECK(I % 3 == 0 && I > 0, "index count %u", I);
  CHECK(idx != nullptr, "null indices");
  for (uint32_t i = 0; i < I; ++i) CHECK(idx[i] < N, "index %u = %u >= output vertex count %u", i, idx[i], N);
  const uint32_t* src = gcs_deformer_source_vertex(d);
  // Unknown statistics: NaN, no error.
  CHECK(std::isnan(gcs_deformer_stat(d, 4)) && std::isnan(gcs_deformer_stat(d, 0xffffffffu)), "unknown stat not NaN");
  const float statSections = gcs_deformer_stat(d, GCS_STAT_SECTIONS), statParts = gcs_deformer_stat(d, GCS_STAT_PARTS);
  if (b.kind == GCS_KIND_GCS || b.kind == GCS_KIND_LBS || b.kind == GCS_KIND_DQS) {
    CHECK(N == in.vertexCount, "output vertex count %u, rig %u", N, in.vertexCount);
    CHECK(I == in.indexCount, "index count %u, rig %u", I, in.indexCount);
    CHECK(src != nullptr, "null source vertices");
    std::vector<uint8_t> seen(N, 0);
    b.outputOf.assign(N, 0);
    for (uint32_t o = 0; o < N; ++o) {
      CHECK(src[o] < in.vertexCount, "source vertex %u of output %u out of range", src[o], o);
      CHECK(!seen[src[o]], "rig vertex %u appears twice in the output", src[o]);
      seen[src[o]] = 1;
      b.outputOf[src[o]] = o;
      if (b.kind != GCS_KIND_GCS) CHECK(src[o] == o, "LBS/DQS output %u comes from rig vertex %u", o, src[o]);
    }
    for (uint32_t i = 0; i < I; ++i)
      CHECK(src[idx[i]] == in.indices[i], "output triangle index %u: rig vertex %u, the rig's triangle has %u", i,
            src[idx[i]], in.indices[i]);
    CHECK(gcs_classic_part_count(d) == 0 && gcs_classic_parts(d) == nullptr && !gcs_classic_contour_of_vertex(d) &&
              !gcs_classic_source_of_vertex(d), "classic report on a non-classic deformer");
    CHECK(std::isnan(gcs_classic_detail_loss(d, 0)), "classic detail loss on a non-classic deformer");
    CHECK(gcs_classic_set_bulge(d, 1.0f) == 0, "set_bulge accepted on a non-classic deformer");
    checkRejected("set_bulge on a non-classic deformer", [](int c) { return c == GCS_ERR_INVALID_ARGUMENT; });
  }
  if (b.kind == GCS_KIND_LBS || b.kind == GCS_KIND_DQS) {
    CHECK(statSections == 0.0f && statParts == 0.0f && gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SHARE) == 0.0f &&
              gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SECTIONS) == 0.0f,
          "LBS/DQS stats %g %g", double(statSections), double(statParts));
    CHECK(!gcs_gcs_section_of_vertex(d) && !gcs_gcs_section_info(d) && !gcs_gcs_section_matrices(d) &&
              !gcs_gcs_section_influences(d) && !gcs_gcs_section_centres(d),
          "GCS introspection on LBS/DQS");
  }
  if (b.kind == GCS_KIND_GCS) {
    // Smooth weights nodes: up to three per welded vertex (a three-joint vertex's lattice cell), and a
    // node only blended towards holds none.
    const bool nodes = b.c == GCS_CRITERION_WEIGHTS && b.smooth != 0;
    CHECK(statSections >= 1.0f && statSections <= float(nodes ? 3 * N : N) && statSections == std::floor(statSections),
          "section count %g (vertices %u)", double(statSections), N);
    CHECK(statParts >= 1.0f && statParts <= float(in.jointCount) && statParts == std::floor(statParts), "part count %g",
          double(statParts));
    const uint32_t S = uint32_t(statSections);
    b.sections = S;
    const uint32_t* sov = gcs_gcs_section_of_vertex(d);
    const float* info = gcs_gcs_section_info(d);
    CHECK(sov && info && gcs_gcs_section_matrices(d), "null GCS introspection");
    uint32_t next = 0;
    for (uint32_t s = 0; s < S; ++s) {
      const float* e = &info[8 * size_t(s)];
      CHECK(e[0] == float(next), "section %u starts at %g, the previous ended at %u", s, double(e[0]), next);
      CHECK(e[1] >= (nodes ? 0.0f : 1.0f) && e[1] == std::floor(e[1]) && double(e[0]) + double(e[1]) <= double(N),
            "section %u range [%g, +%g) outside the output (%u vertices)", s, double(e[0]), double(e[1]), N);
      CHECK(e[2] >= 0.0f && e[2] < float(in.jointCount) && e[2] == std::floor(e[2]), "section %u part %g", s, double(e[2]));
      CHECK(e[3] == -1.0f || (e[3] >= 0.0f && e[3] < float(in.jointCount) && e[3] == std::floor(e[3])),
            "section %u distal %g", s, double(e[3]));
      CHECK(e[4] == 0.0f || e[4] == 1.0f || e[4] == 2.0f, "section %u kind %g", s, double(e[4]));
      CHECK(std::isfinite(e[5]) && std::isfinite(e[6]) && std::isfinite(e[7]), "section %u t/alpha/beta not finite", s);
      for (uint32_t o = uint32_t(e[0]); o < uint32_t(e[0] + e[1]); ++o)
        CHECK(sov[o] == s, "output vertex %u in section %u's range says section %u", o, s, sov[o]);
      next = uint32_t(e[0] + e[1]);
    }
    CHECK(next == N, "sections cover %u of %u output vertices", next, N);
  }
  if (b.kind == GCS_KIND_CLASSIC) {
    CHECK(src == nullptr, "classic source vertices not null");
    CHECK(!gcs_gcs_section_of_vertex(d) && !gcs_gcs_section_info(d) && !gcs_gcs_section_matrices(d) &&
              !gcs_gcs_section_influences(d) && !gcs_gcs_section_centres(d),
          "GCS introspection on classic");
    const uint32_t P = gcs_classic_part_count(d);
    const int32_t* parts = gcs_classic_parts(d);
    CHECK(P >= 1 && P <= in.jointCount && parts, "classic part count %u (joints %u)", P, in.jointCount);
    CHECK(statParts == float(P), "classic stat parts %g, part count %u", double(statParts), P);
    CHECK(statSections >= 0.0f && statSections == std::floor(statSections), "classic contours %g", double(statSections));
    CHECK(gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SECTIONS) == statSections, "classic adjusted sections %g, contours %g",
          double(gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SECTIONS)), double(statSections));
    int32_t prevJoint = -1;
    log("classic: %u output vertices, %g contours, parts (joint, resampled, first, count, reason):", N, double(statSections));
    for (uint32_t p = 0; p < P; ++p)
      log(" (%d %d %d %d %d)", parts[5 * p], parts[5 * p + 1], parts[5 * p + 2], parts[5 * p + 3], parts[5 * p + 4]);
    log("\n");
    for (uint32_t p = 0; p < P; ++p) {
      const int32_t* e = &parts[5 * size_t(p)];
      CHECK(e[0] > prevJoint && e[0] < int32_t(in.jointCount), "classic part %u joint %d", p, e[0]);
      prevJoint = e[0];
      CHECK(e[1] == 0 || e[1] == 1, "classic part %u resampled flag %d", p, e[1]);
      CHECK(e[4] >= GCS_CLASSIC_RESAMPLED && e[4] <= GCS_CLASSIC_OFF_SURFACE &&
                (e[1] == 1) == (e[4] == GCS_CLASSIC_RESAMPLED || e[4] == GCS_CLASSIC_TRUNK),
            "classic part %u reason %d with resampled flag %d", p, e[4], e[1]);
      CHECK(e[2] >= 0 && e[3] >= 0 && int64_t(e[2]) + e[3] <= int64_t(N), "classic part %u range [%d, +%d) outside %u",
            p, e[2], e[3], N);
    }
    const int32_t* contourOf = gcs_classic_contour_of_vertex(d);
    const int32_t* sourceOf = gcs_classic_source_of_vertex(d);
    CHECK((contourOf != nullptr && sourceOf != nullptr) || N == 0, "classic contour / source of vertex is null");
    for (uint32_t o = 0; contourOf && sourceOf && o < N; ++o) {
      CHECK(contourOf[o] >= -1 && float(contourOf[o]) < statSections, "output vertex %u on contour %d of %g", o,
            contourOf[o], double(statSections));
      // A vertex is on a contour (a ring or cap), a copy of a rig vertex, or neither (a band
      // vertex: gcs_skin.h), never both.
      CHECK(!(contourOf[o] >= 0 && sourceOf[o] >= 0) && sourceOf[o] >= -1 && sourceOf[o] < int32_t(in.vertexCount),
            "output vertex %u: contour %d, source %d", o, contourOf[o], sourceOf[o]);
    }
    for (uint32_t which = 0; which < 3; ++which) {
      const float a = gcs_classic_detail_loss(d, which), again = gcs_classic_detail_loss(d, which);
      if (which == 2) {
        CHECK(std::isnan(a), "detail loss 2 is %g, not NaN", double(a));
        continue;
      }
      CHECK(std::isfinite(a) && a >= 0.0f, "detail loss %u = %g", which, double(a));
      CHECK(std::memcmp(&a, &again, 4) == 0, "detail loss %u changes between calls", which);
    }
    CHECK(gcs_classic_detail_loss(d, 0) <= gcs_classic_detail_loss(d, 1) * 1.0001f + 1e-6f, "detail loss RMS %g > max %g",
          double(gcs_classic_detail_loss(d, 0)), double(gcs_classic_detail_loss(d, 1)));
  }
}

// After a successful deform: finite output, unit normals where promised, the GCS rest pose.
void checkFrame(Built& b, const RigInput& in, const Frame& fr, bool restExact) {
  GcsDeformer* d = b.d;
  const uint32_t N = b.vertexCount;
  CHECK(gcs_deformer_positions(d) == b.positions && gcs_deformer_normals(d) == b.normals,
        "output arrays moved");
  CHECK(gcs_deformer_vertex_count(d) == N, "vertex count changed");
  size_t bad = 0;
  CHECK(finiteArray(b.positions, size_t(N) * 3, bad), "non-finite position: vertex %zu = (%g, %g, %g)", bad / 3,
        double(b.positions[bad / 3 * 3]), double(b.positions[bad / 3 * 3 + 1]), double(b.positions[bad / 3 * 3 + 2]));
  CHECK(finiteArray(b.normals, size_t(N) * 3, bad), "non-finite normal: vertex %zu = (%g, %g, %g)", bad / 3,
        double(b.normals[bad / 3 * 3]), double(b.normals[bad / 3 * 3 + 1]), double(b.normals[bad / 3 * 3 + 2]));
  const uint32_t* src = gcs_deformer_source_vertex(d);
  bool unitCheck = b.kind == GCS_KIND_LBS || b.kind == GCS_KIND_DQS || (fr.nice && b.kind == GCS_KIND_GCS) ||
                   (fr.nice && b.kind == GCS_KIND_CLASSIC && in.allUnit);
  if (unitCheck)
    for (uint32_t o = 0; o < N; ++o) {
      if (src && !in.unitNormal[src[o]]) continue;
      const float* n = &b.normals[3 * size_t(o)];
      const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
      CHECK(std::fabs(len - 1.0) <= 1e-3, "normal of output vertex %u (rig vertex %d) has length %.9g: (%g, %g, %g)", o,
            src ? int(src[o]) : -1, len, double(n[0]), double(n[1]), double(n[2]));
    }
  if (b.tangents) {
    CHECK(gcs_deformer_tangents(d) == b.tangents, "tangent array moved");
    CHECK(finiteArray(b.tangents, size_t(N) * 4, bad), "non-finite tangent: vertex %zu", bad / 4);
    for (uint32_t o = 0; o < N; ++o) {
      const float* t = &b.tangents[4 * size_t(o)];
      CHECK(t[3] == b.tangentW[src[o]], "tangent w of output vertex %u is %g, set %g", o, double(t[3]), double(b.tangentW[src[o]]));
      if (!unitCheck) continue;
      const double len = std::sqrt(double(t[0]) * t[0] + double(t[1]) * t[1] + double(t[2]) * t[2]);
      CHECK(std::fabs(len - 1.0) <= 1e-3, "tangent of output vertex %u has length %.9g", o, len);
    }
  }
  if (b.kind == GCS_KIND_GCS && fr.identity && restExact) {
    for (uint32_t o = 0; o < N; ++o)
      for (int c = 0; c < 3; ++c) {
        const float got = b.positions[3 * size_t(o) + c], want = in.positions[3 * size_t(src[o]) + c];
        uint32_t gb, wb;
        std::memcpy(&gb, &got, 4);
        std::memcpy(&wb, &want, 4);
        // Exact means equal values: a -0 coordinate may come back +0 (-0 + +0 = +0 in the
        // affine transform); the two are the same point and render the same.
        if (gb != wb && got == want) continue;
        CHECK(gb == wb, "rest pose not exact: output vertex %u (rig vertex %u) coordinate %d is %.9g (0x%08x), rig %.9g (0x%08x)",
              o, src[o], c, double(got), gb, double(want), wb);
      }
    CHECK(gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SECTIONS) == 0.0f, "identity frame: %g adjusted sections",
          double(gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SECTIONS)));
  }
  if (b.kind == GCS_KIND_GCS) {
    // Welded vertices (same bind position) move together: a seam never opens (values, not bits:
    // +0 and -0 weld). Not under active morph targets: their deltas may move welded vertices apart.
    for (size_t k = 1; restExact && k < in.weldOrder.size(); ++k) {
      const uint32_t u = in.weldOrder[k - 1], v = in.weldOrder[k];
      if (!in.samePosition(u, v)) continue;
      const float* pu = &b.positions[3 * size_t(b.outputOf[u])];
      const float* pv = &b.positions[3 * size_t(b.outputOf[v])];
      CHECK(pu[0] == pv[0] && pu[1] == pv[1] && pu[2] == pv[2],
            "seam opened: rig vertices %u and %u share a position, outputs (%g, %g, %g) and (%g, %g, %g)", u, v,
            double(pu[0]), double(pu[1]), double(pu[2]), double(pv[0]), double(pv[1]), double(pv[2]));
    }
    const float adjusted = gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SECTIONS), share = gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SHARE);
    CHECK(adjusted >= 0.0f && adjusted <= float(b.sections) && adjusted == std::floor(adjusted), "adjusted sections %g of %u",
          double(adjusted), b.sections);
    CHECK(share == adjusted / float(b.sections), "adjusted share %g, sections %g of %u", double(share), double(adjusted),
          b.sections);
    const float* sm = gcs_gcs_section_matrices(d);
    size_t badM = 0;
    CHECK(finiteArray(sm, size_t(b.sections) * 16, badM), "non-finite section matrix %zu", badM / 16);
  }
  if (b.kind == GCS_KIND_CLASSIC) {
    CHECK(gcs_deformer_stat(d, GCS_STAT_ADJUSTED_SHARE) == 1.0f, "classic adjusted share");
  }
}

void checkGpuSections(const Built& b, const RigInput& in, const Frame& fr);  // below

// restExact: no morph influence is active, so the identity frame must give the rig's positions
// (and welded vertices must stay together).
void deformOk(Built& b, const RigInput& in, const Frame& fr, bool restExact) {
  std::vector<float> before;
  if (b.keepPrevious) before.assign(b.positions, b.positions + size_t(b.vertexCount) * 3);
  const int rc = gcs_deformer_deform(b.d, fr.skin.data(), in.jointCount);
  CHECK(rc == 1, "deform rejected valid skin matrices");
  checkOk("deform");
  if (b.keepPrevious) {
    // The last frame's positions became the previous ones, bit for bit, in the other array.
    const float* previous = gcs_deformer_previous_positions(b.d);
    CHECK(previous == b.positions && gcs_deformer_positions(b.d) != previous, "previous positions: not the last frame's array");
    CHECK(std::memcmp(previous, before.data(), before.size() * 4) == 0, "previous positions differ from the last frame's");
    b.positions = gcs_deformer_positions(b.d);
  }
  checkFrame(b, in, fr, restExact);
  if (b.kind == GCS_KIND_GCS) checkGpuSections(b, in, fr);
}

struct Snapshot {
  std::vector<float> positions, normals, tangents;
  void take(const Built& b) {
    positions.assign(b.positions, b.positions + size_t(b.vertexCount) * 3);
    normals.assign(b.normals, b.normals + size_t(b.vertexCount) * 3);
    if (b.tangents) tangents.assign(b.tangents, b.tangents + size_t(b.vertexCount) * 4);
    else tangents.clear();
  }
  bool same(const Built& b) const {
    return std::memcmp(positions.data(), b.positions, positions.size() * 4) == 0 &&
           std::memcmp(normals.data(), b.normals, normals.size() * 4) == 0 &&
           tangents.empty() == !b.tangents && (!b.tangents || std::memcmp(tangents.data(), b.tangents, tangents.size() * 4) == 0);
  }
};

// Joint j's bind-pose centre as the core takes it (rig.h: c_j = B_j · origin, B_j the inverse of the
// inverse bind matrix M_j): x with M_j x = (0, 0, 0, 1), by Gauss-Jordan elimination in double.
bool jointCentre(const float* ibm, double out[3]) {
  double a[4][5];
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) a[r][c] = ibm[4 * c + r];
    a[r][4] = r == 3 ? 1.0 : 0.0;
  }
  for (int p = 0; p < 4; ++p) {
    int best = p;
    for (int r = p + 1; r < 4; ++r)
      if (std::fabs(a[r][p]) > std::fabs(a[best][p])) best = r;
    if (a[best][p] == 0.0) return false;
    for (int c = 0; c < 5; ++c) std::swap(a[p][c], a[best][c]);
    for (int r = 0; r < 4; ++r) {
      if (r == p) continue;
      const double f = a[r][p] / a[p][p];
      for (int c = p; c < 5; ++c) a[r][c] -= f * a[p][c];
    }
  }
  for (int k = 0; k < 3; ++k) out[k] = a[k][4] / a[k][k];
  return std::isfinite(out[0]) && std::isfinite(out[1]) && std::isfinite(out[2]);
}

// The joint-level GPU path (weights criterion): the static table names each section's joints (in
// range, -1 past the last), weights ≥ 0 summing to 1, one joint exactly for a rigid core; the joint
// poses of two instances are the rows of their S_j bit for bit and a finite unit quaternion; a
// rejected call (0 instances, a wrong joint count, NaN in the last joint of the second instance)
// writes nothing. Y / axial: no table, and compute_joint_poses is refused. `skins` holds two
// instances, the second's last joint already NaN.
// The compact format of the same two instances (`full`: what compute_joint_poses wrote): the full
// format exactly, or 6 floats per joint that decode to the rotation within the tolerance of S and
// to its translation bit for bit.
void checkCompactJointPoses(GcsDeformer* d, const std::vector<float>& skins, uint32_t J, const std::vector<float>& full) {
  std::vector<float> out(full.size(), 0.0f);
  const int format = gcs_gcs_compute_joint_poses_compact(d, skins.data(), J, 2, out.data());
  checkOk("compute_joint_poses_compact");
  CHECK(format == GCS_JOINT_POSES_FULL || format == GCS_JOINT_POSES_COMPACT, "compute_joint_poses_compact returned %d", format);
  if (format == GCS_JOINT_POSES_FULL) {
    CHECK(std::memcmp(full.data(), out.data(), out.size() * 4) == 0, "the full format of compute_joint_poses_compact differs");
    return;
  }
  for (uint32_t k = 0; k < 2 * J; ++k) {
    const float* o = &out[GCS_COMPACT_FLOATS_PER_JOINT * size_t(k)];
    const float* m = &skins[16 * size_t(k)];
    uint32_t b0, b1;
    std::memcpy(&b0, &o[0], 4);
    std::memcpy(&b1, &o[1], 4);
    const uint32_t dropped = (b0 & 1u) | ((b1 & 1u) << 1);
    const double c[3] = {o[0], o[1], o[2]};
    double q[4], rest = 1.0 - (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    CHECK(rest >= 0.25 - 1e-5, "compact joint %u: dropped component %g below 1/2", k, std::sqrt(std::max(rest, 0.0)));
    for (uint32_t i = 0, n = 0; i < 4; ++i) q[i] = i == dropped ? std::sqrt(std::max(rest, 0.0)) : c[n++];
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),   // columns of R(q)
                         2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x),
                         2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row)
        CHECK(std::fabs(r[3 * col + row] - m[4 * col + row]) <= GCS_COMPACT_POSE_TOLERANCE + 1e-6, "compact joint %u: R(q)[%d][%d] %g, S has %g",
              k, col, row, r[3 * col + row], double(m[4 * col + row]));
    for (int i = 0; i < 3; ++i) CHECK(std::memcmp(&o[3 + i], &m[12 + i], 4) == 0, "compact joint %u translation %d", k, i);
  }
}

void checkJointPoses(const Built& b, const RigInput& in, std::vector<float> skins) {
  GcsDeformer* d = b.d;
  const uint32_t S = b.sections, J = in.jointCount;
  const float* table = gcs_gcs_section_influences(d);
  std::vector<float> out(size_t(J) * 32, -7.0f);
  if (b.c != GCS_CRITERION_WEIGHTS) {
    CHECK(!table && !gcs_gcs_section_centres(d), "criterion %u has a joint-level table", b.c);
    CHECK(gcs_gcs_compute_joint_poses(d, skins.data(), J, 1, out.data()) == 0, "compute_joint_poses took criterion %u", b.c);
    checkRejected("compute_joint_poses(criterion)", [](int c) { return c == GCS_ERR_INVALID_ARGUMENT; });
    return;
  }
  CHECK(table != nullptr, "no joint-level table for the weights criterion");
  const float* info = gcs_gcs_section_info(d);
  const float* centres = gcs_gcs_section_centres(d);
  CHECK(centres != nullptr, "no centres table for the weights criterion");
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t v = 0; v < in.vertexCount; ++v)
    for (int k = 0; k < 3; ++k) lo[k] = std::fmin(lo[k], in.positions[3 * v + k]), hi[k] = std::fmax(hi[k], in.positions[3 * v + k]);
  // A centre lies between its pair's pivot (the child joint's bind centre) and the surface average:
  // the bounds take the joints' centres too.
  for (uint32_t j = 0; j < J; ++j) {
    double c[3];
    if (!jointCentre(&in.inverseBind[16 * size_t(j)], c)) continue;
    for (int k = 0; k < 3; ++k) lo[k] = std::fmin(lo[k], float(c[k])), hi[k] = std::fmax(hi[k], float(c[k]));
  }
  // Float sums of centroids: a rounding allowance relative to the extent and to the distance from the origin.
  float slack = 1e-4f * std::fmax(hi[0] - lo[0], std::fmax(hi[1] - lo[1], hi[2] - lo[2]));
  for (int k = 0; k < 3; ++k) slack += 1e-5f * std::fmax(std::fabs(lo[k]), std::fabs(hi[k]));
  for (uint32_t s = 0; s < S; ++s) {
    const float* e = &table[8 * size_t(s)];
    uint32_t n = 0;
    while (n < 4 && e[n] >= 0.0f) ++n;
    CHECK(n >= 1, "section %u has no joint", s);
    double sum = 0.0;
    for (uint32_t k = 0; k < 4; ++k) {
      if (k < n) {
        CHECK(e[k] < float(J) && e[k] == std::floor(e[k]), "section %u joint %u is %g", s, k, double(e[k]));
        CHECK(std::isfinite(e[4 + k]) && e[4 + k] >= 0.0f, "section %u weight %u is %g", s, k, double(e[4 + k]));
        sum += e[4 + k];
      } else {
        CHECK(e[k] == -1.0f && e[4 + k] == 0.0f, "section %u slot %u past the last joint: (%g, %g)", s, k, double(e[k]),
              double(e[4 + k]));
      }
    }
    CHECK(std::fabs(sum - 1.0) < 1e-4, "section %u weights sum to %g", s, sum);
    CHECK((n == 1) == (info[8 * size_t(s) + 4] == 2.0f), "section %u: %u joints, kind %g", s, n, double(info[8 * size_t(s) + 4]));
    // Its centre of rotation: none for a rigid core or without centres; else a point between a joint's
    // bind centre and a weighted average of triangle centroids, so inside the bounds of both (and finite).
    const float* c = &centres[4 * size_t(s)];
    CHECK(c[3] == 0.0f || c[3] == 1.0f, "section %u centre flag %g", s, double(c[3]));
    if (c[3] == 0.0f) {
      CHECK(c[0] == 0.0f && c[1] == 0.0f && c[2] == 0.0f, "section %u without a centre has (%g, %g, %g)", s, double(c[0]),
            double(c[1]), double(c[2]));
      continue;
    }
    CHECK(b.centres != 0 && n >= 2, "section %u has a centre (centres %d, %u joints)", s, b.centres, n);
    for (int k = 0; k < 3; ++k)
      CHECK(std::isfinite(c[k]) && c[k] >= lo[k] - slack && c[k] <= hi[k] + slack,
            "section %u centre %g outside the bounds [%g, %g] (axis %d)", s, double(c[k]), double(lo[k]), double(hi[k]), k);
  }
  const size_t last = size_t(J) * 16 + 16 * size_t(J - 1) + 3;
  const float broken = skins[last];
  skins[last] = skins[3];  // both instances valid again
  CHECK(gcs_gcs_compute_joint_poses(d, skins.data(), J, 2, out.data()) == 1, "compute_joint_poses rejected a valid frame");
  checkOk("compute_joint_poses");
  for (uint32_t k = 0; k < 2 * J; ++k) {
    const float* o = &out[16 * size_t(k)];
    const float* m = &skins[16 * size_t(k)];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        CHECK(std::memcmp(&o[4 * r + c], &m[4 * c + r], 4) == 0, "joint pose %u row %d col %d: %g, S has %g", k, r, c,
              double(o[4 * r + c]), double(m[4 * c + r]));
    const double len = std::sqrt(double(o[12]) * o[12] + double(o[13]) * o[13] + double(o[14]) * o[14] + double(o[15]) * o[15]);
    CHECK(std::fabs(len - 1.0) < 1e-5, "joint pose %u quaternion length %g", k, len);
  }
  checkCompactJointPoses(d, skins, J, out);
  std::vector<float> kept(out);
  CHECK(gcs_gcs_compute_joint_poses(d, skins.data(), J, 0, out.data()) == 0, "compute_joint_poses took 0 instances");
  checkRejected("compute_joint_poses(0 instances)", [](int c) { return c == GCS_ERR_OUT_OF_RANGE; });
  CHECK(gcs_gcs_compute_joint_poses(d, skins.data(), J + 1, 1, out.data()) == 0, "compute_joint_poses took a wrong joint count");
  checkRejected("compute_joint_poses(joint count)", [](int c) { return c == GCS_ERR_LENGTH_MISMATCH; });
  skins[last] = broken;
  CHECK(gcs_gcs_compute_joint_poses(d, skins.data(), J, 2, out.data()) == 0, "compute_joint_poses took NaN");
  checkRejected("compute_joint_poses(NaN)", [](int c) { return c == GCS_ERR_NON_FINITE; });
  CHECK(std::memcmp(kept.data(), out.data(), out.size() * 4) == 0, "a rejected compute_joint_poses wrote its output");
  CHECK(gcs_gcs_compute_joint_poses_compact(d, skins.data(), J, 2, out.data()) == 0, "compute_joint_poses_compact took NaN");
  checkRejected("compute_joint_poses_compact(NaN)", [](int c) { return c == GCS_ERR_NON_FINITE; });
  CHECK(std::memcmp(kept.data(), out.data(), out.size() * 4) == 0, "a rejected compute_joint_poses_compact wrote its output");
}

// The GPU path (gcs_gcs_compute_sections): for two instances posed by this frame, the packed rows
// are the section matrices gcs_deformer_deform just used, bit for bit; the output mesh is not
// touched; a rejected call (no instances, a non-finite matrix in the second instance) writes
// nothing. Smooth blend data: other sections in range, factors in [0, 1]; null in plain mode.
void checkGpuSections(const Built& b, const RigInput& in, const Frame& fr) {
  GcsDeformer* d = b.d;
  const uint32_t S = b.sections, J = in.jointCount;
  std::vector<float> matrices(gcs_gcs_section_matrices(d), gcs_gcs_section_matrices(d) + size_t(S) * 16);
  Snapshot before;
  before.take(b);
  std::vector<float> skins(fr.skin);
  skins.insert(skins.end(), fr.skin.begin(), fr.skin.end());
  std::vector<float> out(size_t(S) * 24, -7.0f);
  CHECK(gcs_gcs_compute_sections(d, skins.data(), J, 2, out.data()) == 1, "compute_sections rejected a valid frame");
  checkOk("compute_sections");
  CHECK(before.same(b), "compute_sections changed the output mesh");
  for (uint32_t k = 0; k < 2; ++k)
    for (uint32_t i = 0; i < S; ++i)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) {
          const float got = out[(size_t(k) * S + i) * 12 + 4 * r + c], want = matrices[16 * size_t(i) + 4 * c + r];
          CHECK(std::memcmp(&got, &want, 4) == 0, "instance %u section %u row %d col %d: packed %g, deform used %g", k, i, r,
                c, double(got), double(want));
        }
  std::vector<float> kept(out);
  CHECK(gcs_gcs_compute_sections(d, skins.data(), J, 0, out.data()) == 0, "compute_sections took 0 instances");
  checkRejected("compute_sections(0 instances)", [](int c) { return c == GCS_ERR_OUT_OF_RANGE; });
  CHECK(gcs_gcs_compute_sections(d, skins.data(), J + 1, 1, out.data()) == 0, "compute_sections took a wrong joint count");
  checkRejected("compute_sections(joint count)", [](int c) { return c == GCS_ERR_LENGTH_MISMATCH; });
  skins[size_t(J) * 16 + 16 * size_t(J - 1) + 3] = NAN;
  CHECK(gcs_gcs_compute_sections(d, skins.data(), J, 2, out.data()) == 0, "compute_sections took NaN");
  checkRejected("compute_sections(NaN)", [](int c) { return c == GCS_ERR_NON_FINITE; });
  CHECK(std::memcmp(kept.data(), out.data(), out.size() * 4) == 0, "a rejected compute_sections wrote its output");
  checkJointPoses(b, in, skins);
  const uint32_t* other = gcs_gcs_blend_other(d);
  const float* factor = gcs_gcs_blend_factor(d);
  const uint32_t* third = gcs_gcs_blend_third(d);
  const uint32_t* sov = gcs_gcs_section_of_vertex(d);
  const float* thirdFactor = gcs_gcs_blend_third_factor(d);
  CHECK((other != nullptr) == (b.smooth != 0) && (factor != nullptr) == (b.smooth != 0) &&
            (third != nullptr) == (b.smooth != 0) && (thirdFactor != nullptr) == (b.smooth != 0),
        "blend data present %d, smooth %d", other != nullptr, b.smooth);
  if (other)
    for (uint32_t o = 0; o < b.vertexCount; ++o) {
      CHECK(other[o] < S, "output vertex %u blends with section %u of %u", o, other[o], S);
      CHECK(factor[o] >= 0.0f && factor[o] <= 1.0f, "output vertex %u blend factor %g", o, double(factor[o]));
      CHECK(third[o] < S, "output vertex %u blends with a third section %u of %u", o, third[o], S);
      CHECK(thirdFactor[o] >= 0.0f && factor[o] + thirdFactor[o] <= 1.0f + 1e-6f, "output vertex %u factors %g and %g", o,
            double(factor[o]), double(thirdFactor[o]));
      // A third section exists only with a second (a lattice cell); without one its factor is 0.
      CHECK(third[o] != sov[o] ? other[o] != sov[o] : thirdFactor[o] == 0.0f, "output vertex %u: third section %u, factor %g",
            o, third[o], double(thirdFactor[o]));
    }
}

// Morph targets (GCS, LBS, DQS): deltas in the rig's vertex order, the same for every deformer.
struct Morphs {
  uint32_t targets = 0;
  std::vector<float> deltas, normalDeltas;  // targets × vertices × 3
  bool withNormals = false;
  std::vector<float> influences;
  bool active() const {
    for (float w : influences)
      if (w != 0.0f) return true;
    return false;
  }
};

// A cheap pseudo-random value in [-1, 1] from a fuzzed seed (deltas for every vertex would
// otherwise take most of the input's bytes).
float hashValue(uint32_t seed, uint32_t i) {
  uint32_t h = seed * 0x9e3779b1u ^ (i + 0x7f4a7c15u) * 0x85ebca6bu;
  h ^= h >> 15, h *= 0x2c1b3c6du, h ^= h >> 12;
  return float(int32_t(h % 2001u) - 1000) / 1000.0f;
}

Morphs fuzzMorphs(FuzzedDataProvider& f, const RigInput& in, float coordScale) {
  Morphs m;
  if (f.ConsumeIntegralInRange<int>(0, 2) != 0) return m;
  m.targets = f.ConsumeIntegralInRange<uint32_t>(1, 3);
  m.withNormals = f.ConsumeBool();
  const size_t n = size_t(in.vertexCount) * 3;
  m.deltas.resize(n * m.targets);
  m.normalDeltas.resize(m.withNormals ? n * m.targets : 0);
  static const float mags[] = {0.0f, 0.01f, 0.3f, 1.0f};
  static const float nmags[] = {0.0f, 0.1f, 1.0f, 2.0f, 1e-20f, 1e20f};
  for (uint32_t t = 0; t < m.targets; ++t) {
    const float mag = f.PickValueInArray(mags) * coordScale, nmag = f.PickValueInArray(nmags);
    const uint32_t seed = f.ConsumeIntegral<uint32_t>();
    for (size_t i = 0; i < n; ++i) {
      m.deltas[t * n + i] = mag * hashValue(seed, uint32_t(i));
      if (m.withNormals) m.normalDeltas[t * n + i] = nmag * hashValue(seed + 1, uint32_t(i));
    }
  }
  m.influences.assign(m.targets, 0.0f);
  return m;
}

void fuzzInfluences(FuzzedDataProvider& f, Morphs& m) {
  static const float values[] = {0.0f, 0.0f, 1.0f, 0.5f, -1.0f, 10.0f, 0.25f};
  for (float& w : m.influences) w = f.PickValueInArray(values);
}

// A call that must be rejected: deform with a wrong matrix count, null matrices, NaN or infinity in
// a matrix; bad morph targets or influences; set_bulge on the wrong deformer or with a bad gain.
// It must change nothing.
void deformOk(Built& b, const RigInput& in, const Frame& fr, bool restExact);

void rejectedDeform(FuzzedDataProvider& f, Built& b, const RigInput& in, const Frame& fr, const Morphs& morphs) {
  const uint32_t J = in.jointCount;
  Snapshot before;
  before.take(b);
  const int kind = f.ConsumeIntegralInRange<int>(0, 8);
  int rc = -1;
  int expected = 0;
  const bool morphable = b.kind != GCS_KIND_CLASSIC;
  const size_t n = size_t(in.vertexCount) * 3;
  if (kind >= 3 && kind <= 7 && (!morphable || kind == 3)) {  // morph targets on the classic model / a null deformer
    std::vector<float> deltas(n, 0.0f);
    rc = gcs_deformer_set_morph_targets(morphable ? nullptr : b.d, deltas.data(), nullptr, 1, in.vertexCount);
    expected = GCS_ERR_INVALID_ARGUMENT;
  } else if (kind == 4) {  // too many targets, null deltas, a wrong vertex count
    const int which = f.ConsumeIntegralInRange<int>(0, 2);
    const uint32_t targets = which == 0 ? GCS_MAX_MORPH_TARGETS + 1 : 1;
    std::vector<float> deltas(which == 0 ? n * targets : n + 3, 0.0f);  // as long as the call says
    rc = gcs_deformer_set_morph_targets(b.d, which == 1 ? nullptr : deltas.data(), nullptr, targets,
                                        which == 2 ? in.vertexCount + 1 : in.vertexCount);
    expected = which == 0 ? GCS_ERR_OUT_OF_RANGE : which == 1 ? GCS_ERR_INVALID_ARGUMENT : GCS_ERR_LENGTH_MISMATCH;
  } else if (kind == 5) {  // NaN or infinity in the deltas or normal deltas
    std::vector<float> deltas(n, 0.25f), normalDeltas(n, 0.25f);
    const bool inNormals = f.ConsumeBool();
    (inNormals ? normalDeltas : deltas)[f.ConsumeIntegralInRange<size_t>(0, n - 1)] = f.ConsumeBool() ? NAN : -INFINITY;
    rc = gcs_deformer_set_morph_targets(b.d, deltas.data(), normalDeltas.data(), 1, in.vertexCount);
    expected = GCS_ERR_NON_FINITE;
  } else if (kind == 6) {  // influences: a wrong count
    std::vector<float> w(morphs.targets + 1, 0.5f);
    rc = gcs_deformer_set_morph_influences(b.d, w.data(), morphs.targets + 1);
    expected = GCS_ERR_LENGTH_MISMATCH;
  } else if (kind == 7) {  // influences: null, or NaN
    if (morphs.targets == 0) {
      float w = 1.0f;
      rc = gcs_deformer_set_morph_influences(b.d, &w, 1);
      expected = GCS_ERR_LENGTH_MISMATCH;
    } else if (f.ConsumeBool()) {
      rc = gcs_deformer_set_morph_influences(b.d, nullptr, morphs.targets);
      expected = GCS_ERR_INVALID_ARGUMENT;
    } else {
      std::vector<float> w(morphs.targets, 0.5f);
      w[f.ConsumeIntegralInRange<size_t>(0, w.size() - 1)] = INFINITY;
      rc = gcs_deformer_set_morph_influences(b.d, w.data(), morphs.targets);
      expected = GCS_ERR_NON_FINITE;
    }
  } else if (kind == 8) {  // set_bulge on a GCS / LBS / DQS deformer, or a bad gain on the classic one
    rc = gcs_classic_set_bulge(b.d, morphable ? 1.0f : -1.0f);
    expected = morphable ? GCS_ERR_INVALID_ARGUMENT : GCS_ERR_OUT_OF_RANGE;
  } else if (kind == 9) {  // tangents on the classic model / a null deformer, or a wrong vertex count
    std::vector<float> t(size_t(in.vertexCount + 1) * 4, 0.0f);
    const bool wrongCount = morphable && f.ConsumeBool();
    rc = gcs_deformer_set_tangents(wrongCount || !morphable ? b.d : nullptr, t.data(), in.vertexCount + (wrongCount ? 1 : 0));
    expected = wrongCount ? GCS_ERR_LENGTH_MISMATCH : GCS_ERR_INVALID_ARGUMENT;
  } else if (kind == 10) {  // NaN or infinity in the tangents (the classic model refuses any)
    std::vector<float> t(size_t(in.vertexCount) * 4, 0.5f);
    t[f.ConsumeIntegralInRange<size_t>(0, t.size() - 1)] = f.ConsumeBool() ? NAN : INFINITY;
    rc = gcs_deformer_set_tangents(b.d, t.data(), in.vertexCount);
    expected = morphable ? GCS_ERR_NON_FINITE : GCS_ERR_INVALID_ARGUMENT;
  } else if (kind == 0) {
    const uint32_t count = f.ConsumeBool() ? J + 1 : J - 1;
    std::vector<float> m(std::max<size_t>(size_t(count) * 16, 1), 1.0f);
    rc = gcs_deformer_deform(b.d, m.data(), count);
    expected = GCS_ERR_LENGTH_MISMATCH;
  } else if (kind == 1) {
    rc = gcs_deformer_deform(b.d, nullptr, J);
    expected = GCS_ERR_INVALID_ARGUMENT;
  } else {
    std::vector<float> m = fr.skin;
    static const float nonFinite[] = {NAN, INFINITY, -INFINITY};
    m[f.ConsumeIntegralInRange<size_t>(0, m.size() - 1)] = f.PickValueInArray(nonFinite);
    rc = gcs_deformer_deform(b.d, m.data(), J);
    expected = GCS_ERR_NON_FINITE;
  }
  CHECK(rc == 0, "a bad call (kind %d) was accepted", kind);
  CHECK(gcs_last_error_code() == expected, "rejected call (kind %d): code %d, expected %d", kind, gcs_last_error_code(),
        expected);
  CHECK(gcs_last_error_message()[0] != '\0', "rejected call without a message");
  CHECK(before.same(b), "a rejected call (kind %d) changed the output arrays", kind);
  CHECK(gcs_deformer_positions(b.d) == b.positions && gcs_deformer_vertex_count(b.d) == b.vertexCount &&
            gcs_deformer_tangents(b.d) == b.tangents,
        "a rejected call moved the output");
  // Nothing else changed either: the previous frame again gives the same output, bit for bit.
  deformOk(b, in, fr, !morphs.active());
  CHECK(before.same(b), "after a rejected call (kind %d), the same frame gives another output", kind);
}

bool codeSections(int c) { return c == GCS_ERR_SECTION_COUNT || c == GCS_ERR_INVALID_ARGUMENT || c == GCS_ERR_OUT_OF_RANGE; }
bool codeOutOfRange(int c) { return c == GCS_ERR_OUT_OF_RANGE; }
bool codeInvalid(int c) { return c == GCS_ERR_INVALID_ARGUMENT; }
bool codeGcsValidBuild(int c) { return c == GCS_ERR_ZERO_LENGTH_BONE || c == GCS_ERR_DEGENERATE; }

uint32_t fuzzSections(FuzzedDataProvider& f) {
  static const uint32_t odd[] = {0, 1, 2, 3, 256, 257, 1000, 0xffffffffu};
  return f.ConsumeIntegralInRange<int>(0, 9) == 0 ? f.PickValueInArray(odd) : f.ConsumeIntegralInRange<uint32_t>(3, 12);
}

float fuzzWidth(FuzzedDataProvider& f) {
  static const float odd[] = {0.0f, -0.0f, -1.0f, 1.0001f, 2.0f, NAN, INFINITY, FLT_MIN, 1e-30f, 1.0f};
  static const float good[] = {1.0f, 1.0f, 0.5f, 0.25f, 0.8f};
  return f.ConsumeIntegralInRange<int>(0, 9) == 0 ? f.PickValueInArray(odd) : f.PickValueInArray(good);
}

void runRig(FuzzedDataProvider& f, RigInput& in) {
  // ---- the rig
  const bool broken = f.ConsumeIntegralInRange<int>(0, 7) == 0;
  fuzzValidTweaks(f, in);  // first: it may add vertices
  fuzzNormals(f, in);
  in.indexCount = uint32_t(in.indices.size());
  const float* pos = in.positions.data();
  const float* nrm = in.withNormals ? in.normals.data() : nullptr;
  const uint32_t* idx = in.indices.data();
  const uint32_t* jts = in.joints.data();
  const float* wts = in.weights.data();
  const int32_t* par = in.parents.data();
  const float* ibm = in.inverseBind.data();
  uint32_t vertexCount = in.vertexCount, indexCount = in.indexCount, jointCount = in.jointCount, influences = 4;
  GcsError expected = GCS_OK;
  if (broken) expected = fuzzBreak(f, in, pos, nrm, idx, jts, wts, par, ibm, vertexCount, indexCount, jointCount, influences);
  // Eight influences on a quarter of the rigs (chosen by the rig's sizes, so the seeds decode as
  // before): every other vertex's four move to slots 4..7 behind four empty slots (weight 0, a joint
  // id out of range, which the header allows), the rest keep slots 0..3 with 4..7 empty.
  std::vector<uint32_t> wideJoints;
  std::vector<float> wideWeights;
  if (influences == 4 && jts && wts && vertexCount == in.vertexCount && (in.vertexCount * 7 + in.jointCount) % 4 == 0) {
    influences = 8;
    wideJoints.assign(size_t(in.vertexCount) * 8, in.jointCount + 7);
    wideWeights.assign(size_t(in.vertexCount) * 8, 0.0f);
    for (uint32_t v = 0; v < in.vertexCount; ++v)
      for (int i = 0; i < 4; ++i) {
        const size_t to = 8 * size_t(v) + (v % 2 ? 4 : 0) + size_t(i);
        wideJoints[to] = in.joints[4 * size_t(v) + i];
        wideWeights[to] = in.weights[4 * size_t(v) + i];
      }
    jts = wideJoints.data();
    wts = wideWeights.data();
  }
  // The rig is degenerate when every vertex is at one point: the header's GCS_ERR_DEGENERATE.
  float lo[3], hi[3];
  for (int c = 0; c < 3; ++c) lo[c] = hi[c] = in.positions[c];
  for (uint32_t v = 0; v < in.vertexCount; ++v)
    for (int c = 0; c < 3; ++c)
      lo[c] = std::fmin(lo[c], in.positions[3 * size_t(v) + c]), hi[c] = std::fmax(hi[c], in.positions[3 * size_t(v) + c]);
  const float height = std::fmax(hi[0] - lo[0], std::fmax(hi[1] - lo[1], hi[2] - lo[2]));
  if (expected == GCS_OK && !(height > 0.0f)) expected = GCS_ERR_DEGENERATE;
  log("rig: %s, %u vertices, %u indices, %u joints, %u influences, normals %s, expected code %d\n", in.generator,
      in.vertexCount, in.indexCount, in.jointCount, influences, nrm ? "given" : "computed", int(expected));
  if (g_verbose) {
    for (uint32_t v = 0; v < in.vertexCount; ++v) {
      const float* p = &in.positions[3 * size_t(v)];
      log("  v%u pos (%.9g, %.9g, %.9g)", v, double(p[0]), double(p[1]), double(p[2]));
      if (in.withNormals)
        log(" nrm (%g, %g, %g)", double(in.normals[3 * size_t(v)]), double(in.normals[3 * size_t(v) + 1]),
            double(in.normals[3 * size_t(v) + 2]));
      for (int i = 0; i < 4; ++i) log(" %u:%g", in.joints[4 * size_t(v) + i], double(in.weights[4 * size_t(v) + i]));
      log("\n");
    }
    log("  indices");
    for (uint32_t i = 0; i < in.indexCount; ++i) log(" %u", in.indices[i]);
    log("\n");
    for (uint32_t j = 0; j < in.jointCount; ++j) {
      log("  joint %u parent %d inverse bind", j, in.parents[j]);
      for (int i = 0; i < 16; ++i) log(" %g", double(in.inverseBind[16 * size_t(j) + i]));
      log("\n");
    }
  }
  char ctx[160];
  std::snprintf(ctx, sizeof ctx, "rig %s: %u vertices, %u indices, %u joints, expected code %d", in.generator,
                in.vertexCount, in.indexCount, in.jointCount, int(expected));
  g_context = ctx;
  GcsRig* rig = gcs_rig_create(pos, nrm, vertexCount, idx, indexCount, jts, wts, influences, par, ibm, jointCount);
  if (expected != GCS_OK) {
    CHECK(rig == nullptr, "gcs_rig_create accepted a broken rig (expected code %d)", int(expected));
    CHECK(gcs_last_error_code() == expected, "gcs_rig_create: code %d, expected %d", gcs_last_error_code(), int(expected));
    CHECK(gcs_last_error_message()[0] != '\0', "gcs_rig_create rejected without a message");
    return;
  }
  CHECK(rig != nullptr, "gcs_rig_create rejected a valid rig");
  checkOk("gcs_rig_create");
  in.sortForWelds();
  CHECK(gcs_rig_vertex_count(rig) == in.vertexCount && gcs_rig_joint_count(rig) == in.jointCount, "rig counts");
  CHECK(gcs_rig_height(rig) == height, "rig height %g, expected %g", double(gcs_rig_height(rig)), double(height));

  // ---- deformers
  std::vector<Built> built;
  auto add = [&](GcsDeformer* d, uint32_t kind, const std::string& label, uint32_t a = 0, uint32_t c = 0, float w = 0.0f,
                 int smooth = 0, int twist = 0, int centres = 0) {
    Built b;
    b.d = d;
    b.kind = kind;
    b.label = label;
    b.a = a, b.c = c, b.w = w, b.smooth = smooth, b.twist = twist, b.centres = centres;
    g_context = std::string(ctx) + "; " + label;
    log("built: %s\n", label.c_str());
    checkStructure(b, in);
    built.push_back(b);
  };
  for (uint32_t criterion = 0; criterion < 3; ++criterion) {
    const uint32_t sections = fuzzSections(f);
    const float width = fuzzWidth(f);
    static const int flags[] = {0, 0, 1, -1, 2};
    const int smooth = f.PickValueInArray(flags), twist = f.PickValueInArray(flags), centres = f.PickValueInArray(flags);
    const bool valid = sections >= GCS_MIN_SECTIONS && sections <= GCS_MAX_SECTIONS && width > 0.0f && width <= 1.0f &&
                       smooth >= GCS_SMOOTH_BY_CRITERION && smooth <= 1 && twist >= 0 && twist <= 1 && centres >= 0 && centres <= 1;
    char label[160];
    std::snprintf(label, sizeof label, "gcs criterion %u sections %u width %g smooth %d twist %d centres %d", criterion,
                  sections, double(width), smooth, twist, centres);
    g_context = std::string(ctx) + "; " + label;
    GcsDeformer* d = buildGcs(rig, sections, criterion, width, smooth, twist, centres);
    if (!valid) {
      CHECK(d == nullptr, "gcs_build_gcs accepted out-of-range settings");
      checkRejected("gcs_build_gcs with out-of-range settings", codeSections);
      continue;
    }
    if (!d) {
      checkRejected("gcs_build_gcs", codeGcsValidBuild);
      CHECK(criterion != GCS_CRITERION_WEIGHTS, "the weights criterion rejected a valid rig");
      continue;
    }
    checkOk("gcs_build_gcs");
    const int smoothBuilt = smooth == GCS_SMOOTH_BY_CRITERION ? int(criterion == GCS_CRITERION_WEIGHTS) : smooth;
    add(d, GCS_KIND_GCS, label, sections, criterion, width, smoothBuilt, twist, centres);
  }
  {  // an unknown criterion
    const uint32_t criterion = 3 + f.ConsumeIntegral<uint8_t>() * (f.ConsumeBool() ? 1u : 0x1000000u);
    g_context = std::string(ctx) + "; unknown criterion";
    CHECK(buildGcs(rig, 6, criterion, 1.0f, 0, 0, 1) == nullptr, "criterion %u accepted", criterion);
    checkRejected("gcs_build_gcs with an unknown criterion", codeInvalid);
    CHECK(gcs_build_gcs(rig, nullptr) == nullptr, "null settings accepted");
    checkRejected("gcs_build_gcs with null settings", codeInvalid);
  }
  {
    static const uint32_t oddC[] = {0, 1, 2, 256, 257, 0xffffffffu};
    static const uint32_t oddR[] = {0, 2, 3, 256, 257, 0xffffffffu};
    static const float oddB[] = {-0.1f, 4.0f, 4.0001f, NAN, INFINITY, -0.0f, 0.0f};
    const uint32_t contours = f.ConsumeIntegralInRange<int>(0, 11) == 0 ? f.PickValueInArray(oddC)
                                                                       : f.ConsumeIntegralInRange<uint32_t>(2, 16);
    const uint32_t rays = f.ConsumeIntegralInRange<int>(0, 11) == 0 ? f.PickValueInArray(oddR)
                                                                   : f.ConsumeIntegralInRange<uint32_t>(3, 16);
    const float bulge = f.ConsumeIntegralInRange<int>(0, 7) == 0 ? f.PickValueInArray(oddB)
                                                                : float(f.ConsumeIntegralInRange<int>(0, 8)) / 2.0f;
    const bool valid = contours >= GCS_CLASSIC_MIN_CONTOURS && contours <= GCS_CLASSIC_MAX_CONTOURS &&
                       rays >= GCS_CLASSIC_MIN_RAYS && rays <= GCS_CLASSIC_MAX_RAYS && bulge >= 0.0f &&
                       bulge <= GCS_CLASSIC_MAX_BULGE;
    char label[160];
    std::snprintf(label, sizeof label, "classic contours %u rays %u bulge %g", contours, rays, double(bulge));
    g_context = std::string(ctx) + "; " + label;
    GcsDeformer* d = gcs_build_classic(rig, contours, rays, bulge);
    if (!valid) {
      CHECK(d == nullptr, "gcs_build_classic accepted out-of-range settings");
      checkRejected("gcs_build_classic with out-of-range settings", codeOutOfRange);
    } else {
      CHECK(d != nullptr, "gcs_build_classic rejected valid settings");
      checkOk("gcs_build_classic");
      add(d, GCS_KIND_CLASSIC, label, contours, rays, bulge);
    }
  }
  {
    GcsDeformer* d = gcs_build_lbs(rig);
    CHECK(d != nullptr, "gcs_build_lbs failed");
    checkOk("gcs_build_lbs");
    add(d, GCS_KIND_LBS, "lbs");
    d = gcs_build_dqs(rig);
    CHECK(d != nullptr, "gcs_build_dqs failed");
    checkOk("gcs_build_dqs");
    add(d, GCS_KIND_DQS, "dqs");
  }
  // The rig survives rejected builds unchanged.
  CHECK(gcs_rig_vertex_count(rig) == in.vertexCount && gcs_rig_joint_count(rig) == in.jointCount &&
            gcs_rig_height(rig) == height,
        "the rig changed");
  // Same input, same output: a twin of one deformer, built again from the rig, deforms a frame
  // to the same bits (catches reads of uninitialised or stale memory).
  const float coordScale = height > 0.0f ? height : 1.0f;
  {
    Built& b = built[f.ConsumeIntegralInRange<size_t>(0, built.size() - 1)];
    g_context = std::string(ctx) + "; " + b.label + "; twin";
    Built twin = b;
    twin.d = b.rebuild(rig);
    CHECK(twin.d != nullptr, "the same build failed the second time");
    checkStructure(twin, in);
    const Frame fr = fuzzFrame(f, in.jointCount, coordScale);
    deformOk(b, in, fr, true);
    deformOk(twin, in, fr, true);
    Snapshot first;
    first.take(b);
    CHECK(first.same(twin), "a deformer built twice from the same rig gives two outputs for the same frame");
    CHECK(std::memcmp(gcs_deformer_indices(b.d), gcs_deformer_indices(twin.d), 4 * size_t(gcs_deformer_index_count(b.d))) == 0,
          "a deformer built twice has two index buffers");
    gcs_deformer_destroy(twin.d);
  }
  // Deformers keep no pointer to the rig.
  gcs_rig_destroy(rig);

  // ---- morph targets (GCS, LBS, DQS)
  Morphs morphs = fuzzMorphs(f, in, coordScale);
  if (morphs.targets)
    for (Built& b : built) {
      if (b.kind == GCS_KIND_CLASSIC) continue;
      g_context = std::string(ctx) + "; " + b.label + "; set_morph_targets";
      CHECK(gcs_deformer_set_morph_targets(b.d, morphs.deltas.data(), morphs.withNormals ? morphs.normalDeltas.data() : nullptr,
                                           morphs.targets, in.vertexCount) == 1,
            "set_morph_targets rejected valid targets");
      checkOk("set_morph_targets");
    }
  log("morphs: %u targets%s\n", morphs.targets, morphs.withNormals ? " with normals" : "");

  // ---- tangents (GCS, LBS, DQS): unit directions (the rig's normals when given, else hashed), w ±1
  if (f.ConsumeBool()) {
    const uint32_t seed = f.ConsumeIntegral<uint32_t>();
    std::vector<float> tangents(size_t(in.vertexCount) * 4);
    for (uint32_t v = 0; v < in.vertexCount; ++v) {
      float* t = &tangents[4 * size_t(v)];
      for (int c = 0; c < 3; ++c) t[c] = in.withNormals ? in.normals[3 * size_t(v) + c] : hashValue(seed, 3 * v + c);
      const float len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
      if (len > 1e-3f && std::isfinite(len)) for (int c = 0; c < 3; ++c) t[c] /= len;
      else t[0] = 1.0f, t[1] = t[2] = 0.0f;
      t[3] = hashValue(seed + 7, v) < 0.0f ? -1.0f : 1.0f;
    }
    for (Built& b : built) {
      g_context = std::string(ctx) + "; " + b.label + "; set_tangents";
      if (b.kind == GCS_KIND_CLASSIC) {
        CHECK(gcs_deformer_set_tangents(b.d, tangents.data(), in.vertexCount) == 0, "the classic model took tangents");
        checkRejected("set_tangents(classic)", codeInvalid);
        CHECK(gcs_deformer_tangents(b.d) == nullptr, "the classic model has tangents");
        continue;
      }
      CHECK(gcs_deformer_set_tangents(b.d, tangents.data(), in.vertexCount) == 1, "set_tangents rejected valid tangents");
      checkOk("set_tangents");
      b.tangents = gcs_deformer_tangents(b.d);
      CHECK(b.tangents != nullptr, "no tangent output after set_tangents");
      b.tangentW.resize(in.vertexCount);
      for (uint32_t v = 0; v < in.vertexCount; ++v) b.tangentW[v] = tangents[4 * size_t(v) + 3];
      // Until the next deform: the rest tangents in the output order.
      const uint32_t* src = gcs_deformer_source_vertex(b.d);
      for (uint32_t o = 0; o < b.vertexCount; ++o)
        CHECK(std::memcmp(&b.tangents[4 * size_t(o)], &tangents[4 * size_t(src[o])], 16) == 0, "output vertex %u: not its rest tangent", o);
    }
  }
  log("tangents: %s\n", built.front().tangents || built.back().tangents ? "set" : "none");

  // ---- previous positions (velocity), any deformer
  if (f.ConsumeBool())
    for (Built& b : built) {
      g_context = std::string(ctx) + "; " + b.label + "; keep_previous_positions";
      CHECK(gcs_deformer_keep_previous_positions(b.d, 1) == 1, "keep_previous_positions failed");
      checkOk("keep_previous_positions");
      const float* previous = gcs_deformer_previous_positions(b.d);
      CHECK(previous && previous != b.positions && std::memcmp(previous, b.positions, size_t(b.vertexCount) * 12) == 0,
            "the previous positions do not start as the current ones");
      b.keepPrevious = true;
    }

  // ---- frames
  const uint32_t J = in.jointCount;
  const int frames = f.ConsumeIntegralInRange<int>(1, 4);
  Frame last = identityFrame(J);
  for (int i = 0; i <= frames; ++i) {
    // The last frame is the identity (the GCS rest pose), after the fuzzed ones; its influences are
    // either all 0, or the targets are removed, so the rest pose must be the rig's, exactly.
    Frame fr = i < frames ? fuzzFrame(f, J, coordScale) : identityFrame(J);
    Morphs next = morphs;
    bool removeTargets = false;
    if (next.targets) {
      if (i < frames) fuzzInfluences(f, next);
      else if (f.ConsumeBool()) std::fill(next.influences.begin(), next.influences.end(), 0.0f);
      else removeTargets = true;
    }
    if (g_verbose && next.targets) {
      log("frame %d influences", i);
      for (float w : next.influences) log(" %g", double(w));
      log("%s\n", removeTargets ? " (targets removed)" : "");
    }
    const bool reject = i > 0 && f.ConsumeIntegralInRange<int>(0, 2) == 0;  // after a first deform
    for (Built& b : built) {
      char what[64];
      std::snprintf(what, sizeof what, "; frame %d%s%s", i, fr.identity ? " (identity)" : "", fr.nice ? " (nice)" : "");
      g_context = std::string(ctx) + "; " + b.label + what;
      if (reject) rejectedDeform(f, b, in, last, morphs);
      if (next.targets && b.kind != GCS_KIND_CLASSIC) {
        if (removeTargets) {
          CHECK(gcs_deformer_set_morph_targets(b.d, nullptr, nullptr, 0, 0) == 1, "removing the morph targets failed");
          checkOk("set_morph_targets(0)");
        } else {
          CHECK(gcs_deformer_set_morph_influences(b.d, next.influences.data(), next.targets) == 1,
                "set_morph_influences rejected valid influences");
          checkOk("set_morph_influences");
        }
      }
      deformOk(b, in, fr, removeTargets || !next.active());
    }
    last = fr;
    morphs = next;
    if (removeTargets) morphs = Morphs();
  }
  // A rejected set_bulge changes nothing: the same frame gives the same output.
  for (Built& b : built) {
    if (b.kind != GCS_KIND_CLASSIC) continue;
    g_context = std::string(ctx) + "; " + b.label + "; set_bulge";
    Frame fr = fuzzFrame(f, J, coordScale);
    deformOk(b, in, fr, true);
    Snapshot before;
    before.take(b);
    static const float oddB[] = {-0.1f, 4.0001f, NAN, INFINITY, -INFINITY};
    CHECK(gcs_classic_set_bulge(b.d, f.PickValueInArray(oddB)) == 0, "set_bulge accepted a bad gain");
    checkRejected("set_bulge", codeOutOfRange);
    deformOk(b, in, fr, true);
    CHECK(before.same(b), "a rejected set_bulge changed the output of the same frame");
    CHECK(gcs_classic_set_bulge(b.d, float(f.ConsumeIntegralInRange<int>(0, 8)) / 2.0f) == 1, "set_bulge rejected a good gain");
    checkOk("set_bulge");
    deformOk(b, in, fr, true);
  }
  for (Built& b : built) gcs_deformer_destroy(b.d);
}

// Calls on null handles and the memory helpers.
void nullHandles() {
  g_context = "null handles";
  CHECK(buildGcs(nullptr, 6, 2, 1.0f, 0, 0, 1) == nullptr, "build on a null rig");
  checkRejected("gcs_build_gcs(null)", codeInvalid);
  CHECK(gcs_build_classic(nullptr, 25, 20, 1.0f) == nullptr, "classic on a null rig");
  checkRejected("gcs_build_classic(null)", codeInvalid);
  CHECK(gcs_build_lbs(nullptr) == nullptr && gcs_build_dqs(nullptr) == nullptr, "LBS/DQS on a null rig");
  checkRejected("gcs_build_dqs(null)", codeInvalid);
  float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  CHECK(gcs_deformer_deform(nullptr, m, 1) == 0, "deform on a null deformer");
  checkRejected("gcs_deformer_deform(null)", codeInvalid);
  CHECK(gcs_deformer_set_tangents(nullptr, m, 4) == 0, "set_tangents on a null deformer");
  checkRejected("gcs_deformer_set_tangents(null)", codeInvalid);
  CHECK(gcs_deformer_tangents(nullptr) == nullptr, "tangents of a null deformer");
  CHECK(gcs_deformer_keep_previous_positions(nullptr, 1) == 0, "keep_previous_positions on a null deformer");
  checkRejected("gcs_deformer_keep_previous_positions(null)", codeInvalid);
  CHECK(gcs_deformer_previous_positions(nullptr) == nullptr, "previous positions of a null deformer");
  CHECK(gcs_deformer_set_morph_targets(nullptr, m, nullptr, 1, 1) == 0, "set_morph_targets on null");
  checkRejected("gcs_deformer_set_morph_targets(null)", codeInvalid);
  CHECK(gcs_deformer_set_morph_influences(nullptr, m, 1) == 0, "set_morph_influences on null");
  checkRejected("gcs_deformer_set_morph_influences(null)", codeInvalid);
  CHECK(gcs_classic_set_bulge(nullptr, 1.0f) == 0, "set_bulge on null");
  checkRejected("gcs_classic_set_bulge(null)", codeInvalid);
  CHECK(gcs_rig_vertex_count(nullptr) == 0 && gcs_rig_joint_count(nullptr) == 0 && gcs_rig_height(nullptr) == 0.0f,
        "rig getters on null");
  CHECK(gcs_deformer_vertex_count(nullptr) == 0 && !gcs_deformer_positions(nullptr) && !gcs_deformer_normals(nullptr) &&
            gcs_deformer_index_count(nullptr) == 0 && !gcs_deformer_indices(nullptr) &&
            !gcs_deformer_source_vertex(nullptr),
        "deformer getters on null");
  CHECK(std::isnan(gcs_deformer_stat(nullptr, 0)) && !gcs_gcs_section_of_vertex(nullptr) && !gcs_gcs_section_info(nullptr) &&
            !gcs_gcs_section_matrices(nullptr) && gcs_classic_part_count(nullptr) == 0 && !gcs_classic_parts(nullptr) &&
            std::isnan(gcs_classic_detail_loss(nullptr, 0)),
        "introspection on null");
  gcs_deformer_destroy(nullptr);
  gcs_rig_destroy(nullptr);
  void* a = gcs_alloc(0);
  CHECK(a != nullptr, "gcs_alloc(0) failed");
  checkOk("gcs_alloc");
  gcs_free(a);
  gcs_free(nullptr);
  float* b = static_cast<float*>(gcs_alloc(64));
  CHECK(b != nullptr, "gcs_alloc(64) failed");
  gcs_copy_bytes(b, m, 64);
  CHECK(std::memcmp(b, m, 64) == 0, "gcs_copy_bytes");
  gcs_copy_bytes(nullptr, m, 64);
  gcs_copy_bytes(b, nullptr, 64);
  gcs_free(b);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static bool once = [] {
    g_verbose = std::getenv("GCS_FUZZ_VERBOSE") != nullptr;
    return true;
  }();
  (void)once;
  FuzzedDataProvider f(data, size);
  nullHandles();
  if (size == 0) return 0;
  RigInput in;
  if (f.ConsumeIntegralInRange<int>(0, 3) == 0) makeSoup(f, in);
  else makeTube(f, in);
  runRig(f, in);
  return 0;
}
