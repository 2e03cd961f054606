// The classic cross-section model (Shen, Magnenat-Thalmann, Thalmann 1994; the paper's section 2;
// docs/method.md §6): cylinder-like parts are resampled into contours × star rays and deformed contour by
// contour; the other parts keep their original triangles, carried by dual-quaternion skinning of
// their own weights (so they follow the skin the tubes meet instead of standing off it).
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>
#include "deformer.h"
#include "rig.h"
#include "transform.h"

namespace gcs {

// One contour: a ring of `rays` output vertices in a plane.
struct ClassicContour {
  uint32_t first = 0;        // first output vertex of the ring
  uint32_t radii = 0;        // offset of its `rays` radii in ClassicModel::radii
  int32_t part = -1;         // the part whose parameter t applies (for a shared contour: distal part)
  int32_t proximal = -1;     // shared contour: the proximal part (whose distal end it is); else -1
  float t = 0.0f;            // 0 at the part's proximal joint … 1 at its distal joint
  glm::vec3 centre{0.0f}, normal{0.0f, 1.0f, 0.0f}, u{1.0f, 0.0f, 0.0f};  // bind pose
  // The skin it resamples: the mean influences of the input vertices around its plane (the 4 largest of all their influences).
  glm::uvec4 joints{0u};
  glm::vec4 weights{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 posedCentre{0.0f}, posedNormal{0.0f, 1.0f, 0.0f};  // per-frame scratch (caps)
};

// A tube end that meets the carried mesh: a band of triangles zipping the tube's end ring to the
// boundary loop of the carried triangles (both sides' own vertices: no gap, no overlap).
// An end of a tube whose input skin is closed but meets nothing (a robot's finger plate): a flat
// fan (rim copies of its ring + a centre vertex) in its end contour's plane.
struct ClassicCap {
  uint32_t contour = 0;
  uint32_t first = 0;        // rays rim vertices, then the centre
  float sign = 1.0f;         // +1: outward = +contour normal (distal end), −1: proximal end
};

struct ClassicBand {
  uint32_t part = 0;
  uint32_t firstIndex = 0, indexCount = 0;  // its triangles in ClassicModel::indices
};

struct ClassicPart {
  uint32_t joint = 0;
  bool isPart = false;       // the joint owns vertices
  bool candidate = false;    // cylinder-like by shape (one child part, long enough; or a trunk part)
  // A branching part of the trunk (pelvis, chest) resampled along its continuing child's bone on
  // the side away from its branches; its branch region (crotch, shoulders) is carried rigidly.
  // 0: not split; 1: vertices with t <= cut carried (pelvis); 2: vertices with t >= cut (chest).
  uint8_t split = 0;
  float cut = 0.0f;
  bool resampled = false;    // candidate whose rays hit well enough
  uint8_t reason = 0;        // why it is (not) resampled: a GcsClassicReason
  int32_t parent = -1;       // parent part joint or −1
  int32_t child = -1;        // the single child part joint (chain parts), or −1
  float length = 0.0f;
  glm::vec3 axis{0.0f, 1.0f, 0.0f};  // bind bone direction (c_child − c_joint, normalised)
  glm::vec3 u{1.0f, 0.0f, 0.0f};     // bind reference direction ⟂ axis (parallel-transported)
  glm::vec3 direction{0.0f, 1.0f, 0.0f};  // bind direction of any part (for the bend of its joint)
  uint32_t contourCount = 0;         // m_j (including shared end contours)
  // Contours span t in [tLo, tHi]: 0 / 1 at a joint shared with a resampled neighbour; at an end
  // that meets the carried mesh, the innermost point of the boundary loop (the band covers the
  // rest); at an open end (nothing beyond), the part's own vertices (up to half a bone past).
  float tLo = 0.0f, tHi = 1.0f, ownTMin = 0.0f, ownTMax = 1.0f;
  float loopTLo = 0.0f, loopTHi = 1.0f;
  int32_t proxLoop = -1, distLoop = -1;  // boundary loops stitched at each end, or −1
  bool proxShared = false, distShared = false;
  std::vector<uint32_t> contours;    // contour ids, proximal → distal
  uint32_t first = 0, count = 0;     // reported output range
  uint32_t runFirst = 0, runCount = 0;  // the part's carried rig vertices (output range)
  float flex = 0.0f;          // per-frame scratch: bend of its distal joint, 0 … 1 (π)
};


class ClassicModel final : public Deformer {
 public:
  GcsDeformerKind kind() const override { return GCS_KIND_CLASSIC; }
  void deform(const glm::mat4* skin) override;
  // The rings only (positions of every tube vertex, caps excepted; no normals): what the on-skin
  // test poses. Returns the frame's scale state.
  ScaleState poseRings(const glm::mat4* skin);
  float stat(GcsStat which) const override;
  float detailLoss(uint32_t which) const;  // 0: RMS, 1: max, % of height (computed on first use)

  uint32_t rays = 0;
  float bulge = 0.0f;
  float height = 1.0f;
  std::vector<ClassicPart> parts;          // indexed by joint
  std::vector<glm::vec3> jointCentres;
  std::vector<ClassicContour> contours;
  std::vector<ClassicBand> bands;         // bands, and caps' fans (their part's "ends")
  std::vector<ClassicCap> caps;
  std::vector<float> radii;                // per contour, `rays` bind radii
  std::vector<float> cosTable, sinTable;   // ray directions in a contour frame
  uint32_t tubeIndexCount = 0;             // tube triangles come first in `indices`
  uint32_t bandIndexCount = 0;             // then the bands' and caps' triangles
  uint32_t tubeVertexCount = 0;            // ring vertices come first in the output (caps follow)
  uint32_t carriedFirst = 0;               // carried rig vertices: [carriedFirst, vertexCount)
  std::vector<float> restPositions, restNormals;  // carried vertices, interleaved (+1 spare)
  std::vector<glm::uvec4> carriedJoints;   // carried vertices' own influences (skinned by DQS)
  std::vector<glm::vec4> carriedWeights;
  std::vector<glm::uvec4> carriedJoints1;  // their slots 4..7 (empty for a rig of at most 4 influences)
  std::vector<glm::vec4> carriedWeights1;
  std::vector<JointPose> poses;            // per-frame scratch: every S_j decomposed
  std::vector<int32_t> report;             // partCount × 5 (see gcs_classic_parts)
  std::vector<int32_t> contourOfVertex;    // per output vertex: its contour, −1 for carried vertices
  std::vector<int32_t> sourceOfVertex;     // per output vertex: the rig vertex it copies, −1 if resampled
  std::vector<uint32_t> reportJoints;      // parts in report order
  // Detail loss inputs: original vertices replaced by the tubes and bands (position, part).
  std::vector<glm::vec3> lossPoints;
  std::vector<uint32_t> lossParts;
  std::vector<glm::vec3> bindPositions;    // every output vertex in the bind pose
  mutable bool lossDone = false;
  mutable float lossRms = 0.0f, lossMax = 0.0f;
};

// Builds the model; records an error and returns null on bad settings (see gcs_build_classic).
ClassicModel* buildClassic(const Rig& rig, uint32_t contours, uint32_t rays, float bulge);

}  // namespace gcs
