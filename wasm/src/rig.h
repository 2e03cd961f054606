// The raw input, validated: a skinned mesh and its skeleton in the bind pose.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>
#include <glm/glm.hpp>
#include "../include/gcs_skin.h"

namespace gcs {

struct CentreSurface;

// Each welded group's weights as cleanWeights gives them (`slots` entries per group, count[g]
// used) and, for a group of exactly two joints, the index of its ordered pair (dominant joint,
// other joint; the dominant as the weights criterion picks it) in `pairs`, else ~0u. No section
// count changes any of it: computed by the first weights-criterion build and kept on the rig.
struct WeightGroups {
  uint32_t slots = 4;
  std::vector<uint32_t> joint;
  std::vector<float> weight;
  std::vector<uint8_t> count;
  std::vector<uint32_t> pairOf;
  std::vector<glm::uvec2> pairs;
};

// What the builds derive from a rig, computed by the first build that asks and kept: the rig never
// changes once validated, and the sliders rebuild it again and again. A cache, not state: each
// entry is a pure function of the rig (weldRig, weightGroupsOf, centreSurfaceOf fill it).
struct RigCache {
  // weldByPosition's result.
  std::vector<uint32_t> weldGroup, weldRepresentative;
  bool welded = false;
  // What the weights criterion reads of each welded group (weightGroupsOf).
  std::shared_ptr<const WeightGroups> weightGroups;
  // The surface the centres of rotation integrate over (rotation_centres.h).
  std::shared_ptr<const CentreSurface> centreSurface;
};

constexpr uint32_t kMaxInfluences = GCS_MAX_INFLUENCES;  // per vertex, and so per section

struct Rig {
  uint32_t vertexCount = 0;
  uint32_t jointCount = 0;
  std::vector<glm::vec3> positions;      // bind pose, mesh space
  std::vector<glm::vec3> normals;        // unit length
  std::vector<uint32_t> indices;         // triangle list
  // Influence slots per vertex: 4, or 8 when the input gave more than 4 (slots 4..7 in joints1 /
  // weights1, empty otherwise, so a 4-influence rig costs what it always did).
  uint32_t influenceSlots = 4;
  std::vector<glm::uvec4> joints;        // slots 0..3 (ids < jointCount; unused: joint 0, weight 0)
  std::vector<glm::vec4> weights;        // slots 0..3; all slots together normalised, sum 1
  std::vector<glm::uvec4> joints1;       // slots 4..7 (influenceSlots == 8 only)
  std::vector<glm::vec4> weights1;
  std::vector<int32_t> parents;          // -1 for roots; parents[j] < jointCount
  std::vector<glm::mat4> inverseBind;    // B_j^-1
  std::vector<glm::mat4> bind;           // B_j
  std::vector<glm::vec3> jointCentres;   // c_j = B_j · origin
  glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
  float height = 0.0f;                   // largest bounding-box extent

  // Index of the joint with the largest weight on vertex v (ties: the first listed).
  uint32_t dominantJoint(uint32_t v) const;
  // Slot i (< influenceSlots) of vertex v.
  uint32_t jointAt(uint32_t v, uint32_t i) const { return i < 4 ? joints[v][int(i)] : joints1[v][int(i - 4)]; }
  float weightAt(uint32_t v, uint32_t i) const { return i < 4 ? weights[v][int(i)] : weights1[v][int(i - 4)]; }

  // What the builds derive from the rig and keep (see RigCache): the one mutable member of a const Rig.
  mutable RigCache cache;
};

// Validates the raw arrays (see gcs_rig_create in gcs_skin.h) and fills `rig`.
// On failure records the error and leaves `rig` unspecified.
bool buildRig(const float* positions, const float* normals, uint32_t vertexCount,
              const uint32_t* indices, uint32_t indexCount, const uint32_t* joints,
              const float* weights, uint32_t influences, const int32_t* parents, const float* inverseBind,
              uint32_t jointCount, Rig& rig);

// Area-weighted vertex normals of a triangle mesh (zero-area neighbourhoods get +Y).
void computeNormals(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                    std::vector<glm::vec3>& normals);

// Vertices at the same bind-pose position (UV or normal seams split them in glTF) are one
// surface point: returns each vertex's group id and fills `representative` (first vertex of
// each group). Both models group by it, so a seam can never open.
// (Computed once per rig, then copied from its cache.)
std::vector<uint32_t> weldByPosition(const Rig& rig, std::vector<uint32_t>& representative);
// Fills the rig's weld cache (cache.weldGroup, cache.weldRepresentative) if it is not yet: the builds that
// only read it take it from there without a copy.
void weldRig(const Rig& rig);
// The rig's WeightGroups, computed by the first call and kept.
const WeightGroups& weightGroupsOf(const Rig& rig);

// A vertex's skin weights as the GCS criteria read them: influences below 0.5 % dropped (but the
// largest), the same joint listed twice merged, the rest normalised to sum 1. Returns their count.
uint32_t cleanWeights(const Rig& rig, uint32_t v, uint32_t* joint, float* weight);

// The index of the first NaN or infinity among `count` floats; `count` when all are finite.
size_t firstNonFinite(const float* values, size_t count);
// Checks that `count` floats are all finite.
bool allFinite(const float* values, size_t count);

}  // namespace gcs

// The opaque handle of the C API is the validated rig.
struct GcsRig {
  gcs::Rig rig;
};
