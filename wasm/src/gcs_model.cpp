// The GCS model per frame: each section's transform (the weights criterion's blends, scalar and
// SIMD; the paper's fractional rotations), then every vertex by its section's transform. The build
// is gcs_build*.cpp.
#include "gcs_model.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <tuple>
#include "error.h"

namespace gcs {

float Deformer::stat(GcsStat) const { return std::nanf(""); }

float GcsDeformerImpl::stat(GcsStat which) const {
  switch (which) {
    case GCS_STAT_SECTIONS: return float(sections.size());
    case GCS_STAT_PARTS: return float(partCount);
    case GCS_STAT_ADJUSTED_SHARE:
      return sections.empty() ? 0.0f : float(countAdjusted()) / float(sections.size());
    case GCS_STAT_ADJUSTED_SECTIONS: return float(countAdjusted());
  }
  return std::nanf("");
}

namespace {
// [R | t] of a decomposed skin matrix (its rigid part) and the inverse of such a matrix.
glm::mat4 rigidOf(const JointPose& p) {
  glm::mat4 m = glm::mat4_cast(p.rotation);
  m[3] = glm::vec4(p.translation, 1.0f);
  return m;
}
glm::mat4 rigidInverse(const glm::mat4& m) {
  glm::mat3 rt = glm::transpose(glm::mat3(m));
  glm::mat4 out(rt);
  out[3] = glm::vec4(-(rt * glm::vec3(m[3])), 1.0f);
  return out;
}
}  // namespace

// A section with a centre of rotation p* (rotation_centres.h): its 3×3 part M (the blend's rotation
// and scale) stays; its translation makes M p* + t = Σ w_j S_j p*, p* moved by linear blend
// skinning. Written t = Σ w_j (S_j p* − p*) − (M p* − p*): identity poses give t = 0 exactly.
void GcsDeformerImpl::turnAboutCentre(const glm::mat4* skin, const Section& sec, glm::mat4& position) const {
  const glm::vec3 p = sec.rotationCentre;
  glm::vec3 moved(0.0f);
  for (uint32_t k = 0; k < sec.influenceCount; ++k) {
    const Influence& in = influences[sec.influenceFirst + k];
    const glm::mat4& s = skin[in.joint];
    moved += in.weight * (glm::vec3(s[0]) * p.x + glm::vec3(s[1]) * p.y + glm::vec3(s[2]) * p.z + glm::vec3(s[3]) - p);
  }
  const glm::vec3 turned = glm::vec3(position[0]) * p.x + glm::vec3(position[1]) * p.y + glm::vec3(position[2]) * p.z - p;
  position[3] = glm::vec4(moved - turned, 1.0f);
}

// Weights criterion: each section's transform is the dual-quaternion blend of its joints at its
// mean weights (a rigid core: S_j itself), or with centres the blend's rotation about its centre of
// rotation. O(sections × influences).
void GcsDeformerImpl::sectionTransformsWeights(const glm::mat4* skin, const ScaleState& scale) {
#if defined(__wasm_simd128__)
  if (moderateUniform(scale)) return sectionTransformsWeightsUniform(skin, scale.s);
#endif
  const uint32_t S = uint32_t(sections.size());
  for (uint32_t i = 0; i < S; ++i) {
    const Section& sec = sections[i];
    bool renorm = false;
    if (sec.rigid) {
      sectionMatrices[i] = skin[sec.part];
      normalMatrices[i] = poses[sec.part].normal;
      renorm = poses[sec.part].renormalise;
    } else {
      float w[kMaxInfluences];
      for (uint32_t k = 0; k < sec.influenceCount; ++k) {
        const Influence& in = influences[sec.influenceFirst + k];
        blendPoseScratch[k] = &poses[in.joint];
        w[k] = in.weight;
      }
      blendPoses(blendPoseScratch.data(), w, sec.influenceCount, scale, sectionMatrices[i], normalMatrices[i], renorm);
      if (sec.aboutCentre) turnAboutCentre(skin, sec, sectionMatrices[i]);
    }
    renormalise[i] = renorm;
  }
}

#if defined(__wasm_simd128__)

namespace {
// A node's dual quaternion (real part in br, dual part in bd): its joints' weighted sum, each
// weight negated when the joint's quaternion lies in the other hemisphere from the first's.
template <uint32_t Count>
inline void accumulateNode(const JointPose* poses, const Influence* in, uint32_t count, v128_t& br, v128_t& bd) {
  const v128_t signBit = wasm_f32x4_splat(-0.0f);
  const v128_t pivot = wasm_v128_load(&poses[in[0].joint].real);
  const v128_t w0 = wasm_f32x4_splat(in[0].weight);
  br = wasm_f32x4_mul(w0, pivot);
  bd = wasm_f32x4_mul(w0, wasm_v128_load(&poses[in[0].joint].dual));
  const uint32_t n = Count ? Count : count;
  for (uint32_t k = 1; k < n; ++k) {
    const JointPose& p = poses[in[k].joint];
    const v128_t r = wasm_v128_load(&p.real);
    v128_t dot = wasm_f32x4_mul(r, pivot);
    dot = wasm_f32x4_add(dot, wasm_i32x4_shuffle(dot, dot, 1, 0, 3, 2));
    dot = wasm_f32x4_add(dot, wasm_i32x4_shuffle(dot, dot, 2, 3, 0, 1));
    const v128_t w = wasm_v128_xor(wasm_f32x4_splat(in[k].weight), wasm_v128_and(dot, signBit));
    br = wasm_f32x4_add(br, wasm_f32x4_mul(w, r));
    bd = wasm_f32x4_add(bd, wasm_f32x4_mul(w, wasm_v128_load(&p.dual)));
  }
}
}  // namespace

// The same blends as sectionTransformsWeights when every scale is s·I (the common case), in SIMD:
// each blended section's dual quaternion accumulated in two registers (nodes grouped by joint
// count), then four sections at a time turned into matrices (one lane each), with the very formulas
// of blendPoses. Blended sections' normal matrices are not written: with a uniform scale they are
// their position matrices over s, and deform() uses them so.
void GcsDeformerImpl::sectionTransformsWeightsUniform(const glm::mat4* skin, float s) {
  std::fill(renormalise.begin(), renormalise.end(), uint8_t(0));
  for (uint32_t i : rigidSections) {
    const uint32_t j = sections[i].part;
    sectionMatrices[i] = skin[j];
    normalMatrices[i] = poses[j].normal;
  }
  const JointPose* pose = poses.data();
  const Influence* influence = influences.data();
  uint32_t b = 0;
  for (uint32_t count = 1; count <= kMaxInfluences; ++count) {
    const uint32_t end = nodesWithCount[count + 1];
    for (; b < end; ++b) {
      v128_t br, bd;
      const Influence* in = influence + nodeInfluenceFirst[b];
      if (count == 2) accumulateNode<2>(pose, in, count, br, bd);
      else if (count == 3) accumulateNode<3>(pose, in, count, br, bd);
      else if (count == 4) accumulateNode<4>(pose, in, count, br, bd);
      else accumulateNode<0>(pose, in, count, br, bd);
      wasm_v128_store(&nodeReal[b], br);
      wasm_v128_store(&nodeDual[b], bd);
    }
  }
  const uint32_t B = b;
  const v128_t one = wasm_f32x4_splat(1.0f), two = wasm_f32x4_splat(2.0f), scale = wasm_f32x4_splat(s);
  const v128_t zero = wasm_f32x4_splat(0.0f);
  for (uint32_t g = 0; g < B; g += 4) {
    v128_t x = wasm_v128_load(&nodeReal[g]), y = wasm_v128_load(&nodeReal[g + 1]);
    v128_t z = wasm_v128_load(&nodeReal[g + 2]), w = wasm_v128_load(&nodeReal[g + 3]);
    transpose4(x, y, z, w);
    v128_t dx = wasm_v128_load(&nodeDual[g]), dy = wasm_v128_load(&nodeDual[g + 1]);
    v128_t dz = wasm_v128_load(&nodeDual[g + 2]), dw = wasm_v128_load(&nodeDual[g + 3]);
    transpose4(dx, dy, dz, dw);
    const v128_t inv2 = wasm_f32x4_div(
        one, wasm_f32x4_add(wasm_f32x4_add(wasm_f32x4_mul(x, x), wasm_f32x4_mul(y, y)),
                            wasm_f32x4_add(wasm_f32x4_mul(z, z), wasm_f32x4_mul(w, w))));
    const v128_t k2 = wasm_f32x4_mul(two, inv2);
    const v128_t xx = wasm_f32x4_mul(x, x), yy = wasm_f32x4_mul(y, y), zz = wasm_f32x4_mul(z, z);
    const v128_t xy = wasm_f32x4_mul(x, y), xz = wasm_f32x4_mul(x, z), yz = wasm_f32x4_mul(y, z);
    const v128_t wx = wasm_f32x4_mul(w, x), wy = wasm_f32x4_mul(w, y), wz = wasm_f32x4_mul(w, z);
    auto oneMinus = [&](v128_t a, v128_t b2) { return wasm_f32x4_sub(one, wasm_f32x4_mul(k2, wasm_f32x4_add(a, b2))); };
    auto times = [&](v128_t a) { return wasm_f32x4_mul(k2, a); };
    // Rows of the transposed blocks: entry (row r of column c) for the four sections.
    v128_t c00 = oneMinus(yy, zz), c01 = times(wasm_f32x4_add(xy, wz)), c02 = times(wasm_f32x4_sub(xz, wy)), c03 = zero;
    v128_t c10 = times(wasm_f32x4_sub(xy, wz)), c11 = oneMinus(xx, zz), c12 = times(wasm_f32x4_add(yz, wx)), c13 = zero;
    v128_t c20 = times(wasm_f32x4_add(xz, wy)), c21 = times(wasm_f32x4_sub(yz, wx)), c22 = oneMinus(xx, yy), c23 = zero;
    // t = 2·(w·d − dw·r − d × r)/|r|² (the vector part of 2·bd·conj(br)/|br|²).
    auto tRow = [&](v128_t wd, v128_t dwr, v128_t crossA, v128_t crossB) {
      return wasm_f32x4_mul(k2, wasm_f32x4_sub(wasm_f32x4_sub(wasm_f32x4_mul(w, wd), wasm_f32x4_mul(dw, dwr)),
                                               wasm_f32x4_sub(crossA, crossB)));
    };
    v128_t t0 = tRow(dx, x, wasm_f32x4_mul(dy, z), wasm_f32x4_mul(y, dz));
    v128_t t1 = tRow(dy, y, wasm_f32x4_mul(dz, x), wasm_f32x4_mul(z, dx));
    v128_t t2 = tRow(dz, z, wasm_f32x4_mul(dx, y), wasm_f32x4_mul(x, dy));
    v128_t t3 = one;
    transpose4(c00, c01, c02, c03);
    transpose4(c10, c11, c12, c13);
    transpose4(c20, c21, c22, c23);
    transpose4(t0, t1, t2, t3);
    const v128_t normalCol[3][4] = {{c00, c01, c02, c03}, {c10, c11, c12, c13}, {c20, c21, c22, c23}};
    const v128_t translation[4] = {t0, t1, t2, t3};
    for (uint32_t k = 0; k < 4 && g + k < B; ++k) {
      float* m = &sectionMatrices[blendedSections[g + k]][0][0];
      for (int c = 0; c < 3; ++c) wasm_v128_store(m + 4 * c, wasm_f32x4_mul(scale, normalCol[c][k]));
      wasm_v128_store(m + 12, translation[k]);
    }
  }
  if (settings.centres)  // the centres' translations replace the blends' (none otherwise: no pass)
    for (uint32_t b2 = 0; b2 < B; ++b2)
      if (nodeCentre[b2].w != 0.0f) {
        const uint32_t i = blendedSections[b2];
        turnAboutCentre(skin, sections[i], sectionMatrices[i]);
      }
}
#endif

// The paper's rule (Y and axial criteria): M = S_p · D_j^α · D_k^β on the rigid parts of the skin
// matrices, then the section's scale (the same blend of the joints' scales) applied first.
void GcsDeformerImpl::sectionTransformsPaper(const glm::mat4* skin, const ScaleState& scale) {
  const uint32_t J = jointCount;
  // Relative motion of each part with respect to its parent part: D_j = rigid(S_p)^-1 · rigid(S_j).
  for (uint32_t j = 0; j < J; ++j) {
    if (!parts[j].isPart || parts[j].parent < 0) continue;
    glm::mat4 d = rigidInverse(rigidOf(poses[parts[j].parent])) * rigidOf(poses[j]);
    // The rigid parts act on scaled points (S = [R | t]·K): their joint centre is K·c_j.
    motions[j] = motionAbout(d, poses[j].scale * jointCentres[j]);
    if (settings.twistSpread) swingTwist(motions[j].rotation, parts[j].twistAxis, swings[j], twists[j]);
  }
  const uint32_t S = uint32_t(sections.size());
  for (uint32_t i = 0; i < S; ++i) {
    const Section& sec = sections[i];
    bool renorm = false;
    if (sec.parent < 0 && !(sec.distal >= 0 && sec.beta > 0.0f)) {
      sectionMatrices[i] = skin[sec.part];
      normalMatrices[i] = poses[sec.part].normal;
      renormalise[i] = poses[sec.part].renormalise;
      continue;
    }
    glm::mat4 m;
    if (sec.parent < 0) {
      m = rigidOf(poses[sec.part]);
    } else {
      const Motion& d = motions[sec.part];
      glm::mat4 frac;
      if (settings.twistSpread) {
        glm::quat r = fractionOf(swings[sec.part], sec.alpha) * fractionOf(twists[sec.part], sec.tau);
        frac = matrixOf(r, d.centre, sec.alpha * d.translation);
      } else {
        frac = fractionMatrix(d, sec.alpha);
      }
      m = rigidOf(poses[sec.parent]) * frac;
    }
    if (sec.distal >= 0 && sec.beta > 0.0f) {
      const Motion& d = motions[sec.distal];
      if (settings.twistSpread)
        m = m * matrixOf(fractionOf(swings[sec.distal], sec.beta), d.centre, sec.beta * d.translation);
      else
        m = m * fractionMatrix(d, sec.beta);
    }
    // Scale: parent, part and distal joint weighted (1 − α, α − β, β), applied first.
    if (scale.uniform) {  // the common case: m's rotation carries the normals as it is
      sectionMatrices[i] = glm::mat4(scale.s * m[0], scale.s * m[1], scale.s * m[2], m[3]);
      normalMatrices[i] = glm::mat4(m[0], m[1], m[2], glm::vec4(0.0f));
      renormalise[i] = 0;
      continue;
    }
    glm::mat3 k = poses[sec.part].scale;
    if (!scale.same) {
      k = (sec.parent >= 0 ? sec.alpha : 1.0f) * k;
      if (sec.parent >= 0) k += (1.0f - sec.alpha) * poses[sec.parent].scale;
      if (sec.distal >= 0 && sec.beta > 0.0f) k += sec.beta * (poses[sec.distal].scale - poses[sec.part].scale);
    }
    glm::mat3 r(m);
    glm::mat3 rk = r * k;
    sectionMatrices[i] = glm::mat4(glm::vec4(rk[0], 0.0f), glm::vec4(rk[1], 0.0f), glm::vec4(rk[2], 0.0f), m[3]);
    glm::mat4 n(normalMatrix(glm::quat_cast(r), k, renorm));
    n[3] = glm::vec4(0.0f);
    normalMatrices[i] = n;
    renormalise[i] = renorm;
  }
}

// Adjusted: the section's transform differs from its part's rigid S_j by more than the tolerance
// anywhere on the section's bounding sphere. Over the last frame; cached until the next deform.
uint32_t GcsDeformerImpl::countAdjusted() const {
  if (adjustedValid) return adjustedSections;
  uint32_t adjusted = 0;
  for (uint32_t i = 0; i < uint32_t(sections.size()); ++i) {
    const Section& sec = sections[i];
    glm::mat4 diff = sectionMatrices[i] - lastSkin[sec.part];
    glm::vec3 atCentre = glm::vec3(diff * glm::vec4(sec.centre, 1.0f));
    float linear = std::sqrt(glm::dot(glm::vec3(diff[0]), glm::vec3(diff[0])) +
                             glm::dot(glm::vec3(diff[1]), glm::vec3(diff[1])) +
                             glm::dot(glm::vec3(diff[2]), glm::vec3(diff[2])));
    if (glm::length(atCentre) + linear * sec.radius > adjustTolerance) ++adjusted;
  }
  adjustedSections = adjusted;
  adjustedValid = true;
  return adjusted;
}

void GcsDeformerImpl::computeSections(const glm::mat4* skin) {
  const uint32_t J = jointCount;
  const ScaleState scale = decomposeJoints(skin, usedJoints.data(), uint32_t(usedJoints.size()), poses.data());
  frameScale = scale;
  if (settings.criterion == GCS_CRITERION_WEIGHTS) sectionTransformsWeights(skin, scale);
  else sectionTransformsPaper(skin, scale);
  // The adjusted-section statistic is computed when asked for (stat), from a copy of the skin.
  std::memcpy(lastSkin.data(), skin, size_t(J) * sizeof(glm::mat4));
  adjustedValid = false;
}

void GcsDeformerImpl::deform(const glm::mat4* skin) {
  computeSections(skin);
  transformVertices(restNormals.data(), positions.data(), normals.data());
  if (!tangents.empty()) {
    // Tangents turn like normals: the same kernels over the rest tangents (positions discarded).
    transformVertices(restTangents.data(), tangentPassPositions.data(), turnedTangents.data());
    packTangents();
  }
}

// Every vertex by this frame's section transforms: positions from the rest positions, and
// `inNrm` (the rest normals, or the rest tangents) turned into `outNrm`.
void GcsDeformerImpl::transformVertices(const float* inNrm, float* outPos, float* outNrm) {
  const uint32_t S = uint32_t(sections.size());
  // Every scale the same uniform s (and the weights criterion, whose normal matrices are then the
  // rotations of the position matrices, and are not written for blended sections): one matrix, or
  // one lerp, serves positions and normals.
  const bool uniform = moderateUniform(frameScale) && settings.criterion == GCS_CRITERION_WEIGHTS;
  const float invS = uniform ? 1.0f / frameScale.s : 1.0f, invS2 = invS * invS;
  if (settings.smooth) {
    for (const BlendRun& run : blendRuns) {
      size_t o = size_t(run.first) * 3;
      const uint32_t a = run.section, b = run.other;
      if (uniform) {
        const float* f = &blendF[run.first];
        const float* p = &restPositions[o];
        const float* n = inNrm + o;
        if (run.third != a) {  // a three-joint lattice cell
          const uint32_t c = run.third;
          const float* g = &blendThirdF[run.first];
          const NormalFix fix3 =
              rotationBlendFix3(leastRotationTrace(sectionMatrices[a], sectionMatrices[b], sectionMatrices[c]) * invS2);
          withUniformFix(fix3, invS == 1.0f, [&](auto fixTag, auto unitTag) {
            blendRun3UniformT<decltype(fixTag)::value, decltype(unitTag)::value>(
                sectionMatrices[a], sectionMatrices[b], sectionMatrices[c], invS, f, g, p, n, outPos + o, outNrm + o,
                run.count);
          });
          continue;
        }
        if (a == b) {
          transformRunUniform(sectionMatrices[a], invS, p, n, outPos + o, outNrm + o, run.count);
          continue;
        }
        const NormalFix fix = rotationBlendFix(rotationTrace(sectionMatrices[a], sectionMatrices[b]) * invS2);
        withUniformFix(fix, invS == 1.0f, [&](auto fixTag, auto unitTag) {
          blendRunUniformT<decltype(fixTag)::value, decltype(unitTag)::value>(
              sectionMatrices[a], sectionMatrices[b], invS, f, p, n, outPos + o, outNrm + o, run.count);
        });
      } else if (run.third != a) {
        const uint32_t c = run.third;
        const NormalFix fix = renormalise[a] || renormalise[b] || renormalise[c]
                                  ? NormalFix::Exact
                                  : rotationBlendFix3(leastRotationTrace(normalMatrices[a], normalMatrices[b], normalMatrices[c]));
        blendRun3(sectionMatrices[a], normalMatrices[a], sectionMatrices[b], normalMatrices[b], sectionMatrices[c],
                  normalMatrices[c], fix, &blendF[run.first], &blendThirdF[run.first], &restPositions[o],
                  inNrm + o, outPos + o, outNrm + o, run.count);
      } else if (a == b) {
        transformRun(sectionMatrices[a], normalMatrices[a], renormalise[a] != 0, &restPositions[o], inNrm + o,
                     outPos + o, outNrm + o, run.count);
      } else {
        blendRun(sectionMatrices[a], normalMatrices[a], renormalise[a] != 0, sectionMatrices[b], normalMatrices[b],
                 renormalise[b] != 0, &blendF[run.first], &restPositions[o], inNrm + o, outPos + o, outNrm + o,
                 run.count);
      }
    }
    return;
  }
  for (uint32_t i = 0; i < S; ++i) {
    const Section& sec = sections[i];
    size_t o = size_t(sec.first) * 3;
    if (uniform)
      transformRunUniform(sectionMatrices[i], invS, &restPositions[o], inNrm + o, outPos + o, outNrm + o,
                          sec.count);
    else
      transformRun(sectionMatrices[i], normalMatrices[i], renormalise[i] != 0, &restPositions[o], inNrm + o,
                   outPos + o, outNrm + o, sec.count);
  }
}

}  // namespace gcs
