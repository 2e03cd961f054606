// The weights criterion's build (docs/method.md §2): sections, or in smooth mode nodes, from the
// welded vertices' skin weights; their centres of rotation; then the shared layout (gcs_build.h).
#include "gcs_build.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <tuple>
#include "error.h"
#include "rotation_centres.h"

namespace gcs {
namespace {

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
// a grid of step 1/Q, Q = GCS_WEIGHT_GRID_STEPS(sections) (so the even split between two joints is
// a bin: their shared section). Each section's blend is its members' mean weights on the joints of its key; a
// key with one joint is that joint's rigid core (transform exactly S_j). The stepped level of
// detail (smooth: false); smooth mode builds nodes instead (buildWeightNodes).
void buildWeightSections(const Rig& rig, GcsDeformerImpl& m, const std::vector<uint32_t>& representative,
                         std::vector<uint32_t>& sectionOfGroup) {
  const uint32_t G = uint32_t(representative.size());
  const uint32_t Q = GCS_WEIGHT_GRID_STEPS(m.settings.sections);
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

// The key of a group's node at level l > 0 (d its dominant joint, s = 1 − w_d): d keeps 8·(Q − l)
// units, the shape u's 8·l units go by largest remainders.
WeightKey levelKey(const uint32_t* joint, const float* weight, uint32_t n, uint32_t d, float s, uint32_t l, uint32_t Q) {
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
  return key;
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
  const uint32_t G = uint32_t(rig.cache.weldRepresentative.size());
  // Keys count weight in units of 1/(8Q): at level l the shape u gets 8·l units, so every node's
  // weights sit on one grid of 1/(8Q) (1/64 at the default) and the shape is resolved to s/(8l) ≤ 1/(8Q).
  const uint32_t Q = GCS_WEIGHT_GRID_STEPS(m.settings.sections), total = 8 * Q;
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
    // The node at level l (levelKey), looked up once per (pair, level) where the group has a pair.
    uint32_t* pairLevels = byPair && groups.pairOf[g] != ~0u ? &pairNode[size_t(groups.pairOf[g]) * levels] : nullptr;
    auto nodeKey = [&](uint32_t l) {
      if (l == 0) return rigidId(joint[d]);  // the key below would reduce to it (canonical)
      if (pairLevels && pairLevels[l] != ~0u) return pairLevels[l];
      const uint32_t id = keyId(levelKey(joint, weight, n, d, s, l, Q));
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

}  // namespace gcs
