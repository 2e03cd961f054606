#include "gcs_model.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <unordered_map>
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

}  // namespace

float Deformer::stat(GcsStat) const { return std::nanf(""); }

float GcsDeformerImpl::stat(GcsStat which) const {
  switch (which) {
    case GCS_STAT_SECTIONS: return float(sections.size());
    case GCS_STAT_PARTS: return float(partCount);
    case GCS_STAT_ADJUSTED_SHARE:
      return sections.empty() ? 0.0f : float(adjustedSections) / float(sections.size());
    case GCS_STAT_ADJUSTED_SECTIONS: return float(adjustedSections);
  }
  return std::nanf("");
}

GcsDeformerImpl* buildGcs(const Rig& rig, const GcsSettings& settings) {
  if (settings.sections < GCS_MIN_SECTIONS || settings.sections > GCS_MAX_SECTIONS) {
    fail(GCS_ERR_SECTION_COUNT, "the section count must be between %d and %d (2 shared + at least 1 inner per part); got %u",
         GCS_MIN_SECTIONS, GCS_MAX_SECTIONS, settings.sections);
    return nullptr;
  }
  if (!(settings.influenceWidth > 0.0f && settings.influenceWidth <= 1.0f)) {
    fail(GCS_ERR_OUT_OF_RANGE, "the influence width must be in (0, 1]; got %g", double(settings.influenceWidth));
    return nullptr;
  }
  if (settings.criterion != GCS_CRITERION_Y && settings.criterion != GCS_CRITERION_AXIAL) {
    fail(GCS_ERR_INVALID_ARGUMENT, "unknown section criterion %d (0 = Y, 1 = axial)", int(settings.criterion));
    return nullptr;
  }
  GcsDeformerImpl* model = nullptr;
  try {
    model = new GcsDeformerImpl();
    GcsDeformerImpl& m = *model;
    m.settings = settings;
    m.jointCount = rig.jointCount;
    m.jointCentres = rig.jointCentres;
    m.adjustTolerance = 1e-3f * rig.height;
    const uint32_t J = rig.jointCount;

    // 1. Parts by dominant weight (per welded position).
    std::vector<uint32_t> representative;
    std::vector<uint32_t> group = weldByPosition(rig, representative);
    const uint32_t G = uint32_t(representative.size());
    std::vector<uint32_t> partOfGroup(G);
    m.parts.assign(J, PartInfo());
    for (uint32_t g = 0; g < G; ++g) {
      partOfGroup[g] = rig.dominantJoint(representative[g]);
      m.parts[partOfGroup[g]].isPart = true;
    }
    // Parent part: the nearest ancestor joint that owns vertices.
    std::vector<std::vector<uint32_t>> childParts(J);
    for (uint32_t j = 0; j < J; ++j) {
      if (!m.parts[j].isPart) continue;
      ++m.partCount;
      int32_t p = rig.parents[j];
      while (p >= 0 && !m.parts[p].isPart) p = rig.parents[p];
      m.parts[j].parent = p;
      if (p >= 0) childParts[p].push_back(j);
    }

    // 2. Shared sections: vertices on a triangle that spans a part and its parent part.
    std::vector<int32_t> sgsOf(G, -1);  // child part joint whose proximal SGS holds the group
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

    // 3. Branches and their axes.
    const bool axial = settings.criterion == GCS_CRITERION_AXIAL;
    const float minBone = 1e-4f * rig.height;
    std::vector<Branch> branches;
    std::vector<uint32_t> firstBranch(J + 1, 0);
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
          if (glm::length(bone) < minBone) {
            fail(GCS_ERR_ZERO_LENGTH_BONE,
                 "part of joint %u and its child part of joint %u have their joints at the same point (a zero-length bone)",
                 j, k);
            delete model;
            return nullptr;
          }
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

    auto coordinate = [&](const Branch& b, const glm::vec3& x) {
      return axial ? glm::dot(x - rig.jointCentres[b.part], b.axis) : x.y;
    };
    // Branch of an inner group: the nearest child segment.
    std::vector<uint32_t> branchOfGroup(G, 0);
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

    // 4. Proximal and distal ends of each branch: the means of its shared sections.
    {
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
      // Leaves end at their vertex farthest from the proximal end.
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

    // 5. Bins: sections−2 inner sections uniform in t between the shared sections.
    const uint32_t inner = settings.sections - 2;
    std::vector<float> tOfGroup(G, 0.0f);
    // Section slots: per part, one shared (proximal SGS) slot, then per branch `inner` slots.
    // slot id = partSlot[j] (shared) ; branchSlot[bi] + bin (inner)
    std::vector<int32_t> slotOfGroup(G, -1);
    std::vector<uint32_t> sharedSlot(J, 0), branchSlot(branches.size(), 0);
    uint32_t slots = 0;
    for (uint32_t j = 0; j < J; ++j) {
      if (!m.parts[j].isPart) continue;
      sharedSlot[j] = slots++;
      for (uint32_t bi = firstBranch[j]; bi < firstBranch[j + 1]; ++bi) {
        branchSlot[bi] = slots;
        slots += inner;
      }
    }
    std::vector<uint32_t> slotBranch(slots, 0);
    std::vector<uint8_t> slotShared(slots, 0);
    std::vector<uint32_t> slotPart(slots, 0);
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

    // 6. Sections: non-empty slots, vertices stored section-contiguous (counting sort).
    std::vector<uint32_t> slotCount(slots, 0);
    std::vector<double> slotT(slots, 0.0);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) {
      uint32_t g = group[v];
      ++slotCount[slotOfGroup[g]];
      slotT[slotOfGroup[g]] += tOfGroup[g];
    }
    std::vector<int32_t> sectionOfSlot(slots, -1);
    const float w = settings.influenceWidth;
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
    const uint32_t S = uint32_t(m.sections.size());
    m.allocateOutput(rig.vertexCount);
    m.restPositions.assign(size_t(rig.vertexCount) * 3 + 1, 0.0f);
    m.restNormals.assign(size_t(rig.vertexCount) * 3 + 1, 0.0f);
    m.sourceVertex.resize(rig.vertexCount);
    m.sectionOfVertex.resize(rig.vertexCount);
    std::vector<uint32_t> cursor(S);
    for (uint32_t i = 0; i < S; ++i) cursor[i] = m.sections[i].first;
    std::vector<uint32_t> outputOf(rig.vertexCount);
    std::vector<float> tOfOutput(rig.vertexCount);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) {
      uint32_t sec = uint32_t(sectionOfSlot[slotOfGroup[group[v]]]);
      uint32_t o = cursor[sec]++;
      outputOf[v] = o;
      m.sourceVertex[o] = v;
      m.sectionOfVertex[o] = sec;
      tOfOutput[o] = tOfGroup[group[v]];
      for (int c = 0; c < 3; ++c) {
        m.restPositions[3 * o + c] = rig.positions[v][c];
        m.restNormals[3 * o + c] = rig.normals[v][c];
      }
    }
    m.indices.resize(rig.indices.size());
    for (size_t i = 0; i < rig.indices.size(); ++i) m.indices[i] = outputOf[rig.indices[i]];

    // Bounding spheres (for the adjusted-section statistic) and the introspection table.
    m.sectionInfo.resize(size_t(S) * 8);
    for (uint32_t i = 0; i < S; ++i) {
      Section& sec = m.sections[i];
      glm::vec3 lo(INFINITY), hi(-INFINITY);
      for (uint32_t o = sec.first; o < sec.first + sec.count; ++o) {
        glm::vec3 p(m.restPositions[3 * o], m.restPositions[3 * o + 1], m.restPositions[3 * o + 2]);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
      sec.centre = 0.5f * (lo + hi);
      sec.radius = 0.5f * glm::length(hi - lo);
      float* info = &m.sectionInfo[size_t(i) * 8];
      info[0] = float(sec.first);
      info[1] = float(sec.count);
      info[2] = float(sec.part);
      info[3] = float(sec.distal);
      info[4] = sec.shared ? 1.0f : 0.0f;
      info[5] = sec.t;
      info[6] = sec.alpha;
      info[7] = sec.beta;
    }

    // 7. Smooth mode: each inner vertex blends the two sections whose mean t brackets its own t,
    // along its branch: proximal SGS (t = 0), the inner sections, the distal SGS (t = 1).
    if (settings.smooth) {
      m.blendA.resize(rig.vertexCount);
      m.blendB.resize(rig.vertexCount);
      m.blendF.assign(rig.vertexCount, 0.0f);
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
            float t = tOfOutput[o];
            size_t k = 0;
            while (k + 1 < chain.size() && chain[k + 1].first < t) ++k;
            uint32_t a = chain[k].second, bsec = k + 1 < chain.size() ? chain[k + 1].second : a;
            float ta = chain[k].first, tb = k + 1 < chain.size() ? chain[k + 1].first : ta;
            float f = tb > ta ? glm::clamp((t - ta) / (tb - ta), 0.0f, 1.0f) : 0.0f;
            m.blendA[o] = a;
            m.blendB[o] = bsec;
            m.blendF[o] = f;
          }
        }
      }
      for (uint32_t i = 0; i < S; ++i) {  // shared sections: no blend
        const Section& sec = m.sections[i];
        if (!sec.shared) continue;
        for (uint32_t o = sec.first; o < sec.first + sec.count; ++o) m.blendA[o] = m.blendB[o] = i;
      }
    }

    m.motions.resize(J);
    m.swings.resize(J);
    m.twists.resize(J);
    m.sectionMatrices.assign(S, glm::mat4(1.0f));
    std::memcpy(m.positions.data(), m.restPositions.data(), m.restPositions.size() * sizeof(float));
    std::memcpy(m.normals.data(), m.restNormals.data(), m.restNormals.size() * sizeof(float));
  } catch (const std::bad_alloc&) {
    delete model;
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while building the GCS model");
    return nullptr;
  }
  return model;
}

void GcsDeformerImpl::deform(const glm::mat4* skin) {
  const uint32_t J = jointCount;
  // Relative motion of each part with respect to its parent part: D_j = S_parent^-1 · S_j.
  for (uint32_t j = 0; j < J; ++j) {
    if (!parts[j].isPart || parts[j].parent < 0) continue;
    glm::mat4 d = glm::inverse(skin[parts[j].parent]) * skin[j];
    motions[j] = motionAbout(d, jointCentres[j]);
    if (settings.twistSpread) swingTwist(motions[j].rotation, parts[j].twistAxis, swings[j], twists[j]);
  }
  adjustedSections = 0;
  const uint32_t S = uint32_t(sections.size());
  for (uint32_t i = 0; i < S; ++i) {
    const Section& sec = sections[i];
    glm::mat4 m;
    if (sec.parent < 0) {
      m = skin[sec.part];
    } else {
      const Motion& d = motions[sec.part];
      glm::mat4 frac;
      if (settings.twistSpread) {
        glm::quat r = fractionOf(swings[sec.part], sec.alpha) * fractionOf(twists[sec.part], sec.tau);
        frac = matrixOf(r, d.centre, sec.alpha * d.translation);
      } else {
        frac = fractionMatrix(d, sec.alpha);
      }
      m = skin[sec.parent] * frac;
    }
    if (sec.distal >= 0 && sec.beta > 0.0f) {
      const Motion& d = motions[sec.distal];
      if (settings.twistSpread)
        m = m * matrixOf(fractionOf(swings[sec.distal], sec.beta), d.centre, sec.beta * d.translation);
      else
        m = m * fractionMatrix(d, sec.beta);
    }
    sectionMatrices[i] = m;
    // Adjusted: the section's transform differs from its part's rigid S_j by more than the
    // tolerance anywhere on the section's bounding sphere.
    glm::mat4 diff = m - skin[sec.part];
    glm::vec3 atCentre = glm::vec3(diff * glm::vec4(sec.centre, 1.0f));
    float linear = std::sqrt(glm::dot(glm::vec3(diff[0]), glm::vec3(diff[0])) +
                             glm::dot(glm::vec3(diff[1]), glm::vec3(diff[1])) +
                             glm::dot(glm::vec3(diff[2]), glm::vec3(diff[2])));
    if (glm::length(atCentre) + linear * sec.radius > adjustTolerance) ++adjustedSections;
  }

  if (!settings.smooth) {
    for (uint32_t i = 0; i < S; ++i) {
      const Section& sec = sections[i];
      size_t o = size_t(sec.first) * 3;
      transformRun(sectionMatrices[i], &restPositions[o], &restNormals[o], &positions[o], &normals[o], sec.count);
    }
    return;
  }
  for (uint32_t o = 0; o < vertexCount; ++o) {
    float f = blendF[o];
    const glm::mat4& a = sectionMatrices[blendA[o]];
    const glm::mat4& b = sectionMatrices[blendB[o]];
    glm::mat4 mm = f == 0.0f ? a : a + f * (b - a);
    const float* p = &restPositions[3 * size_t(o)];
    const float* n = &restNormals[3 * size_t(o)];
    glm::vec3 rp = glm::vec3(mm * glm::vec4(p[0], p[1], p[2], 1.0f));
    glm::vec3 rn = glm::vec3(mm * glm::vec4(n[0], n[1], n[2], 0.0f));
    float len = glm::length(rn);
    if (len > 0.0f) rn /= len;
    float* op = &positions[3 * size_t(o)];
    float* on = &normals[3 * size_t(o)];
    op[0] = rp.x, op[1] = rp.y, op[2] = rp.z;
    on[0] = rn.x, on[1] = rn.y, on[2] = rn.z;
  }
}

}  // namespace gcs
