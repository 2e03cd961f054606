// The GCS model's build: the entry (buildGcs: weld the rig, run its criterion) and the steps both
// criteria end with — the output mesh laid out run by run, then finishModel (gcs_build.h).
#include "gcs_build.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <tuple>
#include "error.h"

namespace gcs {

std::vector<uint32_t> layoutRuns(const Rig& rig, GcsDeformerImpl& m, const std::vector<uint32_t>& group,
                                 const std::vector<uint32_t>& runOfGroup, const std::vector<RunKey>& runs,
                                 const float* blendOfGroup, const float* blendThirdOfGroup) {
  const bool blends = blendOfGroup != nullptr;
  const uint32_t R = uint32_t(runs.size());
  std::vector<uint32_t> order(R), rank(R);
  for (uint32_t r = 0; r < R; ++r) order[r] = r;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return runs[a] < runs[b]; });
  for (uint32_t r = 0; r < R; ++r) rank[order[r]] = r;
  std::vector<uint32_t> cursor(R, 0);  // per ranked run: its vertex count, then its next output slot
  for (uint32_t v = 0; v < rig.vertexCount; ++v) ++cursor[rank[runOfGroup[group[v]]]];
  for (Section& sec : m.sections) sec.count = 0;
  uint32_t first = 0;
  for (uint32_t r = 0; r < R; ++r) {
    const RunKey& run = runs[order[r]];
    const uint32_t count = cursor[r];
    m.sections[run.section].count += count;
    if (blends && count) m.blendRuns.push_back({first, count, run.section, run.other, run.third});
    cursor[r] = first;
    first += count;
  }
  first = 0;
  for (Section& sec : m.sections) sec.first = first, first += sec.count;
  const uint32_t V = rig.vertexCount;
  m.vertexCount = V;  // the output arrays: finishModel copies the rest pose into them
  m.restPositions.resize(size_t(V) * 3 + 1);
  m.restNormals.resize(size_t(V) * 3 + 1);
  m.sourceVertex.resize(V);
  m.sectionOfVertex.resize(V);
  if (blends) m.blendOther.resize(V), m.blendThird.resize(V), m.blendF.resize(V), m.blendThirdF.resize(V);
  std::vector<uint32_t> outputOf(V);
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t g = group[v], r = rank[runOfGroup[g]], o = cursor[r]++;
    const RunKey& run = runs[order[r]];
    outputOf[v] = o;
    m.sourceVertex[o] = v;
    m.sectionOfVertex[o] = run.section;
    if (blends) {
      m.blendOther[o] = run.other, m.blendF[o] = blendOfGroup[g];
      m.blendThird[o] = run.third, m.blendThirdF[o] = blendThirdOfGroup[g];
    }
    for (int c = 0; c < 3; ++c) {
      m.restPositions[3 * o + c] = rig.positions[v][c];
      m.restNormals[3 * o + c] = rig.normals[v][c];
    }
  }
  m.indices.resize(rig.indices.size());
  for (size_t i = 0; i < rig.indices.size(); ++i) m.indices[i] = outputOf[rig.indices[i]];
  // The compact joint poses' tolerance (gcs_gcs_compute_joint_poses_compact): R(q)·x for S·x moves
  // a vertex by up to 3 · tolerance · |x|, so a skin far from the origin for its size (a visor 1.7 m
  // up, 12 cm tall) gets a tighter one: its error stays a fraction of its own height.
  float reach = 0.0f;
  for (uint32_t v = 0; v < V; ++v) reach = std::max(reach, glm::length(rig.positions[v]));
  m.compactTolerance = GCS_COMPACT_POSE_TOLERANCE * (reach > rig.height ? rig.height / reach : 1.0f);
  return outputOf;
}

std::vector<uint32_t> layoutSections(const Rig& rig, GcsDeformerImpl& m, const std::vector<uint32_t>& group,
                                     const std::vector<uint32_t>& sectionOfGroup) {
  std::vector<RunKey> runs(m.sections.size());
  for (uint32_t i = 0; i < uint32_t(runs.size()); ++i) runs[i] = {i, i, i};
  return layoutRuns(rig, m, group, sectionOfGroup, runs, nullptr, nullptr);
}

namespace {

// Smooth mode: sorts each section's vertices by the section they blend with (a stable counting
// sort within the section; output arrays and triangle indices follow) and records the runs.
void groupBlendRuns(GcsDeformerImpl& m) {
  const uint32_t N = m.vertexCount;
  std::vector<uint32_t> order(N);  // new output slot → old output index
  for (uint32_t i = 0; i < N; ++i) order[i] = i;
  for (const Section& sec : m.sections) {
    auto begin = order.begin() + sec.first, end = begin + sec.count;
    std::stable_sort(begin, end, [&](uint32_t a, uint32_t b) {
      return std::make_pair(m.blendOther[a], m.blendThird[a]) < std::make_pair(m.blendOther[b], m.blendThird[b]);
    });
  }
  std::vector<uint32_t> newIndex(N);
  for (uint32_t i = 0; i < N; ++i) newIndex[order[i]] = i;
  auto permute3 = [&](std::vector<float>& a) {
    std::vector<float> b(a.size(), 0.0f);
    for (uint32_t i = 0; i < N; ++i)
      for (int c = 0; c < 3; ++c) b[3 * size_t(i) + c] = a[3 * size_t(order[i]) + c];
    a.swap(b);
  };
  permute3(m.restPositions);
  permute3(m.restNormals);
  auto permute = [&](auto& a) {
    auto b = a;
    for (uint32_t i = 0; i < N; ++i) b[i] = a[order[i]];
    a.swap(b);
  };
  permute(m.sourceVertex);
  permute(m.sectionOfVertex);
  permute(m.blendOther);
  permute(m.blendF);
  permute(m.blendThird);
  permute(m.blendThirdF);
  for (uint32_t& index : m.indices) index = newIndex[index];
  m.blendRuns.clear();
  for (uint32_t i = 0; i < uint32_t(m.sections.size()); ++i) {
    const Section& sec = m.sections[i];
    for (uint32_t o = sec.first; o < sec.first + sec.count;) {
      uint32_t end = o;
      while (end < sec.first + sec.count && m.blendOther[end] == m.blendOther[o] && m.blendThird[end] == m.blendThird[o])
        ++end;
      m.blendRuns.push_back({o, end - o, i, m.blendOther[o], m.blendThird[o]});
      o = end;
    }
  }
}

}  // namespace

void finishModel(GcsDeformerImpl& m, bool runsGrouped) {
  const uint32_t S = uint32_t(m.sections.size());
  if (m.settings.smooth && !runsGrouped) groupBlendRuns(m);
  m.sectionInfo.resize(size_t(S) * GCS_SECTION_INFO_FLOATS);
  for (uint32_t i = 0; i < S; ++i) {
    Section& sec = m.sections[i];
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (uint32_t o = sec.first; o < sec.first + sec.count; ++o) {
      glm::vec3 p(m.restPositions[3 * o], m.restPositions[3 * o + 1], m.restPositions[3 * o + 2]);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    sec.centre = sec.count ? 0.5f * (lo + hi) : glm::vec3(0.0f);  // a node only blended towards has no vertex
    sec.radius = sec.count ? 0.5f * glm::length(hi - lo) : 0.0f;
    float* info = &m.sectionInfo[size_t(i) * GCS_SECTION_INFO_FLOATS];
    info[GCS_SECTION_INFO_FIRST] = float(sec.first);
    info[GCS_SECTION_INFO_COUNT] = float(sec.count);
    info[GCS_SECTION_INFO_PART] = float(sec.part);
    info[GCS_SECTION_INFO_DISTAL] = float(sec.distal);
    info[GCS_SECTION_INFO_KIND] = float(sec.rigid ? GCS_SECTION_RIGID : sec.shared ? GCS_SECTION_SHARED : GCS_SECTION_INNER);
    info[GCS_SECTION_INFO_T] = sec.t;
    info[GCS_SECTION_INFO_ALPHA] = sec.alpha;
    info[GCS_SECTION_INFO_BETA] = sec.beta;
  }
  if (m.settings.criterion == GCS_CRITERION_WEIGHTS) {
    uint32_t most = 1;
    for (const Section& sec : m.sections) most = std::max(most, sec.influenceCount);
    const uint32_t slots = m.influenceTableSlots = most > 4 ? 8 : 4;
    m.influenceTable.assign(size_t(S) * 2 * slots, 0.0f);
    for (uint32_t i = 0; i < S; ++i) {
      const Section& sec = m.sections[i];
      float* row = &m.influenceTable[size_t(i) * 2 * slots];
      for (uint32_t k = 0; k < slots; ++k) {
        const bool used = k < sec.influenceCount;
        float* texels = row + 8 * (k / 4);  // per 4 slots: a texel of joints, then one of weights
        texels[k % 4] = used ? float(m.influences[sec.influenceFirst + k].joint) : -1.0f;
        texels[4 + k % 4] = used ? m.influences[sec.influenceFirst + k].weight : 0.0f;
      }
    }
    m.centreTable.assign(size_t(S) * 4, 0.0f);
    for (uint32_t i = 0; i < S; ++i)
      if (m.sections[i].aboutCentre) {
        float* texel = &m.centreTable[size_t(i) * 4];
        for (int c = 0; c < 3; ++c) texel[c] = m.sections[i].rotationCentre[c];
        texel[3] = 1.0f;
      }
  }
  m.poses.resize(m.jointCount);
  std::vector<uint8_t> used(m.jointCount, m.settings.criterion == GCS_CRITERION_WEIGHTS ? 0 : 1);
  for (const Section& sec : m.sections)
    if (sec.rigid) used[sec.part] = 1;
  for (const Influence& in : m.influences) used[in.joint] = 1;
  m.usedJoints.clear();
  for (uint32_t j = 0; j < m.jointCount; ++j)
    if (used[j]) m.usedJoints.push_back(j);
  m.lastSkin.assign(m.jointCount, glm::mat4(1.0f));
  m.sectionMatrices.assign(S, glm::mat4(1.0f));
  m.normalMatrices.assign(S, glm::mat4(1.0f));
  m.renormalise.assign(S, 0);
  uint32_t most = 1;
  for (const Section& sec : m.sections) most = std::max(most, sec.influenceCount);
  m.blendPoseScratch.resize(most);
  // The blended sections ordered by how many joints they blend (so the per-frame accumulation runs
  // one fixed-length loop per count, with no mispredicted exits), and the rigid cores.
  m.blendedSections.clear();
  m.rigidSections.clear();
  for (uint32_t i = 0; i < S; ++i)
    if (m.settings.criterion == GCS_CRITERION_WEIGHTS) (m.sections[i].rigid ? m.rigidSections : m.blendedSections).push_back(i);
  std::stable_sort(m.blendedSections.begin(), m.blendedSections.end(), [&](uint32_t a, uint32_t b) {
    return m.sections[a].influenceCount < m.sections[b].influenceCount;
  });
  m.nodeInfluenceFirst.resize(m.blendedSections.size());
  m.nodesWithCount.assign(kMaxInfluences + 2, 0);
  for (size_t b = 0; b < m.blendedSections.size(); ++b) {
    const Section& sec = m.sections[m.blendedSections[b]];
    m.nodeInfluenceFirst[b] = sec.influenceFirst;
    ++m.nodesWithCount[sec.influenceCount + 1];
  }
  for (uint32_t c = 1; c < kMaxInfluences + 2; ++c) m.nodesWithCount[c] += m.nodesWithCount[c - 1];
  const size_t padded = (m.blendedSections.size() + 3) / 4 * 4;
  m.nodeReal.assign(padded, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  m.nodeDual.assign(padded, glm::vec4(0.0f));
  m.nodeCentre.assign(padded, glm::vec4(0.0f));
  for (size_t b = 0; b < m.blendedSections.size(); ++b) {
    const Section& sec = m.sections[m.blendedSections[b]];
    if (sec.aboutCentre) m.nodeCentre[b] = glm::vec4(sec.rotationCentre, 1.0f);
  }
  m.positions = m.restPositions;
  m.normals = m.restNormals;
}

bool validateSettings(const GcsSettings& given, ModelSettings& settings) {
  if (given.sections < GCS_MIN_SECTIONS || given.sections > GCS_MAX_SECTIONS) {
    fail(GCS_ERR_SECTION_COUNT, "the section count must be between %d and %d (2 shared + at least 1 inner per part); got %u",
         GCS_MIN_SECTIONS, GCS_MAX_SECTIONS, given.sections);
    return false;
  }
  if (given.criterion > GCS_CRITERION_WEIGHTS) {
    fail(GCS_ERR_INVALID_ARGUMENT, "unknown section criterion %u (0 = Y, 1 = axial, 2 = weights)", given.criterion);
    return false;
  }
  if (!(given.influenceWidth > 0.0f && given.influenceWidth <= 1.0f)) {
    fail(GCS_ERR_OUT_OF_RANGE, "the influence width must be in (0, 1]; got %g", double(given.influenceWidth));
    return false;
  }
  if (given.smooth < GCS_SMOOTH_BY_CRITERION || given.smooth > 1) {
    fail(GCS_ERR_INVALID_ARGUMENT, "smooth must be 0, 1 or GCS_SMOOTH_BY_CRITERION (-1); got %d", int(given.smooth));
    return false;
  }
  if (given.twistSpread < 0 || given.twistSpread > 1 || given.centres < 0 || given.centres > 1) {
    fail(GCS_ERR_INVALID_ARGUMENT, "twistSpread and centres must be 0 or 1; got %d and %d", int(given.twistSpread), int(given.centres));
    return false;
  }
  settings.sections = given.sections;
  settings.criterion = GcsCriterion(given.criterion);
  settings.influenceWidth = given.influenceWidth;
  settings.smooth = given.smooth == GCS_SMOOTH_BY_CRITERION ? settings.criterion == GCS_CRITERION_WEIGHTS : given.smooth == 1;
  settings.twistSpread = given.twistSpread == 1;
  settings.centres = given.centres == 1;
  return true;
}

// The settings are checked (validateSettings, by gcs_build_gcs).
GcsDeformerImpl* buildGcs(const Rig& rig, const ModelSettings& settings) {
  GcsDeformerImpl* model = nullptr;
  try {
    model = new GcsDeformerImpl();
    GcsDeformerImpl& m = *model;
    m.settings = settings;
    m.jointCount = rig.jointCount;
    m.jointCentres = rig.jointCentres;
    m.adjustTolerance = 1e-3f * rig.height;
    weldRig(rig);  // kept on the rig: the sliders rebuild it again and again
    const Welded welded{rig.cache.weldGroup, rig.cache.weldRepresentative};
    const bool built = settings.criterion == GCS_CRITERION_WEIGHTS ? buildWeightsCriterion(rig, m, welded)
                                                                    : buildPaperCriterion(rig, m, welded);
    if (!built) {
      delete model;
      return nullptr;
    }
  } catch (const std::bad_alloc&) {
    delete model;
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while building the GCS model");
    return nullptr;
  }
  return model;
}

}  // namespace gcs
