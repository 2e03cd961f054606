// Allocation failure without exceptions: the wasm build has none, so a failed `new` inside a
// std::vector aborts the whole module. Every build first reserves its estimated peak in one
// malloc (which returns null when wasm memory cannot grow) and frees it: the heap has then grown
// enough for the build's own allocations, and a build that cannot fit fails with
// GCS_ERR_OUT_OF_MEMORY instead of aborting.
#pragma once
#include <cstdint>

namespace gcs {

// Reserves `bytes` (an upper bound of a build's peak, computed in 64 bits) and releases them.
// Returns false with GCS_ERR_OUT_OF_MEMORY recorded (naming `what`) when they cannot be had.
bool reserveMemory(uint64_t bytes, const char* what);

// Upper bounds of the peak memory of each build (bytes), from the input sizes; `slots` is the
// rig's influence slots per vertex (4 or 8).
uint64_t rigPeakBytes(uint64_t vertexCount, uint64_t indexCount, uint64_t jointCount, uint64_t slots);
uint64_t gcsPeakBytes(uint64_t vertexCount, uint64_t indexCount, uint64_t jointCount, uint64_t slots);
uint64_t skinningPeakBytes(uint64_t vertexCount, uint64_t indexCount, uint64_t jointCount, uint64_t slots);
uint64_t classicPeakBytes(uint64_t vertexCount, uint64_t indexCount, uint64_t partCount, uint64_t contours,
                          uint64_t rays);

}  // namespace gcs
