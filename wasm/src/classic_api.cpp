// The C API of the classic cross-section model (gcs_skin.h, "classic cross-sections").
#include <cmath>
#include <vector>
#include "../include/gcs_skin.h"
#include "classic_model.h"
#include "error.h"
#include "memory.h"

namespace {
gcs::ClassicModel* asClassic(const GcsDeformer* d) {
  return d && d->impl && d->impl->kind() == GCS_KIND_CLASSIC ? static_cast<gcs::ClassicModel*>(d->impl) : nullptr;
}
}  // namespace

extern "C" {

GcsDeformer* gcs_build_classic(const GcsRig* rig, uint32_t contours, uint32_t rays, float bulge) {
  gcs::clearError();
  if (!rig) {
    gcs::fail(GCS_ERR_INVALID_ARGUMENT, "the rig is null (destroyed or never created)");
    return nullptr;
  }
  {
    // Parts (joints owning a vertex by dominant weight): what the contour count multiplies.
    const gcs::Rig& r = rig->rig;
    std::vector<uint8_t> owns;
    uint64_t parts = 0;
    if (r.jointCount <= GCS_MAX_JOINTS) {
      owns.assign(r.jointCount, 0);
      for (uint32_t v = 0; v < r.vertexCount; ++v) {
        uint32_t j = r.dominantJoint(v);
        if (j < r.jointCount && !owns[j]) owns[j] = 1, ++parts;
      }
    }
    const uint64_t c = contours <= GCS_CLASSIC_MAX_CONTOURS ? contours : 0, k = rays <= GCS_CLASSIC_MAX_RAYS ? rays : 0;
    if (!gcs::reserveMemory(gcs::classicPeakBytes(r.vertexCount, r.indices.size(), parts, c, k), "the classic model"))
      return nullptr;
  }
  gcs::ClassicModel* model = gcs::buildClassic(rig->rig, contours, rays, bulge);
  if (!model) return nullptr;
  GcsDeformer* handle = new (std::nothrow) GcsDeformer{model};
  if (!handle) {
    delete model;
    gcs::fail(GCS_ERR_OUT_OF_MEMORY, "out of memory while creating a deformer");
  }
  return handle;
}

int gcs_classic_set_bulge(GcsDeformer* deformer, float bulge) {
  gcs::clearError();
  gcs::ClassicModel* m = asClassic(deformer);
  if (!m) return gcs::fail(GCS_ERR_INVALID_ARGUMENT, "the deformer is null or not a classic cross-section model");
  if (!(bulge >= 0.0f && bulge <= GCS_CLASSIC_MAX_BULGE))
    return gcs::fail(GCS_ERR_OUT_OF_RANGE, "the bulge must be between 0 and %g; got %g",
                     double(GCS_CLASSIC_MAX_BULGE), double(bulge));
  m->bulge = bulge;
  return 1;
}

uint32_t gcs_classic_part_count(const GcsDeformer* deformer) {
  const gcs::ClassicModel* m = asClassic(deformer);
  return m ? uint32_t(m->reportJoints.size()) : 0;
}

const int32_t* gcs_classic_parts(const GcsDeformer* deformer) {
  const gcs::ClassicModel* m = asClassic(deformer);
  return m && !m->report.empty() ? m->report.data() : nullptr;
}

const int32_t* gcs_classic_contour_of_vertex(const GcsDeformer* deformer) {
  const gcs::ClassicModel* m = asClassic(deformer);
  return m && !m->contourOfVertex.empty() ? m->contourOfVertex.data() : nullptr;
}

const int32_t* gcs_classic_source_of_vertex(const GcsDeformer* deformer) {
  const gcs::ClassicModel* m = asClassic(deformer);
  return m && !m->sourceOfVertex.empty() ? m->sourceOfVertex.data() : nullptr;
}

float gcs_classic_detail_loss(const GcsDeformer* deformer, uint32_t which) {
  const gcs::ClassicModel* m = asClassic(deformer);
  return m ? m->detailLoss(which) : std::nanf("");
}

}  // extern "C"
