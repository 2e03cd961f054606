// Star rays of the classic model: one contour plane's rays cast against a triangle list, far hits
// dropped as misses, misses filled from their neighbours.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace gcs {
namespace classic {

// Casts the `k` star rays of one contour plane (origin O, normal n, frame u, w) against `triCount`
// triangles (3 contiguous corners each). radius[r]: the outermost hit so far (the caller resets it
// to −1, so several lists can be cast in turn); hitTriangle[r]: the index of the triangle it hit.
void castContour(const glm::vec3* corners, uint32_t triCount, const glm::vec3& O, const glm::vec3& n,
                 const glm::vec3& u, const glm::vec3& w, uint32_t k, const float* cosT, const float* sinT, float* radius,
                 uint32_t* hitTriangle);

// Hits farther than 3 × the contour's median hit become misses (a ray that slipped past the limb
// and hit a far part of the surface). Returns the number of hits left.
uint32_t rejectOutliers(float* radius, uint32_t k, std::vector<float>& scratch);

// Misses take the radius of their nearest hit neighbours (interpolated by angle). False when the
// contour has no hit at all.
bool fillMisses(float* radius, uint32_t k);

}  // namespace classic
}  // namespace gcs
