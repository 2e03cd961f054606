// Placeholder until the classic cross-section model lands (issue 3): every call reports that
// the model is unavailable.
#include <cmath>
#include "../include/gcs_skin.h"
#include "error.h"

extern "C" {
GcsDeformer* gcs_build_classic(const GcsRig*, uint32_t, uint32_t, float) {
  gcs::fail(GCS_ERR_DEGENERATE, "the classic cross-section model is not built into this binary yet");
  return nullptr;
}
int gcs_classic_set_bulge(GcsDeformer*, float) {
  return gcs::fail(GCS_ERR_DEGENERATE, "the classic cross-section model is not built into this binary yet");
}
uint32_t gcs_classic_part_count(const GcsDeformer*) { return 0; }
const int32_t* gcs_classic_parts(const GcsDeformer*) { return nullptr; }
float gcs_classic_detail_loss(const GcsDeformer*, uint32_t) { return std::nanf(""); }
}
