// The GCS model's build, raw → runtime (as ozz-animation's offline builders): the steps both
// criteria share (the output layout, finishModel) and each criterion's entry. The weights
// criterion is gcs_build_weights.cpp, the paper's Y and axial criteria gcs_build_paper.cpp; this
// file's steps are gcs_build.cpp, the per-frame kernels gcs_model.cpp.
#pragma once
#include <cstdint>
#include <tuple>
#include <vector>
#include "gcs_model.h"

namespace gcs {

// An output run: the vertices of one section that blend with the same other sections.
struct RunKey {
  uint32_t section = 0, other = 0, third = 0;
  bool operator==(const RunKey& o) const { return section == o.section && other == o.other && third == o.third; }
  bool operator<(const RunKey& o) const { return std::tie(section, other, third) < std::tie(o.section, o.other, o.third); }
};
struct RunKeyHash {
  size_t operator()(const RunKey& k) const {
    uint64_t h = (uint64_t(k.other) << 32 | k.third) * 0x9e3779b97f4a7c15ull ^ uint64_t(k.section) * 0xbf58476d1ce4e5b9ull;
    return size_t(h ^ (h >> 29));
  }
};

// The welded rig: each vertex's group (vertices at one bind-pose position) and each group's first vertex.
struct Welded {
  const std::vector<uint32_t>& group;
  const std::vector<uint32_t>& representative;
};

// Writes the output mesh run by run: a counting sort of the vertices (stable in vertex order) by
// their welded group's run, the runs ordered by (section, other, third). A section's vertices are
// then contiguous, and within it those that blend alike (groupBlendRuns' order, in one pass).
// `runs` in any order. With blends (`blendOfGroup` and `blendThirdOfGroup` not null: each group's
// factors towards its run's other and third), m.blendRuns and the per-vertex blendOther, blendF,
// blendThird, blendThirdF are filled too. Fills m.sections[i].count/first. Returns, for each rig
// vertex, its output index.
std::vector<uint32_t> layoutRuns(const Rig& rig, GcsDeformerImpl& m, const std::vector<uint32_t>& group,
                                 const std::vector<uint32_t>& runOfGroup, const std::vector<RunKey>& runs,
                                 const float* blendOfGroup, const float* blendThirdOfGroup);

// layoutRuns with one run per section (the blends, if any, grouped later: groupBlendRuns).
std::vector<uint32_t> layoutSections(const Rig& rig, GcsDeformerImpl& m, const std::vector<uint32_t>& group,
                                     const std::vector<uint32_t>& sectionOfGroup);

// Bounding spheres (for the adjusted-section statistic), the introspection table, the per-frame
// buffers, and the rest pose in the output. Smooth mode: the blend runs too, unless the layout
// grouped them (`runsGrouped`).
void finishModel(GcsDeformerImpl& m, bool runsGrouped = false);

// Weights criterion: sections (plain) or nodes (smooth) from the weights, their centres of
// rotation, the output layout, the per-vertex blends. False (the error recorded) on failure.
bool buildWeightsCriterion(const Rig& rig, GcsDeformerImpl& m, const Welded& welded);

// The Y and axial criteria (the paper, docs/method.md §4). False (the error recorded) on failure.
bool buildPaperCriterion(const Rig& rig, GcsDeformerImpl& m, const Welded& welded);

}  // namespace gcs
