// The generalized cross-section (GCS) model: build once per mesh and setting, deform per frame.
// docs/method.md §2–4; the paper's sections 3.1–3.2.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>
#include "deformer.h"
#include "rig.h"
#include "transform.h"

namespace gcs {

// The settings a model is built with: the C API's GcsSettings once checked and their defaults
// resolved (validateSettings). Zero until then: the defaults are the header's, stated nowhere else.
struct ModelSettings {
  uint32_t sections = 0;                    // level of detail (see GcsSettings)
  GcsCriterion criterion = GCS_CRITERION_Y;
  float influenceWidth = 0.0f;              // (0, 1]
  bool smooth = false;
  bool twistSpread = false;
  // Weights criterion: blended sections rotate about their centre of rotation (rotation_centres.h)
  // instead of moving by the dual-quaternion blend's translation.
  bool centres = false;
};

// Checks the C API's settings (gcs_skin.h GcsSettings: each field's range) and resolves smooth's
// default into `settings`: the one check of a build's settings. False with the error recorded.
bool validateSettings(const GcsSettings& given, ModelSettings& settings);

// One generalized section: a run of output vertices that share one transform per frame.
// Y/axial criteria: M = S_parent · D_part^(alpha, tau) · D_distal^beta (parent < 0: S_part · D_distal^beta).
// Weights criterion: M = the dual-quaternion blend of its joints with its mean weights
// (influences[influenceFirst .. +influenceCount]); a rigid core (rigid = true) is exactly S_part.
struct Section {
  uint32_t first = 0, count = 0;  // output vertex run
  uint32_t part = 0;              // joint owning the part (for a shared section: the child part)
  int32_t parent = -1;            // the part's parent part joint, or -1 (root part)
  int32_t distal = -1;            // the child part joint this section's branch leads to, or -1
  bool shared = false;            // a shared generalized section (SGS) between part and parent
  float t = 0.0f;                 // mean normalised axial coordinate, 0 proximal … 1 distal
  float alpha = 1.0f, beta = 0.0f, tau = 1.0f;
  glm::vec3 centre{0.0f};         // bind-pose bounding sphere, for the "adjusted" test
  float radius = 0.0f;
  bool rigid = false;             // weights criterion: a rigid core, transform exactly S_part
  uint32_t influenceFirst = 0, influenceCount = 0;  // weights criterion: its blend
  // Weights criterion with centres: the section turns by its blend's rotation about this bind-pose
  // point, which itself moves by linear blend skinning (false: the dual-quaternion blend).
  bool aboutCentre = false;
  glm::vec3 rotationCentre{0.0f};
};

struct Influence {
  uint32_t joint = 0;
  float weight = 0.0f;
};

struct PartInfo {
  int32_t parent = -1;            // parent part joint or -1
  glm::vec3 twistAxis{0.0f, 1.0f, 0.0f};
  bool isPart = false;
};

class GcsDeformerImpl final : public Deformer {
 public:
  GcsDeformerKind kind() const override { return GCS_KIND_GCS; }
  void deform(const glm::mat4* skin) override;
  // The per-frame section transforms only (sectionMatrices, normalMatrices, renormalise), no
  // per-vertex work: the first half of deform(). The GPU path (gcs_gcs_compute_sections).
  void computeSections(const glm::mat4* skin);
  std::vector<float>* morphableRestPositions() override { return &restPositions; }
  std::vector<float>* morphableRestNormals() override { return &restNormals; }
  float stat(GcsStat which) const override;

  ModelSettings settings;
  std::vector<Section> sections;
  std::vector<PartInfo> parts;          // indexed by joint
  std::vector<glm::vec3> jointCentres;  // bind pose
  uint32_t partCount = 0;
  std::vector<float> restPositions;     // output order, interleaved
  std::vector<float> restNormals;
  std::vector<uint32_t> sectionOfVertex;
  std::vector<float> sectionInfo;       // 8 floats per section (see gcs_skin.h)
  std::vector<Influence> influences;    // weights criterion: the sections' blends
  // Weights criterion: the sections' blends as gcs_gcs_section_influences packs them (2 ·
  // influenceTableSlots floats per section: per 4 slots, joints, -1 past the last, then weights);
  // empty for the other criteria. 4 slots unless a section blends more than 4 joints, then 8.
  std::vector<float> influenceTable;
  uint32_t influenceTableSlots = 0;
  // Weights criterion: each section's centre of rotation as gcs_gcs_section_centres packs it (x, y,
  // z, 1), or 0, 0, 0, 0 where the section moves by the plain blend; empty for the other criteria.
  std::vector<float> centreTable;
  // Smooth mode: per output vertex, the other section it blends with and the factor towards it
  // (its own section is the run it sits in).
  std::vector<uint32_t> blendOther;
  std::vector<float> blendF;
  // Smooth weights criterion, a vertex of three joints: the third node of its lattice cell and the
  // factor towards it (M = A + f·(B − A) + g·(C − A)); others: their own section and 0.
  std::vector<uint32_t> blendThird;
  std::vector<float> blendThirdF;
  // Smooth mode: runs of vertices of one section that blend with the same other section (vertices
  // are sorted by it within their section at build time), so the kernel loads both transforms once.
  struct BlendRun {
    uint32_t first = 0, count = 0, section = 0, other = 0, third = 0;
  };
  std::vector<BlendRun> blendRuns;
  float adjustTolerance = 0.0f;
  float compactTolerance = 0.0f;        // GCS_COMPACT_POSE_TOLERANCE × min(1, height / reach): see gcs_build

  // Per-frame state, allocated at build time.
  std::vector<Motion> motions;          // D_j per part joint
  std::vector<glm::quat> swings, twists;
  std::vector<JointPose> poses;         // S_j split into rotation, translation and scale
  // The joints whose poses a frame needs (weights criterion: those the sections blend or carry;
  // others: every joint). A mesh of a shared skeleton (a robot's hand) uses a few of its joints.
  std::vector<uint32_t> usedJoints;
  std::vector<glm::mat4> sectionMatrices;   // position transform of each section
  std::vector<glm::mat4> normalMatrices;    // normal transform of each section (3×3 in a mat4)
  std::vector<uint8_t> renormalise;         // normals of the section need renormalising
  std::vector<const JointPose*> blendPoseScratch;
  // Weights criterion, uniform scale: the blended sections' dual quaternions (real, dual), four
  // sections converted to matrices at a time; blendedSections lists them (padded to a multiple of 4).
  // blendedSections is ordered by joint count: nodesWithCount[c] of them blend fewer than c joints;
  // nodeInfluenceFirst[b] is blendedSections[b]'s first influence. rigidSections: the rigid cores.
  std::vector<glm::vec4> nodeReal, nodeDual;
  // blendedSections[b]'s centre of rotation (x, y, z, 1), or w = 0 where it moves by the plain blend.
  std::vector<glm::vec4> nodeCentre;
  std::vector<uint32_t> blendedSections, rigidSections, nodeInfluenceFirst, nodesWithCount;
  std::vector<glm::mat4> lastSkin;          // the last frame's S_j, for the adjusted statistic
  ScaleState frameScale;                    // what the last frame's scales have in common
  mutable uint32_t adjustedSections = 0;
  mutable bool adjustedValid = false;

 private:
  uint32_t countAdjusted() const;
  void sectionTransformsWeights(const glm::mat4* skin, const ScaleState& scale);
  void sectionTransformsWeightsUniform(const glm::mat4* skin, float s);
  void sectionTransformsPaper(const glm::mat4* skin, const ScaleState& scale);
  void transformVertices(const float* inNrm, float* outPos, float* outNrm);
  void turnAboutCentre(const glm::mat4* skin, const Section& sec, glm::mat4& position) const;
};

// Builds the GCS model of a rig. Returns null with the error recorded on failure.
GcsDeformerImpl* buildGcs(const Rig& rig, const ModelSettings& settings);

}  // namespace gcs
