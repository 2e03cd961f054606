// The raw input, validated: a skinned mesh and its skeleton in the bind pose.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace gcs {

struct Rig {
  uint32_t vertexCount = 0;
  uint32_t jointCount = 0;
  std::vector<glm::vec3> positions;      // bind pose, mesh space
  std::vector<glm::vec3> normals;        // unit length
  std::vector<uint32_t> indices;         // triangle list
  std::vector<glm::uvec4> joints;        // 4 influences per vertex (ids < jointCount)
  std::vector<glm::vec4> weights;        // normalised, sum 1
  std::vector<int32_t> parents;          // -1 for roots; parents[j] < jointCount
  std::vector<glm::mat4> inverseBind;    // B_j^-1
  std::vector<glm::mat4> bind;           // B_j
  std::vector<glm::vec3> jointCentres;   // c_j = B_j · origin
  glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
  float height = 0.0f;                   // largest bounding-box extent

  // Index of the joint with the largest weight on vertex v (ties: the first listed).
  uint32_t dominantJoint(uint32_t v) const;

  // weldByPosition's result, computed by the first build that asks and kept: the positions never
  // change, and the sliders rebuild the same rig again and again.
  mutable std::vector<uint32_t> weldGroup, weldRepresentative;
  mutable bool welded = false;
};

// Validates the raw arrays (see gcs_rig_create in gcs_skin.h) and fills `rig`.
// On failure records the error and leaves `rig` unspecified.
bool buildRig(const float* positions, const float* normals, uint32_t vertexCount,
              const uint32_t* indices, uint32_t indexCount, const uint32_t* joints,
              const float* weights, const int32_t* parents, const float* inverseBind,
              uint32_t jointCount, Rig& rig);

// Area-weighted vertex normals of a triangle mesh (zero-area neighbourhoods get +Y).
void computeNormals(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                    std::vector<glm::vec3>& normals);

// Vertices at the same bind-pose position (UV or normal seams split them in glTF) are one
// surface point: returns each vertex's group id and fills `representative` (first vertex of
// each group). Both models group by it, so a seam can never open.
// (Computed once per rig, then copied from its cache.)
std::vector<uint32_t> weldByPosition(const Rig& rig, std::vector<uint32_t>& representative);

// Checks that `count` floats are all finite.
bool allFinite(const float* values, size_t count);

}  // namespace gcs

// The opaque handle of the C API is the validated rig.
struct GcsRig {
  gcs::Rig rig;
};
