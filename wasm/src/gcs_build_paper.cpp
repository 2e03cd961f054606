// The paper's build (Y and axial criteria, docs/method.md §4): parts, shared sections, branches,
// their ends, bins, sections, smooth blends along the branches; then the shared layout (gcs_build.h).
#include "gcs_build.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <tuple>
#include "error.h"

namespace gcs {
namespace {

float segmentDistance2(const glm::vec3& x, const glm::vec3& a, const glm::vec3& b) {
  glm::vec3 ab = b - a;
  float len2 = glm::dot(ab, ab);
  float u = len2 > 0.0f ? glm::clamp(glm::dot(x - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  glm::vec3 d = x - (a + u * ab);
  return glm::dot(d, d);
}

// A branch of a part: the stretch from the part's joint towards one child part (or, for a leaf
// part, along its own bone). Vertices of the part pick the branch of the nearest child segment.
struct Branch {
  uint32_t part = 0;
  int32_t child = -1;        // child part joint, -1 for a leaf
  glm::vec3 axis{0.0f, 1.0f, 0.0f};
  float sProximal = 0.0f, sDistal = 1.0f;
};

// The Y and axial criteria (the paper, docs/method.md §4), step by step: parts, shared sections,
// branches, their ends, bins, sections, smooth blends. Each step reads what the ones before wrote.
class PaperBuild {
 public:
  PaperBuild(const Rig& rig, GcsDeformerImpl& m, const Welded& welded)
      : rig(rig), m(m), group(welded.group), representative(welded.representative), G(uint32_t(representative.size())),
        J(rig.jointCount), axial(m.settings.criterion == GCS_CRITERION_AXIAL) {}

  bool run() {
    assignParts();
    findSharedSections();
    if (!makeBranches()) return false;
    chooseBranches();
    measureBranchEnds();
    binGroups();
    makeSections();
    if (m.settings.smooth) blendAlongBranches();
    m.motions.resize(J);
    m.swings.resize(J);
    m.twists.resize(J);
    finishModel(m);
    return true;
  }

 private:
  const Rig& rig;
  GcsDeformerImpl& m;
  const std::vector<uint32_t>& group;
  const std::vector<uint32_t>& representative;
  const uint32_t G, J;
  const bool axial;
  std::vector<uint32_t> partOfGroup;
  std::vector<std::vector<uint32_t>> childParts;
  std::vector<int32_t> sgsOf;           // child part joint whose proximal SGS holds the group, or -1
  std::vector<Branch> branches;
  std::vector<uint32_t> firstBranch;    // branches of part j: [firstBranch[j], firstBranch[j + 1])
  std::vector<uint32_t> branchOfGroup;
  std::vector<float> tOfGroup;
  // Section slots: per part, one shared (proximal SGS) slot, then per branch `inner` slots.
  std::vector<int32_t> slotOfGroup, sectionOfSlot;
  std::vector<uint32_t> sharedSlot, branchSlot, slotBranch, slotPart;
  std::vector<uint8_t> slotShared;
  uint32_t slots = 0;
  std::vector<float> tOfOutput;

  float coordinate(const Branch& b, const glm::vec3& x) const {
    return axial ? glm::dot(x - rig.jointCentres[b.part], b.axis) : x.y;
  }

  // 1. Parts by dominant weight (per welded position); parent part: the nearest ancestor joint that owns vertices.
  void assignParts() {
    partOfGroup.resize(G);
    m.parts.assign(J, PartInfo());
    for (uint32_t g = 0; g < G; ++g) {
      partOfGroup[g] = rig.dominantJoint(representative[g]);
      m.parts[partOfGroup[g]].isPart = true;
    }
    childParts.assign(J, {});
    for (uint32_t j = 0; j < J; ++j) {
      if (!m.parts[j].isPart) continue;
      ++m.partCount;
      int32_t p = rig.parents[j];
      while (p >= 0 && !m.parts[p].isPart) p = rig.parents[p];
      m.parts[j].parent = p;
      if (p >= 0) childParts[p].push_back(j);
    }
  }

  // 2. Shared sections: vertices on a triangle that spans a part and its parent part.
  void findSharedSections() {
    sgsOf.assign(G, -1);
    for (size_t t = 0; t < rig.indices.size(); t += 3) {
      for (int e = 0; e < 3; ++e) {
        uint32_t a = group[rig.indices[t + e]], b = group[rig.indices[t + (e + 1) % 3]];
        uint32_t pa = partOfGroup[a], pb = partOfGroup[b];
        if (pa == pb) continue;
        int32_t child;
        if (m.parts[pa].parent == int32_t(pb)) child = int32_t(pa);
        else if (m.parts[pb].parent == int32_t(pa)) child = int32_t(pb);
        else continue;  // siblings or unrelated parts: no shared section between them
        if (sgsOf[a] < 0) sgsOf[a] = child;
        if (sgsOf[b] < 0) sgsOf[b] = child;
      }
    }
  }

  // 3. Branches and their axes (and each part's twist axis). False on a zero-length bone.
  bool makeBranches() {
    const float minBone = 1e-4f * rig.height;
    firstBranch.assign(J + 1, 0);
    for (uint32_t j = 0; j < J; ++j) {
      firstBranch[j] = uint32_t(branches.size());
      if (!m.parts[j].isPart) continue;
      const glm::vec3 cj = rig.jointCentres[j];
      if (childParts[j].empty()) {
        Branch b;
        b.part = j;
        int32_t p = m.parts[j].parent;
        glm::vec3 dir = p >= 0 ? cj - rig.jointCentres[p] : glm::vec3(0.0f, 1.0f, 0.0f);
        if (glm::length(dir) < minBone) dir = glm::vec3(0.0f, 1.0f, 0.0f);
        b.axis = glm::normalize(dir);
        branches.push_back(b);
      } else {
        for (uint32_t k : childParts[j]) {
          glm::vec3 bone = rig.jointCentres[k] - cj;
          if (glm::length(bone) < minBone)
            return fail(GCS_ERR_ZERO_LENGTH_BONE,
                        "part of joint %u and its child part of joint %u have their joints at the same point (a zero-length bone)",
                        j, k);
          Branch b;
          b.part = j;
          b.child = int32_t(k);
          b.axis = glm::normalize(bone);
          branches.push_back(b);
        }
      }
      glm::vec3 twist(0.0f);
      for (uint32_t bi = firstBranch[j]; bi < branches.size(); ++bi) twist += branches[bi].axis;
      m.parts[j].twistAxis = glm::length(twist) > 1e-6f ? glm::normalize(twist) : branches[firstBranch[j]].axis;
    }
    firstBranch[J] = uint32_t(branches.size());
    return true;
  }

  // 4. Branch of an inner group: the nearest child segment.
  void chooseBranches() {
    branchOfGroup.assign(G, 0);
    for (uint32_t g = 0; g < G; ++g) {
      uint32_t j = sgsOf[g] >= 0 ? uint32_t(sgsOf[g]) : partOfGroup[g];
      uint32_t best = firstBranch[j];
      if (sgsOf[g] < 0 && firstBranch[j + 1] - firstBranch[j] > 1) {
        const glm::vec3& x = rig.positions[representative[g]];
        float bestD = INFINITY;
        for (uint32_t bi = firstBranch[j]; bi < firstBranch[j + 1]; ++bi) {
          float d = segmentDistance2(x, rig.jointCentres[j], rig.jointCentres[branches[bi].child]);
          if (d < bestD) bestD = d, best = bi;
        }
      }
      branchOfGroup[g] = best;
    }
  }

  // 5. Proximal and distal ends of each branch: the means of its shared sections; leaves end at
  // their vertex farthest from the proximal end.
  void measureBranchEnds() {
    std::vector<double> proxSum(branches.size(), 0.0), distSum(branches.size(), 0.0);
    std::vector<uint32_t> proxN(branches.size(), 0), distN(branches.size(), 0);
    std::vector<float> extreme(branches.size(), 0.0f);
    std::vector<uint8_t> hasExtreme(branches.size(), 0);
    for (uint32_t g = 0; g < G; ++g) {
      const glm::vec3& x = rig.positions[representative[g]];
      if (sgsOf[g] >= 0) {
        uint32_t k = uint32_t(sgsOf[g]);
        for (uint32_t bi = firstBranch[k]; bi < firstBranch[k + 1]; ++bi)
          proxSum[bi] += coordinate(branches[bi], x), ++proxN[bi];
        int32_t p = m.parts[k].parent;
        for (uint32_t bi = firstBranch[p]; bi < firstBranch[p + 1]; ++bi)
          if (branches[bi].child == int32_t(k)) distSum[bi] += coordinate(branches[bi], x), ++distN[bi];
      }
    }
    for (size_t bi = 0; bi < branches.size(); ++bi) {
      Branch& b = branches[bi];
      b.sProximal = proxN[bi] ? float(proxSum[bi] / proxN[bi]) : coordinate(b, rig.jointCentres[b.part]);
      if (b.child >= 0)
        b.sDistal = distN[bi] ? float(distSum[bi] / distN[bi]) : coordinate(b, rig.jointCentres[b.child]);
    }
    for (uint32_t g = 0; g < G; ++g) {
      if (sgsOf[g] >= 0) continue;
      uint32_t bi = branchOfGroup[g];
      if (branches[bi].child >= 0) continue;
      float s = coordinate(branches[bi], rig.positions[representative[g]]);
      if (!hasExtreme[bi] || std::fabs(s - branches[bi].sProximal) > std::fabs(extreme[bi] - branches[bi].sProximal))
        extreme[bi] = s, hasExtreme[bi] = 1;
    }
    for (size_t bi = 0; bi < branches.size(); ++bi)
      if (branches[bi].child < 0)
        branches[bi].sDistal = hasExtreme[bi] ? extreme[bi] : branches[bi].sProximal + 1.0f;
  }

  // 6. Bins: sections−2 inner sections uniform in t between the shared sections.
  //    slot id = sharedSlot[j] (shared) ; branchSlot[bi] + bin (inner)
  void binGroups() {
    const uint32_t inner = m.settings.sections - 2;
    tOfGroup.assign(G, 0.0f);
    slotOfGroup.assign(G, -1);
    sharedSlot.assign(J, 0);
    branchSlot.assign(branches.size(), 0);
    for (uint32_t j = 0; j < J; ++j) {
      if (!m.parts[j].isPart) continue;
      sharedSlot[j] = slots++;
      for (uint32_t bi = firstBranch[j]; bi < firstBranch[j + 1]; ++bi) {
        branchSlot[bi] = slots;
        slots += inner;
      }
    }
    slotBranch.assign(slots, 0);
    slotShared.assign(slots, 0);
    slotPart.assign(slots, 0);
    for (uint32_t j = 0; j < J; ++j) {
      if (!m.parts[j].isPart) continue;
      slotShared[sharedSlot[j]] = 1;
      slotPart[sharedSlot[j]] = j;
      slotBranch[sharedSlot[j]] = firstBranch[j];
      for (uint32_t bi = firstBranch[j]; bi < firstBranch[j + 1]; ++bi)
        for (uint32_t s = 0; s < inner; ++s) slotBranch[branchSlot[bi] + s] = bi, slotPart[branchSlot[bi] + s] = j;
    }
    for (uint32_t g = 0; g < G; ++g) {
      if (sgsOf[g] >= 0) {
        slotOfGroup[g] = int32_t(sharedSlot[sgsOf[g]]);
        continue;
      }
      const Branch& b = branches[branchOfGroup[g]];
      float span = b.sDistal - b.sProximal;
      float s = coordinate(b, rig.positions[representative[g]]);
      float t = std::fabs(span) > 1e-6f * rig.height ? (s - b.sProximal) / span : 0.5f;
      t = glm::clamp(t, 0.0f, 1.0f);
      tOfGroup[g] = t;
      uint32_t bin = std::min(inner - 1, uint32_t(t * float(inner)));
      slotOfGroup[g] = int32_t(branchSlot[branchOfGroup[g]] + bin);
    }
  }

  // 7. Sections: non-empty slots with their fractions, vertices stored section-contiguous.
  void makeSections() {
    std::vector<uint32_t> slotCount(slots, 0);
    std::vector<double> slotT(slots, 0.0);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) {
      uint32_t g = group[v];
      ++slotCount[slotOfGroup[g]];
      slotT[slotOfGroup[g]] += tOfGroup[g];
    }
    sectionOfSlot.assign(slots, -1);
    const float w = m.settings.influenceWidth;
    uint32_t first = 0;
    for (uint32_t sl = 0; sl < slots; ++sl) {
      if (!slotCount[sl]) continue;
      Section sec;
      sec.first = first;
      sec.count = slotCount[sl];
      first += sec.count;
      const Branch& b = branches[slotBranch[sl]];
      sec.part = slotPart[sl];
      sec.parent = m.parts[sec.part].parent;
      if (slotShared[sl]) {
        // The SGS between part and parent: S_parent · D_part^0.5, computed once for both sides.
        sec.shared = true;
        sec.t = 0.0f;
        sec.alpha = sec.parent >= 0 ? 0.5f : 1.0f;
        sec.beta = 0.0f;
        sec.tau = 0.0f;
        sec.distal = -1;
      } else {
        sec.t = float(slotT[sl] / sec.count);
        sec.distal = b.child;
        sec.alpha = sec.parent >= 0 ? 0.5f + 0.5f * glm::clamp(sec.t / w, 0.0f, 1.0f) : 1.0f;
        sec.beta = b.child >= 0 ? 0.5f * glm::clamp(1.0f - (1.0f - sec.t) / w, 0.0f, 1.0f) : 0.0f;
        sec.tau = sec.t;
      }
      sectionOfSlot[sl] = int32_t(m.sections.size());
      m.sections.push_back(sec);
    }
    std::vector<uint32_t> sectionOfGroup(G);
    for (uint32_t g = 0; g < G; ++g) sectionOfGroup[g] = uint32_t(sectionOfSlot[slotOfGroup[g]]);
    std::vector<uint32_t> outputOf = layoutSections(rig, m, group, sectionOfGroup);
    tOfOutput.resize(rig.vertexCount);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) tOfOutput[outputOf[v]] = tOfGroup[group[v]];
  }

  // 8. Smooth mode: each inner vertex blends the two sections whose mean t brackets its own t,
  //    along its branch: proximal SGS (t = 0), the inner sections, the distal SGS (t = 1).
  void blendAlongBranches() {
    const uint32_t inner = m.settings.sections - 2;
    m.blendOther.resize(rig.vertexCount);
    m.blendF.assign(rig.vertexCount, 0.0f);
    m.blendThird = m.sectionOfVertex;  // two sections at most per vertex here
    m.blendThirdF.assign(rig.vertexCount, 0.0f);
    for (uint32_t o = 0; o < rig.vertexCount; ++o) m.blendOther[o] = m.sectionOfVertex[o];
    std::vector<std::pair<float, uint32_t>> chain;
    for (size_t bi = 0; bi < branches.size(); ++bi) {
      const Branch& b = branches[bi];
      chain.clear();
      int32_t prox = sectionOfSlot[sharedSlot[b.part]];
      if (prox >= 0 && m.sections[prox].parent >= 0) chain.push_back({0.0f, uint32_t(prox)});
      for (uint32_t s = 0; s < inner; ++s) {
        int32_t id = sectionOfSlot[branchSlot[bi] + s];
        if (id >= 0) chain.push_back({m.sections[id].t, uint32_t(id)});
      }
      if (b.child >= 0) {
        int32_t dist = sectionOfSlot[sharedSlot[b.child]];
        if (dist >= 0) chain.push_back({1.0f, uint32_t(dist)});
      }
      for (uint32_t s = 0; s < inner; ++s) {
        int32_t id = sectionOfSlot[branchSlot[bi] + s];
        if (id < 0) continue;
        const Section& sec = m.sections[id];
        for (uint32_t o = sec.first; o < sec.first + sec.count; ++o) {
          // The two sections whose mean t brackets the vertex's t; its own is one of them.
          float t = tOfOutput[o];
          size_t k = 0;
          while (k + 1 < chain.size() && chain[k + 1].first < t) ++k;
          uint32_t a = chain[k].second, bsec = k + 1 < chain.size() ? chain[k + 1].second : a;
          float ta = chain[k].first, tb = k + 1 < chain.size() ? chain[k + 1].first : ta;
          float f = tb > ta ? glm::clamp((t - ta) / (tb - ta), 0.0f, 1.0f) : 0.0f;
          if (a == uint32_t(id)) m.blendOther[o] = bsec, m.blendF[o] = f;
          else if (bsec == uint32_t(id)) m.blendOther[o] = a, m.blendF[o] = 1.0f - f;
        }
      }
    }
  }
};

}  // namespace

bool buildPaperCriterion(const Rig& rig, GcsDeformerImpl& m, const Welded& welded) {
  return PaperBuild(rig, m, welded).run();
}

}  // namespace gcs
