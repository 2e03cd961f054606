// The runtime side: a deformer owns its output mesh and fills it once per frame.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>
#include "../include/gcs_skin.h"

namespace gcs {

class Deformer {
 public:
  virtual ~Deformer() = default;
  virtual GcsDeformerKind kind() const = 0;
  // skin: jointCount matrices S_j, already validated (count and finiteness) by the caller.
  virtual void deform(const glm::mat4* skin) = 0;
  virtual float stat(GcsStat which) const;

  uint32_t jointCount = 0;
  uint32_t vertexCount = 0;
  // One spare float at the end of each array: the SIMD path stores 4 lanes per vertex.
  std::vector<float> positions;
  std::vector<float> normals;
  std::vector<uint32_t> indices;
  std::vector<uint32_t> sourceVertex;  // empty when output vertices have no single source

  // Morph targets (blend shapes), applied to the rest mesh before skinning (three.js's order).
  // A deformer whose output vertices are rig vertices exposes its rest arrays (output order) here;
  // the classic model, which resamples, returns null and takes no morph targets.
  virtual std::vector<float>* morphableRestPositions() { return nullptr; }
  virtual std::vector<float>* morphableRestNormals() { return nullptr; }
  uint32_t morphTargetCount = 0;
  std::vector<float> morphBasePositions, morphBaseNormals;  // the unmorphed rest (output order)
  std::vector<float> morphDeltas, morphNormalDeltas;        // target × output vertex × 3
  std::vector<float> morphInfluences, morphApplied;         // requested and last applied
  // Brings the rest arrays to base + Σ influence · delta when the influences changed.
  void applyMorphs();

  // Velocity (gcs_deformer_keep_previous_positions): the last frame's positions, swapped with
  // `positions` before each deform (no copy); empty when not kept.
  std::vector<float> previousPositions;

  // Tangents (normal maps, gcs_deformer_set_tangents), in output order: the rest tangents' xyz,
  // turned like the normals by a second pass of the same kernels, and their w (handedness),
  // carried; the output, 4 floats per vertex. All empty when the deformer has none.
  std::vector<float> restTangents, tangentSigns, tangents;
  // The tangent pass's scratch: the kernels' own output (xyz and a spare lane) and the positions
  // they also write (discarded).
  std::vector<float> turnedTangents, tangentPassPositions;
  // Writes turnedTangents with their signs into `tangents`.
  void packTangents();

  void allocateOutput(uint32_t count) {
    vertexCount = count;
    positions.assign(size_t(count) * 3 + 1, 0.0f);
    normals.assign(size_t(count) * 3 + 1, 0.0f);
  }
};

}  // namespace gcs

// The opaque handle of the C API is the C++ object.
struct GcsDeformer {
  gcs::Deformer* impl;
};
