// Star rays of the classic model: one contour plane's rays cast against a triangle list, far hits
// dropped as misses, misses filled from their neighbours.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace gcs {
namespace classic {

// Casts the `k` star rays of one contour plane (origin O, normal n, frame u, w) against the
// triangles listed in `triangles` (indices into `corners`, 3 contiguous corners each, any order).
// radius[r]: the outermost hit (the caller resets it to −1); hitTriangle[r]: the index of the
// triangle it hit (of equally far hits, the lowest index: the result does not depend on the order).
void castContour(const glm::vec3* corners, const uint32_t* triangles, uint32_t count, const glm::vec3& O,
                 const glm::vec3& n, const glm::vec3& u, const glm::vec3& w, uint32_t k, const float* cosT,
                 const float* sinT, float* radius, uint32_t* hitTriangle);

// A part's gathered triangles in slabs along its bone, so that a contour reads a few slabs instead
// of every triangle: a plane through O tilted from the bone by θ cuts only triangles that come
// within rmax · tan θ of O along the bone (rmax: the farthest corner from the bone's line).
class TriangleSlabs {
 public:
  void build(const glm::vec3* corners, uint32_t triCount, const glm::vec3& origin, const glm::vec3& axis);
  // Every triangle the plane through O with unit normal n may cut (each once; a superset).
  void candidates(const glm::vec3& O, const glm::vec3& n, std::vector<uint32_t>& out) const;

 private:
  uint32_t slabOf(float s) const;
  glm::vec3 origin{0.0f}, axis{0.0f, 1.0f, 0.0f};
  float lo = 0.0f, width = 1.0f, rmax = 0.0f, margin = 0.0f;
  uint32_t triCount = 0, slabCount = 1;
  std::vector<float> triLo, triHi;        // each triangle's extent along the bone
  std::vector<uint32_t> first, members;   // slab b holds members[first[b] … first[b + 1])
};

// Hits farther than 3 × the contour's median hit become misses (a ray that slipped past the limb
// and hit a far part of the surface). Returns the number of hits left.
uint32_t rejectOutliers(float* radius, uint32_t k, std::vector<float>& scratch);

// Misses take the radius of their nearest hit neighbours (interpolated by angle). False when the
// contour has no hit at all.
bool fillMisses(float* radius, uint32_t k);

}  // namespace classic
}  // namespace gcs
