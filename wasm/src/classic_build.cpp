// The classic model's build, steps 1–9 (classic_build.h lists them; the bands are
// classic_bands.cpp). Longer than one job's file usually is: every step is a method over the one
// build's shared state, read in order, and splitting them across files would only scatter that state.
#include "classic_build.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include "classic_geometry.h"
#include "classic_on_skin.h"
#include "classic_rays.h"
#include "error.h"

namespace gcs {

using namespace classic;

namespace {

constexpr float kMinBoneFraction = 0.03f;  // a cylinder-like part is at least 3 % of the height long
constexpr float kMaxMissShare = 0.3f;      // more missing rays than this: carried
constexpr float kMaxExtension = 0.5f;      // a tube end passes a rigid neighbour's joint by ≤ ½ bone
constexpr float kMaxBendCos = 0.70710678f; // a chain continues only while bones turn by ≤ 45°
constexpr float kBranchBehind = 0.25f;     // a root trunk part's branches start before ¼ of its bone
constexpr float kCutMargin = 0.05f;        // a trunk tube ends ¹⁄₂₀ bone short of its branches
constexpr float kMinTrunkSpan = 0.25f;     // … and keeps at least ¼ of its bone
constexpr float kMinTubeSpan = 0.1f;       // a tube between its end loops spans ≥ ⅒ of its bone
constexpr float kBandWidth = 0.02f;        // a tube ends ¹⁄₅₀ bone inside its loop
constexpr uint32_t kProbeContours = 5;     // contours cast to decide whether a part resamples
constexpr float kEndStep = 0.01f;          // an open tube end moves in by ¹⁄₁₀₀ bone until its rays all hit,
constexpr int kEndHalvings = 7;            // then to within ¹⁄₁₂₈ of that step

// A tube's span along its bone: 0 / 1 at a shared joint, just inside its border loop where it
// meets carried skin, its own vertices' extent at an open end.
void spanOf(const ClassicPart& P, float& lo, float& hi) {
  lo = P.proxShared ? 0.0f : P.proxLoop >= 0 ? P.loopTLo : P.ownTMin;
  hi = P.distShared ? 1.0f : P.distLoop >= 0 ? P.loopTHi : P.ownTMax;
}

}  // namespace

ClassicBuild::ClassicBuild(const Rig& rig, uint32_t contours, uint32_t rays, float bulge)
    : rig(rig), contourSetting(contours), k(rays), bulge(bulge), J(rig.jointCount),
      T(uint32_t(rig.indices.size() / 3)) {
  newModel();
  findParts();
  gatherOwnTriangles();
  findChains();
  splitTrunk();
  transportFrames();
  countContours();
  sortWeldedEdges();
  findPieces();
  analysedParts = model->parts;
  partTriangles.resize(J);
}

ClassicModel* ClassicBuild::build(const std::vector<uint8_t>* carry) {
  if (!model) newModel(), model->parts = analysedParts;
  // (the on-skin test's verdict: applied before the decisions, so the tubes around are redone)
  if (carry)
    for (uint32_t j = 0; j < J; ++j)
      if ((*carry)[j] && part(j).resampled) part(j).resampled = false, part(j).reason = GCS_CLASSIC_OFF_SURFACE;
  decideParts();
  castFinalContours();
  layContours();
  fillEmptyContours();
  contourInfluences();
  addCaps();
  planBands();
  copyCarriedVertices();
  buildTriangles();
  writeReport();
  restPose();
  return model.release();
}

void ClassicBuild::newModel() {
  model.reset(new ClassicModel());
  ClassicModel& m = *model;
  m.jointCount = J;
  m.rays = k;
  m.bulge = bulge;
  m.height = rig.height > 0.0f ? rig.height : 1.0f;
  m.jointCentres = rig.jointCentres;
  m.cosTable.resize(k);
  m.sinTable.resize(k);
  for (uint32_t r = 0; r < k; ++r) {
    double a = 2.0 * 3.14159265358979323846 * double(r) / double(k);
    m.cosTable[r] = float(std::cos(a));
    m.sinTable[r] = float(std::sin(a));
  }
}

// ---------------------------------------------------------------- 1–3: the rig's analysis

void ClassicBuild::findParts() {
  ClassicModel& m = *model;
  group = weldByPosition(rig, representative);
  G = uint32_t(representative.size());
  partOf.resize(rig.vertexCount);
  m.parts.assign(J, ClassicPart());
  for (uint32_t j = 0; j < J; ++j) m.parts[j].joint = j;
  for (uint32_t v = 0; v < rig.vertexCount; ++v) {
    partOf[v] = rig.dominantJoint(representative[group[v]]);
    m.parts[partOf[v]].isPart = true;
  }
  childParts.assign(J, {});
  for (uint32_t j = 0; j < J; ++j) {
    if (!m.parts[j].isPart) continue;
    int32_t p = rig.parents[j];
    while (p >= 0 && !m.parts[p].isPart) p = rig.parents[p];
    m.parts[j].parent = p;
    if (p >= 0) childParts[p].push_back(j);
  }
  gPart.resize(G);
  for (uint32_t g = 0; g < G; ++g) gPart[g] = partOf[representative[g]];
}

// Own triangles: triangles with at least one vertex in the part (boundary triangles count for
// both sides, so the end contours find skin on either side of the weight boundary).
void ClassicBuild::gatherOwnTriangles() {
  triFirst.assign(J + 1, 0);
  auto forParts = [&](uint32_t t, auto&& fn) {
    uint32_t a = partOf[rig.indices[3 * t]], b = partOf[rig.indices[3 * t + 1]],
             c = partOf[rig.indices[3 * t + 2]];
    fn(a);
    if (b != a) fn(b);
    if (c != a && c != b) fn(c);
  };
  for (uint32_t t = 0; t < T; ++t) forParts(t, [&](uint32_t p) { ++triFirst[p + 1]; });
  for (uint32_t j = 0; j < J; ++j) triFirst[j + 1] += triFirst[j];
  triList.resize(triFirst[J]);
  std::vector<uint32_t> cursor(triFirst.begin(), triFirst.end() - 1);
  for (uint32_t t = 0; t < T; ++t) forParts(t, [&](uint32_t p) { triList[cursor[p]++] = t; });
}

// Directions of every part (for bends), candidates (chain parts long enough), their axes.
void ClassicBuild::findChains() {
  ClassicModel& m = *model;
  std::vector<glm::vec3> centroid(J, glm::vec3(0.0f));
  std::vector<uint32_t> ownCount(J, 0);
  for (uint32_t g = 0; g < G; ++g) {
    uint32_t v = representative[g];
    centroid[partOf[v]] += rig.positions[v];
    ++ownCount[partOf[v]];
  }
  const float minBone = kMinBoneFraction * m.height;
  for (uint32_t j = 0; j < J; ++j) {
    ClassicPart& P = m.parts[j];
    if (!P.isPart) continue;
    const glm::vec3 cj = rig.jointCentres[j];
    glm::vec3 dir(0.0f);
    for (uint32_t c : childParts[j]) {
      glm::vec3 d = rig.jointCentres[c] - cj;
      if (glm::length(d) > 1e-6f * m.height) dir += glm::normalize(d);
    }
    if (childParts[j].empty() && ownCount[j]) dir = centroid[j] / float(ownCount[j]) - cj;
    if (glm::length(dir) < 1e-6f * m.height && P.parent >= 0) dir = cj - rig.jointCentres[P.parent];
    P.direction = glm::length(dir) > 1e-6f * m.height ? glm::normalize(dir) : glm::vec3(0, 1, 0);
    if (childParts[j].empty()) {
      P.reason = GCS_CLASSIC_LEAF;
    } else if (childParts[j].size() > 1) {
      P.reason = GCS_CLASSIC_BRANCHING;
    } else {
      P.child = int32_t(childParts[j][0]);
      glm::vec3 bone = rig.jointCentres[P.child] - cj;
      P.length = glm::length(bone);
      if (!(P.length >= minBone)) {
        P.reason = GCS_CLASSIC_TOO_SHORT;
      } else {
        P.candidate = P.resampled = true;
        P.axis = bone / P.length;
      }
    }
  }
}

// Trunk parts that branch (pelvis, chest): resampled along the child that continues the trunk,
// on the side away from the other children (the branches), whose region stays carried.
// The continuing child: after a resampled-candidate parent, the one child whose own direction
// turns by at most 45° from the parent's bone (a chest's neck, not its shoulders); with no such
// parent, the one child whose siblings' joints lie behind a quarter of the bone to it and whose
// siblings' own directions all point away from its own (a pelvis's spine, the thighs below).
// branchOf[j][x]: for a split part j, the child of j whose subtree holds part x (−1: none or
// the continuing child's).
void ClassicBuild::splitTrunk() {
  ClassicModel& m = *model;
  const float minBone = kMinBoneFraction * m.height;
  branchOf.assign(J, {});
  for (uint32_t j = 0; j < J; ++j) {
    ClassicPart& P = m.parts[j];
    if (!P.isPart || childParts[j].size() < 2) continue;
    const glm::vec3 cj = rig.jointCentres[j];
    const bool afterTube = P.parent >= 0 && m.parts[P.parent].candidate && !m.parts[P.parent].split;
    int32_t chosen = -1, matches = 0;
    for (uint32_t c : childParts[j]) {
      glm::vec3 bone = rig.jointCentres[c] - cj;
      float len = glm::length(bone);
      if (!(len >= minBone)) continue;
      // The child's own direction (its bone onward): a shoulder's points along the arm.
      const glm::vec3 a = bone / len, own = m.parts[c].direction;
      bool ok;
      if (afterTube) {
        ok = glm::dot(own, m.parts[P.parent].axis) >= kMaxBendCos;
      } else {
        ok = true;
        for (uint32_t o : childParts[j])
          if (o != c && (glm::dot(rig.jointCentres[o] - cj, a) > kBranchBehind * len ||
                         glm::dot(m.parts[o].direction, own) >= 0.0f))
            ok = false;
      }
      if (ok) chosen = int32_t(c), ++matches;
    }
    if (matches != 1) continue;
    branchOf[j].assign(J, -1);
    for (uint32_t x = 0; x < J; ++x) {
      if (!m.parts[x].isPart) continue;
      int32_t y = int32_t(x);
      while (y >= 0 && m.parts[y].parent != int32_t(j)) y = m.parts[y].parent;
      if (y >= 0 && y != chosen) branchOf[j][x] = y;
    }
    glm::vec3 bone = rig.jointCentres[chosen] - cj;
    P.split = afterTube ? 2 : 1;
    P.child = chosen;
    P.length = glm::length(bone);
    P.axis = bone / P.length;
    P.candidate = P.resampled = true;
    P.reason = GCS_CLASSIC_TRUNK;
  }
}

// Reference directions: parallel-transported down each chain of candidates, so that the
// contour frames agree at shared contours; a chain starts from +Z (or +Y) projected.
void ClassicBuild::transportFrames() {
  ClassicModel& m = *model;
    std::vector<uint8_t> done(J, 0);
    std::vector<uint32_t> stack;
    for (uint32_t j0 = 0; j0 < J; ++j0) {
      if (!m.parts[j0].candidate || done[j0]) continue;
      stack.clear();
      uint32_t j = j0;
      while (true) {  // climb to the first undone candidate ancestor
        stack.push_back(j);
        int32_t p = m.parts[j].parent;
        if (p < 0 || !m.parts[p].candidate || done[p]) break;
        j = uint32_t(p);
      }
      for (size_t s = stack.size(); s-- > 0;) {
        ClassicPart& P = m.parts[stack[s]];
        int32_t p = P.parent;
        if (p >= 0 && m.parts[p].candidate) {
          P.u = orthonormal(minRotate(m.parts[p].axis, P.axis, m.parts[p].u), P.axis);
        } else {
          glm::vec3 g = std::fabs(P.axis.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
          P.u = orthonormal(g, P.axis);
        }
        done[stack[s]] = 1;
      }
    }
}

void ClassicBuild::countContours() {
  ClassicModel& m = *model;
  float longest = 0.0f;
  for (uint32_t j = 0; j < J; ++j)
    if (m.parts[j].candidate) longest = std::max(longest, m.parts[j].length);
  for (uint32_t j = 0; j < J; ++j) {
    ClassicPart& P = m.parts[j];
    if (!P.candidate) continue;
    float share = P.length / longest;
    P.contourCount = std::max<uint32_t>(GCS_CLASSIC_MIN_CONTOURS,
                                        uint32_t(std::lround(double(contourSetting) * share)));
    P.contourCount = std::min(P.contourCount, contourSetting);
  }
}

// Triangles over welded vertices, and their edges sorted by (smaller, larger) welded vertex: what
// the boundary loops between tubes and the carried mesh are traced on. Grouped by the smaller
// welded vertex (a counting sort: linear), each group by the larger.
void ClassicBuild::sortWeldedEdges() {
  std::vector<uint32_t> first(G + 1, 0);
  auto forEdges = [&](auto&& fn) {
    for (uint32_t t = 0; t < T; ++t) {
      uint32_t g[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
      if (g[0] == g[1] || g[1] == g[2] || g[0] == g[2]) continue;
      for (int e = 0; e < 3; ++e) {
        uint32_t a = g[e], b = g[(e + 1) % 3];
        fn(WeldedEdge{std::min(a, b), std::max(a, b), a, t});
      }
    }
  };
  forEdges([&](const WeldedEdge& e) { ++first[e.lo + 1]; });
  for (uint32_t g = 0; g < G; ++g) first[g + 1] += first[g];
  edges.resize(first[G]);
  forEdges([&](const WeldedEdge& e) { edges[first[e.lo]++] = e; });
  for (uint32_t g = G; g > 0; --g) first[g] = first[g - 1];
  first[0] = 0;
  for (uint32_t g = 0; g < G; ++g)  // a vertex has a handful of edges: insertion sort
    for (uint32_t i = first[g] + 1; i < first[g + 1]; ++i)
      for (uint32_t j = i; j > first[g] && edges[j - 1].hi > edges[j].hi; --j) std::swap(edges[j - 1], edges[j]);
}

// Pieces: triangles joined through shared (welded) edges. One on most characters; one per part on
// a rig of separate rigid shells (Mixamo's X Bot: a shell per bone, gaps at the joints), where a
// contour near a joint has the neighbouring shell around its plane but its rays hit only its
// own. (Edges, not vertices: two shells whose ends touch at one point are still two pieces.)
void ClassicBuild::findPieces() {
  std::vector<uint32_t> triRoot(T);
  for (uint32_t t = 0; t < T; ++t) triRoot[t] = t;
  auto findTri = [&](uint32_t x) {
    while (triRoot[x] != x) x = triRoot[x] = triRoot[triRoot[x]];
    return x;
  };
  for (size_t e0 = 0; e0 < edges.size();) {
    size_t e1 = e0 + 1;
    for (; e1 < edges.size() && edges[e1].lo == edges[e0].lo && edges[e1].hi == edges[e0].hi; ++e1) {
      uint32_t a = findTri(edges[e0].tri), b = findTri(edges[e1].tri);
      if (a != b) triRoot[std::max(a, b)] = std::min(a, b);
    }
    e0 = e1;
  }
  triPiece.resize(T);
  for (uint32_t t = 0; t < T; ++t) triPiece[t] = findTri(t);
  // A welded vertex's piece: its first triangle's. A part's pieces: those of the triangles it
  // holds most corners of (ties: the first corner's part).
  piece.assign(G, UINT32_MAX);
  std::vector<std::pair<uint32_t, uint32_t>> partPiece;
  for (uint32_t t = 0; t < T; ++t) {
    const uint32_t p = triPiece[t];
    const uint32_t* v = &rig.indices[size_t(t) * 3];
    for (int e = 0; e < 3; ++e)
      if (piece[group[v[e]]] == UINT32_MAX) piece[group[v[e]]] = p;
    const uint32_t a = partOf[v[0]], b = partOf[v[1]], c = partOf[v[2]];
    partPiece.push_back({b == c && b != a ? b : a, p});
  }
  std::sort(partPiece.begin(), partPiece.end());
  partPiece.erase(std::unique(partPiece.begin(), partPiece.end()), partPiece.end());
  piecesFirst.assign(J + 1, 0);
  pieceList.clear();
  for (const auto& pp : partPiece) ++piecesFirst[pp.first + 1], pieceList.push_back(pp.second);
  for (uint32_t j = 0; j < J; ++j) piecesFirst[j + 1] += piecesFirst[j];
}

// ---------------------------------------------------------------- helpers over the shared state

float ClassicBuild::tOn(const ClassicPart& P, uint32_t v) const {
  return glm::dot(rig.positions[v] - rig.jointCentres[P.joint], P.axis) / P.length;
}

// x is j, or a carried direct branch child of j.
bool ClassicBuild::member(uint32_t j, uint32_t x) const {
  return x == j || (branchOf[j][x] == int32_t(x) && !model->parts[x].resampled);
}

bool ClassicBuild::beforeCut(const ClassicPart& P, uint32_t v) const {
  float t = tOn(P, v);
  return P.split == 1 ? t > P.cut : t < P.cut;
}

// Which welded vertices the tubes replace. A split trunk part's tube side: its vertices short of
// its cut, and those of its carried direct branch children (a shoulder's skin down the flank)
// short of it too; the rest of it is carried. Returns the part whose tube replaces welded vertex
// g, or −1 if it is carried (before islands).
int32_t ClassicBuild::baseOwner(uint32_t g) const {
  const ClassicModel& m = *model;
  const uint32_t x = gPart[g], v = representative[g];
  const ClassicPart& X = m.parts[x];
  if (X.resampled) return !X.split || beforeCut(X, v) ? int32_t(x) : -1;
  const int32_t p = X.parent;
  if (p >= 0 && m.parts[p].split && m.parts[p].resampled && member(uint32_t(p), x) && beforeCut(m.parts[p], v)) return p;
  return -1;
}

// A split trunk part's cut: 1/20 bone short of the nearest of its (and its carried branch
// children's) vertices that share a triangle with the rest of its branches. False: less than
// kMinTrunkSpan of the bone is left.
bool ClassicBuild::updateCut(uint32_t j) {
  ClassicModel& m = *model;
  ClassicPart& P = m.parts[j];
  float lo = INFINITY, hi = -INFINITY;
  for (uint32_t x = 0; x < J; ++x) {
    if (!m.parts[x].isPart || !member(j, x)) continue;
    for (uint32_t i = triFirst[x]; i < triFirst[x + 1]; ++i) {
      const uint32_t* t = &rig.indices[size_t(triList[i]) * 3];
      bool touches = false;
      for (int e = 0; e < 3; ++e) touches = touches || (branchOf[j][partOf[t[e]]] >= 0 && !member(j, partOf[t[e]]));
      if (!touches) continue;
      for (int e = 0; e < 3; ++e)
        if (member(j, partOf[t[e]])) {
          float tv = tOn(P, t[e]);
          lo = std::min(lo, tv), hi = std::max(hi, tv);
        }
    }
  }
  // (a chest's tube ends by its continuing child's joint; a pelvis's starts at most half a
  // bone before its joint: beyond, its branches are not around it but along it)
  if (P.split == 2) P.cut = std::isfinite(lo) ? std::min(1.0f, lo - kCutMargin) : 1.0f;
  else P.cut = std::isfinite(hi) ? hi + kCutMargin : 0.0f;
  return P.split == 2 ? P.cut >= kMinTrunkSpan : P.cut <= 1.0f - kMinTrunkSpan && P.cut >= -kMaxExtension;
}

// Extent of each candidate's tube-side vertices along its bone (for open tube ends).
void ClassicBuild::updateExtents() {
  ClassicModel& m = *model;
  for (uint32_t j = 0; j < J; ++j) m.parts[j].ownTMin = 0.0f, m.parts[j].ownTMax = 1.0f;
  for (uint32_t g = 0; g < G; ++g) {
    int32_t o = baseOwner(g);
    if (o < 0) continue;
    ClassicPart& P = m.parts[o];
    float t = tOn(P, representative[g]);
    P.ownTMin = std::max(-kMaxExtension, std::min(P.ownTMin, t));
    P.ownTMax = std::min(1.0f + kMaxExtension, std::max(P.ownTMax, t));
  }
  for (uint32_t j = 0; j < J; ++j) {
    ClassicPart& P = m.parts[j];
    if (P.split == 1) P.ownTMin = P.cut;
    if (P.split == 2) P.ownTMax = P.cut;
  }
}

void ClassicBuild::endNormals(const ClassicPart& P, glm::vec3& nProx, glm::vec3& nDist) const {
  const ClassicModel& m = *model;
  nProx = P.proxShared ? bisector(m.parts[P.parent].axis, P.axis) : P.axis;
  nDist = P.distShared ? bisector(P.axis, m.parts[P.child].axis) : P.axis;
}

void ClassicBuild::contourFrame(const ClassicPart& P, float t, const glm::vec3& nProx, const glm::vec3& nDist,
                                glm::vec3& centre, glm::vec3& n, glm::vec3& u) const {
  centre = rig.jointCentres[P.joint] + t * P.length * P.axis;
  float tc = glm::clamp(t, 0.0f, 1.0f);
  n = glm::normalize((1.0f - tc) * nProx + tc * nDist);
  u = orthonormal(minRotate(P.axis, n, P.u), n);
}

// The triangles part j's contours are cast against: its own; a trunk part's also its continuing
// child's and its carried branch children's (its tube runs through their skin). Gathered once per
// set of parts (a trunk part's set changes as its branch children are carried), kept across rebuilds.
ClassicBuild::PartTriangles& ClassicBuild::trianglesOf(uint32_t j) {
  ClassicModel& m = *model;
  const ClassicPart& P = m.parts[j];
  gathered.clear();
  for (uint32_t x = 0; x < J; ++x)
    if (x == j || (P.split && (int32_t(x) == P.child || (m.parts[x].isPart && member(j, x))))) gathered.push_back(x);
  PartTriangles& own = partTriangles[j];
  if (!own.valid || own.parts != gathered) {
    own.valid = true;
    own.parts = gathered;
    own.corners.clear();
    own.triangle.clear();
    own.casts.clear();
    for (uint32_t x : gathered)
      for (uint32_t i = triFirst[x]; i < triFirst[x + 1]; ++i) {
        for (int e = 0; e < 3; ++e) own.corners.push_back(rig.positions[rig.indices[size_t(triList[i]) * 3 + e]]);
        own.triangle.push_back(triList[i]);
      }
    own.slabs.build(own.corners.data(), uint32_t(own.triangle.size()), rig.jointCentres[P.joint], P.axis);
  }
  return own;
}

// Casts `count` contours of part j evenly over [tLo, tHi] into out (count × k radii), against
// trianglesOf(j). Counts the hits left after outliers, and those between joints.
void ClassicBuild::castPart(uint32_t j, uint32_t count, const glm::vec3& nProx, const glm::vec3& nDist,
                            std::vector<float>& out, std::vector<uint32_t>& outTriangles, uint32_t& hitCount,
                            uint32_t& inRangeHits, uint32_t& inRangeRays) {
  ClassicModel& m = *model;
  const ClassicPart& P = m.parts[j];
  out.assign(size_t(count) * k, -1.0f);  // no hit yet
  outTriangles.assign(size_t(count) * k, 0);
  PartTriangles& own = trianglesOf(j);
  // The same contours were cast before (by an earlier round, or the build before the on-skin
  // test carried a part elsewhere): the same result.
  for (const PartTriangles::Cast& c : own.casts)
    if (c.count == count && c.tLo == P.tLo && c.tHi == P.tHi && c.nProx == nProx && c.nDist == nDist) {
      out = c.radii, outTriangles = c.triangles;
      hitCount += c.hitCount, inRangeHits += c.inRangeHits, inRangeRays += c.inRangeRays;
      return;
    }
  PartTriangles::Cast cast{count, P.tLo, P.tHi, nProx, nDist, {}, {}, 0, 0, 0};
  for (uint32_t i = 0; i < count; ++i) {
    float t = P.tLo + (P.tHi - P.tLo) * float(i) / float(count - 1);
    glm::vec3 O, n, u;
    contourFrame(P, t, nProx, nDist, O, n, u);
    float* rad = &out[size_t(i) * k];
    uint32_t* tri = &outTriangles[size_t(i) * k];
    own.slabs.candidates(O, n, cut);
    castContour(own.corners.data(), cut.data(), uint32_t(cut.size()), O, n, u, glm::cross(n, u), k, m.cosTable.data(),
                m.sinTable.data(), rad, tri);
    for (uint32_t r = 0; r < k; ++r) tri[r] = rad[r] > 0.0f ? own.triangle[tri[r]] : 0;
    uint32_t h = rejectOutliers(rad, k, scratch);
    cast.hitCount += h;
    if (t >= -1e-4f && t <= 1.0001f) cast.inRangeHits += h, cast.inRangeRays += k;
  }
  hitCount += cast.hitCount, inRangeHits += cast.inRangeHits, inRangeRays += cast.inRangeRays;
  cast.radii = out, cast.triangles = outTriangles;
  own.casts.push_back(std::move(cast));
}

// P's distal joint contour is shared with its child: both resampled, and skin joins them (two
// separate shells have only a gap at their joint, where a shared ring would stand in the air).
bool ClassicBuild::shares(const ClassicPart& P) const {
  const ClassicModel& m = *model;
  if (!P.resampled || P.child < 0 || P.split == 2) return false;
  const ClassicPart& C = m.parts[P.child];
  return C.resampled && C.split != 1 && joinedBySkin(P.joint, uint32_t(P.child));
}

// Parts a and b have skin in one piece.
bool ClassicBuild::joinedBySkin(uint32_t a, uint32_t b) const {
  for (uint32_t i = piecesFirst[a], e = piecesFirst[b]; i < piecesFirst[a + 1]; ++i) {
    while (e < piecesFirst[b + 1] && pieceList[e] < pieceList[i]) ++e;
    if (e < piecesFirst[b + 1] && pieceList[e] == pieceList[i]) return true;
  }
  return false;
}

void ClassicBuild::carry(uint32_t j, uint8_t reason) {
  ClassicModel& m = *model;
  ClassicPart& P = m.parts[j];
  P.resampled = false;
  P.reason = reason;
  if (P.parent >= 0 && m.parts[P.parent].resampled) dirty[P.parent] = 1;
  if (P.child >= 0 && m.parts[P.child].resampled) dirty[P.child] = 1;
}

uint32_t ClassicBuild::find(uint32_t x) {
  while (root[x] != x) x = root[x] = root[root[x]];
  return x;
}

void ClassicBuild::unite(uint32_t a, uint32_t b) {
  a = find(a), b = find(b);
  if (a != b) root[std::max(a, b)] = std::min(a, b);
}

// ---------------------------------------------------------------- 4: resampled or carried

// Which parts are resampled, and where their tubes end. Rays decide (too many misses: carried);
// then the boundary between the tubes and the carried triangles (those with a carried vertex) is
// traced: each loop must be one ring around one tube's unshared end, or the part is carried
// (GCS_CLASSIC_SEAM); that end's contours start just inside the loop. Parts are only ever
// removed, so this ends.
void ClassicBuild::decideParts() {
  ClassicModel& m = *model;
  hits.assign(J, {});
  hitTriangles.assign(J, {});
  dirty.assign(J, 0);
  for (uint32_t j = 0; j < J; ++j) dirty[j] = m.parts[j].candidate && !m.parts[j].split;  // trunk parts: once cut
  scratch.reserve(k);
  triCarried.assign(T, 0);
  gOwner.assign(G, -1);
  root.resize(G);
  for (int round = 0; round < 64; ++round) {
    updateExtents();
    settleRayTests();
    if (recutTrunk(round)) continue;
    // The carried mesh and its boundary loops with the tubes.
    computeOwners();
    for (uint32_t t = 0; t < T; ++t)
      triCarried[t] = owner(group[rig.indices[3 * t]]) < 0 || owner(group[rig.indices[3 * t + 1]]) < 0 ||
                      owner(group[rig.indices[3 * t + 2]]) < 0;
    std::vector<uint8_t> failed(J, 0);
    traceLoops(failed);
    if (carrySeams(failed)) continue;
    if (endTubesAtLoops()) continue;
    bool pending = false;
    for (uint32_t j = 0; j < J; ++j) pending = pending || (m.parts[j].resampled && dirty[j]);
    if (!pending) break;
  }
}

// Ray tests on every part marked dirty, until none is carried; then bends (a part turned from its
// parent's bone), again until nothing changes.
void ClassicBuild::settleRayTests() {
  ClassicModel& m = *model;
  for (int pass = 0; pass < 64; ++pass) {
    bool any = false;
    for (uint32_t j = 0; j < J; ++j) {
      ClassicPart& P = m.parts[j];
      if (!P.resampled || !dirty[j]) continue;
      dirty[j] = 0;
      P.proxShared = P.parent >= 0 && m.parts[P.parent].child == int32_t(j) && shares(m.parts[P.parent]);
      P.distShared = shares(P);
      spanOf(P, P.tLo, P.tHi);
      glm::vec3 nProx, nDist;
      endNormals(P, nProx, nDist);
      // The decision looks at up to kProbeContours contours (the full set is cast once, at the end).
      const uint32_t mm = std::min(P.contourCount, kProbeContours);
      uint32_t hitCount = 0, inRangeHits = 0, inRangeRays = 0;
      castPart(j, mm, nProx, nDist, probe, probeTriangles, hitCount, inRangeHits, inRangeRays);
      // The miss rule looks at the contours between the joints (past a joint, skin of the
      // carried neighbour is expected to be missing); all contours if none lies between them.
      float miss = inRangeRays ? 1.0f - float(inRangeHits) / float(inRangeRays)
                               : 1.0f - float(hitCount) / float(mm * k);
      if (hitCount == 0 || miss > kMaxMissShare) carry(j, GCS_CLASSIC_RAYS_MISS), any = true;
    }
    if (any) continue;
    // Once the ray tests have settled: a part whose bone turns by more than 45° from its
    // resampled parent's bone is not a continuation of that limb (a foot on a shank): carried.
    for (uint32_t j = 0; j < J; ++j) {
      ClassicPart& P = m.parts[j];
      // (only where it continues its parent's tube: a pelvis's thighs are branches)
      if (!P.resampled || P.parent < 0 || !m.parts[P.parent].resampled || P.split ||
          m.parts[P.parent].child != int32_t(j))
        continue;
      if (glm::dot(P.axis, m.parts[P.parent].axis) >= kMaxBendCos) continue;
      carry(j, GCS_CLASSIC_BENT);
      any = true;
    }
    if (!any) break;
  }
}

// Trunk cuts, once the parts around them have settled (a shoulder found carried lets the chest's
// tube run down its flank); a part whose cut moved is cast again. True: cast again.
bool ClassicBuild::recutTrunk(int round) {
  ClassicModel& m = *model;
  bool recast = false;
  for (uint32_t j = 0; j < J; ++j) {
    ClassicPart& P = m.parts[j];
    if (!P.resampled || !P.split) continue;
    float before = P.cut;
    if (!updateCut(j)) carry(j, GCS_CLASSIC_BRANCHING), recast = true;
    else if (P.cut != before || round == 0) dirty[j] = 1, recast = true;
  }
  return recast;
}

// Islands (real meshes: a strap or a pouch weighted to another bone, a few vertices of a part
// inside its neighbour's skin): a tube region cut off from the main region of its part is
// carried; a carried patch that touches one tube only, lies along its bone and is no bigger than
// its tube-side skin is replaced by that tube. Either would leave a loop that is no ring around a
// tube end (a side loop): a gap or an overlap.
void ClassicBuild::computeOwners() {
  ClassicModel& m = *model;
  for (uint32_t g = 0; g < G; ++g) gOwner[g] = baseOwner(g);
  // Skin where two tubes that share no ring touch (a crotch between the thighs) is carried:
  // no tube surface would cover it.
  auto joined = [&](int32_t a, int32_t b) {
    return a == b || (m.parts[a].child == b && m.parts[a].distShared) || (m.parts[b].child == a && m.parts[b].distShared);
  };
  std::vector<uint8_t> apart(G, 0);
  for (uint32_t t = 0; t < T; ++t) {
    uint32_t v[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
    for (int e = 0; e < 3; ++e) {
      int32_t a = gOwner[v[e]], b = gOwner[v[(e + 1) % 3]];
      if (a >= 0 && b >= 0 && !joined(a, b)) apart[v[e]] = apart[v[(e + 1) % 3]] = 1;
    }
  }
  for (uint32_t g = 0; g < G; ++g)
    if (apart[g]) gOwner[g] = -1;
  // Tube regions: welded vertices joined by triangles of three tube-side vertices.
  for (uint32_t g = 0; g < G; ++g) root[g] = g;
  for (uint32_t t = 0; t < T; ++t) {
    uint32_t a = group[rig.indices[3 * t]], b = group[rig.indices[3 * t + 1]], c = group[rig.indices[3 * t + 2]];
    if (gOwner[a] >= 0 && gOwner[b] >= 0 && gOwner[c] >= 0) unite(a, b), unite(b, c);
  }
  std::vector<std::pair<uint32_t, uint32_t>> partRoot;  // (owner, region) per tube vertex
  for (uint32_t g = 0; g < G; ++g)
    if (gOwner[g] >= 0) partRoot.push_back({uint32_t(gOwner[g]), find(g)});
  std::sort(partRoot.begin(), partRoot.end());
  std::vector<uint32_t> mainRegion(J, UINT32_MAX), mainSize(J, 0), tubeSize(J, 0);
  for (size_t i = 0; i < partRoot.size();) {
    size_t e = i;
    while (e < partRoot.size() && partRoot[e] == partRoot[i]) ++e;
    uint32_t part = partRoot[i].first;
    tubeSize[part] += uint32_t(e - i);
    if (e - i > mainSize[part]) mainSize[part] = uint32_t(e - i), mainRegion[part] = partRoot[i].second;
    i = e;
  }
  for (uint32_t g = 0; g < G; ++g)
    if (gOwner[g] >= 0 && find(g) != mainRegion[gOwner[g]]) gOwner[g] = -1;
  // Carried patches: carried welded vertices joined by triangles; the tubes each one touches.
  for (uint32_t g = 0; g < G; ++g) root[g] = g;
  for (uint32_t t = 0; t < T; ++t) {
    uint32_t v[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
    for (int e = 0; e < 3; ++e)
      if (gOwner[v[e]] < 0 && gOwner[v[(e + 1) % 3]] < 0) unite(v[e], v[(e + 1) % 3]);
  }
  std::vector<int32_t> touches(G, -2);  // per patch: −2 none yet, a part, or −1 several
  for (uint32_t t = 0; t < T; ++t) {
    uint32_t v[3] = {group[rig.indices[3 * t]], group[rig.indices[3 * t + 1]], group[rig.indices[3 * t + 2]]};
    for (int e = 0; e < 3; ++e) {
      if (gOwner[v[e]] >= 0) continue;
      for (int f = 0; f < 3; ++f) {
        if (gOwner[v[f]] < 0) continue;
        int32_t& tt = touches[find(v[e])];
        tt = tt == -2 || tt == gOwner[v[f]] ? gOwner[v[f]] : -1;
      }
    }
  }
  std::vector<uint32_t> patchSize(G, 0);
  std::vector<float> patchT(G, 0.0f);
  for (uint32_t g = 0; g < G; ++g) {
    if (gOwner[g] >= 0) continue;
    uint32_t r = find(g);
    if (touches[r] < 0) continue;
    ++patchSize[r];
    patchT[r] += tOn(m.parts[touches[r]], representative[g]);
  }
  for (uint32_t g = 0; g < G; ++g) {
    if (gOwner[g] >= 0) continue;
    uint32_t r = find(g);
    if (touches[r] < 0) continue;
    float t = patchT[r] / float(patchSize[r]);
    if (patchSize[r] <= tubeSize[touches[r]] && t > 0.0f && t < 1.0f) gOwner[g] = touches[r];
  }
}

// Loop edges: an edge of a carried triangle shared with a tube triangle, directed as in the
// carried triangle (an edge of the input's own border stays open), chained into loops; each loop
// must be one ring around one tube's unshared end, else its part fails.
void ClassicBuild::traceLoops(std::vector<uint8_t>& failed) {
  ClassicModel& m = *model;
  std::vector<std::pair<uint32_t, uint32_t>> loopEdges;
  for (size_t e0 = 0; e0 < edges.size();) {
    size_t e1 = e0;
    int carriedAt = -1;
    bool tube = false;
    while (e1 < edges.size() && edges[e1].lo == edges[e0].lo && edges[e1].hi == edges[e0].hi) {
      if (triCarried[edges[e1].tri]) { if (carriedAt < 0) carriedAt = int(e1); }
      else tube = true;
      ++e1;
    }
    if (carriedAt >= 0 && tube) {
      const WeldedEdge& e = edges[size_t(carriedAt)];
      loopEdges.push_back({e.from, e.from == e.lo ? e.hi : e.lo});
    }
    e0 = e1;
  }
  std::sort(loopEdges.begin(), loopEdges.end());
  std::vector<uint8_t> used(loopEdges.size(), 0);
  loops.clear();
  for (size_t s = 0; s < loopEdges.size(); ++s) {
    if (used[s]) continue;
    Loop L;
    size_t e = s;
    bool closed = false;
    while (true) {
      used[e] = 1;
      L.groups.push_back(loopEdges[e].first);
      uint32_t next = loopEdges[e].second;
      if (next == loopEdges[s].first) { closed = true; break; }
      auto it = std::lower_bound(loopEdges.begin(), loopEdges.end(), std::make_pair(next, 0u));
      size_t f = size_t(it - loopEdges.begin());
      while (f < loopEdges.size() && loopEdges[f].first == next && used[f]) ++f;
      if (f >= loopEdges.size() || loopEdges[f].first != next) break;
      e = f;
    }
    // The part it closes: most of its vertices'.
    uint32_t best = uint32_t(owner(L.groups[0])), bestCount = 0;
    for (uint32_t g : L.groups) {
      uint32_t c = 0;
      for (uint32_t h : L.groups) c += owner(h) == owner(g);
      if (c > bestCount) best = uint32_t(owner(g)), bestCount = c;
      if (bestCount * 2 > L.groups.size()) break;
    }
    L.part = best;
    ClassicPart& P = m.parts[best];
    if (!closed || !P.resampled) {  // an open chain (it runs into the input's own border)
      if (P.resampled) failed[best] = 1;
      continue;
    }
    const glm::vec3 cj = rig.jointCentres[P.joint];
    float mean = 0.0f;
    for (uint32_t g : L.groups) mean += glm::dot(rig.positions[representative[g]] - cj, P.axis) / P.length;
    mean /= float(L.groups.size());
    L.distal = mean > 0.5f * (P.ownTMin + P.ownTMax);
    // One turn around the bone, seen along it.
    const glm::vec3 w = glm::cross(P.axis, P.u);
    double turn = 0.0;
    float prev = 0.0f;
    for (size_t i = 0; i <= L.groups.size(); ++i) {
      glm::vec3 d = rig.positions[representative[L.groups[i % L.groups.size()]]] - cj;
      float a = std::atan2(glm::dot(d, w), glm::dot(d, P.u));
      if (i) {
        float da = a - prev;
        if (da > kPi) da -= 2.0f * kPi;
        if (da < -kPi) da += 2.0f * kPi;
        turn += da;
      }
      prev = a;
    }
    bool ring = std::fabs(std::fabs(turn) - 2.0 * 3.14159265358979) < 3.14159265358979;
    bool shared = L.distal ? shares(P) : P.proxShared;
    bool taken = false;
    for (const Loop& other : loops)
      if (other.part == best && other.distal == L.distal) taken = true;
    if (!ring || shared || taken) { failed[best] = 1; continue; }
    loops.push_back(std::move(L));
  }
}

// A part whose loops failed, or a tube that replaces no triangle (every one of its part's
// triangles has a carried vertex: a coarse part one triangle long; it would only be laid over the
// kept skin), is carried. True if any was.
bool ClassicBuild::carrySeams(const std::vector<uint8_t>& failed) {
  ClassicModel& m = *model;
  std::vector<uint32_t> replaced(J, 0);
  for (uint32_t t = 0; t < T; ++t)
    if (!triCarried[t]) ++replaced[uint32_t(owner(group[rig.indices[3 * t]]))];
  bool any = false;
  for (uint32_t j = 0; j < J; ++j)
    if (failed[j] || (m.parts[j].resampled && replaced[j] == 0)) carry(j, GCS_CLASSIC_SEAM), any = true;
  return any;
}

// Tube ends from the loops: just inside the innermost point of each loop (a flat loop would
// otherwise leave a band of zero width). True if a tube got too short and was carried.
bool ClassicBuild::endTubesAtLoops() {
  ClassicModel& m = *model;
  bool any = false;
  for (uint32_t j = 0; j < J; ++j) m.parts[j].proxLoop = m.parts[j].distLoop = -1;
  for (size_t l = 0; l < loops.size(); ++l) {
    ClassicPart& P = m.parts[loops[l].part];
    float lo = INFINITY, hi = -INFINITY;
    for (uint32_t g : loops[l].groups) {
      float t = glm::dot(rig.positions[representative[g]] - rig.jointCentres[P.joint], P.axis) / P.length;
      lo = std::min(lo, t), hi = std::max(hi, t);
    }
    if (loops[l].distal) P.distLoop = int32_t(l), P.loopTHi = lo - kBandWidth;
    else P.proxLoop = int32_t(l), P.loopTLo = hi + kBandWidth;
  }
  for (uint32_t j = 0; j < J; ++j) {
    ClassicPart& P = m.parts[j];
    if (!P.resampled) continue;
    float lo, hi;
    spanOf(P, lo, hi);
    if (!P.proxShared && P.proxLoop < 0) lo = fullRingEnd(j, lo, hi);
    if (!P.distShared && P.distLoop < 0) hi = fullRingEnd(j, hi, lo);
    // (the ray test is not run again on the final span: the loops only trim the ends of a
    // tube whose rays already hit, and the contours are cast below)
    if (!(hi - lo >= kMinTubeSpan)) carry(j, GCS_CLASSIC_SEAM), any = true;
    else P.tLo = lo, P.tHi = hi;
  }
  return any;
}

// An open end of part j's tube (its skin meets nothing there: a shell's own end, a sleeve's
// border) at `end`, moved towards `other` to where a contour's rays all find skin: in steps of
// ¹⁄₁₀₀ bone over at most half the span, then halving the last step (a plane through a cut
// border finds nothing, one a hair inside finds it all); none: the contour with the most hits.
// Beyond it, misses would be filled from their neighbours' radii and the ring would stand in the
// air past a rounded or slanted end of the skin (Mixamo's X Bot: a closed shell per bone, its
// knee end slanted).
float ClassicBuild::fullRingEnd(uint32_t j, float end, float other) {
  const ClassicPart& P = model->parts[j];
  PartTriangles& own = trianglesOf(j);
  glm::vec3 nProx, nDist;
  endNormals(P, nProx, nDist);
  std::vector<float> radius(k);
  std::vector<uint32_t> triangle(k);
  auto hitsAt = [&](float t) {
    glm::vec3 O, n, u;
    contourFrame(P, t, nProx, nDist, O, n, u);
    own.slabs.candidates(O, n, cut);
    std::fill(radius.begin(), radius.end(), -1.0f);
    castContour(own.corners.data(), cut.data(), uint32_t(cut.size()), O, n, u, glm::cross(n, u), k, model->cosTable.data(),
                model->sinTable.data(), radius.data(), triangle.data());
    return rejectOutliers(radius.data(), k, scratch);
  };
  const float step = other > end ? kEndStep : -kEndStep;
  const int steps = int(std::floor(0.5f * std::fabs(other - end) / kEndStep));
  float best = end;
  uint32_t bestHits = 0;
  for (int i = 0; i <= steps; ++i) {
    const float t = end + step * float(i);
    const uint32_t hits = hitsAt(t);
    if (hits == k) {
      if (i == 0) return t;
      float outside = t - step, inside = t;  // the ring turns full between them
      for (int halving = 0; halving < kEndHalvings; ++halving) {
        const float mid = 0.5f * (outside + inside);
        (hitsAt(mid) == k ? inside : outside) = mid;
      }
      return inside;
    }
    if (hits > bestHits) best = t, bestHits = hits;
  }
  return best;
}

// The contours of the parts that stay resampled, cast once at their final span.
void ClassicBuild::castFinalContours() {
  ClassicModel& m = *model;
  for (uint32_t j = 0; j < J; ++j) {
    const ClassicPart& P = m.parts[j];
    if (!P.resampled) continue;
    glm::vec3 nProx, nDist;
    endNormals(P, nProx, nDist);
    uint32_t hitCount = 0, inRangeHits = 0, inRangeRays = 0;
    castPart(j, P.contourCount, nProx, nDist, hits[j], hitTriangles[j], hitCount, inRangeHits, inRangeRays);
  }
}

// ---------------------------------------------------------------- 5: contours

// Chains of resampled parts are laid out root → leaf, so that a part's rings are contiguous and a
// shared contour is the last ring of one part and the first of the next.
void ClassicBuild::layContours() {
  ClassicModel& m = *model;
  ringTriangle.clear();
  vertex = 0;
  for (uint32_t j0 = 0; j0 < J; ++j0) {
    ClassicPart& head = m.parts[j0];
    if (!head.resampled || head.proxShared) continue;
    for (int32_t j = int32_t(j0); j >= 0 && m.parts[j].resampled; j = m.parts[j].distShared ? m.parts[j].child : -1) {
      ClassicPart& P = m.parts[j];
      glm::vec3 nProx, nDist;
      endNormals(P, nProx, nDist);
      const uint32_t mm = P.contourCount;
      P.contours.clear();
      for (uint32_t i = 0; i < mm; ++i) {
        if (i == 0 && P.proxShared) {  // the parent's last contour
          uint32_t id = m.parts[P.parent].contours.back();
          P.contours.push_back(id);
          ClassicContour& c = m.contours[id];
          float* rad = &m.radii[c.radii];
          const float* mine = &hits[j][0];
          for (uint32_t r = 0; r < k; ++r)  // union of both sides
            if (mine[r] > rad[r]) rad[r] = mine[r], ringTriangle[c.first + r] = hitTriangles[j][r];
          c.part = j;
          c.proximal = P.parent;
          c.t = 0.0f;
          continue;
        }
        ClassicContour c;
        c.part = j;
        c.t = P.tLo + (P.tHi - P.tLo) * float(i) / float(mm - 1);
        contourFrame(P, c.t, nProx, nDist, c.centre, c.normal, c.u);
        c.first = vertex;
        vertex += k;
        c.radii = uint32_t(m.radii.size());
        m.radii.insert(m.radii.end(), hits[j].begin() + size_t(i) * k, hits[j].begin() + size_t(i + 1) * k);
        for (uint32_t r = 0; r < k; ++r)
          ringTriangle.push_back(hits[j][size_t(i) * k + r] > 0.0f ? hitTriangles[j][size_t(i) * k + r] : T);
        P.contours.push_back(uint32_t(m.contours.size()));
        m.contours.push_back(c);
      }
      P.first = m.contours[P.contours.front()].first;
      P.count = mm * k;
    }
  }
  m.tubeVertexCount = vertex;
}

// Misses: from neighbours in the contour, or, for a contour without any hit, from the nearest
// contour of its part that has hits.
void ClassicBuild::fillEmptyContours() {
  ClassicModel& m = *model;
  std::vector<uint8_t> empty(m.contours.size(), 0);
  for (size_t c = 0; c < m.contours.size(); ++c) empty[c] = !fillMisses(&m.radii[m.contours[c].radii], k);
  for (uint32_t j = 0; j < J; ++j) {
    const ClassicPart& P = m.parts[j];
    if (!P.resampled) continue;
    const int n = int(P.contours.size());
    for (int i = 0; i < n; ++i) {
      uint32_t id = P.contours[i];
      if (!empty[id]) continue;
      for (int d = 1; d < n; ++d) {
        int cand[2] = {i - d, i + d};
        int found = -1;
        for (int q : cand)
          if (q >= 0 && q < n && !empty[P.contours[q]]) { found = q; break; }
        if (found >= 0) {
          std::memcpy(&m.radii[m.contours[id].radii], &m.radii[m.contours[P.contours[found]].radii], k * sizeof(float));
          empty[id] = 0;
          break;
        }
      }
    }
  }
  for (size_t c = 0; c < m.contours.size(); ++c)
    if (empty[c]) std::fill(m.radii.begin() + m.contours[c].radii, m.radii.begin() + m.contours[c].radii + k, 0.0f);
}

// The skin each contour resamples, as influences: the mean weights of the input vertices of its
// part and its neighbours that lie around its plane (within half the contour spacing, widened
// where the mesh is coarse) and no farther from its centre than its rays reached. A ring then
// moves as that skin does, not as its bone's straight line (a twisting spine, a thigh whose
// skin the hip's weights bend).
void ClassicBuild::contourInfluences() {
  ClassicModel& m = *model;
  std::vector<float> sum(J, 0.0f);
  std::vector<uint32_t> touched;
  std::vector<uint32_t> vertexFirst(J + 1, 0), vertexList(rig.vertexCount);  // rig vertices by part
  for (uint32_t v = 0; v < rig.vertexCount; ++v) ++vertexFirst[partOf[v] + 1];
  for (uint32_t j = 0; j < J; ++j) vertexFirst[j + 1] += vertexFirst[j];
  {
    std::vector<uint32_t> cursor(vertexFirst.begin(), vertexFirst.end() - 1);
    for (uint32_t v = 0; v < rig.vertexCount; ++v) vertexList[cursor[partOf[v]]++] = v;
  }
  // The vertices of a contour's part and its neighbours, sorted along the part's bone: a contour
  // reads only those that can lie within its window, then takes them in part, vertex order (the
  // order of the sums: the same rounding whatever is skipped).
  std::vector<std::pair<float, uint32_t>> along;  // (position along the bone, rig vertex)
  std::vector<std::pair<uint32_t, uint32_t>> nearby;  // (part, rig vertex)
  int32_t alongPart = -1, alongProximal = -1;
  std::vector<uint32_t> hitPieces;  // the pieces of skin the contour's rays hit (none: any)
  for (ClassicContour& c : m.contours) {
    hitPieces.clear();
    for (uint32_t r = 0; r < k; ++r)
      if (ringTriangle[c.first + r] < T) hitPieces.push_back(triPiece[ringTriangle[c.first + r]]);
    std::sort(hitPieces.begin(), hitPieces.end());
    hitPieces.erase(std::unique(hitPieces.begin(), hitPieces.end()), hitPieces.end());
    const ClassicPart& P = m.parts[c.part];
    auto near = [&](uint32_t x) {
      if (x == uint32_t(c.part) || int32_t(x) == P.child || int32_t(x) == P.parent || (c.proximal >= 0 && int32_t(x) == c.proximal))
        return true;
      return P.split && m.parts[x].isPart && member(c.part, x);
    };
    const glm::vec3 base = rig.jointCentres[P.joint];
    // The proximal part widens the set only when it is not the parent already (a contour shared
    // with the parent has it as its proximal): then the sorted list of the part's others serves.
    const int32_t proximal = c.proximal >= 0 && c.proximal != P.parent && c.proximal != P.child ? c.proximal : -1;
    if (alongPart != c.part || alongProximal != proximal) {
      along.clear();
      for (uint32_t x = 0; x < J; ++x)
        if (m.parts[x].isPart && near(x))
          for (uint32_t i = vertexFirst[x]; i < vertexFirst[x + 1]; ++i)
            along.push_back({glm::dot(rig.positions[vertexList[i]] - base, P.axis), vertexList[i]});
      std::sort(along.begin(), along.end());
      alongPart = c.part, alongProximal = proximal;
    }
    float reach = 0.0f;
    for (uint32_t r = 0; r < k; ++r) reach = std::max(reach, m.radii[c.radii + r]);
    reach = 1.25f * reach + 1e-6f * m.height;
    float window = 0.5f * P.length * std::max(P.tHi - P.tLo, 1e-3f) / float(std::max<uint32_t>(P.contourCount - 1, 1));
    const float cosTilt = std::fabs(glm::dot(c.normal, P.axis)), sinTilt = std::sqrt(std::max(0.0f, 1.0f - cosTilt * cosTilt));
    const float centre = glm::dot(c.centre - base, P.axis);
    float total = 0.0f;
    for (int attempt = 0; attempt < 4 && total <= 0.0f; ++attempt, window *= 2.0f) {
      // A vertex in the window lies within √(window² + reach²) of the centre, so within
      // (window + that · sin tilt) / cos tilt of it along the bone.
      auto lo = along.begin(), hi = along.end();
      if (cosTilt > 0.2f) {
        const float extent = (window + std::sqrt(window * window + reach * reach) * sinTilt) / cosTilt * 1.001f + 1e-5f * m.height;
        lo = std::lower_bound(along.begin(), along.end(), std::make_pair(centre - extent, 0u));
        hi = std::upper_bound(lo, along.end(), std::make_pair(centre + extent, UINT32_MAX));
      }
      nearby.clear();
      for (auto it = lo; it != hi; ++it) nearby.push_back({partOf[it->second], it->second});
      std::sort(nearby.begin(), nearby.end());
      for (const auto& pv : nearby) {
        const uint32_t v = pv.second;
        // (skin the rays never reached: another shell around the plane, moving with its own bone)
        if (!hitPieces.empty() && !std::binary_search(hitPieces.begin(), hitPieces.end(), piece[group[v]])) continue;
        glm::vec3 x = rig.positions[v] - c.centre;
        float h = glm::dot(x, c.normal);
        if (std::fabs(h) > window || glm::length(x - h * c.normal) > reach) continue;
        float f = 1.0f - std::fabs(h) / window + 1e-3f;
        for (uint32_t i = 0; i < rig.influenceSlots; ++i) {
          const uint32_t jj = rig.jointAt(v, i);
          if (!(rig.weightAt(v, i) > 0.0f)) continue;
          if (sum[jj] == 0.0f) touched.push_back(jj);
          sum[jj] += f * rig.weightAt(v, i);
        }
        total += f;
      }
    }
    // The four largest, renormalised; none found: the part's own joint.
    c.joints = glm::uvec4(c.part, 0, 0, 0);
    c.weights = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
    std::sort(touched.begin(), touched.end(), [&](uint32_t a, uint32_t b) { return sum[a] > sum[b] || (sum[a] == sum[b] && a < b); });
    float kept = 0.0f;
    for (size_t i = 0; i < touched.size() && i < 4; ++i) kept += sum[touched[i]];
    if (kept > 0.0f)
      for (size_t i = 0; i < 4; ++i) {
        c.joints[int(i)] = i < touched.size() ? touched[i] : 0u;
        c.weights[int(i)] = i < touched.size() ? sum[touched[i]] / kept : 0.0f;
      }
    for (uint32_t jj : touched) sum[jj] = 0.0f;
    touched.clear();
  }
  // A joint contour shared by two tubes takes the mean of its two neighbours' influences (the
  // paper's bisector where the skin is bound hard to each bone; the skin's own blend elsewhere).
  for (const ClassicPart& P : m.parts) {
    if (!P.resampled || !P.proxShared || P.contours.size() < 2) continue;
    const ClassicPart& Q = m.parts[P.parent];
    if (Q.contours.size() < 2) continue;
    ClassicContour& c = m.contours[P.contours.front()];
    for (const ClassicContour* x : {&m.contours[Q.contours[Q.contours.size() - 2]], &m.contours[P.contours[1]]})
      for (int i = 0; i < 4; ++i)
        if (x->weights[i] > 0.0f) {
          if (sum[x->joints[i]] == 0.0f) touched.push_back(x->joints[i]);
          sum[x->joints[i]] += 0.5f * x->weights[i];
        }
    std::sort(touched.begin(), touched.end(), [&](uint32_t a, uint32_t b) { return sum[a] > sum[b] || (sum[a] == sum[b] && a < b); });
    float kept = 0.0f;
    for (size_t i = 0; i < touched.size() && i < 4; ++i) kept += sum[touched[i]];
    for (size_t i = 0; i < 4; ++i) {
      c.joints[int(i)] = i < touched.size() ? touched[i] : 0u;
      c.weights[int(i)] = i < touched.size() ? sum[touched[i]] / kept : 0.0f;
    }
    for (uint32_t jj : touched) sum[jj] = 0.0f;
    touched.clear();
  }
}

// Caps: a tube end that meets neither a resampled neighbour nor the carried mesh is closed by a
// flat fan when the part's input skin has no border (a robot's finger plate); an open input
// (a sleeve) stays open.
void ClassicBuild::addCaps() {
  ClassicModel& m = *model;
  std::vector<uint8_t> bordered(J, 0);
  for (size_t e0 = 0; e0 < edges.size();) {
    size_t e1 = e0;
    while (e1 < edges.size() && edges[e1].lo == edges[e0].lo && edges[e1].hi == edges[e0].hi) ++e1;
    if (e1 - e0 == 1)
      for (uint32_t g : {edges[e0].lo, edges[e0].hi})
        if (owner(g) >= 0) bordered[owner(g)] = 1;
    e0 = e1;
  }
  for (uint32_t j = 0; j < J; ++j) {
    const ClassicPart& P = m.parts[j];
    if (!P.resampled || bordered[j]) continue;
    if (!P.proxShared && P.proxLoop < 0) {
      m.caps.push_back({P.contours.front(), vertex, -1.0f});
      vertex += k + 1;
    }
    if (!P.distShared && P.distLoop < 0) {
      m.caps.push_back({P.contours.back(), vertex, 1.0f});
      vertex += k + 1;
    }
  }
}

// ---------------------------------------------------------------- 6–9: the output

// 6. Carried triangles (those with a carried vertex): their vertices are copied and move
// by dual-quaternion skinning of their own weights; the copies are grouped by part (ranges per part).
void ClassicBuild::copyCarriedVertices() {
  ClassicModel& m = *model;
  outputOf.assign(rig.vertexCount, -1);
  for (uint32_t t = 0; t < T; ++t)
    if (triCarried[t])
      for (int e = 0; e < 3; ++e) outputOf[rig.indices[3 * t + e]] = 0;
  std::vector<uint32_t> runCount(J, 0);
  for (uint32_t v = 0; v < rig.vertexCount; ++v)
    if (outputOf[v] == 0) ++runCount[partOf[v]];
  m.carriedFirst = vertex;
  for (uint32_t j = 0; j < J; ++j) {
    m.parts[j].runFirst = vertex;
    m.parts[j].runCount = runCount[j];
    vertex += runCount[j];
  }
  bandFirst = vertex;  // then the bands' own skin points, carried the same way
  vertex += uint32_t(bandVertices.size());
  groupOutput.assign(G, -1);
  {
    std::vector<uint32_t> cursor(J);
    for (uint32_t j = 0; j < J; ++j) cursor[j] = m.parts[j].runFirst;
    for (uint32_t v = 0; v < rig.vertexCount; ++v)
      if (outputOf[v] == 0) groupOutput[group[v]] = outputOf[v] = cursor[partOf[v]]++;
  }
  m.allocateOutput(vertex);
  const uint32_t carried = vertex - m.carriedFirst;
  m.restPositions.assign(size_t(carried) * 3 + 1, 0.0f);
  m.restNormals.assign(size_t(carried) * 3 + 1, 0.0f);
  m.carriedJoints.resize(carried);
  m.carriedWeights.resize(carried);
  const bool eight = rig.influenceSlots == 8;
  if (eight) m.carriedJoints1.resize(carried), m.carriedWeights1.resize(carried);
  m.poses.resize(J);
  for (uint32_t v = 0; v < rig.vertexCount; ++v) {
    if (outputOf[v] < 0) continue;
    m.carriedJoints[size_t(outputOf[v] - m.carriedFirst)] = rig.joints[v];
    m.carriedWeights[size_t(outputOf[v] - m.carriedFirst)] = rig.weights[v];
    if (eight) {
      m.carriedJoints1[size_t(outputOf[v] - m.carriedFirst)] = rig.joints1[v];
      m.carriedWeights1[size_t(outputOf[v] - m.carriedFirst)] = rig.weights1[v];
    }
    size_t o = size_t(outputOf[v] - m.carriedFirst) * 3;
    for (int c = 0; c < 3; ++c) {
      m.restPositions[o + c] = rig.positions[v][c];
      m.restNormals[o + c] = rig.normals[v][c];
    }
  }
  for (size_t b = 0; b < bandVertices.size(); ++b) {
    const BandVertex& x = bandVertices[b];
    const size_t o = bandFirst - m.carriedFirst + b;
    m.carriedJoints[o] = x.joints[0], m.carriedWeights[o] = x.weights[0];
    if (eight) m.carriedJoints1[o] = x.joints[1], m.carriedWeights1[o] = x.weights[1];
    for (int c = 0; c < 3; ++c) m.restPositions[3 * o + c] = x.position[c], m.restNormals[3 * o + c] = x.normal[c];
  }
}

// 7. Triangles: tube quads (outward winding: rays turn from u to w = n × u, counter-clockwise
// about the contour normal, which points distally), then the bands, then the carried triangles.
void ClassicBuild::buildTriangles() {
  ClassicModel& m = *model;
  for (uint32_t j = 0; j < J; ++j) {
    const ClassicPart& P = m.parts[j];
    if (!P.resampled) continue;
    for (size_t i = 0; i + 1 < P.contours.size(); ++i) {
      uint32_t a = m.contours[P.contours[i]].first, b = m.contours[P.contours[i + 1]].first;
      for (uint32_t r = 0; r < k; ++r) {
        uint32_t r1 = (r + 1) % k;
        m.indices.insert(m.indices.end(), {a + r, a + r1, b + r1, a + r, b + r1, b + r});
      }
    }
  }
  m.tubeIndexCount = uint32_t(m.indices.size());
  for (size_t l = 0; l < loops.size(); ++l) zipBand(loops[l], plans[l]);
  for (const ClassicCap& cap : m.caps) {
    ClassicBand fan;
    fan.part = uint32_t(m.contours[cap.contour].part);
    fan.firstIndex = uint32_t(m.indices.size());
    uint32_t centre = cap.first + k;
    for (uint32_t r = 0; r < k; ++r) {
      uint32_t r1 = (r + 1) % k;
      if (cap.sign > 0.0f) m.indices.insert(m.indices.end(), {centre, cap.first + r, cap.first + r1});
      else m.indices.insert(m.indices.end(), {centre, cap.first + r1, cap.first + r});
    }
    fan.indexCount = uint32_t(m.indices.size()) - fan.firstIndex;
    m.bands.push_back(fan);
  }
  m.bandIndexCount = uint32_t(m.indices.size()) - m.tubeIndexCount;
  for (uint32_t t = 0; t < T; ++t) {
    if (!triCarried[t]) continue;
    for (int e = 0; e < 3; ++e) m.indices.push_back(uint32_t(outputOf[rig.indices[3 * t + e]]));
  }
}

// 8. The report (parts in joint order), contours per vertex, and the detail-loss inputs: the
// input vertices the tubes and bands replace.
void ClassicBuild::writeReport() {
  ClassicModel& m = *model;
  for (uint32_t j = 0; j < J; ++j) {
    const ClassicPart& P = m.parts[j];
    if (!P.isPart) continue;
    m.reportJoints.push_back(j);
    m.report.insert(m.report.end(), {int32_t(j), P.resampled ? 1 : 0, int32_t(P.resampled ? P.first : P.runFirst),
                                     int32_t(P.resampled ? P.count : P.runCount), int32_t(P.reason)});
  }
  m.contourOfVertex.assign(m.vertexCount, -1);
  for (uint32_t c = 0; c < m.contours.size(); ++c)
    for (uint32_t r = 0; r < k; ++r) m.contourOfVertex[m.contours[c].first + r] = int32_t(c);
  for (const ClassicCap& cap : m.caps)
    for (uint32_t r = 0; r <= k; ++r) m.contourOfVertex[cap.first + r] = int32_t(cap.contour);
  m.sourceOfVertex.assign(m.vertexCount, -1);
  for (uint32_t v = 0; v < rig.vertexCount; ++v)
    if (outputOf[v] >= 0) m.sourceOfVertex[size_t(outputOf[v])] = int32_t(v);
  for (uint32_t g = 0; g < G; ++g)
    if (groupOutput[g] < 0 && owner(g) >= 0) {
      m.lossPoints.push_back(rig.positions[representative[g]]);
      m.lossParts.push_back(uint32_t(owner(g)));
    }
}

// The bind pose as the initial output (and the bind surface for the detail loss).
void ClassicBuild::restPose() {
  ClassicModel& m = *model;
  std::vector<glm::mat4> identity(J, glm::mat4(1.0f));
  m.deform(identity.data());
  m.bindPositions.resize(m.vertexCount);
  for (uint32_t o = 0; o < m.vertexCount; ++o)
    m.bindPositions[o] = glm::vec3(m.positions[3 * o], m.positions[3 * o + 1], m.positions[3 * o + 2]);
}

ClassicModel* buildClassic(const Rig& rig, uint32_t contours, uint32_t rays, float bulge) {
  if (contours < GCS_CLASSIC_MIN_CONTOURS || contours > GCS_CLASSIC_MAX_CONTOURS) {
    fail(GCS_ERR_OUT_OF_RANGE, "the contour count must be between %d and %d; got %u",
         GCS_CLASSIC_MIN_CONTOURS, GCS_CLASSIC_MAX_CONTOURS, contours);
    return nullptr;
  }
  if (rays < GCS_CLASSIC_MIN_RAYS || rays > GCS_CLASSIC_MAX_RAYS) {
    fail(GCS_ERR_OUT_OF_RANGE, "the ray count must be between %d and %d; got %u", GCS_CLASSIC_MIN_RAYS,
         GCS_CLASSIC_MAX_RAYS, rays);
    return nullptr;
  }
  if (!(bulge >= 0.0f && bulge <= GCS_CLASSIC_MAX_BULGE)) {
    fail(GCS_ERR_OUT_OF_RANGE, "the bulge must be between 0 and %g; got %g", double(GCS_CLASSIC_MAX_BULGE),
         double(bulge));
    return nullptr;
  }
  ClassicModel* m = nullptr;
  try {
    ClassicBuild build(rig, contours, rays, bulge);
    m = build.build(nullptr);
    // The on-skin test, and a rebuild without the parts that fail it. Parts are only ever added
    // to the carried set, so this ends.
    std::vector<uint8_t> carried(rig.jointCount, 0);
    for (uint32_t round = 0; round < rig.jointCount; ++round) {
      std::vector<uint8_t> failed = offSurfaceParts(rig, *m, build.ringTriangles());
      bool any = false;
      for (uint32_t j = 0; j < rig.jointCount; ++j)
        if (failed[j] && !carried[j]) carried[j] = 1, any = true;
      if (!any) break;
      delete m;
      m = nullptr;
      m = build.build(&carried);
    }
  } catch (const std::bad_alloc&) {
    delete m;
    fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while building the classic cross-section model");
    return nullptr;
  }
  return m;
}

}  // namespace gcs
