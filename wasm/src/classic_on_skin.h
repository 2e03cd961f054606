// The classic model's on-skin test: which resampled parts would stand off the skin they replace.
#pragma once
#include <cstdint>
#include <vector>
#include "classic_model.h"
#include "rig.h"

namespace gcs {

// Per joint: 1 if its part's tube fails the test (see classic_on_skin.cpp). ringTriangle: per ring
// vertex, the rig triangle its ray hit (the triangle count: a filled miss). Leaves the model at
// the bind pose. May throw std::bad_alloc.
std::vector<uint8_t> offSurfaceParts(const Rig& rig, ClassicModel& m, const std::vector<uint32_t>& ringTriangle);

}  // namespace gcs
