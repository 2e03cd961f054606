/**
 * The GPU path's data layout and the constants of its maths: one source of truth for the GLSL
 * chunk (glsl.ts, WebGLRenderer) and the TSL function (tsl.ts, WebGPURenderer), which compute the
 * same thing from these numbers (docs/gpu.md).
 */
import { GPU_TEXELS_PER_JOINT, GPU_TEXELS_PER_SECTION } from '../index.js';

export { GPU_TEXELS_PER_JOINT, GPU_TEXELS_PER_SECTION };

/**
 * Textures the node pass writes (joint-level path, WebGLRenderer), one texel per node in each:
 * the three rows of the node's affine 3×4 [M | T], then its normal texel (x, y, 0, flag), from
 * which the vertex stage takes the normal matrix N = cof(M·x)·y (the rotation where the scale is
 * uniform: x = 1/s, y = 1; flag −1 where normals renormalise, else 0).
 */
export const GPU_NODE_TEXTURES = 4;

/**
 * What the GPU gets per frame: 'joints' (joint poses, O(joints); weights criterion only) or
 * 'sections' (section transforms, O(sections); any criterion).
 */
export type GpuPath = 'joints' | 'sections';

/**
 * Joints per section in the joint-level path's static table (gcs_gcs_section_influence_slots): 4,
 * or 8 where some section blends more than 4 (a rig with up to 8 influences per vertex).
 */
export type TableSlots = 4 | 8;
/**
 * Texels per section in the static table: per 4 slots, its joints (−1 past the last), then their
 * weights; last, its centre of rotation (x, y, z, 1), or (0, 0, 0, 0) where it moves by the plain
 * dual-quaternion blend (gcs_gcs_section_centres).
 */
export const tableTexelsPerSection = (slots: TableSlots): number => slots / 2 + 1;

/** What the GPU backend runs per vertex: GCS (nodes), or LBS / DQS of the vertex's own joints. */
export type GpuMethod = 'gcs' | 'lbs' | 'dqs';

/**
 * LBS and DQS on the GPU: per vertex its joints (−1 where the weight is 0) and weights, as the core
 * normalises them; the second of each only on rigs with up to 8 influences per vertex.
 */
export const INFLUENCE_ATTRIBUTES = ['gcsInfluences0', 'gcsInfluences1'] as const;
export const WEIGHT_ATTRIBUTES = ['gcsWeights0', 'gcsWeights1'] as const;

/** Per-vertex attribute, plain mode: the vertex's section (a float). */
export const SECTION_ATTRIBUTE = 'gcsSection';
/** Per-vertex attribute, smooth mode: (section, other section, factor towards the other). */
export const BLEND_ATTRIBUTE = 'gcsBlend';
/**
 * Per-vertex attribute, smooth mode: (third section, factor towards it): a vertex of three joints
 * blends its weight-lattice cell's three nodes, A + f·(B − A) + g·(C − A); others (own section, 0).
 */
export const BLEND_THIRD_ATTRIBUTE = 'gcsBlendThird';

/**
 * CPU backend on WebGPURenderer, velocity: each vertex's position the frame before (the deformer's
 * previous positions), read by the TSL kit's velocity material.
 */
export const PREVIOUS_POSITION_ATTRIBUTE = 'gcsPreviousPosition';

/**
 * DQS's joint pass: texels per joint in its four targets, one row per instance. Texel (2j, k): the
 * rotation quaternion q_j, the dual part d_j = ½ (0, t_j)·q_j, then (u_j, 0, 0, 0) with u_j = s_j
 * where the joint's scale part K_j = R_jᵀ S_j is a positive uniform scale s_j·I (within
 * RIGID_JOINT_TOLERANCE), else 0. Texel (2j + 1, k): the rows of K_j, read only by vertices with a
 * joint whose u_j is 0. (2 · GCS_MAX_JOINTS = 2048 texels: a row fits WebGL2's guaranteed width.)
 */
export const DQS_TEXELS_PER_JOINT = 2;

/**
 * DQS: a joint's K_j counts as s_j·I when every entry is within this × s_j of it: the CPU's test
 * for a frame whose every K is s·I (decomposeEach), per joint. A vertex all of whose joints pass
 * it is moved by s·R (no scale blend, the normal by R), as the CPU's quaternion-only path.
 */
export const RIGID_JOINT_TOLERANCE = 1e-5;

/** The CPU's test for "the scale part K is a positive uniform scale": every entry within this × s of s·I. */
export const UNIFORM_SCALE_TOLERANCE = 1e-4;
/** Below this a largest entry counts as zero (a collapsed scale): the normal keeps its rotation. */
export const COLLAPSED = 1e-30;
/**
 * Smooth mode: two sections' normal matrices (both rotations) are "near" when their trace exceeds
 * 1 + 2·cos 35°; then the CPU fixes a blended normal's length by a cubic rather than normalising.
 */
export const NEAR_TRACE = 1 + 2 * 0.82;
/**
 * Smooth mode: rotations "almost equal" (less than 2.8° apart: trace above 1 + 2·0.9988): the CPU
 * leaves a blended normal's length as it is (short of 1 by at most (1 − cos θ)/4 ≤ 3e-4).
 */
export const ALMOST_EQUAL_TRACE = 1 + 2 * 0.9988;
/**
 * Smooth mode, three sections: the least of their three pairwise traces decides, over 1 + 2·0.9991
 * (2.4°) no length fix, over 1 + 2·cos 25° the cubic, else exact normalisation (a convex blend of
 * three unit vectors θ apart falls short of 1 by at most 1 − cos(θ/√3)).
 */
export const ALMOST_EQUAL_TRACE3 = 1 + 2 * 0.9991;
export const NEAR_TRACE3 = 1 + 2 * 0.9063;
/** The cubic length fix n·(1 + e·(a + b·e)), e = |n|² − 1: a ≈ −1/2, b ≈ 3/8 (1/√(1+e) to second order). */
export const LENGTH_FIX = [-0.5, 0.375] as const;
