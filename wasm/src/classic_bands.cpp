// The bands between a tube's end ring and the boundary loop of the carried skin it meets.
// One row of triangles from the ring to the loop is a fan of long slivers where the loop runs far
// down the bone (our human's thighs are webbed to each other along the inner thigh: the hip loop
// runs 30 cm down it). So the band is laid in a chart of the end ring (angle about its centre ×
// height along its normal): above each ring vertex, a column of new vertices one ring spacing apart
// up to where the loop crosses that ray; each is the input surface its ray meets, carried by
// dual-quaternion skinning of the weights there like the carried skin, so it moves with both sides.
// Each strip between two neighbouring columns (ring below, loop above) is triangulated by ear
// clipping, best smallest angle first. A loop the chart cannot hold (one that crosses no ray once)
// gets the single zip.
#include <algorithm>
#include <cmath>
#include "classic_build.h"
#include "classic_geometry.h"
#include "classic_rays.h"
#include "transform.h"

namespace gcs {

using namespace classic;

namespace {

// A band triangle's corner before the output is laid out: a ring vertex, a loop vertex, or a band vertex.
constexpr uint32_t kLoopRef = 0x80000000u, kRingRef = 0x40000000u, kRefMask = 0x3fffffffu;
constexpr uint32_t kMaxRows = 64;          // band vertices per column
constexpr float kClearance = 0.5f;         // columns keep ½ ring spacing from the loop
constexpr float kMaxWiden = 1.5f;          // a column ends where its ray's hit jumps outwards (another limb)

struct ChartPoint {
  glm::vec2 at;     // angle × mean ring radius, height above the ring
  glm::vec3 bind;   // bind-pose position (the angles that choose the ears)
  uint32_t ref;
};

float cross2(const glm::vec2& a, const glm::vec2& b) { return a.x * b.y - a.y * b.x; }

// The sine of a triangle's smallest angle (the angle between its two longer edges): what the
// ears and flips compare, without an arc tangent (the smallest angle is at most 60°).
float smallestSine(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  float e[3] = {glm::length(b - c), glm::length(c - a), glm::length(a - b)};
  std::sort(e, e + 3);
  const float twiceArea = glm::length(glm::cross(b - a, c - a));
  return e[2] > 0.0f ? twiceArea / (e[1] * e[2]) : 0.0f;
}

float wrapAngle(float a) {
  while (a > kPi) a -= 2.0f * kPi;
  while (a <= -kPi) a += 2.0f * kPi;
  return a;
}

// Not three ring vertices (flat, in the ring's plane) nor three loop vertices: what a flip may make.
bool mixed(uint32_t a, uint32_t b, uint32_t c) {
  const uint32_t all = a & b & c;
  return !(all & kRingRef) && !(all & kLoopRef);
}

// Triangulates a simple counter-clockwise chart polygon by ear clipping, each time the ear whose
// smallest angle in the bind pose is largest. False if it gets stuck (the polygon is not simple).
bool clipEars(const std::vector<ChartPoint>& poly, std::vector<uint32_t>& out) {
  const size_t n = poly.size();
  if (n < 3) return false;
  std::vector<size_t> prev(n), next(n);
  std::vector<float> score(n);
  for (size_t i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
  auto evaluate = [&](size_t i) {
    const glm::vec2 a = poly[prev[i]].at, b = poly[i].at, c = poly[next[i]].at;
    if (!(cross2(b - a, c - b) > 0.0f)) return -1.0f;  // reflex or flat
    for (size_t j = next[next[i]]; j != prev[i]; j = next[j]) {
      const glm::vec2 p = poly[j].at;
      if (cross2(b - a, p - a) >= 0.0f && cross2(c - b, p - b) >= 0.0f && cross2(a - c, p - c) >= 0.0f) return -1.0f;
    }
    return smallestSine(poly[prev[i]].bind, poly[i].bind, poly[next[i]].bind);
  };
  for (size_t i = 0; i < n; ++i) score[i] = evaluate(i);
  size_t left = n, any = 0;
  for (; left > 3; --left) {
    size_t best = n, i = any;
    for (size_t s = 0; s < left; ++s, i = next[i])
      if (score[i] >= 0.0f && (best == n || score[i] > score[best])) best = i;
    if (best == n) return false;
    out.insert(out.end(), {poly[prev[best]].ref, poly[best].ref, poly[next[best]].ref});
    const size_t a = prev[best], c = next[best];
    next[a] = c, prev[c] = a, any = a;
    score[a] = evaluate(a), score[c] = evaluate(c);
  }
  if (!(evaluate(any) >= 0.0f)) return false;
  out.insert(out.end(), {poly[prev[any]].ref, poly[any].ref, poly[next[any]].ref});
  return true;
}

// Whether segments ab and cd cross at a point inside both.
bool segmentsCross(const glm::vec2& a, const glm::vec2& b, const glm::vec2& c, const glm::vec2& d) {
  const float d1 = cross2(b - a, c - a), d2 = cross2(b - a, d - a), d3 = cross2(d - c, a - c), d4 = cross2(d - c, b - c);
  return ((d1 > 0.0f && d2 < 0.0f) || (d1 < 0.0f && d2 > 0.0f)) && ((d3 > 0.0f && d4 < 0.0f) || (d3 < 0.0f && d4 > 0.0f));
}

// Flips the inner edges of a band (an edge two of its triangles share) where the other diagonal
// of their quad gives a larger smallest angle in the bind pose and both new triangles face as the
// old ones did (Lawson's flips, for the angle): ear clipping chose each strip's diagonals one ear
// at a time. Each flip raises the smaller of the two smallest angles, so this ends.
template <typename At>
void flipEdges(std::vector<uint32_t>& tris, const At& at) {
  const uint32_t T = uint32_t(tris.size() / 3);
  auto key = [](uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); };
  // across[3t + e]: the triangle across edge e of t (corner e → corner e + 1), or −1; the edges, sorted.
  std::vector<int32_t> across(size_t(3) * T, -1);
  std::vector<uint64_t> edges(size_t(3) * T);
  {
    std::vector<std::pair<uint64_t, uint32_t>> slots(size_t(3) * T);
    for (uint32_t s = 0; s < 3 * T; ++s) slots[s] = {key(tris[s], tris[s - s % 3 + (s + 1) % 3]), s};
    std::sort(slots.begin(), slots.end());
    for (size_t i = 0; i < slots.size();) {
      size_t j = i;
      while (j < slots.size() && slots[j].first == slots[i].first) ++j;
      if (j - i == 2) across[slots[i].second] = int32_t(slots[i + 1].second / 3), across[slots[i + 1].second] = int32_t(slots[i].second / 3);
      i = j;
    }
    for (size_t i = 0; i < slots.size(); ++i) edges[i] = slots[i].first;
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  }
  std::vector<float> quality(T);
  for (uint32_t t = 0; t < T; ++t) quality[t] = smallestSine(at(tris[3 * t]), at(tris[3 * t + 1]), at(tris[3 * t + 2]));
  auto repoint = [&](int32_t n, uint32_t p, uint32_t q, int32_t to) {  // n's edge {p, q} now faces `to`
    if (n < 0) return;
    for (uint32_t s = 0; s < 3; ++s)
      if (key(tris[3 * size_t(n) + s], tris[3 * size_t(n) + (s + 1) % 3]) == key(p, q)) across[3 * size_t(n) + s] = to;
  };
  std::vector<uint32_t> stack(T);
  std::vector<uint8_t> queued(T, 1);
  for (uint32_t t = 0; t < T; ++t) stack[t] = T - 1 - t;
  for (uint32_t flips = 0; !stack.empty() && flips < 16 * T;) {
    const uint32_t t = stack.back();
    stack.pop_back();
    queued[t] = 0;
    for (uint32_t e = 0; e < 3; ++e) {
      const int32_t u = across[3 * size_t(t) + e];
      if (u < 0) continue;
      const uint32_t a = tris[3 * t + e], b = tris[3 * t + (e + 1) % 3], c = tris[3 * t + (e + 2) % 3];
      uint32_t f = 0;
      while (f < 3 && !(tris[3 * size_t(u) + f] == b && tris[3 * size_t(u) + (f + 1) % 3] == a)) ++f;
      if (f == 3) continue;
      const uint32_t d = tris[3 * size_t(u) + (f + 2) % 3];
      if (c == d || !mixed(c, a, d) || !mixed(d, b, c) || std::binary_search(edges.begin(), edges.end(), key(c, d))) continue;
      const glm::vec3 A = at(a), B = at(b), C = at(c), D = at(d);
      const float q1 = smallestSine(C, A, D), q2 = smallestSine(D, B, C);
      if (!(std::min(q1, q2) > std::min(quality[t], quality[u]) + 1e-4f)) continue;
      const glm::vec3 facing = glm::cross(B - A, C - A) + glm::cross(A - B, D - B);
      if (!(glm::dot(glm::cross(A - C, D - C), facing) > 0.0f) || !(glm::dot(glm::cross(B - D, C - D), facing) > 0.0f)) continue;
      // t = (a, b, c), u = (b, a, d) → t = (c, a, d), u = (d, b, c).
      const int32_t nbc = across[3 * size_t(t) + (e + 1) % 3], nca = across[3 * size_t(t) + (e + 2) % 3];
      const int32_t nad = across[3 * size_t(u) + (f + 1) % 3], ndb = across[3 * size_t(u) + (f + 2) % 3];
      tris[3 * t] = c, tris[3 * t + 1] = a, tris[3 * t + 2] = d;
      tris[3 * size_t(u)] = d, tris[3 * size_t(u) + 1] = b, tris[3 * size_t(u) + 2] = c;
      across[3 * size_t(t)] = nca, across[3 * size_t(t) + 1] = nad, across[3 * size_t(t) + 2] = u;
      across[3 * size_t(u)] = ndb, across[3 * size_t(u) + 1] = nbc, across[3 * size_t(u) + 2] = int32_t(t);
      repoint(nad, a, d, int32_t(t));
      repoint(nbc, b, c, u);
      quality[t] = q1, quality[u] = q2;
      edges.erase(std::lower_bound(edges.begin(), edges.end(), key(a, b)));
      edges.insert(std::lower_bound(edges.begin(), edges.end(), key(c, d)), key(c, d));
      for (uint32_t x : {t, uint32_t(u)})
        if (!queued[x]) queued[x] = 1, stack.push_back(x);
      ++flips;
      break;
    }
  }
}

}  // namespace

// A point x of the input surface on the triangle with corners `corner` (rig vertices v): its
// normal and influences interpolated from the corners (the largest the rig has slots for,
// renormalised), so that DQS carries it as the skin around it.
ClassicBuild::BandVertex ClassicBuild::skinPoint(const glm::vec3& x, const glm::vec3* corner, const uint32_t* v,
                                                 uint32_t fallbackJoint, const glm::vec3& fallbackNormal) const {
  const glm::vec3 e1 = corner[1] - corner[0], e2 = corner[2] - corner[0], ex = x - corner[0];
  const float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
  const float dx1 = glm::dot(ex, e1), dx2 = glm::dot(ex, e2), den = d11 * d22 - d12 * d12;
  float b1 = den > 0.0f ? (d22 * dx1 - d12 * dx2) / den : 0.0f, b2 = den > 0.0f ? (d11 * dx2 - d12 * dx1) / den : 0.0f;
  b1 = glm::clamp(b1, 0.0f, 1.0f), b2 = glm::clamp(b2, 0.0f, 1.0f - b1);
  const float bary[3] = {1.0f - b1 - b2, b1, b2};
  BandVertex bv;
  bv.position = x;
  glm::vec3 normal(0.0f);
  uint32_t joint[24], order[24], count = 0;
  float weight[24];
  for (int e = 0; e < 3; ++e) {
    normal += bary[e] * rig.normals[v[e]];
    for (uint32_t s = 0; s < rig.influenceSlots; ++s) {
      const uint32_t jj = rig.jointAt(v[e], s);
      const float ww = rig.weightAt(v[e], s) * bary[e];
      if (!(ww > 0.0f)) continue;
      uint32_t at = 0;
      while (at < count && joint[at] != jj) ++at;
      if (at == count) joint[count] = jj, weight[count++] = 0.0f;
      weight[at] += ww;
    }
  }
  bv.normal = unitOr(normal, unitOr(glm::cross(e1, e2), fallbackNormal));
  for (uint32_t a = 0; a < count; ++a) order[a] = a;
  std::sort(order, order + count, [&](uint32_t a, uint32_t b) { return weight[a] > weight[b] || (weight[a] == weight[b] && joint[a] < joint[b]); });
  const uint32_t kept = std::min(count, rig.influenceSlots);
  float sum = 0.0f;
  for (uint32_t a = 0; a < kept; ++a) sum += weight[order[a]];
  bv.joints[0] = bv.joints[1] = glm::uvec4(0u);
  bv.weights[0] = bv.weights[1] = glm::vec4(0.0f);
  if (!(sum > 0.0f)) bv.joints[0][0] = fallbackJoint, bv.weights[0][0] = 1.0f;
  for (uint32_t a = 0; a < kept && sum > 0.0f; ++a)
    bv.joints[a / 4][int(a % 4)] = joint[order[a]], bv.weights[a / 4][int(a % 4)] = weight[order[a]] / sum;
  return bv;
}

void ClassicBuild::planBands() {
  plans.assign(loops.size(), BandPlan());
  bandVertices.clear();
  for (size_t l = 0; l < loops.size(); ++l) {
    const Loop& L = loops[l];
    const ClassicPart& P = model->parts[L.part];
    const ClassicContour& c = model->contours[L.distal ? P.contours.back() : P.contours.front()];
    const float* radii = &model->radii[c.radii];
    const std::vector<uint32_t>& gathered = partTriangles[L.part].parts;
    const uint32_t offset = uint32_t(bandVertices.size());
    auto same = [&](const LaidBand& b) {
      return b.part == L.part && b.distal == L.distal && b.centre == c.centre && b.normal == c.normal && b.u == c.u &&
             b.groups == L.groups && b.gathered == gathered && std::equal(b.radii.begin(), b.radii.end(), radii);
    };
    auto laid = std::find_if(laidBands.begin(), laidBands.end(), same);
    if (laid != laidBands.end()) {
      plans[l] = laid->plan;
      for (uint32_t& ref : plans[l].triangles)
        if (!(ref & (kLoopRef | kRingRef))) ref += offset;
      bandVertices.insert(bandVertices.end(), laid->vertices.begin(), laid->vertices.end());
      continue;
    }
    if (!planBand(L, plans[l])) plans[l].triangles.clear(), bandVertices.resize(offset);
    LaidBand b{L.part, L.distal, L.groups, gathered, c.centre, c.normal, c.u, std::vector<float>(radii, radii + k),
               plans[l], std::vector<BandVertex>(bandVertices.begin() + offset, bandVertices.end())};
    for (uint32_t& ref : b.plan.triangles)
      if (!(ref & (kLoopRef | kRingRef))) ref -= offset;
    laidBands.push_back(std::move(b));
  }
}

// planBand's shared state: the end ring the band starts from, the loop's chart (angle about the
// ring × height above it; beta and the loop's order are the plan's) and the columns of band
// vertices raised above the ring's vertices.
struct ClassicBuild::BandChart {
  const ClassicContour& c;
  glm::vec3 w;                        // the ring's second in-plane axis (normal × u)
  float d;                            // towards the loop: 1 at a distal end, −1 at a proximal one
  bool distal;
  uint32_t k;                         // rays
  const std::vector<float>* beta = nullptr;
  size_t n = 0;                       // loop vertices
  float step = 0.0f, turn = 0.0f, meanRadius = 0.0f, spacing = 0.0f;
  std::vector<float> height;          // per loop vertex: its height above the ring
  std::vector<uint8_t> stands;        // per ring index: a column stands there
  std::vector<std::vector<BandVertex>> made;  // per ring index: its column's vertices, bottom up

  BandChart(const ClassicContour& ring, const glm::vec3& axis, float towards, bool distalEnd, uint32_t rays)
      : c(ring), w(axis), d(towards), distal(distalEnd), k(rays) {}
  uint32_t rayOf(uint32_t i) const { return distal ? i % k : (k - i % k) % k; }  // ring index → ray
  // Where the loop crosses ring index i's angle: the crossing count, the last crossing's loop
  // edge and unwrapped angle, and how high a column there may rise: to its lowest crossing, or
  // lower where the loop runs down the bone within kClearance spacings of its ray.
  int column(uint32_t i, size_t& edge, float& angle, float& top) const {
    const std::vector<float>& beta = *this->beta;
    int count = 0;
    top = INFINITY;
    for (int lap = -1; lap <= 1; ++lap) {
      const float x = float(i) * step + float(lap) * turn;
      for (size_t j = 0; j < n; ++j) {
        const float b0 = beta[j], b1 = beta[j + 1];
        if (!(std::min(b0, b1) <= x && x < std::max(b0, b1))) continue;
        ++count, edge = j, angle = x;
        top = std::min(top, height[j] + (x - b0) / (b1 - b0) * (height[(j + 1) % n] - height[j]));
      }
    }
    for (size_t j = 0; j < n; ++j)
      if (std::fabs(wrapAngle(beta[j] - float(i) * step)) * meanRadius < kClearance * spacing &&
          height[j] < top - kClearance * spacing)
        return 0;
    return count;
  }
};

bool ClassicBuild::planBand(const Loop& L, BandPlan& plan) {
  ClassicModel& m = *model;
  const ClassicPart& P = m.parts[L.part];
  const ClassicContour& c = m.contours[L.distal ? P.contours.back() : P.contours.front()];
  BandChart chart{c, glm::cross(c.normal, c.u), L.distal ? 1.0f : -1.0f, L.distal, k};
  orderLoop(L, chart, plan);
  if (!chartLoop(chart, plan)) return false;
  raiseColumns(L, chart);
  return layStrips(chart, plan);
}

// The loop in the ring's turn (the carried triangles walk it the same way on an outward-wound
// mesh; an inward-wound input: backwards), from its vertex nearest ray 0, with unwrapped angles.
void ClassicBuild::orderLoop(const Loop& L, BandChart& chart, BandPlan& plan) const {
  const ClassicContour& c = chart.c;
  const glm::vec3 w = chart.w;
  const float d = chart.d;
  const size_t n = chart.n = L.groups.size();
  auto angleOf = [&](uint32_t g) {
    glm::vec3 x = rig.positions[representative[g]] - c.centre;
    return d * std::atan2(glm::dot(x, w), glm::dot(x, c.u));
  };
  float total = 0.0f;
  for (size_t i = 0; i < n; ++i) total += wrapAngle(angleOf(L.groups[(i + 1) % n]) - angleOf(L.groups[i]));
  auto turned = [&](size_t i) { return L.groups[total >= 0.0f ? i : n - 1 - i]; };
  size_t start = 0;
  float nearest = INFINITY;
  for (size_t i = 0; i < n; ++i) {
    float a = std::fabs(wrapAngle(angleOf(turned(i))));
    if (a < nearest) nearest = a, start = i;
  }
  plan.loop.resize(n);
  for (size_t i = 0; i < n; ++i) plan.loop[i] = turned((start + i) % n);
  plan.beta.resize(n + 1);
  plan.beta[0] = wrapAngle(angleOf(plan.loop[0]));
  for (size_t i = 1; i <= n; ++i) plan.beta[i] = plan.beta[i - 1] + wrapAngle(angleOf(plan.loop[i % n]) - angleOf(plan.loop[i - 1]));
  chart.beta = &plan.beta;
}

// The chart: heights of the loop above the ring, a ring spacing as the row spacing. False where
// it has no extent (no ring spacing, fewer than three loop vertices, a loop that does not turn).
bool ClassicBuild::chartLoop(BandChart& chart, const BandPlan& plan) const {
  ClassicModel& m = *model;
  const ClassicContour& c = chart.c;
  const float d = chart.d;
  const size_t n = chart.n;
  const std::vector<float>& beta = plan.beta;
  const float step = chart.step = 2.0f * kPi / float(k), turn = chart.turn = beta[n] - beta[0];
  float meanRadius = 0.0f;
  for (uint32_t r = 0; r < k; ++r) meanRadius += m.radii[c.radii + r] / float(k);
  chart.meanRadius = meanRadius;
  const float spacing = chart.spacing = meanRadius * step;
  if (!(spacing > 0.0f) || n < 3 || !(turn > 0.0f)) return false;
  std::vector<float>& height = chart.height;
  height.resize(n);
  for (size_t j = 0; j < n; ++j) height[j] = d * glm::dot(rig.positions[representative[plan.loop[j]]] - c.centre, c.normal);
  return true;
}

// The columns' vertices, ray by ray: one contour plane per row, cast against the part's triangles.
void ClassicBuild::raiseColumns(const Loop& L, BandChart& chart) {
  ClassicModel& m = *model;
  const ClassicPart& P = m.parts[L.part];
  const ClassicContour& c = chart.c;
  const glm::vec3 w = chart.w;
  const float d = chart.d, spacing = chart.spacing;
  auto rayOf = [&](uint32_t i) { return chart.rayOf(i); };
  auto column = [&](uint32_t i, size_t& edge, float& angle, float& top) { return chart.column(i, edge, angle, top); };
  std::vector<uint8_t>& stands = chart.stands;
  std::vector<std::vector<BandVertex>>& made = chart.made;
  stands.assign(k, 0);
  made.assign(k, {});
  std::vector<float> reach(k);
  std::vector<uint32_t> rows(k, 0);
  uint32_t levels = 0;
  for (uint32_t i = 0; i < k; ++i) {
    size_t edge;
    float angle, top;
    if (column(i, edge, angle, top) == 0) continue;
    stands[i] = 1;
    const float q = std::floor(top / spacing - kClearance);
    rows[i] = q > 0.0f ? std::min(kMaxRows, uint32_t(q)) : 0u;
    levels = std::max(levels, rows[i]);
    reach[i] = m.radii[c.radii + rayOf(i)];
  }
  PartTriangles& own = partTriangles[L.part];
  std::vector<float> radius(k);
  std::vector<uint32_t> hit(k);
  for (uint32_t q = 1; q <= levels; ++q) {
    const glm::vec3 O = c.centre + (d * float(q) * spacing) * c.normal;
    own.slabs.candidates(O, c.normal, cut);
    std::fill(radius.begin(), radius.end(), -1.0f);
    std::fill(hit.begin(), hit.end(), 0u);
    castContour(own.corners.data(), cut.data(), uint32_t(cut.size()), O, c.normal, c.u, w, k, m.cosTable.data(),
                m.sinTable.data(), radius.data(), hit.data());
    for (uint32_t i = 0; i < k; ++i) {
      if (rows[i] < q) continue;
      const uint32_t r = rayOf(i);
      if (!(radius[r] > 0.0f) || radius[r] > kMaxWiden * reach[i]) { rows[i] = q - 1; continue; }
      reach[i] = radius[r];
      made[i].push_back(skinPoint(O + radius[r] * (m.cosTable[r] * c.u + m.sinTable[r] * w), own.corners.data() + size_t(hit[r]) * 3,
                                  &rig.indices[size_t(own.triangle[hit[r]]) * 3], P.joint, c.normal));
    }
  }
}

// Strips between neighbouring standing columns: ring below, the column on the right up, the
// loop back above (from the far end of the loop edge the right column crosses: that edge is
// this strip's), the column on the left down (counter-clockwise in the chart, the winding of
// the single zip's triangles). A column whose strip edges cross the loop in the chart (a loop
// that kinks back over it) is taken down, and the strips are laid again.
bool ClassicBuild::layStrips(BandChart& chart, BandPlan& plan) {
  ClassicModel& m = *model;
  const ClassicContour& c = chart.c;
  const glm::vec3 w = chart.w;
  const size_t n = chart.n;
  const std::vector<float>& beta = plan.beta;
  const std::vector<float>& height = chart.height;
  const float step = chart.step, turn = chart.turn, meanRadius = chart.meanRadius, spacing = chart.spacing;
  std::vector<uint8_t>& stands = chart.stands;
  const std::vector<std::vector<BandVertex>>& made = chart.made;
  auto rayOf = [&](uint32_t i) { return chart.rayOf(i); };
  auto column = [&](uint32_t i, size_t& edge, float& angle, float& top) { return chart.column(i, edge, angle, top); };
  std::vector<float> S(n + 2), H(n + 2);  // 0: the first column's crossing, 1…n: the loop, n + 1: its first vertex a turn on
  std::vector<int64_t> pos(k + 1);
  std::vector<ChartPoint> poly;
  std::vector<size_t> sides;  // per strip: ring points, right column, loop points, left column
  for (uint32_t attempt = 0; attempt < k; ++attempt) {
    // The first standing column starts the walk round: the loop from its crossing, unwrapped.
    uint32_t c0 = k;
    size_t e0 = 0;
    float a0 = 0.0f, top0 = 0.0f;
    for (uint32_t i = 0; i < k && c0 == k; ++i)
      if (stands[i] && column(i, e0, a0, top0) == 1) c0 = i;
    if (c0 == k) return false;
    S[0] = a0, H[0] = top0;
    for (size_t p = 1; p <= n; ++p) {
      const size_t j = e0 + p;
      S[p] = beta[j % n] + float(j / n) * turn, H[p] = height[j % n];
    }
    S[n + 1] = S[1] + turn, H[n + 1] = H[1];
    // Columns t = 0…k (ring index c0 + t; t = k is t = 0 a turn on): the loop edge each crosses.
    // A strip holds at least one loop vertex (a loop edge that spans two columns' rays has none to
    // give the strip between them: the later column goes).
    std::fill(pos.begin(), pos.end(), -1);
    pos[0] = 0, pos[k] = int64_t(n);
    for (uint32_t t = 1, last = 0; t < k; ++t) {
      if (!stands[(c0 + t) % k]) continue;
      const float A = a0 + float(t) * step;
      for (size_t p = 0; p <= n && pos[t] < 0; ++p)
        if (std::min(S[p], S[p + 1]) <= A && A < std::max(S[p], S[p + 1])) pos[t] = int64_t(p);
      if (pos[t] <= pos[last] || pos[t] >= int64_t(n)) pos[t] = -1;
      else last = t;
    }
    auto ringPoint = [&](uint32_t t) {
      const uint32_t r = rayOf(c0 + t);
      return ChartPoint{glm::vec2(float(t) * spacing, 0.0f),
                        c.centre + m.radii[c.radii + r] * (m.cosTable[r] * c.u + m.sinTable[r] * w), kRingRef | ((c0 + t) % k)};
    };
    auto columnPoint = [&](uint32_t t, uint32_t q) {
      const uint32_t i = (c0 + t) % k;
      return ChartPoint{glm::vec2(float(t) * spacing, float(q + 1) * spacing), made[i][q].position, i * kMaxRows + q};
    };
    auto loopPoint = [&](size_t p) {
      const size_t j = (e0 + p) % n;
      return ChartPoint{glm::vec2((S[p] - a0) * meanRadius, H[p]), rig.positions[representative[plan.loop[j]]],
                        kLoopRef | uint32_t(j)};
    };
    auto strip = [&](uint32_t ta, uint32_t tb) {
      poly.clear();
      sides.assign(4, 0);
      for (uint32_t t = ta; t <= tb; ++t) poly.push_back(ringPoint(t));
      sides[0] = poly.size();
      for (uint32_t q = 0; q < made[(c0 + tb) % k].size(); ++q) poly.push_back(columnPoint(tb, q));
      sides[1] = poly.size();
      for (int64_t p = pos[tb] + 1; p > pos[ta]; --p) poly.push_back(loopPoint(size_t(p)));
      sides[2] = poly.size();
      for (uint32_t q = uint32_t(made[(c0 + ta) % k].size()); q-- > 0;) poly.push_back(columnPoint(ta, q));
      sides[3] = poly.size();
    };
    // Edges e (poly[e] → poly[e + 1]) of the right column: sides[0] − 1 … sides[1]; of the left:
    // sides[2] − 1 … the last. A crossing that involves neither is the loop's own: no chart.
    bool again = false;
    for (uint32_t ta = 0; ta < k;) {
      uint32_t tb = ta + 1;
      while (tb < k && pos[tb] < 0) ++tb;
      strip(ta, tb);
      const size_t np = poly.size();
      auto right = [&](size_t e) { return e + 1 >= sides[0] && e <= sides[1]; };
      auto left = [&](size_t e) { return e + 1 >= sides[2]; };
      for (size_t e = 0; e < np; ++e)
        for (size_t f = e + 2; f < np; ++f) {
          if (e == 0 && f == np - 1) continue;
          if (!segmentsCross(poly[e].at, poly[e + 1].at, poly[f].at, poly[(f + 1) % np].at)) continue;
          const bool r = right(e) || right(f), l = left(e) || left(f);
          if (!r && !l) return false;
          if (r) stands[(c0 + tb) % k] = 0;
          if (l) stands[(c0 + ta) % k] = 0;
          again = true;
        }
      ta = tb;
    }
    if (again) continue;
    // Laid: the standing columns' vertices join the band's, and each strip is clipped.
    std::vector<uint32_t> global(size_t(k) * kMaxRows, 0);
    for (uint32_t t = 0; t < k; ++t) {
      if (pos[t] < 0) continue;
      const uint32_t i = (c0 + t) % k;
      for (uint32_t q = 0; q < made[i].size(); ++q) global[i * kMaxRows + q] = uint32_t(bandVertices.size()), bandVertices.push_back(made[i][q]);
    }
    plan.triangles.clear();
    for (uint32_t ta = 0; ta < k;) {
      uint32_t tb = ta + 1;
      while (tb < k && pos[tb] < 0) ++tb;
      strip(ta, tb);
      if (!clipEars(poly, plan.triangles)) return false;
      ta = tb;
    }
    for (uint32_t& ref : plan.triangles)
      if (!(ref & (kLoopRef | kRingRef))) ref = global[ref];
    flipEdges(plan.triangles, [&](uint32_t ref) {
      if (ref & kLoopRef) return rig.positions[representative[plan.loop[ref & kRefMask]]];
      if (!(ref & kRingRef)) return bandVertices[ref].position;
      const uint32_t r = rayOf(ref & kRefMask);
      return c.centre + m.radii[c.radii + r] * (m.cosTable[r] * c.u + m.sinTable[r] * w);
    });
    return true;
  }
  return false;
}

// Emits a band's triangles: its plan's, or (no plan) a single zip of the ring to the loop, always
// advancing on the side whose next vertex comes first by angle: every edge of both used once, so
// the seam is closed whatever the two sides' vertex counts.
void ClassicBuild::zipBand(const Loop& L, const BandPlan& plan) {
  ClassicModel& m = *model;
  const ClassicPart& P = m.parts[L.part];
  const ClassicContour& c = m.contours[L.distal ? P.contours.back() : P.contours.front()];
  const size_t n = plan.loop.size();
  auto ringAt = [&](uint32_t i) { return c.first + (L.distal ? i % k : (k - i % k) % k); };
  auto loopAt = [&](size_t j) { return uint32_t(groupOutput[plan.loop[j % n]]); };
  ClassicBand band;
  band.part = L.part;
  band.firstIndex = uint32_t(m.indices.size());
  if (!plan.triangles.empty()) {
    for (uint32_t ref : plan.triangles)
      m.indices.push_back(ref & kLoopRef ? loopAt(ref & kRefMask) : ref & kRingRef ? ringAt(ref & kRefMask) : bandFirst + ref);
  } else {
    uint32_t i = 0;
    size_t jj = 0;
    const float step = 2.0f * kPi / float(k);
    while (i < k || jj < n) {
      if (jj == n || (i < k && float(i + 1) * step <= plan.beta[jj + 1])) {
        m.indices.insert(m.indices.end(), {ringAt(i), ringAt(i + 1), loopAt(jj)});
        ++i;
      } else {
        m.indices.insert(m.indices.end(), {ringAt(i), loopAt(jj + 1), loopAt(jj)});
        ++jj;
      }
    }
  }
  band.indexCount = uint32_t(m.indices.size()) - band.firstIndex;
  m.bands.push_back(band);
}

}  // namespace gcs
