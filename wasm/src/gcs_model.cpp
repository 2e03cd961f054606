#include "gcs_model.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <tuple>
#include "error.h"
#include "rotation_centres.h"

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

// The distinct keys of a build, numbered in order of first sight: open addressing over a
// power-of-two table of key numbers (a node-based map allocates per key and chases pointers; the
// default build looks up two or three keys per welded vertex on every slider step).
template <class Key, class Hash>
class FlatIndex {
 public:
  explicit FlatIndex(size_t expected) { grow(expected); }
  uint32_t idOf(const Key& key) {
    const size_t h = Hash()(key);
    for (size_t i = h & mask;; i = (i + 1) & mask) {
      const uint32_t id = slots[i];
      if (id == 0) break;
      if (hashes[id - 1] == h && keys[id - 1] == key) return id - 1;
    }
    keys.push_back(key);
    hashes.push_back(h);
    if (4 * keys.size() > slots.size()) grow(keys.size());
    else place(uint32_t(keys.size()), h);
    return uint32_t(keys.size() - 1);
  }
  std::vector<Key> keys;

 private:
  void place(uint32_t id, size_t h) {
    size_t i = h & mask;
    while (slots[i]) i = (i + 1) & mask;
    slots[i] = id;
  }
  void grow(size_t count) {  // kept at most a quarter full: regrown to an eighth, every key placed again
    size_t size = 64;
    while (size < 8 * count) size *= 2;
    slots.assign(size, 0);
    mask = size - 1;
    for (size_t k = 0; k < keys.size(); ++k) place(uint32_t(k + 1), hashes[k]);
  }
  std::vector<uint32_t> slots;  // key number + 1, 0 empty
  std::vector<size_t> hashes;   // per key
  size_t mask = 0;
};

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

// Writes the output mesh run by run: a counting sort of the vertices (stable in vertex order) by
// their welded group's run, the runs ordered by (section, other, third). A section's vertices are
// then contiguous, and within it those that blend alike (groupBlendRuns' order, in one pass).
// `runs` in any order. With blends (`blendOfGroup` and `blendThirdOfGroup` not null: each group's
// factors towards its run's other and third), m.blendRuns and the per-vertex blendOther, blendF,
// blendThird, blendThirdF are filled too. Fills m.sections[i].count/first. Returns, for each rig
// vertex, its output index.
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
  return outputOf;
}

// layoutRuns with one run per section (the blends, if any, grouped later: groupBlendRuns).
std::vector<uint32_t> layoutSections(const Rig& rig, GcsDeformerImpl& m, const std::vector<uint32_t>& group,
                                     const std::vector<uint32_t>& sectionOfGroup) {
  std::vector<RunKey> runs(m.sections.size());
  for (uint32_t i = 0; i < uint32_t(runs.size()); ++i) runs[i] = {i, i, i};
  return layoutRuns(rig, m, group, sectionOfGroup, runs, nullptr, nullptr);
}

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

// Bounding spheres (for the adjusted-section statistic), the introspection table, the per-frame
// buffers, and the rest pose in the output. Smooth mode: the blend runs too, unless the layout
// grouped them (`runsGrouped`).
void finishModel(GcsDeformerImpl& m, bool runsGrouped = false) {
  const uint32_t S = uint32_t(m.sections.size());
  if (m.settings.smooth && !runsGrouped) groupBlendRuns(m);
  m.sectionInfo.resize(size_t(S) * 8);
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
    float* info = &m.sectionInfo[size_t(i) * 8];
    info[0] = float(sec.first);
    info[1] = float(sec.count);
    info[2] = float(sec.part);
    info[3] = float(sec.distal);
    info[4] = sec.rigid ? 2.0f : sec.shared ? 1.0f : 0.0f;
    info[5] = sec.t;
    info[6] = sec.alpha;
    info[7] = sec.beta;
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

// A section key of the weights criterion: up to 8 (joint, quantised weight) pairs sorted by joint.
struct WeightKey {
  uint32_t joint[kMaxInfluences] = {~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u};
  uint32_t q[kMaxInfluences] = {0, 0, 0, 0, 0, 0, 0, 0};
  uint32_t n = 0;
  bool operator==(const WeightKey& o) const {
    if (n != o.n) return false;
    for (uint32_t i = 0; i < n; ++i)
      if (joint[i] != o.joint[i] || q[i] != o.q[i]) return false;
    return true;
  }
  // Drops zero entries, sorts by joint, and makes a single joint the rigid core (q = Q).
  void canonical(uint32_t Q) {
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; ++i)
      if (q[i] > 0) joint[k] = joint[i], q[k] = q[i], ++k;
    for (uint32_t i = k; i < kMaxInfluences; ++i) joint[i] = ~0u, q[i] = 0;
    n = k;
    for (uint32_t i = 1; i < n; ++i)
      for (uint32_t j = i; j > 0 && joint[j] < joint[j - 1]; --j) std::swap(joint[j], joint[j - 1]), std::swap(q[j], q[j - 1]);
    if (n == 1) q[0] = Q;
  }
  uint32_t slot(uint32_t j) const {
    for (uint32_t i = 0; i < n; ++i)
      if (joint[i] == j) return i;
    return ~0u;
  }
  // The joint with the largest quantised weight (ties: the lowest id).
  uint32_t dominant() const {
    uint32_t best = 0;
    for (uint32_t i = 1; i < n; ++i)
      if (q[i] > q[best]) best = i;
    return best;
  }
};
struct WeightKeyHash {
  size_t operator()(const WeightKey& k) const {
    uint64_t h = 0x9e3779b97f4a7c15ull ^ k.n;
    for (uint32_t i = 0; i < k.n; ++i) {
      h ^= (uint64_t(k.joint[i]) << 20 | k.q[i]) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      h *= 0xbf58476d1ce4e5b9ull;
    }
    return size_t(h ^ (h >> 31));
  }
};

// The keys in section order: by dominant joint, its rigid core first, then by joint count, then
// joints and weights slot by slot (a part is contiguous).
std::vector<uint32_t> sectionOrder(const std::vector<WeightKey>& keys) {
  const uint32_t K = uint32_t(keys.size());
  std::vector<uint32_t> order(K);
  for (uint32_t k = 0; k < K; ++k) order[k] = k;
  std::vector<uint32_t> dominantJoint(K);
  for (uint32_t k = 0; k < K; ++k) dominantJoint[k] = keys[k].joint[keys[k].dominant()];
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const WeightKey &x = keys[a], &y = keys[b];
    if (dominantJoint[a] != dominantJoint[b]) return dominantJoint[a] < dominantJoint[b];
    if ((x.n == 1) != (y.n == 1)) return x.n == 1;
    if (x.n != y.n) return x.n < y.n;
    for (uint32_t i = 0; i < kMaxInfluences; ++i) {
      if (x.joint[i] != y.joint[i]) return x.joint[i] < y.joint[i];
      if (x.q[i] != y.q[i]) return x.q[i] < y.q[i];
    }
    return false;
  });
  return order;
}

// The sections of the weights criterion from their keys, ordered by dominant joint, its rigid core
// first, then by key (a part is contiguous); `weightOf(key, slot)` is the blend weight of the key's
// joint in that slot (ignored for a rigid core: weight 1). Returns each key's section index.
template <class WeightOf>
std::vector<uint32_t> sectionsFromKeys(GcsDeformerImpl& m, const std::vector<WeightKey>& keys, WeightOf weightOf) {
  const uint32_t K = uint32_t(keys.size());
  const std::vector<uint32_t> order = sectionOrder(keys);
  std::vector<uint32_t> sectionOfKey(K);
  m.sections.resize(K);
  m.influences.clear();
  for (uint32_t i = 0; i < K; ++i) {
    const uint32_t k = order[i];
    sectionOfKey[k] = i;
    const WeightKey& key = keys[k];
    Section& sec = m.sections[i];
    const uint32_t d = key.dominant();
    sec.part = key.joint[d];
    sec.rigid = key.n == 1;
    sec.influenceFirst = uint32_t(m.influences.size());
    uint32_t second = ~0u;
    for (uint32_t s = 0; s < key.n; ++s) {
      m.influences.push_back({key.joint[s], sec.rigid ? 1.0f : weightOf(k, s)});
      if (s != d && (second == ~0u || key.q[s] > key.q[second])) second = s;
    }
    sec.influenceCount = key.n;
    sec.distal = second == ~0u ? -1 : int32_t(key.joint[second]);
    sec.shared = second != ~0u && key.q[second] == key.q[d];
    sec.alpha = m.influences[sec.influenceFirst + d].weight;
    sec.beta = second == ~0u ? 0.0f : m.influences[sec.influenceFirst + second].weight;
    sec.t = sec.beta;
  }
  return sectionOfKey;
}

// The weights criterion (docs/method.md §2): sections are bins of the welded vertices' skin weights on
// a grid of step 1/Q, Q = 2 · (sections − 2) (so the even split between two joints is a bin: their
// shared section). Each section's blend is its members' mean weights on the joints of its key; a
// key with one joint is that joint's rigid core (transform exactly S_j). The stepped level of
// detail (smooth: false); smooth mode builds nodes instead (buildWeightNodes).
void buildWeightSections(const Rig& rig, GcsDeformerImpl& m, const std::vector<uint32_t>& representative,
                         std::vector<uint32_t>& sectionOfGroup) {
  const uint32_t G = uint32_t(representative.size());
  const uint32_t Q = 2 * (m.settings.sections - 2);
  FlatIndex<WeightKey, WeightKeyHash> table(256);  // sections are far fewer than vertices (it grows)
  const std::vector<WeightKey>& keys = table.keys;
  std::vector<uint32_t> keyOf(G);
  // Each group's cleaned weights, kept on the rig (`slots` joints, `slots` weights, a count).
  const WeightGroups& groups = weightGroupsOf(rig);
  const uint32_t slots = groups.slots;
  const std::vector<uint32_t>& cleanJoints = groups.joint;
  const std::vector<float>& cleanWeightsOf = groups.weight;
  const std::vector<uint8_t>& cleanCount = groups.count;
  for (uint32_t g = 0; g < G; ++g) {
    const uint32_t* joint = &cleanJoints[size_t(g) * slots];
    const float* weight = &cleanWeightsOf[size_t(g) * slots];
    const uint32_t n = cleanCount[g];
    uint32_t d = 0;
    for (uint32_t i = 1; i < n; ++i)
      if (weight[i] > weight[d]) d = i;
    WeightKey key;
    key.n = n;
    uint32_t others = 0, largest = 0;
    for (uint32_t i = 0; i < n; ++i) {
      key.joint[i] = joint[i];
      if (i == d) continue;
      key.q[i] = uint32_t(std::floor(weight[i] * float(Q) + 0.5f));
      others += key.q[i];
      largest = std::max(largest, key.q[i]);
    }
    key.q[d] = std::max(others < Q ? Q - others : 0u, std::max(largest, 1u));
    key.canonical(Q);
    keyOf[g] = table.idOf(key);
  }
  // Mean weights per key on its own joints.
  const uint32_t K = uint32_t(keys.size());
  std::vector<double> sums(size_t(K) * kMaxInfluences, 0.0);
  for (uint32_t g = 0; g < G; ++g) {
    const uint32_t* joint = &cleanJoints[size_t(g) * slots];
    const float* weight = &cleanWeightsOf[size_t(g) * slots];
    const uint32_t n = cleanCount[g];
    const WeightKey& key = keys[keyOf[g]];
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t s = key.slot(joint[i]);
      if (s != ~0u) sums[size_t(keyOf[g]) * kMaxInfluences + s] += weight[i];
    }
  }
  // Each key's blend: its members' mean weights (a rigid core: weight 1 on its joint).
  const std::vector<uint32_t> sectionOfKey = sectionsFromKeys(m, keys, [&](uint32_t k, uint32_t slot) {
    double total = 0.0;
    for (uint32_t t = 0; t < keys[k].n; ++t) total += sums[size_t(k) * kMaxInfluences + t];
    return float(sums[size_t(k) * kMaxInfluences + slot] / total);
  });
  sectionOfGroup.resize(G);
  for (uint32_t g = 0; g < G; ++g) sectionOfGroup[g] = sectionOfKey[keyOf[g]];
  m.partCount = 0;
  for (uint32_t i = 0; i < K; ++i) m.partCount += i == 0 || m.sections[i].part != m.sections[i - 1].part;
}

// The cell of the weight lattice (steps of 1/Q) holding three weights that sum to 1: with partial
// sums z1 = Q·w0, z2 = Q·(w0 + w1), the Kuhn triangle of the unit square of (z1, z2) around them.
// x[c]: the c-th corner's weights in units of 1/Q (they sum to Q); mu[c]: its barycentric factor
// (they sum to 1; corner 0 is the square's lower corner).
struct LatticeCell {
  uint32_t x[3][3];
  float mu[3];
};
LatticeCell latticeCell(const float (&weight)[kMaxInfluences], uint32_t Q) {
  const double z1 = double(weight[0]) * Q, z2 = (double(weight[0]) + double(weight[1])) * Q;
  const double f1 = std::floor(z1), f2 = std::min(std::floor(z2), double(Q) - 1.0);
  const double r1 = glm::clamp(z1 - f1, 0.0, 1.0), r2 = glm::clamp(z2 - f2, 0.0, 1.0);
  const uint32_t b1 = uint32_t(f1), b2 = uint32_t(f2);
  // Corners in (z1, z2): (b1, b2), then one step along the larger fraction first, then (b1+1, b2+1).
  const bool firstZ1 = r1 >= r2;
  const uint32_t zc[3][2] = {{b1, b2}, {firstZ1 ? b1 + 1 : b1, firstZ1 ? b2 : b2 + 1}, {b1 + 1, b2 + 1}};
  LatticeCell cell{{}, {float(1.0 - std::max(r1, r2)), float(std::fabs(r1 - r2)), float(std::min(r1, r2))}};
  for (int c = 0; c < 3; ++c) cell.x[c][0] = zc[c][0], cell.x[c][1] = zc[c][1] - zc[c][0], cell.x[c][2] = Q - zc[c][1];
  return cell;
}

// Smooth weights criterion (the default). A welded vertex's cleaned weights are w = (1 − s)·e_d + s·u:
// d its dominant joint, s = 1 − w_d how far it lies from d's rigid core, u the shape of the rest
// (the other joints' shares of s, summing to 1). Sections are NODES on the rays leaving each rigid
// core: (d, u quantised, level l) with s = l/Q; a node moves by the DQS blend at its exact weights
// (level 0 is the rigid core itself, S_d). A vertex belongs to the node at the level just below its
// s and blends with the node just above by its fraction: the result is continuous in s, and in u up
// to 1/(8Q) of weight (1/64 at the default 6 sections), so no step between bins (docs/method.md §2;
// creases measured in §7). The even split of two joints is one key from either side, so their rays
// share that node.
//   A vertex of exactly three joints instead blends the three nodes of its cell on the lattice of
// weights in steps of 1/Q (the triangle of lattice points around it, barycentric factors): the
// result is continuous in all its weights, and its nodes are shared by every vertex of the cell
// (on the human: ~250 nodes instead of ~1,150 for its 1,469 three-joint vertices). Lattice points
// with a zero weight are the two-joint nodes above (the same keys), so the skin stays seamless
// where a third joint's weight fades out.
//   Output: each group's run (the nodes it blends: own, other, third) as an index into `runs`
// (section numbers), and its factors towards the other and the third.
void buildWeightNodes(const Rig& rig, GcsDeformerImpl& m, std::vector<uint32_t>& runOfGroup, std::vector<RunKey>& runs,
                      std::vector<float>& blendOfGroup, std::vector<float>& blendThirdOfGroup) {
  const uint32_t G = uint32_t(rig.weldRepresentative.size());
  // Keys count weight in units of 1/(8Q): at level l the shape u gets 8·l units, so every node's
  // weights sit on one grid of 1/(8Q) (1/64 at the default) and the shape is resolved to s/(8l) ≤ 1/(8Q).
  const uint32_t Q = 2 * (m.settings.sections - 2), total = 8 * Q;
  FlatIndex<WeightKey, WeightKeyHash> table(256);  // nodes are far fewer than vertices (it grows)
  const std::vector<WeightKey>& keys = table.keys;
  auto keyId = [&](WeightKey key) {
    key.canonical(total);
    return table.idOf(key);
  };
  // Each joint's rigid core, looked up once (about half the human's welded vertices sit on one).
  std::vector<uint32_t> rigidKey(rig.jointCount, ~0u);
  auto rigidId = [&](uint32_t j) {
    if (rigidKey[j] == ~0u) {
      WeightKey key;
      key.n = 1;
      key.joint[0] = j;
      key.q[0] = total;
      rigidKey[j] = keyId(key);
    }
    return rigidKey[j];
  };
  const WeightGroups& groups = weightGroupsOf(rig);  // each group's cleaned weights, kept on the rig
  const uint32_t slots = groups.slots;
  // The node of a two-joint group at level l > 0 depends on its ordered pair (d, other) and l
  // only: its other joint's share is w_o / s · 8l with s = 1 − w_d = w_o to a few ulps (d weighs
  // at least 1/2, so 1 − w_d is exact), which the largest remainder rounds to 8l. So each (pair,
  // level) is looked up once (while the table stays in proportion to the groups).
  const uint32_t levels = Q + 1;
  const bool byPair = groups.pairs.size() * levels <= size_t(G) + 4096;
  std::vector<uint32_t> pairNode(byPair ? groups.pairs.size() * levels : 0, ~0u);
  // Runs as key triples (low, high, third), numbered in order of first sight; the run of a rigid
  // vertex per joint, and of a two-joint group per (pair, level, blends or not), looked up once.
  FlatIndex<RunKey, RunKeyHash> runTable(1024);
  std::vector<uint32_t> rigidRun(rig.jointCount, ~0u), pairRun(pairNode.size() * 2, ~0u);
  runOfGroup.resize(G);
  blendOfGroup.assign(G, 0.0f);
  blendThirdOfGroup.assign(G, 0.0f);
  for (uint32_t g = 0; g < G; ++g) {
    uint32_t joint[kMaxInfluences] = {};
    float weight[kMaxInfluences] = {};
    const uint32_t n = groups.count[g];
    for (uint32_t i = 0; i < n; ++i)
      joint[i] = groups.joint[size_t(g) * slots + i], weight[i] = groups.weight[size_t(g) * slots + i];
    if (n == 1) {
      uint32_t& run = rigidRun[joint[0]];
      if (run == ~0u) {
        const uint32_t k = rigidId(joint[0]);
        run = runTable.idOf({k, k, k});
      }
      runOfGroup[g] = run;
      continue;
    }
    if (n == 3) {
      // One triangulation per joint triple: the joints in a fixed order (by index).
      for (uint32_t i = 1; i < 3; ++i)
        for (uint32_t k = i; k > 0 && joint[k] < joint[k - 1]; --k) std::swap(joint[k], joint[k - 1]), std::swap(weight[k], weight[k - 1]);
      const LatticeCell cell = latticeCell(weight, Q);
      uint32_t ids[3];
      for (int c = 0; c < 3; ++c) {
        WeightKey key;
        key.n = 3;
        for (int i = 0; i < 3; ++i) key.joint[i] = joint[i], key.q[i] = 8 * cell.x[c][i];
        ids[c] = keyId(key);
      }
      runOfGroup[g] = runTable.idOf({ids[0], ids[1], ids[2]});
      blendOfGroup[g] = cell.mu[1];
      blendThirdOfGroup[g] = cell.mu[2];
      continue;
    }
    uint32_t d = 0;
    for (uint32_t i = 1; i < n; ++i)
      if (weight[i] > weight[d]) d = i;
    const float s = n > 1 ? glm::clamp(1.0f - weight[d], 0.0f, 1.0f) : 0.0f;
    const float x = s * float(Q);
    const uint32_t level = std::min(uint32_t(std::floor(x)), Q);
    const float frac = x - float(level);
    // The node at level l: d keeps 8·(Q − l) units, the shape u's 8·l units go by largest remainders.
    uint32_t* pairLevels = byPair && groups.pairOf[g] != ~0u ? &pairNode[size_t(groups.pairOf[g]) * levels] : nullptr;
    auto nodeKey = [&](uint32_t l) {
      if (l == 0) return rigidId(joint[d]);  // the key below would reduce to it (canonical)
      if (pairLevels && pairLevels[l] != ~0u) return pairLevels[l];
      WeightKey key;
      key.n = n;
      const uint32_t units = 8 * l;
      float rem[kMaxInfluences] = {-1.0f, -1.0f, -1.0f, -1.0f, -1.0f, -1.0f, -1.0f, -1.0f};
      uint32_t used = 0;
      for (uint32_t i = 0; i < n; ++i) {
        key.joint[i] = joint[i];
        if (i == d) continue;
        const float share = s > 0.0f ? weight[i] / s * float(units) : 0.0f;
        key.q[i] = uint32_t(std::floor(share));
        rem[i] = share - float(key.q[i]);
        used += key.q[i];
      }
      while (used < units) {
        uint32_t best = d == 0 ? 1 : 0;
        for (uint32_t i = 0; i < n; ++i)
          if (i != d && rem[i] > rem[best]) best = i;
        ++key.q[best], rem[best] = -1.0f, ++used;
      }
      key.q[d] = 8 * (Q - l);
      const uint32_t id = keyId(key);
      if (pairLevels) pairLevels[l] = id;
      return id;
    };
    const bool blends = frac > 1e-6f && level < Q;
    if (blends) blendOfGroup[g] = frac;
    uint32_t* run = pairLevels ? &pairRun[2 * (size_t(groups.pairOf[g]) * levels + level) + blends] : nullptr;
    if (run && *run != ~0u) {
      runOfGroup[g] = *run;
      continue;
    }
    const uint32_t low = nodeKey(level), high = blends ? nodeKey(level + 1) : low;
    runOfGroup[g] = runTable.idOf({low, high, low});
    if (run) *run = runOfGroup[g];
  }
  // Each node's blend: exactly its key's weights.
  const std::vector<uint32_t> sectionOfKey = sectionsFromKeys(m, keys, [&](uint32_t k, uint32_t slot) {
    return float(keys[k].q[slot]) / float(total);
  });
  const uint32_t K = uint32_t(keys.size());
  runs.resize(runTable.keys.size());
  for (size_t r = 0; r < runs.size(); ++r) {
    const RunKey& k = runTable.keys[r];
    runs[r] = {sectionOfKey[k.section], sectionOfKey[k.other], sectionOfKey[k.third]};
  }
  m.partCount = 0;
  for (uint32_t i = 0; i < K; ++i) m.partCount += i == 0 || m.sections[i].part != m.sections[i - 1].part;
}

// Weights criterion with centres: each blended section's centre of rotation from its blend weights
// (nodeCentre: a bending pair's only; a rigid core needs none, it is S_j; any other section keeps the
// plain blend).
bool placeRotationCentres(const Rig& rig, GcsDeformerImpl& m) {
  const CentreSurface* surface = centreSurfaceOf(rig);
  if (!surface) return false;
  uint32_t joints[kMaxInfluences];
  float weights[kMaxInfluences];
  for (Section& sec : m.sections) {
    if (sec.rigid) continue;
    for (uint32_t k = 0; k < sec.influenceCount; ++k) {
      joints[k] = m.influences[sec.influenceFirst + k].joint;
      weights[k] = m.influences[sec.influenceFirst + k].weight;
    }
    sec.aboutCentre = nodeCentre(rig, *surface, joints, weights, sec.influenceCount, sec.rotationCentre);
  }
  return true;
}

}  // namespace

float Deformer::stat(GcsStat) const { return std::nanf(""); }

float GcsDeformerImpl::stat(GcsStat which) const {
  switch (which) {
    case GCS_STAT_SECTIONS: return float(sections.size());
    case GCS_STAT_PARTS: return float(partCount);
    case GCS_STAT_ADJUSTED_SHARE:
      return sections.empty() ? 0.0f : float(countAdjusted()) / float(sections.size());
    case GCS_STAT_ADJUSTED_SECTIONS: return float(countAdjusted());
  }
  return std::nanf("");
}

namespace {

// The build, raw → runtime (ozz's builders): each criterion as a sequence of named steps over the
// welded rig. Every step leaves the model consistent for the next; finishModel ends both.

// The welded rig: each vertex's group (vertices at one bind-pose position) and each group's first vertex.
struct Welded {
  const std::vector<uint32_t>& group;
  const std::vector<uint32_t>& representative;
};

// Weights criterion: sections (plain) or nodes (smooth) from the weights, their centres of
// rotation, the output layout, the per-vertex blends. False (the error recorded) on failure.
bool buildWeightsCriterion(const Rig& rig, GcsDeformerImpl& m, const Welded& welded) {
  if (!m.settings.smooth) {
    std::vector<uint32_t> sectionOfGroup;
    buildWeightSections(rig, m, welded.representative, sectionOfGroup);
    if (m.settings.centres && !placeRotationCentres(rig, m)) return false;
    layoutSections(rig, m, welded.group, sectionOfGroup);
    finishModel(m);
    return true;
  }
  std::vector<uint32_t> runOfGroup;
  std::vector<RunKey> runs;
  std::vector<float> blendOfGroup, blendThirdOfGroup;
  buildWeightNodes(rig, m, runOfGroup, runs, blendOfGroup, blendThirdOfGroup);
  if (m.settings.centres && !placeRotationCentres(rig, m)) return false;
  layoutRuns(rig, m, welded.group, runOfGroup, runs, blendOfGroup.data(), blendThirdOfGroup.data());
  finishModel(m, true);
  return true;
}

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

// The settings are the C API's, checked there once (gcs_build_gcs).
GcsDeformerImpl* buildGcs(const Rig& rig, const GcsSettings& settings) {
  GcsDeformerImpl* model = nullptr;
  try {
    model = new GcsDeformerImpl();
    GcsDeformerImpl& m = *model;
    m.settings = settings;
    m.jointCount = rig.jointCount;
    m.jointCentres = rig.jointCentres;
    m.adjustTolerance = 1e-3f * rig.height;
    weldRig(rig);  // kept on the rig: the sliders rebuild it again and again
    const Welded welded{rig.weldGroup, rig.weldRepresentative};
    const bool built = settings.criterion == GCS_CRITERION_WEIGHTS ? buildWeightsCriterion(rig, m, welded)
                                                                    : PaperBuild(rig, m, welded).run();
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

namespace {
// [R | t] of a decomposed skin matrix (its rigid part) and the inverse of such a matrix.
glm::mat4 rigidOf(const JointPose& p) {
  glm::mat4 m = glm::mat4_cast(p.rotation);
  m[3] = glm::vec4(p.translation, 1.0f);
  return m;
}
glm::mat4 rigidInverse(const glm::mat4& m) {
  glm::mat3 rt = glm::transpose(glm::mat3(m));
  glm::mat4 out(rt);
  out[3] = glm::vec4(-(rt * glm::vec3(m[3])), 1.0f);
  return out;
}
}  // namespace

// A section with a centre of rotation p* (rotation_centres.h): its 3×3 part M (the blend's rotation
// and scale) stays; its translation makes M p* + t = Σ w_j S_j p*, p* moved by linear blend
// skinning. Written t = Σ w_j (S_j p* − p*) − (M p* − p*): identity poses give t = 0 exactly.
void GcsDeformerImpl::turnAboutCentre(const glm::mat4* skin, const Section& sec, glm::mat4& position) const {
  const glm::vec3 p = sec.rotationCentre;
  glm::vec3 moved(0.0f);
  for (uint32_t k = 0; k < sec.influenceCount; ++k) {
    const Influence& in = influences[sec.influenceFirst + k];
    const glm::mat4& s = skin[in.joint];
    moved += in.weight * (glm::vec3(s[0]) * p.x + glm::vec3(s[1]) * p.y + glm::vec3(s[2]) * p.z + glm::vec3(s[3]) - p);
  }
  const glm::vec3 turned = glm::vec3(position[0]) * p.x + glm::vec3(position[1]) * p.y + glm::vec3(position[2]) * p.z - p;
  position[3] = glm::vec4(moved - turned, 1.0f);
}

// Weights criterion: each section's transform is the dual-quaternion blend of its joints at its
// mean weights (a rigid core: S_j itself), or with centres the blend's rotation about its centre of
// rotation. O(sections × influences).
void GcsDeformerImpl::sectionTransformsWeights(const glm::mat4* skin, const ScaleState& scale) {
#if defined(__wasm_simd128__)
  if (moderateUniform(scale)) return sectionTransformsWeightsUniform(skin, scale.s);
#endif
  const uint32_t S = uint32_t(sections.size());
  for (uint32_t i = 0; i < S; ++i) {
    const Section& sec = sections[i];
    bool renorm = false;
    if (sec.rigid) {
      sectionMatrices[i] = skin[sec.part];
      normalMatrices[i] = poses[sec.part].normal;
      renorm = poses[sec.part].renormalise;
    } else {
      float w[kMaxInfluences];
      for (uint32_t k = 0; k < sec.influenceCount; ++k) {
        const Influence& in = influences[sec.influenceFirst + k];
        blendPoseScratch[k] = &poses[in.joint];
        w[k] = in.weight;
      }
      blendPoses(blendPoseScratch.data(), w, sec.influenceCount, scale, sectionMatrices[i], normalMatrices[i], renorm);
      if (sec.aboutCentre) turnAboutCentre(skin, sec, sectionMatrices[i]);
    }
    renormalise[i] = renorm;
  }
}

#if defined(__wasm_simd128__)

namespace {
// A node's dual quaternion (real part in br, dual part in bd): its joints' weighted sum, each
// weight negated when the joint's quaternion lies in the other hemisphere from the first's.
template <uint32_t Count>
inline void accumulateNode(const JointPose* poses, const Influence* in, uint32_t count, v128_t& br, v128_t& bd) {
  const v128_t signBit = wasm_f32x4_splat(-0.0f);
  const v128_t pivot = wasm_v128_load(&poses[in[0].joint].real);
  const v128_t w0 = wasm_f32x4_splat(in[0].weight);
  br = wasm_f32x4_mul(w0, pivot);
  bd = wasm_f32x4_mul(w0, wasm_v128_load(&poses[in[0].joint].dual));
  const uint32_t n = Count ? Count : count;
  for (uint32_t k = 1; k < n; ++k) {
    const JointPose& p = poses[in[k].joint];
    const v128_t r = wasm_v128_load(&p.real);
    v128_t dot = wasm_f32x4_mul(r, pivot);
    dot = wasm_f32x4_add(dot, wasm_i32x4_shuffle(dot, dot, 1, 0, 3, 2));
    dot = wasm_f32x4_add(dot, wasm_i32x4_shuffle(dot, dot, 2, 3, 0, 1));
    const v128_t w = wasm_v128_xor(wasm_f32x4_splat(in[k].weight), wasm_v128_and(dot, signBit));
    br = wasm_f32x4_add(br, wasm_f32x4_mul(w, r));
    bd = wasm_f32x4_add(bd, wasm_f32x4_mul(w, wasm_v128_load(&p.dual)));
  }
}
}  // namespace

// The same blends as sectionTransformsWeights when every scale is s·I (the common case), in SIMD:
// each blended section's dual quaternion accumulated in two registers (nodes grouped by joint
// count), then four sections at a time turned into matrices (one lane each), with the very formulas
// of blendPoses. Blended sections' normal matrices are not written: with a uniform scale they are
// their position matrices over s, and deform() uses them so.
void GcsDeformerImpl::sectionTransformsWeightsUniform(const glm::mat4* skin, float s) {
  std::fill(renormalise.begin(), renormalise.end(), uint8_t(0));
  for (uint32_t i : rigidSections) {
    const uint32_t j = sections[i].part;
    sectionMatrices[i] = skin[j];
    normalMatrices[i] = poses[j].normal;
  }
  const JointPose* pose = poses.data();
  const Influence* influence = influences.data();
  uint32_t b = 0;
  for (uint32_t count = 1; count <= kMaxInfluences; ++count) {
    const uint32_t end = nodesWithCount[count + 1];
    for (; b < end; ++b) {
      v128_t br, bd;
      const Influence* in = influence + nodeInfluenceFirst[b];
      if (count == 2) accumulateNode<2>(pose, in, count, br, bd);
      else if (count == 3) accumulateNode<3>(pose, in, count, br, bd);
      else if (count == 4) accumulateNode<4>(pose, in, count, br, bd);
      else accumulateNode<0>(pose, in, count, br, bd);
      wasm_v128_store(&nodeReal[b], br);
      wasm_v128_store(&nodeDual[b], bd);
    }
  }
  const uint32_t B = b;
  const v128_t one = wasm_f32x4_splat(1.0f), two = wasm_f32x4_splat(2.0f), scale = wasm_f32x4_splat(s);
  const v128_t zero = wasm_f32x4_splat(0.0f);
  for (uint32_t g = 0; g < B; g += 4) {
    v128_t x = wasm_v128_load(&nodeReal[g]), y = wasm_v128_load(&nodeReal[g + 1]);
    v128_t z = wasm_v128_load(&nodeReal[g + 2]), w = wasm_v128_load(&nodeReal[g + 3]);
    transpose4(x, y, z, w);
    v128_t dx = wasm_v128_load(&nodeDual[g]), dy = wasm_v128_load(&nodeDual[g + 1]);
    v128_t dz = wasm_v128_load(&nodeDual[g + 2]), dw = wasm_v128_load(&nodeDual[g + 3]);
    transpose4(dx, dy, dz, dw);
    const v128_t inv2 = wasm_f32x4_div(
        one, wasm_f32x4_add(wasm_f32x4_add(wasm_f32x4_mul(x, x), wasm_f32x4_mul(y, y)),
                            wasm_f32x4_add(wasm_f32x4_mul(z, z), wasm_f32x4_mul(w, w))));
    const v128_t k2 = wasm_f32x4_mul(two, inv2);
    const v128_t xx = wasm_f32x4_mul(x, x), yy = wasm_f32x4_mul(y, y), zz = wasm_f32x4_mul(z, z);
    const v128_t xy = wasm_f32x4_mul(x, y), xz = wasm_f32x4_mul(x, z), yz = wasm_f32x4_mul(y, z);
    const v128_t wx = wasm_f32x4_mul(w, x), wy = wasm_f32x4_mul(w, y), wz = wasm_f32x4_mul(w, z);
    auto oneMinus = [&](v128_t a, v128_t b2) { return wasm_f32x4_sub(one, wasm_f32x4_mul(k2, wasm_f32x4_add(a, b2))); };
    auto times = [&](v128_t a) { return wasm_f32x4_mul(k2, a); };
    // Rows of the transposed blocks: entry (row r of column c) for the four sections.
    v128_t c00 = oneMinus(yy, zz), c01 = times(wasm_f32x4_add(xy, wz)), c02 = times(wasm_f32x4_sub(xz, wy)), c03 = zero;
    v128_t c10 = times(wasm_f32x4_sub(xy, wz)), c11 = oneMinus(xx, zz), c12 = times(wasm_f32x4_add(yz, wx)), c13 = zero;
    v128_t c20 = times(wasm_f32x4_add(xz, wy)), c21 = times(wasm_f32x4_sub(yz, wx)), c22 = oneMinus(xx, yy), c23 = zero;
    // t = 2·(w·d − dw·r − d × r)/|r|² (the vector part of 2·bd·conj(br)/|br|²).
    auto tRow = [&](v128_t wd, v128_t dwr, v128_t crossA, v128_t crossB) {
      return wasm_f32x4_mul(k2, wasm_f32x4_sub(wasm_f32x4_sub(wasm_f32x4_mul(w, wd), wasm_f32x4_mul(dw, dwr)),
                                               wasm_f32x4_sub(crossA, crossB)));
    };
    v128_t t0 = tRow(dx, x, wasm_f32x4_mul(dy, z), wasm_f32x4_mul(y, dz));
    v128_t t1 = tRow(dy, y, wasm_f32x4_mul(dz, x), wasm_f32x4_mul(z, dx));
    v128_t t2 = tRow(dz, z, wasm_f32x4_mul(dx, y), wasm_f32x4_mul(x, dy));
    v128_t t3 = one;
    transpose4(c00, c01, c02, c03);
    transpose4(c10, c11, c12, c13);
    transpose4(c20, c21, c22, c23);
    transpose4(t0, t1, t2, t3);
    const v128_t normalCol[3][4] = {{c00, c01, c02, c03}, {c10, c11, c12, c13}, {c20, c21, c22, c23}};
    const v128_t translation[4] = {t0, t1, t2, t3};
    for (uint32_t k = 0; k < 4 && g + k < B; ++k) {
      float* m = &sectionMatrices[blendedSections[g + k]][0][0];
      for (int c = 0; c < 3; ++c) wasm_v128_store(m + 4 * c, wasm_f32x4_mul(scale, normalCol[c][k]));
      wasm_v128_store(m + 12, translation[k]);
    }
  }
  if (settings.centres)  // the centres' translations replace the blends' (none otherwise: no pass)
    for (uint32_t b2 = 0; b2 < B; ++b2)
      if (nodeCentre[b2].w != 0.0f) {
        const uint32_t i = blendedSections[b2];
        turnAboutCentre(skin, sections[i], sectionMatrices[i]);
      }
}
#endif

// The paper's rule (Y and axial criteria): M = S_p · D_j^α · D_k^β on the rigid parts of the skin
// matrices, then the section's scale (the same blend of the joints' scales) applied first.
void GcsDeformerImpl::sectionTransformsPaper(const glm::mat4* skin, const ScaleState& scale) {
  const uint32_t J = jointCount;
  // Relative motion of each part with respect to its parent part: D_j = rigid(S_p)^-1 · rigid(S_j).
  for (uint32_t j = 0; j < J; ++j) {
    if (!parts[j].isPart || parts[j].parent < 0) continue;
    glm::mat4 d = rigidInverse(rigidOf(poses[parts[j].parent])) * rigidOf(poses[j]);
    // The rigid parts act on scaled points (S = [R | t]·K): their joint centre is K·c_j.
    motions[j] = motionAbout(d, poses[j].scale * jointCentres[j]);
    if (settings.twistSpread) swingTwist(motions[j].rotation, parts[j].twistAxis, swings[j], twists[j]);
  }
  const uint32_t S = uint32_t(sections.size());
  for (uint32_t i = 0; i < S; ++i) {
    const Section& sec = sections[i];
    bool renorm = false;
    if (sec.parent < 0 && !(sec.distal >= 0 && sec.beta > 0.0f)) {
      sectionMatrices[i] = skin[sec.part];
      normalMatrices[i] = poses[sec.part].normal;
      renormalise[i] = poses[sec.part].renormalise;
      continue;
    }
    glm::mat4 m;
    if (sec.parent < 0) {
      m = rigidOf(poses[sec.part]);
    } else {
      const Motion& d = motions[sec.part];
      glm::mat4 frac;
      if (settings.twistSpread) {
        glm::quat r = fractionOf(swings[sec.part], sec.alpha) * fractionOf(twists[sec.part], sec.tau);
        frac = matrixOf(r, d.centre, sec.alpha * d.translation);
      } else {
        frac = fractionMatrix(d, sec.alpha);
      }
      m = rigidOf(poses[sec.parent]) * frac;
    }
    if (sec.distal >= 0 && sec.beta > 0.0f) {
      const Motion& d = motions[sec.distal];
      if (settings.twistSpread)
        m = m * matrixOf(fractionOf(swings[sec.distal], sec.beta), d.centre, sec.beta * d.translation);
      else
        m = m * fractionMatrix(d, sec.beta);
    }
    // Scale: parent, part and distal joint weighted (1 − α, α − β, β), applied first.
    if (scale.uniform) {  // the common case: m's rotation carries the normals as it is
      sectionMatrices[i] = glm::mat4(scale.s * m[0], scale.s * m[1], scale.s * m[2], m[3]);
      normalMatrices[i] = glm::mat4(m[0], m[1], m[2], glm::vec4(0.0f));
      renormalise[i] = 0;
      continue;
    }
    glm::mat3 k = poses[sec.part].scale;
    if (!scale.same) {
      k = (sec.parent >= 0 ? sec.alpha : 1.0f) * k;
      if (sec.parent >= 0) k += (1.0f - sec.alpha) * poses[sec.parent].scale;
      if (sec.distal >= 0 && sec.beta > 0.0f) k += sec.beta * (poses[sec.distal].scale - poses[sec.part].scale);
    }
    glm::mat3 r(m);
    glm::mat3 rk = r * k;
    sectionMatrices[i] = glm::mat4(glm::vec4(rk[0], 0.0f), glm::vec4(rk[1], 0.0f), glm::vec4(rk[2], 0.0f), m[3]);
    glm::mat4 n(normalMatrix(glm::quat_cast(r), k, renorm));
    n[3] = glm::vec4(0.0f);
    normalMatrices[i] = n;
    renormalise[i] = renorm;
  }
}

// Adjusted: the section's transform differs from its part's rigid S_j by more than the tolerance
// anywhere on the section's bounding sphere. Over the last frame; cached until the next deform.
uint32_t GcsDeformerImpl::countAdjusted() const {
  if (adjustedValid) return adjustedSections;
  uint32_t adjusted = 0;
  for (uint32_t i = 0; i < uint32_t(sections.size()); ++i) {
    const Section& sec = sections[i];
    glm::mat4 diff = sectionMatrices[i] - lastSkin[sec.part];
    glm::vec3 atCentre = glm::vec3(diff * glm::vec4(sec.centre, 1.0f));
    float linear = std::sqrt(glm::dot(glm::vec3(diff[0]), glm::vec3(diff[0])) +
                             glm::dot(glm::vec3(diff[1]), glm::vec3(diff[1])) +
                             glm::dot(glm::vec3(diff[2]), glm::vec3(diff[2])));
    if (glm::length(atCentre) + linear * sec.radius > adjustTolerance) ++adjusted;
  }
  adjustedSections = adjusted;
  adjustedValid = true;
  return adjusted;
}

void GcsDeformerImpl::computeSections(const glm::mat4* skin) {
  const uint32_t J = jointCount;
  const ScaleState scale = decomposeJoints(skin, usedJoints.data(), uint32_t(usedJoints.size()), poses.data());
  frameScale = scale;
  if (settings.criterion == GCS_CRITERION_WEIGHTS) sectionTransformsWeights(skin, scale);
  else sectionTransformsPaper(skin, scale);
  // The adjusted-section statistic is computed when asked for (stat), from a copy of the skin.
  std::memcpy(lastSkin.data(), skin, size_t(J) * sizeof(glm::mat4));
  adjustedValid = false;
}

void GcsDeformerImpl::deform(const glm::mat4* skin) {
  computeSections(skin);
  transformVertices(restNormals.data(), positions.data(), normals.data());
  if (!tangents.empty()) {
    // Tangents turn like normals: the same kernels over the rest tangents (positions discarded).
    transformVertices(restTangents.data(), tangentPassPositions.data(), turnedTangents.data());
    packTangents();
  }
}

// Every vertex by this frame's section transforms: positions from the rest positions, and
// `inNrm` (the rest normals, or the rest tangents) turned into `outNrm`.
void GcsDeformerImpl::transformVertices(const float* inNrm, float* outPos, float* outNrm) {
  const uint32_t S = uint32_t(sections.size());
  // Every scale the same uniform s (and the weights criterion, whose normal matrices are then the
  // rotations of the position matrices, and are not written for blended sections): one matrix, or
  // one lerp, serves positions and normals.
  const bool uniform = moderateUniform(frameScale) && settings.criterion == GCS_CRITERION_WEIGHTS;
  const float invS = uniform ? 1.0f / frameScale.s : 1.0f, invS2 = invS * invS;
  if (settings.smooth) {
    for (const BlendRun& run : blendRuns) {
      size_t o = size_t(run.first) * 3;
      const uint32_t a = run.section, b = run.other;
      if (uniform) {
        const float* f = &blendF[run.first];
        const float* p = &restPositions[o];
        const float* n = inNrm + o;
        if (run.third != a) {  // a three-joint lattice cell
          const uint32_t c = run.third;
          const float* g = &blendThirdF[run.first];
          const NormalFix fix3 =
              rotationBlendFix3(leastRotationTrace(sectionMatrices[a], sectionMatrices[b], sectionMatrices[c]) * invS2);
          withUniformFix(fix3, invS == 1.0f, [&](auto fixTag, auto unitTag) {
            blendRun3UniformT<decltype(fixTag)::value, decltype(unitTag)::value>(
                sectionMatrices[a], sectionMatrices[b], sectionMatrices[c], invS, f, g, p, n, outPos + o, outNrm + o,
                run.count);
          });
          continue;
        }
        if (a == b) {
          transformRunUniform(sectionMatrices[a], invS, p, n, outPos + o, outNrm + o, run.count);
          continue;
        }
        const NormalFix fix = rotationBlendFix(rotationTrace(sectionMatrices[a], sectionMatrices[b]) * invS2);
        withUniformFix(fix, invS == 1.0f, [&](auto fixTag, auto unitTag) {
          blendRunUniformT<decltype(fixTag)::value, decltype(unitTag)::value>(
              sectionMatrices[a], sectionMatrices[b], invS, f, p, n, outPos + o, outNrm + o, run.count);
        });
      } else if (run.third != a) {
        const uint32_t c = run.third;
        const NormalFix fix = renormalise[a] || renormalise[b] || renormalise[c]
                                  ? NormalFix::Exact
                                  : rotationBlendFix3(leastRotationTrace(normalMatrices[a], normalMatrices[b], normalMatrices[c]));
        blendRun3(sectionMatrices[a], normalMatrices[a], sectionMatrices[b], normalMatrices[b], sectionMatrices[c],
                  normalMatrices[c], fix, &blendF[run.first], &blendThirdF[run.first], &restPositions[o],
                  inNrm + o, outPos + o, outNrm + o, run.count);
      } else if (a == b) {
        transformRun(sectionMatrices[a], normalMatrices[a], renormalise[a] != 0, &restPositions[o], inNrm + o,
                     outPos + o, outNrm + o, run.count);
      } else {
        blendRun(sectionMatrices[a], normalMatrices[a], renormalise[a] != 0, sectionMatrices[b], normalMatrices[b],
                 renormalise[b] != 0, &blendF[run.first], &restPositions[o], inNrm + o, outPos + o, outNrm + o,
                 run.count);
      }
    }
    return;
  }
  for (uint32_t i = 0; i < S; ++i) {
    const Section& sec = sections[i];
    size_t o = size_t(sec.first) * 3;
    if (uniform)
      transformRunUniform(sectionMatrices[i], invS, &restPositions[o], inNrm + o, outPos + o, outNrm + o,
                          sec.count);
    else
      transformRun(sectionMatrices[i], normalMatrices[i], renormalise[i] != 0, &restPositions[o], inNrm + o,
                   outPos + o, outNrm + o, sec.count);
  }
}

}  // namespace gcs
