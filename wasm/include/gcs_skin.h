/*
 * gcs-skin — skin deformation by generalized cross-sections (Li, Wang, Mao), with the
 * classic cross-section model, linear blend skinning and dual quaternions as references.
 *
 * The C API of the core. One header documents every parameter's contract.
 *
 * Life cycle (ozz-animation style: an offline "raw → runtime" builder, then per-frame jobs):
 *   1. gcs_rig_create()      validates and copies a skinned mesh + skeleton (the raw input).
 *   2. gcs_build_*()         builds a runtime deformer from a rig (GCS, classic, LBS, DQS).
 *                            A deformer keeps no pointer to the rig: the rig may be destroyed.
 *   3. gcs_deformer_deform() once per frame, from J skinning matrices; writes positions and
 *                            normals (and tangents, when set) into arrays owned by the deformer
 *                            (no allocation).
 *   4. gcs_deformer_destroy(), gcs_rig_destroy().
 *
 * Errors: every function that can fail returns 0 (or a null handle) and records an error code
 * (GcsError) and an English sentence, read by gcs_last_error_code()/gcs_last_error_message().
 * A successful call sets the code to GCS_OK. A rejected call never changes the object it was
 * given: the object stays usable.
 *
 * Memory: wasm memory grows up to 4 GiB; pointers are unsigned 32-bit offsets (read them as
 * unsigned in JavaScript: `>>> 0`). The core is built without C++ exceptions, so a failed
 * allocation inside a build would abort the module: every gcs_rig_create / gcs_build_* first
 * reserves an upper bound of its peak memory (one malloc, freed at once) and fails with
 * GCS_ERR_OUT_OF_MEMORY when it cannot be had (as does gcs_deformer_set_morph_targets).
 * gcs_deformer_deform never allocates.
 *
 * Conventions: matrices are column-major float[16] (glTF, three.js, GLM). Positions and normals
 * are float[3] per vertex, interleaved (x, y, z). Indices are uint32 triangle lists.
 * Pointers handed out (positions, normals, indices, …) point into wasm memory: they stay valid
 * until the owning object is destroyed, but JavaScript views on them die when memory grows.
 */
#ifndef GCS_SKIN_H
#define GCS_SKIN_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The version of this header and of the core built from it (the npm package's version):
   major · 10000 + minor · 100 + patch, so 0.1.0 is 100. gcs_version() returns the built core's. */
#define GCS_VERSION_MAJOR 0
#define GCS_VERSION_MINOR 1
#define GCS_VERSION_PATCH 0
#define GCS_VERSION (GCS_VERSION_MAJOR * 10000 + GCS_VERSION_MINOR * 100 + GCS_VERSION_PATCH)

typedef enum GcsError {
  GCS_OK = 0,
  GCS_ERR_INVALID_ARGUMENT = 1,   /* a null pointer, a bad enum value, a bad handle */
  GCS_ERR_LENGTH_MISMATCH = 2,    /* array lengths that do not agree with each other */
  GCS_ERR_INDEX_OUT_OF_RANGE = 3, /* a triangle index >= vertex count */
  GCS_ERR_JOINT_OUT_OF_RANGE = 4, /* a skin joint id or a parent id out of range, or a cycle */
  GCS_ERR_NON_FINITE = 5,         /* NaN or infinity in positions, normals, weights, matrices */
  GCS_ERR_BAD_WEIGHTS = 6,        /* negative weights, or a vertex whose weights sum to 0 */
  GCS_ERR_SECTION_COUNT = 7,      /* section count outside [GCS_MIN_SECTIONS, GCS_MAX_SECTIONS] */
  GCS_ERR_ZERO_LENGTH_BONE = 8,   /* a part whose proximal and distal joints coincide */
  GCS_ERR_OUT_OF_RANGE = 9,       /* another numeric parameter outside its documented range */
  GCS_ERR_NO_SKIN = 10,           /* no vertices, no triangles or no joints */
  GCS_ERR_OUT_OF_MEMORY = 11,     /* an allocation failed (wasm memory cannot grow further) */
  GCS_ERR_DEGENERATE = 12         /* the input cannot be processed at all (e.g. no part can be resampled) */
} GcsError;

#define GCS_MIN_SECTIONS 3
#define GCS_MAX_SECTIONS 256
#define GCS_MAX_JOINTS 1024
#define GCS_MAX_VERTICES 16777216
#define GCS_MAX_INFLUENCES 8  /* skin influences (joint, weight pairs) per vertex: glTF JOINTS_0/1, WEIGHTS_0/1 */

/* ---------------------------------------------------------------- version, errors and memory */

/* GCS_VERSION of the header the core was built from: a wrapper checks it against its own. */
uint32_t gcs_version(void);

/* The code of the last call's outcome (GCS_OK after a successful call). */
int gcs_last_error_code(void);
/* The sentence describing the last error, NUL-terminated, owned by the library ("" when OK). */
const char* gcs_last_error_message(void);

/* Scratch memory for handing arrays across the JS boundary. Returns 0 on failure. */
void* gcs_alloc(uint32_t bytes);
void gcs_free(void* pointer);
/* Copies `bytes` bytes (memcpy). For benchmarks: the memory bound a deformer is measured against. */
void gcs_copy_bytes(void* destination, const void* source, uint32_t bytes);
/*
 * Bytes of the heap in use now (malloc's allocated bytes: mallinfo's uordblks), for leak checks:
 * after an object is made and destroyed it returns to where it was. Wasm memory itself only grows
 * (memory.buffer.byteLength); this says how much of it the library holds.
 */
uint32_t gcs_heap_in_use(void);

/* ---------------------------------------------------------------- rig (raw input) */

typedef struct GcsRig GcsRig;

/*
 * Validates and copies a skinned mesh and its skeleton.
 *   positions        vertexCount × 3 floats, bind-pose positions in mesh space; finite.
 *   normals          vertexCount × 3 floats, or null (then computed, area-weighted); finite.
 *   vertexCount      1 .. GCS_MAX_VERTICES.
 *   indices          indexCount uint32, a triangle list; each < vertexCount.
 *   indexCount       a multiple of 3, at least 3.
 *   joints           vertexCount × influences joint ids (uint32), each < jointCount where its weight > 0
 *                    (vertex v's at v · influences …; glTF's JOINTS_0 then JOINTS_1 for 8).
 *   weights          vertexCount × influences floats, ≥ 0, finite, sum > 0 (normalised on copy over all
 *                    of the vertex's influences).
 *   influences       influences per vertex, 1 .. GCS_MAX_INFLUENCES (else GCS_ERR_OUT_OF_RANGE, checked
 *                    before anything is read or allocated). Every deformer uses all of them. A rig of at
 *                    most 4 costs what a 4-influence rig costs; above 4 it stores 8 slots per vertex.
 *   parents          jointCount int32: the parent joint id, or -1 for a root; no cycles.
 *   inverseBind      jointCount × 16 floats (column-major): glTF inverse bind matrices,
 *                    mapping mesh space to joint space in the bind pose; finite (else
 *                    GCS_ERR_NON_FINITE) and invertible (else GCS_ERR_DEGENERATE).
 *   jointCount       1 .. GCS_MAX_JOINTS.
 * Returns a rig handle, or null with the error recorded.
 */
GcsRig* gcs_rig_create(const float* positions, const float* normals, uint32_t vertexCount,
                       const uint32_t* indices, uint32_t indexCount,
                       const uint32_t* joints, const float* weights, uint32_t influences,
                       const int32_t* parents, const float* inverseBind, uint32_t jointCount);
void gcs_rig_destroy(GcsRig* rig);
uint32_t gcs_rig_vertex_count(const GcsRig* rig);
uint32_t gcs_rig_joint_count(const GcsRig* rig);
/* Model height: the largest extent of the bind-pose bounding box. */
float gcs_rig_height(const GcsRig* rig);

/* ---------------------------------------------------------------- deformers (runtime) */

typedef struct GcsDeformer GcsDeformer;

typedef enum GcsCriterion {
  GCS_CRITERION_Y = 0,       /* the paper's: bin by the bind-pose Y coordinate */
  GCS_CRITERION_AXIAL = 1,   /* the paper's rule, binned by the projection on the bone axis (T-poses) */
  GCS_CRITERION_WEIGHTS = 2  /* the default: bin by skin weights; sections are rigid blends (docs/method.md §2) */
} GcsCriterion;

typedef enum GcsDeformerKind {
  GCS_KIND_GCS = 0,
  GCS_KIND_CLASSIC = 1,
  GCS_KIND_LBS = 2,
  GCS_KIND_DQS = 3
} GcsDeformerKind;

/* The defaults of gcs_build_gcs's settings (GcsSettings): the one statement of each, read by the
   JavaScript library (web/lib/boundary.generated.ts), its demo and docs. */
#define GCS_DEFAULT_SECTIONS 6
#define GCS_DEFAULT_CRITERION GCS_CRITERION_WEIGHTS
#define GCS_DEFAULT_INFLUENCE_WIDTH 1.0f /* the paper */
#define GCS_SMOOTH_BY_CRITERION (-1)     /* smooth's default: on under the weights criterion, off under Y / axial */
#define GCS_DEFAULT_TWIST_SPREAD 0
#define GCS_DEFAULT_CENTRES 0

/* The weights criterion's weight grid: steps of 1/Q, Q = GCS_WEIGHT_GRID_STEPS(sections) =
   2·(sections − 2) (6 sections → eighths; 3 → only rigid cores and even splits). The factor 2 makes
   the even split of two joints a grid point. */
#define GCS_WEIGHT_GRID_STEPS(sections) (2 * ((sections) - 2))

/*
 * The settings of a GCS model, checked once by gcs_build_gcs (each field's range below; a field
 * outside it is refused with the error named there). Fill every field: start from the defaults
 * above.
 *   sections        level of detail, in [GCS_MIN_SECTIONS, GCS_MAX_SECTIONS] (else
 *                   GCS_ERR_SECTION_COUNT). Weights criterion: the grid step of the skin weights is
 *                   1/Q, Q = GCS_WEIGHT_GRID_STEPS(sections). Y / axial: sections per part
 *                   (2 shared + sections − 2 inner).
 *   criterion       a GcsCriterion (else GCS_ERR_INVALID_ARGUMENT).
 *   influenceWidth  Y / axial: fraction of a part over which joint influence ramps, in (0, 1] (else
 *                   GCS_ERR_OUT_OF_RANGE); 1 = the paper. Checked but unused by the weights criterion.
 *   smooth          1: each vertex blends two sections' transforms, normals renormalised (Y / axial:
 *                   the sections bracketing its axial coordinate; weights: the nodes around its
 *                   weights, below); 0: stepped (under the weights criterion the fastest level of
 *                   detail); GCS_SMOOTH_BY_CRITERION: 1 under the weights criterion, 0 under Y / axial.
 *   twistSpread     Y / axial, 1: a joint's twist about its bone is spread along the child part; 0: not.
 *   centres         weights criterion, 1: every section of a bending pair turns about its centre of
 *                   rotation (below) instead of moving by the dual-quaternion blend's translation; 0: not.
 *                   Ignored by Y / axial.
 * smooth, twistSpread and centres outside those values: GCS_ERR_INVALID_ARGUMENT.
 */
typedef struct GcsSettings {
  uint32_t sections;
  uint32_t criterion;
  float influenceWidth;
  int32_t smooth;
  int32_t twistSpread;
  int32_t centres;
} GcsSettings;

/*
 * Builds a generalized cross-section model from a rig with the given settings (above; null
 * settings: GCS_ERR_INVALID_ARGUMENT).
 *
 * Weights criterion (docs/method.md §2): welded vertices (same bind-pose position) are binned by their
 * weights (influences < 0.5 % dropped, renormalised; the non-dominant ones rounded to the grid, the
 * dominant one taking the rest). A bin with one joint is its rigid core: transform exactly S_j, so
 * geometry bound 100 % to a bone moves exactly with it. The bin where two joints share the weight
 * evenly is their shared section (one transform for both parts). Every other bin moves by the
 * dual-quaternion blend of its joints at its members' mean weights (for a parent/child pair: a
 * fraction of the child's rotation about the joint centre, the paper's rule), with the scale parts
 * of the S_j blended linearly and applied first.
 * Weights criterion, smooth (the default of the JS API; no steps): a welded vertex's weights are
 * w = (1 − s)·e_d + s·u (d dominant, s = 1 − w_d, u the other joints' shares). Sections are nodes
 * (d, u, level l) at s = l/Q, Q = GCS_WEIGHT_GRID_STEPS(sections), each node's weights on a grid of 1/(8Q) (the
 * shape u gets 8·l units by largest remainders), moved by the dual-quaternion blend at exactly those
 * weights (level 0: the rigid core, exactly S_d; the even split of two joints: one node for both).
 * A vertex belongs to the node at the level below its s (its run in the output) and blends with the
 * node above by its fraction (gcs_gcs_blend_other / gcs_gcs_blend_factor); a node only blended
 * towards may hold no vertex (count 0). A vertex of exactly three joints instead blends the three
 * corners of its cell on the lattice of weights in steps of 1/Q (the Kuhn triangle in the partial
 * sums of its weights, joints by index; barycentric factors; gcs_gcs_blend_third /
 * gcs_gcs_blend_third_factor): continuous in every weight, and the corners are shared by the cell's
 * vertices (corners with a zero weight are two-joint nodes). Up to three nodes per welded vertex.
 * Centres of rotation (weights criterion, `centres` nonzero; Le & Hodgins, "Real-time Skeletal Skinning
 * with Optimized Centers of Rotation", SIGGRAPH 2016): a section of a bending pair (two joints, one
 * the other's parent; pivot c its child's joint centre) with weights w has the centre
 * p = c + min(1, 0.01·height / |p* − c|)·(p* − c) (docs/method.md), with
 *   p* = Σ_t sim(w, v_t) a_t c_t / Σ_t sim(w, v_t) a_t,
 *   sim(w, v) = Σ_{j<k} w_j w_k v_j v_k exp(−(w_j v_k − w_k v_j)² / 0.1²),
 * over the rig's triangles t (bind-pose area a_t, centroid c_t, v_t the mean of its three corners'
 * weights as the criterion reads them), computed once at build time (the per-triangle data is kept
 * on the rig: rebuilding the same rig does not recompute it). Per frame the section keeps the 3×3
 * part M = R·K of its blend (R from the normalised, hemisphere-aligned blend of its joints'
 * rotations, K the blended scale parts: the same as without centres, so normals turn the same way)
 * and takes the translation t = Σ w_j (S_j p − p) − (M p − p): M p + t = Σ w_j S_j p, the
 * centre moves by linear blend skinning (identity poses give t = 0 exactly). A rigid core is S_j as
 * ever; any other section (three or more joints, two unrelated joints, an empty integral) keeps the
 * dual-quaternion blend. gcs_gcs_section_centres lists the centres.
 * Y / axial criteria (the paper, docs/method.md §4): parts by dominant weight, shared sections from
 * triangles spanning a part and its parent part, inner bins along Y or the bone axis, section
 * transform S_p · D_j^α · D_k^β on the rigid parts of the S_j (scale applied first).
 *
 * Scale: every S_j may carry a scale (uniform ×100 in cm rigs, 0 for a hidden bone, non-uniform):
 * positions follow it; normals stay unit length (a collapsed bone keeps its rotated rest normals).
 * Output is finite for every finite input.
 * The output mesh is the rig's vertices reordered section by section (see
 * gcs_deformer_source_vertex) with the rig's triangles remapped (gcs_deformer_indices).
 */
GcsDeformer* gcs_build_gcs(const GcsRig* rig, const GcsSettings* settings);
/* Linear blend skinning and dual-quaternion skinning; output in the rig's vertex order.
   LBS: positions by Σ w_j S_j, normals by the same matrix then unit length (as three.js), the rest
   normal turned by the first joint's rotation where that matrix has collapsed.
   DQS: the rigid part of each S_j as a dual quaternion (blended, normalised), its scale part
   (Rᵀ·S, 3×3) blended linearly and applied first; unit normals. */
GcsDeformer* gcs_build_lbs(const GcsRig* rig);
GcsDeformer* gcs_build_dqs(const GcsRig* rig);

void gcs_deformer_destroy(GcsDeformer* deformer);
uint32_t gcs_deformer_kind(const GcsDeformer* deformer);

/*
 * Deforms for one frame.
 *   skinMatrices   jointCount × 16 floats: S_j = posed world · inverse bind, column-major,
 *                  mapping bind-pose mesh space to posed mesh space; finite.
 *   jointCount     must equal the rig's joint count.
 * Writes positions and normals (the arrays below). Returns 1, or 0 with the error recorded
 * (then the output arrays keep the previous frame).
 */
int gcs_deformer_deform(GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount);

/*
 * Morph targets (blend shapes), applied to the rest mesh before skinning, as three.js does
 * (morph, then skin). GCS, LBS and DQS only (the classic model resamples: GCS_ERR_INVALID_ARGUMENT).
 *   deltas        targetCount × vertexCount × 3 floats: position deltas in the RIG's vertex order
 *                 (glTF morph targets, mesh space); finite.
 *   normalDeltas  the same for normals, or null (normals then stay the rest normals).
 *   targetCount   0 .. GCS_MAX_MORPH_TARGETS; 0 removes every target (the rest mesh is restored).
 *   vertexCount   must equal the deformer's vertex count (the rig's).
 * Replaces any previous targets; every influence starts at 0. Returns 1, or 0 with the error
 * recorded (nothing changed).
 */
#define GCS_MAX_MORPH_TARGETS 256
int gcs_deformer_set_morph_targets(GcsDeformer* deformer, const float* deltas, const float* normalDeltas,
                                   uint32_t targetCount, uint32_t vertexCount);
/* The influence of each target (three.js's morphTargetInfluences), finite, targetCount of them;
   taken at the next gcs_deformer_deform, which re-morphs the rest mesh only when they changed
   (O(vertices × non-zero targets) then). Returns 1, or 0 with the error recorded. */
int gcs_deformer_set_morph_influences(GcsDeformer* deformer, const float* influences, uint32_t targetCount);

/*
 * Tangents (normal maps), deformed by the same gcs_deformer_deform call as positions and normals.
 *   tangents      vertexCount × 4 floats in the RIG's vertex order (glTF TANGENT: xyz a unit
 *                 direction, w = ±1 the bitangent's handedness); finite. Null removes them.
 *   vertexCount   must equal the deformer's vertex count (the rig's); ignored when tangents is null.
 * From then on every gcs_deformer_deform also writes gcs_deformer_tangents(): each xyz turned as the
 * vertex's normal is (its normal matrix and length fix; a vanished one keeps its rest direction),
 * its w carried. Until the next deform the output holds the rest tangents. GCS, LBS and DQS (the
 * classic model resamples the mesh: GCS_ERR_INVALID_ARGUMENT). Replaces any previous tangents.
 * Returns 1, or 0 with the error recorded (nothing changed).
 */
int gcs_deformer_set_tangents(GcsDeformer* deformer, const float* tangents, uint32_t vertexCount);
/* vertexCount × 4 floats in the output order, or null when the deformer has no tangents. Owned by
   the deformer; at the same address until the next gcs_deformer_set_tangents. */
float* gcs_deformer_tangents(GcsDeformer* deformer);

/*
 * Previous positions (motion vectors: a velocity buffer needs each vertex where it was the frame
 * before). keep = 1 gives the deformer a second positions array, holding the current positions;
 * from then on each gcs_deformer_deform writes into the array that held the frame before last and
 * swaps the two (no copy): gcs_deformer_positions() is this frame's, gcs_deformer_previous_positions()
 * the last frame's. While kept, gcs_deformer_positions() alternates between the two addresses: read
 * both pointers after every deform. keep = 0 frees the second array (positions then stay where they
 * are). A rejected deform swaps nothing. Returns 1, or 0 with the error recorded (nothing changed).
 */
int gcs_deformer_keep_previous_positions(GcsDeformer* deformer, int keep);
/* vertexCount × 3 floats: the positions of the deform before the last one, or null when not kept. */
float* gcs_deformer_previous_positions(GcsDeformer* deformer);

/* The output mesh. Arrays are owned by the deformer and stay at the same address for its life
   (positions: see gcs_deformer_keep_previous_positions). */
uint32_t gcs_deformer_vertex_count(const GcsDeformer* deformer);
float* gcs_deformer_positions(GcsDeformer* deformer);   /* vertexCount × 3 */
float* gcs_deformer_normals(GcsDeformer* deformer);     /* vertexCount × 3 */
uint32_t gcs_deformer_index_count(const GcsDeformer* deformer);
const uint32_t* gcs_deformer_indices(const GcsDeformer* deformer);
/* For each output vertex, the rig vertex it comes from; null for resampled (classic) vertices
   that come from no rig vertex (there, see gcs_classic_source_of_vertex). */
const uint32_t* gcs_deformer_source_vertex(const GcsDeformer* deformer);
/*
 * Vertex data in the output order: item o of `out` (vertexCount items of itemBytes bytes) is item
 * gcs_deformer_source_vertex[o] of `source`, whose sourceCount items start strideBytes apart (an
 * interleaved attribute: its stride). What the adapters carry at every build (uv, colours…).
 * Returns 0 with GCS_ERR_INVALID_ARGUMENT for a deformer without source vertices, itemBytes 0 or
 * above strideBytes, or a source vertex ≥ sourceCount (nothing written then).
 */
int gcs_deformer_gather(const GcsDeformer* deformer, const void* source, uint32_t sourceCount, uint32_t strideBytes,
                        uint32_t itemBytes, void* out);

/*
 * Per-deformer statistics (a float per query; unknown queries return NaN, no error).
 *   GCS_STAT_SECTIONS          number of sections (GCS), contours (classic), 0 otherwise
 *   GCS_STAT_PARTS             number of parts
 *   GCS_STAT_ADJUSTED_SHARE    last frame: share of sections whose transform is not their part's
 *                              rigid transform (moves a vertex by > 0.1 % of model height); classic: 1
 *                              (every contour is recomputed each frame); 0 for LBS and DQS
 *   GCS_STAT_ADJUSTED_SECTIONS last frame: the number of those sections (classic: every contour)
 */
typedef enum GcsStat {
  GCS_STAT_SECTIONS = 0,
  GCS_STAT_PARTS = 1,
  GCS_STAT_ADJUSTED_SHARE = 2,
  GCS_STAT_ADJUSTED_SECTIONS = 3
} GcsStat;
float gcs_deformer_stat(const GcsDeformer* deformer, uint32_t stat);

/*
 * GCS introspection (for colouring by section, tests and metrics).
 *   gcs_gcs_section_of_vertex   output vertexCount uint32: section id of each output vertex.
 *   gcs_gcs_section_info        sectionCount × GCS_SECTION_INFO_FLOATS floats, at the offsets of
 *                               GcsSectionInfoField: [first vertex, vertex count, part joint,
 *                               distal joint or -1, kind (a GcsSectionKind), t, alpha, beta]
 *                               Y / axial: part = the part's joint, distal = the child part its
 *                               branch leads to, t = mean axial coordinate, alpha/beta = fractions.
 *                               Weights: part = dominant joint, distal = second joint, alpha/beta =
 *                               their mean weights, t = beta.
 * Null for deformers that are not GCS.
 */
typedef enum GcsSectionInfoField {
  GCS_SECTION_INFO_FIRST = 0,
  GCS_SECTION_INFO_COUNT = 1,
  GCS_SECTION_INFO_PART = 2,
  GCS_SECTION_INFO_DISTAL = 3,
  GCS_SECTION_INFO_KIND = 4,
  GCS_SECTION_INFO_T = 5,
  GCS_SECTION_INFO_ALPHA = 6,
  GCS_SECTION_INFO_BETA = 7
} GcsSectionInfoField;
#define GCS_SECTION_INFO_FLOATS 8
typedef enum GcsSectionKind {
  GCS_SECTION_INNER = 0,   /* an inner section (Y / axial) or a blended one (weights) */
  GCS_SECTION_SHARED = 1,  /* a shared generalized section: between a part and its parent, or an even split */
  GCS_SECTION_RIGID = 2    /* weights criterion: a rigid core, moved exactly by its joint's S_j */
} GcsSectionKind;
const uint32_t* gcs_gcs_section_of_vertex(const GcsDeformer* deformer);
const float* gcs_gcs_section_info(const GcsDeformer* deformer);
/* The transform (16 floats, column-major) of each section in the last frame; sectionCount × 16. */
const float* gcs_gcs_section_matrices(const GcsDeformer* deformer);

/* ---------------------------------------------------------------- GCS on the GPU */

/*
 * The GPU path (docs/method.md §8): the mesh stays in GPU memory in the bind pose, section by section
 * as gcs_deformer_source_vertex orders it; per vertex the static data is its section
 * (gcs_gcs_section_of_vertex) and, in smooth mode, the other section it blends with and the factor
 * towards it (below); per frame only the section transforms change, computed here, and a vertex
 * shader applies them.
 *
 * Smooth mode only (null for a GCS deformer built without smooth mode, and for other deformers):
 *   gcs_gcs_blend_other          output vertexCount uint32: the section each output vertex blends
 *                                with (its own section when it does not blend).
 *   gcs_gcs_blend_factor         output vertexCount floats in [0, 1]: the factor towards that section.
 *   gcs_gcs_blend_third          output vertexCount uint32: a third section (weights criterion, a
 *                                vertex of three joints: its lattice cell's third node); its own
 *                                section otherwise.
 *   gcs_gcs_blend_third_factor   output vertexCount floats in [0, 1]: the factor towards it (0 when
 *                                there is none); the two factors sum to at most 1.
 * A vertex p of own section A, other sections B and C and factors f and g (plain mode: f = g = 0)
 * moves to
 *   p' = (A + f·(B − A) + g·(C − A))·(p, 1)   (entrywise on the 3×4 affine matrices packed below),
 * which is what gcs_deformer_deform computes. Its normal turns by the cofactor of the 3×3 part
 * (docs/gpu.md: the same direction as gcs_deformer_deform's normal matrix).
 */
#define GCS_GPU_TEXELS_PER_SECTION 3
#define GCS_MAX_INSTANCES 65536
const uint32_t* gcs_gcs_blend_other(const GcsDeformer* deformer);
const float* gcs_gcs_blend_factor(const GcsDeformer* deformer);
const uint32_t* gcs_gcs_blend_third(const GcsDeformer* deformer);
const float* gcs_gcs_blend_third_factor(const GcsDeformer* deformer);
/*
 * Section transforms only, for instanceCount poses of the same model (a crowd), packed for an
 * RGBA32F texture; no per-vertex work.
 *   deformer       a GCS deformer (any criterion, plain or smooth).
 *   skinMatrices   instanceCount × jointCount × 16 floats: instance k's S_j (as gcs_deformer_deform
 *                  takes them) at offset (k · jointCount + j) · 16; finite.
 *   jointCount     must equal the rig's joint count.
 *   instanceCount  1 .. GCS_MAX_INSTANCES; instanceCount · sectionCount · 48 bytes and
 *                  instanceCount · jointCount · 64 bytes must fit in 4 GiB (else GCS_ERR_OUT_OF_RANGE).
 *   out            instanceCount × sectionCount × GCS_GPU_TEXELS_PER_SECTION × 4 floats, written as
 *                  texels: section s of instance k starts at texel (k · sectionCount + s) · 3; its
 *                  three texels are the rows r = 0, 1, 2 of the section's affine transform
 *                  (m[0][r], m[1][r], m[2][r], m[3][r]) — the same matrices gcs_deformer_deform
 *                  applies (gcs_gcs_section_matrices), bit for bit.
 * Morph targets are not applied (they act on vertices: the shader applies them before the section
 * transforms). The deformer's positions and normals are not written; gcs_gcs_section_matrices
 * afterwards holds the last instance's transforms. Nothing is allocated.
 * Returns 1, or 0 with the error recorded (then nothing was written: every matrix is checked first).
 */
int gcs_gcs_compute_sections(GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount,
                             uint32_t instanceCount, float* out);

/*
 * The joint-level GPU path (weights criterion only; docs/gpu.md). Under the weights criterion a
 * section's transform depends only on its joints' poses: a rigid core is exactly S_j; every other
 * section is the dual-quaternion blend of its (at most GCS_MAX_INFLUENCES) joints at its members' mean
 * weights, the scale parts K_j = R_jᵀ·S_j blended linearly and applied first. So per frame only the
 * joint poses change (J per instance), and the vertex shader blends each vertex's section from them
 * and from a static per-section table (below), uploaded once.
 *
 * gcs_gcs_section_influence_slots: the table's joints per section, 4 (every section blends at most 4
 *   joints: every rig of at most 4 influences) or 8; 0 where gcs_gcs_section_influences is null.
 * gcs_gcs_section_influences: sectionCount × 2 · slots floats, the static table, 2 · slots / 4 RGBA32F
 *   texels per section: for each group of 4 slots, [joint 4g, …, joint 4g+3] (ids as floats, -1 past
 *   the last), then [weight 4g, …, weight 4g+3] — the blend gcs_deformer_deform computes, in its
 *   order (the first joint is the blend's hemisphere pivot). With 4 slots: [joints 0–3], [weights
 *   0–3]; with 8: [joints 0–3], [weights 0–3], [joints 4–7], [weights 4–7]. One joint (weight 1): a
 *   rigid core, moved by S_j itself. Null for a GCS deformer built with the Y or axial criterion
 *   (their transforms involve per-section fractions of parent/child motions: use
 *   gcs_gcs_compute_sections), and for other deformers.
 */
#define GCS_GPU_TEXELS_PER_JOINT 4
const float* gcs_gcs_section_influences(const GcsDeformer* deformer);
/*
 * gcs_gcs_section_centres: sectionCount × 4 floats, one RGBA32F texel per section: its centre of
 *   rotation (x, y, z, 1) in the bind pose (mesh space), or (0, 0, 0, 0) where the section has none
 *   (a rigid core, a section that is not a bending pair or whose integral is empty, every section
 *   of a deformer built without centres). A section with a centre p moves by M = R·K as above and
 *   t = Σ_i w_i (S_i p − p) − (M p − p) (gcs_build_gcs). Null where gcs_gcs_section_influences is null.
 */
const float* gcs_gcs_section_centres(const GcsDeformer* deformer);
uint32_t gcs_gcs_section_influence_slots(const GcsDeformer* deformer);
/*
 * Joint poses only, for instanceCount poses of the same model, packed for an RGBA32F texture; O(J)
 * per instance, no per-section and no per-vertex work.
 *   deformer       a GCS deformer built with the weights criterion (plain or smooth); else
 *                  GCS_ERR_INVALID_ARGUMENT.
 *   skinMatrices   instanceCount × jointCount × 16 floats, as gcs_gcs_compute_sections takes them; finite.
 *   jointCount     must equal the rig's joint count.
 *   instanceCount  1 .. GCS_MAX_INSTANCES; instanceCount · jointCount · 64 bytes must fit in 4 GiB
 *                  (else GCS_ERR_OUT_OF_RANGE).
 *   out            instanceCount × jointCount × GCS_GPU_TEXELS_PER_JOINT × 4 floats: joint j of instance
 *                  k starts at texel (k · jointCount + j) · 4; texels 0, 1, 2 are the rows r of S_j
 *                  (m[0][r], m[1][r], m[2][r], m[3][r]), copied bit for bit; texel 3 is the rotation R_j
 *                  of S_j as a unit quaternion (x, y, z, w), the one gcs_deformer_deform splits S_j
 *                  with (S_j = [R_j·K_j | t_j]; robust to uniform, non-uniform, mirrored and collapsed
 *                  scales).
 * The deformer's state is not changed. Nothing is allocated.
 * Returns 1, or 0 with the error recorded (then nothing was written: every matrix is checked first).
 */
int gcs_gcs_compute_joint_poses(const GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount,
                                uint32_t instanceCount, float* out);
/*
 * Joint poses in a compact format where the frame allows it: 6 floats (24 bytes) per joint instead
 * of 16, for the joint-level path's per-frame upload. Same arguments, checks and errors as
 * gcs_gcs_compute_joint_poses; `out` holds the full format's instanceCount × jointCount × 16 floats.
 *   Compact (every joint of every instance rigid with unit scale: each entry of its 3×3 part S_j
 *   within GCS_COMPACT_POSE_TOLERANCE × min(1, height / reach) of the rotation R_j that
 *   gcs_gcs_compute_joint_poses splits off, height the bind mesh's largest bounding-box extent and
 *   reach its farthest vertex from the origin, so that R_j·x and S_j·x differ by at most
 *   3 · GCS_COMPACT_POSE_TOLERANCE of the height at any bind vertex x; real clips measure ≤ 2e-6
 *   from float rounding, a scale or shear key well above): joint j of instance k at
 *   floats (k · jointCount + j) · GCS_COMPACT_FLOATS_PER_JOINT, the first instanceCount · jointCount ·
 *   6 floats of `out` (the rest is not written): the "smallest three" of R_j's unit quaternion
 *   (x, y, z, w in order without its largest-magnitude component, ±q chosen so that the dropped one
 *   is positive: each stored one ≤ 1/√2 in magnitude, the dropped one = sqrt(1 − Σ c²) ≥ 1/2, well
 *   conditioned at every angle, 180° included), then the translation t_j. The dropped component's
 *   index i (0 x, 1 y, 2 z, 3 w) is in the lowest mantissa bit of the first two floats: bit 0 of i
 *   in the first, bit 1 in the second (each moved by at most one unit in the last place; a value
 *   smaller in magnitude than FLT_MIN is first written as ±FLT_MIN, so the bits survive a GPU that
 *   flushes denormals). The reader takes S_j = R(q_j).
 *   Full (any joint scaled, sheared, mirrored, collapsed or out of tolerance): exactly what
 *   gcs_gcs_compute_joint_poses writes.
 * Returns GCS_JOINT_POSES_COMPACT or GCS_JOINT_POSES_FULL, the format of the whole call; or 0 with
 * the error recorded (then nothing was written). Nothing is allocated; the deformer is not changed.
 */
#define GCS_COMPACT_FLOATS_PER_JOINT 6
#define GCS_COMPACT_POSE_TOLERANCE 0.000002f
#define GCS_JOINT_POSES_FULL 1
#define GCS_JOINT_POSES_COMPACT 2
int gcs_gcs_compute_joint_poses_compact(const GcsDeformer* deformer, const float* skinMatrices, uint32_t jointCount,
                                        uint32_t instanceCount, float* out);


/* ---------------------------------------------------------------- classic cross-sections */

#define GCS_CLASSIC_MIN_CONTOURS 2
#define GCS_CLASSIC_MAX_CONTOURS 256
#define GCS_CLASSIC_MIN_RAYS 3
#define GCS_CLASSIC_MAX_RAYS 256
#define GCS_CLASSIC_MAX_BULGE 4.0f
/* The recommended settings of gcs_build_classic (below): the one statement of each. */
#define GCS_CLASSIC_DEFAULT_CONTOURS 25
#define GCS_CLASSIC_DEFAULT_RAYS 20
#define GCS_CLASSIC_DEFAULT_BULGE 0.3f

/*
 * Builds the classic cross-section model (Shen, Magnenat-Thalmann, Thalmann 1994; docs/method.md §6).
 *
 * Parts are the GCS parts (vertices by dominant weight, welded by position; parent part = nearest
 * ancestor joint owning vertices). A part is resampled when it is cylinder-like:
 *   - it has exactly one child part (a chain part: upper arm, forearm, thigh, shank, spine, neck),
 *     or it is a branching part of the trunk (GCS_CLASSIC_TRUNK, below); leaves (head, hands
 *     without fingers, feet, finger tips) and other branching parts (a hand with fingers) are
 *     carried (kept with their own triangles, moved by DQS of their own weights);
 *   - its bone (joint → child part's joint) is at least 3 % of the model height (a zero-length or
 *     tiny bone is carried);
 *   - at most 30 % of its rays miss its own triangles (triangles with a vertex in the part), after
 *     hits farther than 3 × the contour's median are dropped as misses (e.g. a clavicle, or a part
 *     of an open mesh with a side missing, is carried);
 *   - its bone turns by at most 45° from its resampled parent's bone (a foot on a shank is carried);
 *   - where it meets the carried mesh, the boundary is one closed ring around its bone at an end
 *     that is not shared with a resampled neighbour (else GCS_CLASSIC_SEAM: a tube cannot join it
 *     without a gap or an overlap);
 *   - measured once built (else GCS_CLASSIC_OFF_SURFACE, and the model is built again without it):
 *     at six probe poses (every joint turned 35° about world X, Z and Y, each way, around its bind
 *     centre on top of its parent), each ring vertex (shared joint rings excepted) lies within 1 %
 *     of the height at p99 and 2.5 % at most of the point of the input surface its ray hit, posed
 *     by dual-quaternion skinning; and an end cap's centre lies within 1 % of the height of the
 *     input surface at the bind pose.
 * The trunk (Shen et al. resample it like the limbs): a branching part is resampled along the one
 * child bone that continues the trunk — after a resampled parent, the child within 45° of the
 * parent's bone (a chest's neck); with none, the child whose siblings' joints all lie before a
 * quarter of its bone (a pelvis's spine, the hips below) — over the span of its bone away from its
 * branches: its vertices beyond 1/20 bone short of the nearest vertex that shares a triangle with
 * a branch (shoulders, thighs) stay carried (the crotch, the shoulders), the rest is resampled as
 * part of the spine's tube; at least a quarter of the bone must remain.
 * A resampled part gets contour planes at even spacing from tLo to tHi along its bone (t = 0 at
 * its joint, 1 at its child part's joint), each with `rays` star rays at angles 2πr/rays in a
 * frame parallel-transported along the limb; a ray's contour point is its outermost hit with the
 * part's own triangles; a ray that misses takes the radius interpolated from its nearest hit
 * neighbours. Two resampled neighbours share their joint contour (stored once, cast against both
 * parts' triangles, its plane normal the bisector of the two bones): tLo = 0 / tHi = 1 there.
 * Where a tube meets the carried mesh (every triangle with a carried vertex, kept as it is, its
 * vertices moving by dual-quaternion skinning of their own weights), the tube ends just inside the innermost point of
 * the boundary loop of those triangles (tLo = the loop's largest t + 0.02 at a proximal end, tHi
 * its smallest t − 0.02 at a distal one), and a band of triangles zips the tube's end ring to that loop: every
 * edge of the ring and of the loop is used once, so a closed input gives a closed output (no gap,
 * no overlap, the loop's vertices shared by both sides). An end with nothing beyond it (an open
 * input) stays open, the tube spanning the part's own vertices (up to half a bone past the joint).
 *
 *   contours  contour count of the LONGEST resampled-candidate bone, in
 *             [GCS_CLASSIC_MIN_CONTOURS, GCS_CLASSIC_MAX_CONTOURS]; every other part gets
 *             round(contours · its bone length / longest bone length), at least 2, so contours are
 *             evenly spaced over the body. Shared joint contours count in both parts.
 *   rays      rays per contour (all parts), in [GCS_CLASSIC_MIN_RAYS, GCS_CLASSIC_MAX_RAYS].
 *   bulge     muscle bulge gain b in [0, GCS_CLASSIC_MAX_BULGE]: radii of a part's contours scale by
 *             1 + b · flex · sin(π t), flex = bend of the part's distal joint / π (the swing angle
 *             of the child part's bone relative to this part, twist excluded).
 * Recommended settings: GCS_CLASSIC_DEFAULT_CONTOURS, _RAYS and _BULGE (the paper's leg comparison:
 * ≈ 500 points on the thigh, ≈ 400 on the shank): contours × rays points on the longest bone (the
 * thigh on a human), the shank contours · shank/thigh length · rays (the same on the default human,
 * whose thigh and shank are equally long).
 *
 * Bind contour planes: the end normal is the bone direction, or at a shared joint the bisector
 * N_o = normalize(N_u + N_l); inner contours interpolate the end normals linearly (normalised).
 * Deforming: each contour moves as one rigid ring by the dual-quaternion blend (scale parts blended
 * linearly, applied first) of its influences: the mean weights (4 largest) of the input vertices of
 * its part and its neighbours within half a contour spacing of its plane and within 1.25 × its
 * largest radius of its centre; a shared joint contour takes the mean of its two neighbouring
 * contours' influences (half of each bone where each side is bound to its own: the bisector).
 * Tube normals are area-weighted from the deformed tube and band triangles, unit length whatever
 * the scale of the skin matrices; carried vertices and normals are skinned by dual quaternions.
 * Nothing is allocated per frame.
 * The muscle bulge applies to chain parts, not to a trunk part's tube.
 *
 * Its output mesh is its own: the rings of the tubes first (chains laid out root → leaf, so a
 * part's rings are contiguous and a shared ring ends one part and starts the next), then the
 * carried input vertices grouped by part. Triangles: tube quads (2 each, outward), bands, then the
 * carried input triangles. gcs_deformer_source_vertex is null.
 * If no part can be resampled the model still builds (every part carried; the report says so).
 * Errors: GCS_ERR_INVALID_ARGUMENT (null rig), GCS_ERR_OUT_OF_RANGE (a count or the bulge outside
 * its limits; the message states them), GCS_ERR_OUT_OF_MEMORY.
 * Statistics: GCS_STAT_SECTIONS = contours (shared ones once), GCS_STAT_PARTS = parts.
 */
GcsDeformer* gcs_build_classic(const GcsRig* rig, uint32_t contours, uint32_t rays, float bulge);
/* Changes the bulge gain of a classic deformer without rebuilding (takes effect at the next
   deform). Returns 1, or 0 on error (not a classic deformer; bulge outside [0, GCS_CLASSIC_MAX_BULGE]). */
int gcs_classic_set_bulge(GcsDeformer* deformer, float bulge);
/* Why a part of a classic model is or is not resampled (the fifth entry of its report). */
typedef enum GcsClassicReason {
  GCS_CLASSIC_RESAMPLED = 0,  /* a chain part, resampled from joint to joint */
  GCS_CLASSIC_LEAF = 1,       /* carried: no child part (head, hands, feet, finger tips) */
  GCS_CLASSIC_BRANCHING = 2,  /* carried: several child parts and not a trunk part (a hand with fingers) */
  GCS_CLASSIC_TOO_SHORT = 3,  /* carried: bone shorter than 3 % of the height (fingers, zero-length bones) */
  GCS_CLASSIC_RAYS_MISS = 4,  /* carried: over 30 % of its rays miss its own triangles (a clavicle) */
  GCS_CLASSIC_BENT = 5,       /* carried: bone turned > 45° from its resampled parent's (a foot) */
  GCS_CLASSIC_SEAM = 6,       /* carried: its boundary with the carried mesh is not one ring at an end */
  GCS_CLASSIC_TRUNK = 7,      /* resampled along the trunk; its branch region (crotch, shoulders) carried */
  GCS_CLASSIC_OFF_SURFACE = 8 /* carried: its tube would stand off the skin it replaces (measured at build
                                 time at probe poses, every joint bent 35°: p99 > 1 % or max > 2.5 % of
                                 the height), or its end cap would cut across a non-flat end */
} GcsClassicReason;
/*
 * Per-part report of a classic model: partCount × GCS_CLASSIC_PART_INTS int32, parts in joint
 * order, at the offsets of GcsClassicPartField: [joint id, resampled (1) or carried rigidly (0),
 * first output vertex, output vertex count, reason (GcsClassicReason)].
 * Resampled part: its rings, contours × rays vertices, proximal ring first (a shared joint ring is
 * in both neighbours' ranges). Rigid part: its carried input vertices. Not in any range: input
 * vertices of resampled parts kept by carried triangles (a band's loop; a trunk part's branch region).
 * gcs_classic_part_count gives partCount. Null (and 0) for other deformers.
 */
typedef enum GcsClassicPartField {
  GCS_CLASSIC_PART_JOINT = 0,
  GCS_CLASSIC_PART_RESAMPLED = 1,
  GCS_CLASSIC_PART_FIRST_VERTEX = 2,
  GCS_CLASSIC_PART_VERTEX_COUNT = 3,
  GCS_CLASSIC_PART_REASON = 4
} GcsClassicPartField;
#define GCS_CLASSIC_PART_INTS 5
uint32_t gcs_classic_part_count(const GcsDeformer* deformer);
const int32_t* gcs_classic_parts(const GcsDeformer* deformer);
/* For each output vertex (vertexCount int32): the contour its ring belongs to (0 … contours − 1,
   the order of GCS_STAT_SECTIONS), or −1 for a carried input vertex or a band vertex (a point of
   the input surface between a tube's end ring and the carried skin, moved as carried skin). Null
   for other deformers. */
const int32_t* gcs_classic_contour_of_vertex(const GcsDeformer* deformer);
/* For each output vertex (vertexCount int32): the rig vertex a carried vertex copies (its texture
   coordinates, colours and other attributes are that vertex's), or −1 for a resampled (ring, cap
   or band) vertex. Null for other deformers. */
const int32_t* gcs_classic_source_of_vertex(const GcsDeformer* deformer);
/*
 * Detail loss of resampling (the paper's Fig. 5): for each input vertex the tubes and bands replace
 * (welded; vertices kept by carried triangles are not counted), the distance to the bind-pose
 * resampled surface (the nearest triangle among its part's tube cells within ±2 contour intervals
 * and ±2 ray sectors, following shared contours into the neighbour, and its part's bands; a
 * vertex farther than 0.5 % of the height from those is tested against every tube and band
 * triangle), as a percentage of model height. which = 0: RMS, 1: max. 0 when nothing
 * is resampled; NaN for other deformers or another `which`. Computed on the first call (it is not
 * part of the build time).
 */
float gcs_classic_detail_loss(const GcsDeformer* deformer, uint32_t which);

#ifdef __cplusplus
}
#endif

#endif /* GCS_SKIN_H */
