// The C API (gcs_skin.h): argument checks, error recording, and nothing else.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>
#include "../include/gcs_skin.h"
#include "error.h"
#include "gcs_model.h"
#include "memory.h"
#include "reference_deformers.h"
#include "rig.h"


using gcs::fail;

extern "C" {

uint32_t gcs_version(void) { return GCS_VERSION; }
int gcs_last_error_code(void) { return gcs::lastErrorCode(); }
const char* gcs_last_error_message(void) { return gcs::lastErrorMessage(); }

void* gcs_alloc(uint32_t bytes) {
  gcs::clearError();
  void* p = std::malloc(bytes ? bytes : 1);
  if (!p) fail(GCS_ERR_OUT_OF_MEMORY, "out of memory: could not allocate %u bytes", bytes);
  return p;
}
void gcs_free(void* pointer) { std::free(pointer); }
void gcs_copy_bytes(void* destination, const void* source, uint32_t bytes) {
  if (destination && source) std::memcpy(destination, source, bytes);
}

GcsRig* gcs_rig_create(const float* positions, const float* normals, uint32_t vertexCount,
                       const uint32_t* indices, uint32_t indexCount, const uint32_t* joints,
                       const float* weights, uint32_t influences, const int32_t* parents,
                       const float* inverseBind, uint32_t jointCount) {
  gcs::clearError();
  if (vertexCount <= GCS_MAX_VERTICES && jointCount <= GCS_MAX_JOINTS && influences >= 1 && influences <= GCS_MAX_INFLUENCES &&
      !gcs::reserveMemory(gcs::rigPeakBytes(vertexCount, indexCount, jointCount, influences > 4 ? 8 : 4), "the rig"))
    return nullptr;
  GcsRig* handle = new (std::nothrow) GcsRig();
  if (!handle) {
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while creating a rig");
    return nullptr;
  }
  if (!gcs::buildRig(positions, normals, vertexCount, indices, indexCount, joints, weights,
                     influences, parents, inverseBind, jointCount, handle->rig)) {
    delete handle;
    return nullptr;
  }
  return handle;
}

void gcs_rig_destroy(GcsRig* rig) { delete rig; }
uint32_t gcs_rig_vertex_count(const GcsRig* rig) { return rig ? rig->rig.vertexCount : 0; }
uint32_t gcs_rig_joint_count(const GcsRig* rig) { return rig ? rig->rig.jointCount : 0; }
float gcs_rig_height(const GcsRig* rig) { return rig ? rig->rig.height : 0.0f; }

static GcsDeformer* wrap(gcs::Deformer* impl) {
  if (!impl) return nullptr;
  GcsDeformer* handle = new (std::nothrow) GcsDeformer{impl};
  if (!handle) {
    delete impl;
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while creating a deformer");
  }
  return handle;
}

static bool checkRig(const GcsRig* rig) {
  if (!rig) return fail(GCS_ERR_INVALID_ARGUMENT, "the rig is null (destroyed or never created)");
  return true;
}

GcsDeformer* gcs_build_gcs(const GcsRig* rig, const GcsSettings* settings) {
  gcs::clearError();
  if (!checkRig(rig)) return nullptr;
  if (!settings) {
    fail(GCS_ERR_INVALID_ARGUMENT, "the settings are null");
    return nullptr;
  }
  gcs::ModelSettings checked;
  if (!gcs::validateSettings(*settings, checked)) return nullptr;
  const gcs::Rig& r = rig->rig;
  if (!gcs::reserveMemory(gcs::gcsPeakBytes(r.vertexCount, r.indices.size(), r.jointCount, r.influenceSlots), "the GCS model"))
    return nullptr;
  return wrap(gcs::buildGcs(rig->rig, checked));
}

GcsDeformer* gcs_build_lbs(const GcsRig* rig) {
  gcs::clearError();
  if (!checkRig(rig)) return nullptr;
  const gcs::Rig& r = rig->rig;
  if (!gcs::reserveMemory(gcs::skinningPeakBytes(r.vertexCount, r.indices.size(), r.jointCount, r.influenceSlots), "the LBS deformer"))
    return nullptr;
  return wrap(gcs::buildSkinning(rig->rig, GCS_KIND_LBS));
}

GcsDeformer* gcs_build_dqs(const GcsRig* rig) {
  gcs::clearError();
  if (!checkRig(rig)) return nullptr;
  const gcs::Rig& r = rig->rig;
  if (!gcs::reserveMemory(gcs::skinningPeakBytes(r.vertexCount, r.indices.size(), r.jointCount, r.influenceSlots), "the DQS deformer"))
    return nullptr;
  return wrap(gcs::buildSkinning(rig->rig, GCS_KIND_DQS));
}

void gcs_deformer_destroy(GcsDeformer* deformer) {
  if (!deformer) return;
  delete deformer->impl;
  delete deformer;
}

uint32_t gcs_deformer_kind(const GcsDeformer* deformer) {
  return deformer ? uint32_t(deformer->impl->kind()) : 0xffffffffu;
}

int gcs_deformer_deform(GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount) {
  gcs::clearError();
  if (!deformer) return fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null (destroyed or never created)");
  if (!skinMatrices) return fail(GCS_ERR_INVALID_ARGUMENT, "the skin matrices are null");
  gcs::Deformer& d = *deformer->impl;
  if (jointCount != d.jointCount)
    return fail(GCS_ERR_LENGTH_MISMATCH, "got %u skin matrices, but the rig has %u joints", jointCount, d.jointCount);
  const size_t bad = gcs::firstNonFinite(skinMatrices, size_t(jointCount) * 16);
  if (bad != size_t(jointCount) * 16)
    return fail(GCS_ERR_NON_FINITE, "the skin matrix of joint %u contains NaN or infinity", uint32_t(bad / 16));
  // glm::mat4 is 16 floats, column-major, no padding: the array can be read in place.
  static_assert(sizeof(glm::mat4) == 16 * sizeof(float), "glm::mat4 must be 16 packed floats");
  d.applyMorphs();
  if (!d.previousPositions.empty()) d.positions.swap(d.previousPositions);  // last frame's become the previous
  d.deform(reinterpret_cast<const glm::mat4*>(skinMatrices));
  return 1;
}

int gcs_deformer_keep_previous_positions(GcsDeformer* deformer, int keep) {
  gcs::clearError();
  if (!deformer) return fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null (destroyed or never created)");
  gcs::Deformer& d = *deformer->impl;
  if (!keep) {
    std::vector<float>().swap(d.previousPositions);
    return 1;
  }
  if (!d.previousPositions.empty()) return 1;
  if (!gcs::reserveMemory(uint64_t(d.positions.size()) * 4 * 3 / 2 + 4096, "the previous positions")) return 0;
  d.previousPositions = d.positions;
  return 1;
}

float* gcs_deformer_previous_positions(GcsDeformer* d) {
  return d && !d->impl->previousPositions.empty() ? d->impl->previousPositions.data() : nullptr;
}

int gcs_deformer_set_morph_targets(GcsDeformer* deformer, const float* deltas, const float* normalDeltas,
                                   uint32_t targetCount, uint32_t vertexCount) {
  gcs::clearError();
  if (!deformer) return fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null (destroyed or never created)");
  gcs::Deformer& d = *deformer->impl;
  std::vector<float>* rest = d.morphableRestPositions();
  std::vector<float>* restN = d.morphableRestNormals();
  if (!rest || !restN || d.sourceVertex.size() != d.vertexCount)
    return fail(GCS_ERR_INVALID_ARGUMENT, "morph targets apply to the GCS, LBS and DQS deformers; the classic model resamples the mesh");
  if (targetCount > GCS_MAX_MORPH_TARGETS)
    return fail(GCS_ERR_OUT_OF_RANGE, "at most %d morph targets; got %u", GCS_MAX_MORPH_TARGETS, targetCount);
  if (targetCount > 0 && !deltas) return fail(GCS_ERR_INVALID_ARGUMENT, "the morph target deltas are null");
  if (targetCount > 0 && vertexCount != d.vertexCount)
    return fail(GCS_ERR_LENGTH_MISMATCH, "morph targets have %u vertices each, but the mesh has %u", vertexCount, d.vertexCount);
  const size_t n = size_t(d.vertexCount) * 3;
  if (targetCount > 0) {
    if (!gcs::allFinite(deltas, n * targetCount))
      return fail(GCS_ERR_NON_FINITE, "a morph target position delta is NaN or infinite");
    if (normalDeltas && !gcs::allFinite(normalDeltas, n * targetCount))
      return fail(GCS_ERR_NON_FINITE, "a morph target normal delta is NaN or infinite");
    if (!gcs::reserveMemory(uint64_t(n) * 4 * (uint64_t(targetCount) * (normalDeltas ? 2 : 1) + 2) * 3 / 2 + 4096, "the morph targets"))
      return 0;
  }
  // Back to the unmorphed rest first (so that replacing or removing targets starts from it).
  if (d.morphTargetCount > 0) {
    std::copy(d.morphBasePositions.begin(), d.morphBasePositions.end(), rest->begin());
    std::copy(d.morphBaseNormals.begin(), d.morphBaseNormals.end(), restN->begin());
  }
  d.morphTargetCount = targetCount;
  d.morphInfluences.assign(targetCount, 0.0f);
  d.morphApplied.assign(targetCount, 0.0f);
  if (targetCount == 0) {
    d.morphBasePositions.clear(), d.morphBaseNormals.clear(), d.morphDeltas.clear(), d.morphNormalDeltas.clear();
    return 1;
  }
  d.morphBasePositions = *rest;
  d.morphBaseNormals = *restN;
  // Deltas come in rig vertex order; the deformer stores its vertices in its own order.
  d.morphDeltas.assign(n * targetCount, 0.0f);
  d.morphNormalDeltas.assign(normalDeltas ? n * targetCount : 0, 0.0f);
  for (uint32_t t = 0; t < targetCount; ++t)
    for (uint32_t o = 0; o < d.vertexCount; ++o) {
      const uint32_t v = d.sourceVertex[o];
      for (int c = 0; c < 3; ++c) {
        d.morphDeltas[t * n + 3 * size_t(o) + c] = deltas[t * n + 3 * size_t(v) + c];
        if (normalDeltas) d.morphNormalDeltas[t * n + 3 * size_t(o) + c] = normalDeltas[t * n + 3 * size_t(v) + c];
      }
    }
  return 1;
}

int gcs_deformer_set_morph_influences(GcsDeformer* deformer, const float* influences, uint32_t targetCount) {
  gcs::clearError();
  if (!deformer) return fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null (destroyed or never created)");
  gcs::Deformer& d = *deformer->impl;
  if (targetCount != d.morphTargetCount)
    return fail(GCS_ERR_LENGTH_MISMATCH, "got %u morph influences, but the deformer has %u morph targets", targetCount, d.morphTargetCount);
  if (targetCount > 0 && !influences) return fail(GCS_ERR_INVALID_ARGUMENT, "the morph influences are null");
  if (!gcs::allFinite(influences, targetCount)) return fail(GCS_ERR_NON_FINITE, "a morph influence is NaN or infinite");
  std::copy(influences, influences + targetCount, d.morphInfluences.begin());
  return 1;
}

int gcs_deformer_set_tangents(GcsDeformer* deformer, const float* tangents, uint32_t vertexCount) {
  gcs::clearError();
  if (!deformer) return fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null (destroyed or never created)");
  gcs::Deformer& d = *deformer->impl;
  if (!d.morphableRestNormals() || d.sourceVertex.size() != d.vertexCount)
    return fail(GCS_ERR_INVALID_ARGUMENT, "tangents apply to the GCS, LBS and DQS deformers; the classic model resamples the mesh");
  if (!tangents) {
    d.restTangents.clear(), d.tangentSigns.clear(), d.tangents.clear(), d.turnedTangents.clear(), d.tangentPassPositions.clear();
    return 1;
  }
  if (vertexCount != d.vertexCount)
    return fail(GCS_ERR_LENGTH_MISMATCH, "got %u tangents, but the mesh has %u vertices", vertexCount, d.vertexCount);
  const size_t n = d.vertexCount;
  if (!gcs::allFinite(tangents, n * 4)) return fail(GCS_ERR_NON_FINITE, "a tangent is NaN or infinite");
  // Rest xyz, signs, output, the kernels' output and their positions (each with a spare float).
  if (!gcs::reserveMemory(uint64_t(n) * 4 * (3 + 1 + 4 + 3 + 3) * 3 / 2 + 4096, "the tangents")) return 0;
  d.restTangents.assign(n * 3 + 1, 0.0f);
  d.tangentSigns.assign(n, 0.0f);
  d.tangents.assign(n * 4, 0.0f);
  d.turnedTangents.assign(n * 3 + 1, 0.0f);
  d.tangentPassPositions.assign(n * 3 + 1, 0.0f);
  // Tangents come in rig vertex order; the deformer stores its vertices in its own order.
  for (uint32_t o = 0; o < d.vertexCount; ++o) {
    const float* t = tangents + 4 * size_t(d.sourceVertex[o]);
    for (int c = 0; c < 3; ++c) d.restTangents[3 * size_t(o) + c] = d.turnedTangents[3 * size_t(o) + c] = t[c];
    d.tangentSigns[o] = t[3];
  }
  d.packTangents();
  return 1;
}

float* gcs_deformer_tangents(GcsDeformer* d) { return d && !d->impl->tangents.empty() ? d->impl->tangents.data() : nullptr; }

uint32_t gcs_deformer_vertex_count(const GcsDeformer* d) { return d ? d->impl->vertexCount : 0; }
float* gcs_deformer_positions(GcsDeformer* d) { return d ? d->impl->positions.data() : nullptr; }
float* gcs_deformer_normals(GcsDeformer* d) { return d ? d->impl->normals.data() : nullptr; }
uint32_t gcs_deformer_index_count(const GcsDeformer* d) { return d ? uint32_t(d->impl->indices.size()) : 0; }
const uint32_t* gcs_deformer_indices(const GcsDeformer* d) { return d ? d->impl->indices.data() : nullptr; }
const uint32_t* gcs_deformer_source_vertex(const GcsDeformer* d) {
  return d && !d->impl->sourceVertex.empty() ? d->impl->sourceVertex.data() : nullptr;
}

int gcs_deformer_gather(const GcsDeformer* d, const void* source, uint32_t sourceCount, uint32_t strideBytes,
                        uint32_t itemBytes, void* out) {
  gcs::clearError();
  if (!d || d->impl->sourceVertex.empty() || !source || !out || itemBytes == 0 || itemBytes > strideBytes)
    return fail(GCS_ERR_INVALID_ARGUMENT, "gather needs a deformer with source vertices, a source and an output, and 0 < itemBytes <= strideBytes");
  const std::vector<uint32_t>& from = d->impl->sourceVertex;
  for (uint32_t v : from)
    if (v >= sourceCount) return fail(GCS_ERR_INVALID_ARGUMENT, "gather: source vertex %u is past the %u items given", v, sourceCount);
  const auto* src = static_cast<const uint8_t*>(source);
  auto* dst = static_cast<uint8_t*>(out);
  const size_t n = from.size();
  // Whole 32-bit words where the layout allows (every float or 32-bit attribute), else bytes.
  if (itemBytes % 4 == 0 && strideBytes % 4 == 0 && reinterpret_cast<uintptr_t>(src) % 4 == 0 &&
      reinterpret_cast<uintptr_t>(dst) % 4 == 0) {
    const uint32_t words = itemBytes / 4, stride = strideBytes / 4;
    const auto* s32 = reinterpret_cast<const uint32_t*>(src);
    auto* d32 = reinterpret_cast<uint32_t*>(dst);
    for (size_t o = 0; o < n; ++o)
      for (uint32_t k = 0; k < words; ++k) d32[o * words + k] = s32[size_t(from[o]) * stride + k];
  } else {
    for (size_t o = 0; o < n; ++o)
      for (uint32_t k = 0; k < itemBytes; ++k) dst[o * itemBytes + k] = src[size_t(from[o]) * strideBytes + k];
  }
  return 1;
}

float gcs_deformer_stat(const GcsDeformer* d, uint32_t stat) {
  return d && stat <= GCS_STAT_ADJUSTED_SECTIONS ? d->impl->stat(GcsStat(stat)) : std::nanf("");
}

static const gcs::GcsDeformerImpl* asGcs(const GcsDeformer* d) {
  return d && d->impl->kind() == GCS_KIND_GCS ? static_cast<const gcs::GcsDeformerImpl*>(d->impl) : nullptr;
}

const uint32_t* gcs_gcs_section_of_vertex(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g ? g->sectionOfVertex.data() : nullptr;
}
const float* gcs_gcs_section_info(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g ? g->sectionInfo.data() : nullptr;
}
const float* gcs_gcs_section_matrices(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g ? &g->sectionMatrices[0][0][0] : nullptr;
}

const uint32_t* gcs_gcs_blend_other(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g && g->settings.smooth ? g->blendOther.data() : nullptr;
}
const float* gcs_gcs_blend_factor(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g && g->settings.smooth ? g->blendF.data() : nullptr;
}
const uint32_t* gcs_gcs_blend_third(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g && g->settings.smooth ? g->blendThird.data() : nullptr;
}
const float* gcs_gcs_blend_third_factor(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g && g->settings.smooth ? g->blendThirdF.data() : nullptr;
}

// The checks both GPU-path calls make before writing anything: pointers, counts, sizes (the input
// and `outBytesPerInstance` per instance within 4 GiB) and every skin matrix finite.
static bool validGpuInput(const gcs::GcsDeformerImpl& g, const float* skinMatrices, uint32_t jointCount,
                          uint32_t instanceCount, const float* out, uint64_t outBytesPerInstance, uint32_t units,
                          const char* unitName) {
  if (!skinMatrices) return fail(GCS_ERR_INVALID_ARGUMENT, "the skin matrices are null");
  if (!out) return fail(GCS_ERR_INVALID_ARGUMENT, "the output buffer is null");
  if (jointCount != g.jointCount)
    return fail(GCS_ERR_LENGTH_MISMATCH, "got %u skin matrices per instance, but the rig has %u joints", jointCount, g.jointCount);
  if (instanceCount < 1 || instanceCount > GCS_MAX_INSTANCES)
    return fail(GCS_ERR_OUT_OF_RANGE, "the instance count must be from 1 to %d; got %u", GCS_MAX_INSTANCES, instanceCount);
  const uint64_t inFloats = uint64_t(instanceCount) * jointCount * 16;
  if (uint64_t(instanceCount) * outBytesPerInstance > 0xffffffffull || inFloats * 4 > 0xffffffffull)
    return fail(GCS_ERR_OUT_OF_RANGE, "%u instances of %u %s do not fit in 4 GiB of memory", instanceCount, units, unitName);
  const uint64_t i = gcs::firstNonFinite(skinMatrices, size_t(inFloats));
  if (i != inFloats)
    return fail(GCS_ERR_NON_FINITE, "the skin matrix of joint %u of instance %u contains NaN or infinity",
                  uint32_t((i / 16) % jointCount), uint32_t(i / 16 / jointCount));
  return true;
}

int gcs_gcs_compute_sections(GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount,
                             uint32_t instanceCount, float* out) {
  gcs::clearError();
  if (!deformer) return fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null (destroyed or never created)");
  if (deformer->impl->kind() != GCS_KIND_GCS)
    return fail(GCS_ERR_INVALID_ARGUMENT, "section transforms exist only for GCS deformers");
  gcs::GcsDeformerImpl& g = *static_cast<gcs::GcsDeformerImpl*>(deformer->impl);
  const uint32_t S = uint32_t(g.sections.size());
  if (!validGpuInput(g, skinMatrices, jointCount, instanceCount, out, uint64_t(S) * 16 * GCS_GPU_TEXELS_PER_SECTION, S, "sections"))
    return 0;
  const glm::mat4* skins = reinterpret_cast<const glm::mat4*>(skinMatrices);
  float* o = out;
  for (uint32_t k = 0; k < instanceCount; ++k) {
    g.computeSections(skins + size_t(k) * jointCount);
    for (const glm::mat4& m : g.sectionMatrices)
      for (int r = 0; r < 3; ++r, o += 4) o[0] = m[0][r], o[1] = m[1][r], o[2] = m[2][r], o[3] = m[3][r];
  }
  return 1;
}

const float* gcs_gcs_section_influences(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g && !g->influenceTable.empty() ? g->influenceTable.data() : nullptr;
}

const float* gcs_gcs_section_centres(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g && !g->centreTable.empty() ? g->centreTable.data() : nullptr;
}

uint32_t gcs_gcs_section_influence_slots(const GcsDeformer* d) {
  const gcs::GcsDeformerImpl* g = asGcs(d);
  return g && !g->influenceTable.empty() ? g->influenceTableSlots : 0;
}

// The checks both joint-pose calls make before writing anything; the GCS deformer, or null with the error recorded.
static const gcs::GcsDeformerImpl* jointPoseInput(const GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount,
                                                  uint32_t instanceCount, const float* out) {
  const gcs::GcsDeformerImpl* g = asGcs(deformer);
  if (!deformer) fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null (destroyed or never created)");
  else if (!g) fail(GCS_ERR_INVALID_ARGUMENT, "joint poses are for GCS deformers (weights criterion) only");
  else if (g->settings.criterion != GCS_CRITERION_WEIGHTS)
    fail(GCS_ERR_INVALID_ARGUMENT, "joint poses drive the weights criterion only; the Y and axial criteria need gcs_gcs_compute_sections");
  else if (validGpuInput(*g, skinMatrices, jointCount, instanceCount, out, uint64_t(jointCount) * 16 * GCS_GPU_TEXELS_PER_JOINT,
                         jointCount, "joints"))
    return g;
  return nullptr;
}

// The full format: per joint the rows of S_j, bit for bit, then its rotation quaternion.
static void writeFullJointPoses(const glm::mat4* skins, uint64_t count, float* o) {
  for (uint64_t k = 0; k < count; ++k, o += 16) {
    const glm::mat4 m = skins[k];
    const glm::quat q = gcs::rotationOf(m);
    for (int r = 0; r < 3; ++r) o[4 * r] = m[0][r], o[4 * r + 1] = m[1][r], o[4 * r + 2] = m[2][r], o[4 * r + 3] = m[3][r];
    o[12] = q.x, o[13] = q.y, o[14] = q.z, o[15] = q.w;
  }
}

// Sets the lowest mantissa bit of f to `bit` (one unit in the last place at most); a value below
// FLT_MIN in magnitude becomes ±FLT_MIN first, so no GPU flushes it (and the bit) to zero.
static void setLowestBit(float& f, uint32_t bit) {
  if (!(std::fabs(f) >= FLT_MIN)) f = std::copysign(FLT_MIN, f);
  uint32_t u;
  std::memcpy(&u, &f, 4);
  u = (u & ~1u) | bit;
  std::memcpy(&f, &u, 4);
}

// One joint in the compact format (gcs_gcs_compute_joint_poses_compact), or false where its 3×3
// part is not within `tolerance` of its rotation (a scale, a shear, a mirror).
static bool writeCompactJointPose(const glm::mat4& m, float tolerance, float* o) {
  const glm::quat q = gcs::rotationOf(m);
  const glm::dmat3 r = glm::mat3_cast(glm::dquat(q.w, q.x, q.y, q.z));
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i)
      if (!(std::fabs(double(m[c][i]) - r[c][i]) <= double(tolerance))) return false;
  const float v[4] = {q.x, q.y, q.z, q.w};
  uint32_t dropped = 0;
  for (uint32_t i = 1; i < 4; ++i)
    if (std::fabs(v[i]) > std::fabs(v[dropped])) dropped = i;
  const float sign = v[dropped] < 0.0f ? -1.0f : 1.0f;  // ±q: the dropped component positive
  for (uint32_t i = 0, n = 0; i < 4; ++i)
    if (i != dropped) o[n++] = sign * v[i];
  o[3] = m[3][0], o[4] = m[3][1], o[5] = m[3][2];
  setLowestBit(o[0], dropped & 1u);
  setLowestBit(o[1], dropped >> 1);
  return true;
}

int gcs_gcs_compute_joint_poses(const GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount,
                                uint32_t instanceCount, float* out) {
  gcs::clearError();
  if (!jointPoseInput(deformer, skinMatrices, jointCount, instanceCount, out)) return 0;
  writeFullJointPoses(reinterpret_cast<const glm::mat4*>(skinMatrices), uint64_t(instanceCount) * jointCount, out);
  return 1;
}

int gcs_gcs_compute_joint_poses_compact(const GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount,
                                        uint32_t instanceCount, float* out) {
  gcs::clearError();
  const gcs::GcsDeformerImpl* g = jointPoseInput(deformer, skinMatrices, jointCount, instanceCount, out);
  if (!g) return 0;
  const glm::mat4* skins = reinterpret_cast<const glm::mat4*>(skinMatrices);
  const uint64_t count = uint64_t(instanceCount) * jointCount;
  // The compact floats are a prefix of the full format's: a joint out of tolerance rewrites the whole call.
  for (uint64_t k = 0; k < count; ++k)
    if (!writeCompactJointPose(skins[k], g->compactTolerance, out + k * GCS_COMPACT_FLOATS_PER_JOINT)) {
      writeFullJointPoses(skins, count, out);
      return GCS_JOINT_POSES_FULL;
    }
  return GCS_JOINT_POSES_COMPACT;
}

}  // extern "C"
