/**
 * gcs-skin/gpu: generalized cross-sections on the GPU (docs/gpu.md, docs/method.md §8).
 *
 * The mesh stays in GPU memory in the bind pose, section by section; per vertex its section id
 * (smooth mode: also the other section and the factor towards it) is a static attribute. Two paths:
 *   'joints' (the default for the weights criterion): each frame wasm writes only the joint poses
 *     (4 RGBA32F texels per joint: the rows of S_j and its rotation quaternion); a node pass
 *     (gpu/node-pass.ts, once per frame before the skin's first draw) blends every section (node)
 *     from them and a static per-section table (its joints and mean weights, uploaded once) into
 *     float textures, exactly as the CPU does (dual quaternions, scale blended linearly and applied
 *     first, the CPU's normal matrix), and each vertex reads its 1–3 nodes and blends them (the
 *     CPU's smooth-mode length fix).
 *   'sections' (any criterion; the only one for 'y' and 'axial'): each frame wasm computes the
 *     section transforms (3 RGBA32F texels per section) and the shader applies them.
 * LBS and DQS (method 'lbs' | 'dqs') upload the joint poses too; each vertex blends its own joints.
 * Either way the per-frame texels live in wasm memory that a float DataTexture views with no
 * JavaScript copy, and the vertex shader of the source's own material (three.js's built-in
 * materials, patched through onBeforeCompile; shadows through matching depth and distance
 * materials) moves positions, normals and tangents.
 *
 * The code lives in gpu/ (layout.ts: the texel layout and constants; glsl.ts: the GLSL chunks and
 * the node pass's shaders; node-pass.ts: the node pass; tsl.ts: the same maths in TSL for
 * gcs-skin/webgpu; sections.ts: the per-frame texture; webgl-materials.ts: the patched materials);
 * this module is the public face of the GLSL side.
 *
 * Most users never touch this module: `new GcsCharacter(gcs, scene, { backend: 'gpu' })`
 * (gcs-skin/three) uses it. `GcsCrowd` draws many characters sharing one mesh and one section
 * model, each with its own pose, in one instanced draw call per skin.
 *
 * @module gcs-skin/gpu
 */
export { GPU_TEXELS_PER_JOINT, GPU_TEXELS_PER_SECTION, JointPoses, SectionTransforms } from './index.js';
export type { GpuMethod, GpuPath } from './gpu/layout.js';
export { nodePassShaders, patchVertexShader } from './gpu/glsl.js';
export { NodePass } from './gpu/node-pass.js';
export { gcsMaterial, gcsShadowMaterials, gpuMaterialSupport } from './gpu/webgl-materials.js';
export { GpuSections, sectionAttributes, type GcsUniforms, type SectionAttribute } from './gpu/sections.js';
