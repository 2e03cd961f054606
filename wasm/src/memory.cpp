#include "memory.h"
#include <malloc.h>
#include <cstdlib>
#include "error.h"
#include "../include/gcs_skin.h"

namespace gcs {

// The reserved block escapes through this volatile slot: without it the compiler may remove a
// malloc whose result is only tested and freed, and assume it succeeded.
static void* volatile reserved = nullptr;

bool reserveMemory(uint64_t bytes, const char* what) {
  // Leave room below 4 GiB for what the caller holds besides (and for size_t being 32 bits).
  const uint64_t limit = 0xF0000000ull;
  reserved = bytes < limit ? std::malloc(size_t(bytes)) : nullptr;
  void* p = reserved;
  if (!p)
    return fail(GCS_ERR_OUT_OF_MEMORY, "out of memory: %s needs about %llu MB and wasm memory cannot grow that far (4 GB at most)",
                what, (unsigned long long)(bytes >> 20));
  std::free(p);
  reserved = nullptr;
  return true;
}

// The estimates count every array a build holds at its peak (see rig.cpp, gcs_build*.cpp,
// reference_deformers.cpp, classic_model.cpp), with a 1.5× margin for vector growth and the heap.
uint64_t rigPeakBytes(uint64_t v, uint64_t i, uint64_t j, uint64_t slots) {
  return (v * (12 + 12 + 8 * slots + 12) + i * 4 + j * (64 * 2 + 12 + 4)) * 3 / 2 + 65536;
}
uint64_t gcsPeakBytes(uint64_t v, uint64_t i, uint64_t j, uint64_t slots) {
  // Smooth weights nodes: up to two sections per welded vertex (~300 bytes each, tables included;
  // keys and blends of 8 influences add ~40 bytes a slot); the centres' memo up to 4 pair sums per
  // vertex (~60 bytes each in its hash map; the surface it reads reserves its own).
  return (v * (860 + 240 + 40 * (slots - 4)) + i * 8 + j * 4096) * 3 / 2 + 65536;
}
uint64_t skinningPeakBytes(uint64_t v, uint64_t i, uint64_t j, uint64_t slots) {
  return (v * (24 + 24 + 24 + 8 * slots + 4) + i * 4 + j * 128) * 3 / 2 + 65536;
}
uint64_t classicPeakBytes(uint64_t v, uint64_t i, uint64_t parts, uint64_t contours, uint64_t rays) {
  const uint64_t points = parts * (contours + 2) * (rays + 1);
  // i: welded edges (16 bytes × 3 per triangle) and loop edges; each part's gathered triangles with
  // their slabs (a triangle in up to 6 parts' lists, ~60 bytes each); points: rings, and the ray
  // casts each part keeps across rounds and rebuilds.
  return (v * 300 + i * 170 + points * 150) * 3 / 2 + 65536;
}

}  // namespace gcs

extern "C" uint32_t gcs_heap_in_use(void) {
#if defined(__EMSCRIPTEN__)
  return uint32_t(mallinfo().uordblks);  // dlmalloc's count of allocated bytes
#elif defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
  return uint32_t(mallinfo2().uordblks);  // native builds (tests, fuzzers)
#else
  return 0;  // no allocator statistics on this platform
#endif
}
