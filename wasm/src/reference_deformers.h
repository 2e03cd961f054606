// Linear blend skinning and dual-quaternion skinning on the rig's own vertices: the baselines.
#pragma once
#include "deformer.h"
#include "rig.h"
#include "transform.h"

namespace gcs {

class SkinningDeformer final : public Deformer {
 public:
  explicit SkinningDeformer(GcsDeformerKind k) : kind_(k) {}
  GcsDeformerKind kind() const override { return kind_; }
  void deform(const glm::mat4* skin) override;
  std::vector<float>* morphableRestPositions() override { return &restPositions; }
  std::vector<float>* morphableRestNormals() override { return &restNormals; }
  float stat(GcsStat which) const override;

  std::vector<float> restPositions, restNormals;
  std::vector<glm::uvec4> joints;
  std::vector<glm::vec4> weights;
  std::vector<glm::uvec4> joints1;  // influence slots 4..7, empty for a rig of at most 4 influences
  std::vector<glm::vec4> weights1;
  // Per-frame scratch, allocated at build time: per joint, S_j split into rotation, translation
  // (a dual quaternion) and scale.
  std::vector<JointPose> poses;

 private:
  // Every vertex under one frame: positions from the rest positions, `inNrm` (the rest normals, or
  // the rest tangents) turned into `outNrm`.
  void skinVertices(const glm::mat4* skin, const ScaleState& scale, const float* inNrm, float* outPos,
                    float* outNrm) const;
  GcsDeformerKind kind_;
};

SkinningDeformer* buildSkinning(const Rig& rig, GcsDeformerKind kind);

// Dual-quaternion skinning of n vertices (rest positions and normals xyz-interleaved, with their
// joints and weights: slots 0..3, and slots 4..7 in joints1/weights1 or null) under one frame's
// decomposed joint poses (decomposeAll): what the DQS deformer does to every vertex and the classic
// model to its carried skin. Null restNormals and normals: positions only (the classic build's
// on-skin probes).
void dqsVertices(const JointPose* poses, const ScaleState& scale, const glm::uvec4* joints, const glm::vec4* weights,
                 const glm::uvec4* joints1, const glm::vec4* weights1, const float* restPositions,
                 const float* restNormals, float* positions, float* normals, uint32_t n);

}  // namespace gcs
