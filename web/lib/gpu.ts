/**
 * gcs-skin/gpu: generalized cross-sections on the GPU (design.md §6, docs/gpu.md).
 *
 * The mesh stays in GPU memory in the bind pose, section by section; per vertex its section id
 * (smooth mode: also the other section and the factor towards it) is a static attribute. Each
 * frame wasm computes only the section transforms (3 RGBA32F texels per section) into a buffer
 * that a float DataTexture views with no JavaScript copy, and the vertex shader of the source's
 * own material (three.js's built-in materials, patched through onBeforeCompile; shadows through
 * matching depth and distance materials) applies them to positions, normals and tangents.
 *
 * Most users never touch this module: `new GcsCharacter(gcs, scene, { backend: 'gpu' })`
 * (gcs-skin/three) uses it. `GcsCrowd` draws many characters sharing one mesh and one section
 * model, each with its own pose, in one instanced draw call per skin.
 */
import * as THREE from 'three';
import { GcsError } from './errors.js';
import { GPU_TEXELS_PER_SECTION, SectionTransforms, type GcsDeformer } from './index.js';

export { GPU_TEXELS_PER_SECTION, SectionTransforms } from './index.js';

// ---------------------------------------------------------------------------------- shader

/** Declarations: the texture of section transforms and the static per-vertex section data. */
const PARS = /* glsl */ `
uniform highp sampler2D gcsSections;
uniform int gcsBase;
uniform int gcsStride;
#ifdef GCS_SMOOTH
attribute vec3 gcsBlend;
#else
attribute float gcsSection;
#endif
void gcsRows( const in int section, out vec4 r0, out vec4 r1, out vec4 r2 ) {
	int i = gcsBase + section * ${GPU_TEXELS_PER_SECTION};
	#ifdef USE_INSTANCING
	i += gl_InstanceID * gcsStride;
	#endif
	int w = textureSize( gcsSections, 0 ).x;
	r0 = texelFetch( gcsSections, ivec2( i % w, i / w ), 0 );
	i += 1; r1 = texelFetch( gcsSections, ivec2( i % w, i / w ), 0 );
	i += 1; r2 = texelFetch( gcsSections, ivec2( i % w, i / w ), 0 );
}
// Rows of the cofactor matrix of the 3×3 part (rows a, b, c), divided by its largest entry first
// (no overflow under ×1e20 scales): the normal matrix up to a positive factor. Smooth mode blends
// two of them, so each is brought to the CPU's scale: divided by |det|^(2/3) (a rotation times a
// uniform scale gives back the rotation).
void gcsNormalRows( vec4 r0, vec4 r1, vec4 r2, const in bool unitScale, out vec3 n0, out vec3 n1, out vec3 n2 ) {
	vec3 a = r0.xyz, b = r1.xyz, c = r2.xyz;
	vec3 m = max( max( abs( a ), abs( b ) ), abs( c ) );
	float big = max( max( m.x, m.y ), m.z );
	if ( big > 0.0 ) { a /= big; b /= big; c /= big; }
	n0 = cross( b, c ); n1 = cross( c, a ); n2 = cross( a, b );
	if ( unitScale ) {
		float det = abs( dot( a, n0 ) );
		if ( det > 1e-30 ) { float k = 1.0 / pow( det, 2.0 / 3.0 ); n0 *= k; n1 *= k; n2 *= k; }
	}
}
vec3 gcsTurn( const in vec3 v, const in vec3 n0, const in vec3 n1, const in vec3 n2 ) {
	vec3 t = vec3( dot( n0, v ), dot( n1, v ), dot( n2, v ) );
	float l = length( t );
	return l > 0.0 ? t / l : v;
}
`;

/** Per vertex, once: the blended rows of its affine 3×4 and the rows of its normal matrix. */
const BASE = /* glsl */ `
	vec4 gcsR0, gcsR1, gcsR2;
	vec3 gcsN0, gcsN1, gcsN2;
	{
		#ifdef GCS_SMOOTH
		vec4 a0, a1, a2, b0, b1, b2;
		gcsRows( int( gcsBlend.x + 0.5 ), a0, a1, a2 );
		gcsRows( int( gcsBlend.y + 0.5 ), b0, b1, b2 );
		float f = gcsBlend.z;
		gcsR0 = a0 + f * ( b0 - a0 ); gcsR1 = a1 + f * ( b1 - a1 ); gcsR2 = a2 + f * ( b2 - a2 );
		vec3 p0, p1, p2, q0, q1, q2;
		gcsNormalRows( a0, a1, a2, true, p0, p1, p2 );
		gcsNormalRows( b0, b1, b2, true, q0, q1, q2 );
		gcsN0 = p0 + f * ( q0 - p0 ); gcsN1 = p1 + f * ( q1 - p1 ); gcsN2 = p2 + f * ( q2 - p2 );
		#else
		gcsRows( int( gcsSection + 0.5 ), gcsR0, gcsR1, gcsR2 );
		gcsNormalRows( gcsR0, gcsR1, gcsR2, false, gcsN0, gcsN1, gcsN2 );
		#endif
	}
`;

const NORMAL = /* glsl */ `
	objectNormal = gcsTurn( objectNormal, gcsN0, gcsN1, gcsN2 );
	#ifdef USE_TANGENT
	objectTangent = gcsTurn( objectTangent, gcsN0, gcsN1, gcsN2 );
	#endif
`;

const POSITION = /* glsl */ `
	{
		vec4 p = vec4( transformed, 1.0 );
		transformed = vec3( dot( gcsR0, p ), dot( gcsR1, p ), dot( gcsR2, p ) );
	}
`;

const HOOKS = ['#include <skinning_pars_vertex>', '#include <skinbase_vertex>', '#include <skinning_vertex>'] as const;

/**
 * The vertex shader of a three.js built-in material (or any shader written with its chunks) with
 * three's skinning chunks replaced by GCS's: the section transforms come from the `gcsSections`
 * texture. Morph targets still apply first (three's order), then the section transform; normals
 * and tangents turn with the normal matrix. Throws GcsError 'INVALID_ARGUMENT' when the shader
 * lacks the chunks (a ShaderMaterial written without them).
 */
export function patchVertexShader(source: string, smooth: boolean): string {
  for (const hook of HOOKS)
    if (!source.includes(hook)) throw new GcsError('INVALID_ARGUMENT', `this vertex shader has no '${hook}': gcs-skin/gpu patches three.js's skinning chunks`);
  let out = source
    .replace(HOOKS[0], `${HOOKS[0]}\n${PARS}`)
    .replace(HOOKS[1], BASE)
    .replace(HOOKS[2], POSITION);
  // Materials that do not compute normals (depth, distance) have no skinnormal chunk.
  out = out.replace('#include <skinnormal_vertex>', NORMAL);
  return `${smooth ? '#define GCS_SMOOTH\n' : ''}${out}`;
}

/** Why a material cannot draw a GCS mesh on the GPU, or null when it can. */
export function gpuMaterialSupport(material: THREE.Material): string | null {
  const m = material as THREE.Material & { isShaderMaterial?: boolean; isNodeMaterial?: boolean };
  if (m.isNodeMaterial) return `${material.type} is a node material (WebGPU / TSL): the GPU backend patches WebGLRenderer's GLSL materials`;
  if (m.isShaderMaterial) return `${material.type} is a custom shader: the GPU backend patches three.js's built-in materials`;
  return null;
}

/** The uniforms a patched material reads; shared by every material of one skin. */
export interface GcsUniforms {
  gcsSections: { value: THREE.DataTexture };
  /** Texel of instance 0's first section. */
  gcsBase: { value: number };
  /** Texels per instance (sections × 3). */
  gcsStride: { value: number };
  [name: string]: THREE.IUniform;
}

/**
 * A clone of `source` (sharing its textures) whose vertex shader applies GCS section transforms
 * read from `uniforms`. The source's own onBeforeCompile, if any, runs first.
 */
export function gcsMaterial<M extends THREE.Material>(source: M, uniforms: GcsUniforms, smooth: boolean): M {
  const reason = gpuMaterialSupport(source);
  if (reason) throw new GcsError('INVALID_ARGUMENT', reason);
  const material = source.clone() as M;
  const own = source.onBeforeCompile;
  const ownKey = source.customProgramCacheKey();
  material.onBeforeCompile = (shader, renderer) => {
    own.call(source, shader, renderer);
    Object.assign(shader.uniforms, uniforms);
    shader.vertexShader = patchVertexShader(shader.vertexShader, smooth);
  };
  material.customProgramCacheKey = () => `${ownKey}|gcs-${smooth ? 'smooth' : 'plain'}`;
  material.name = source.name;
  material.userData.gcsSource = source;
  return material;
}

/**
 * Shadow materials for a GCS mesh: depth (directional and spot lights) and distance (point
 * lights), patched the same way; alpha-tested maps carried so cut-outs cast the right shadow.
 */
export function gcsShadowMaterials(source: THREE.Material, uniforms: GcsUniforms, smooth: boolean): { depth: THREE.MeshDepthMaterial; distance: THREE.MeshDistanceMaterial } {
  const depth = new THREE.MeshDepthMaterial({ depthPacking: THREE.RGBADepthPacking });
  const distance = new THREE.MeshDistanceMaterial();
  const s = source as THREE.Material & { map?: THREE.Texture | null; alphaMap?: THREE.Texture | null };
  for (const m of [depth, distance]) {
    if (source.alphaTest > 0) {
      m.alphaTest = source.alphaTest;
      m.map = s.map ?? null;
      m.alphaMap = s.alphaMap ?? null;
    }
  }
  return { depth: gcsMaterial(depth, uniforms, smooth), distance: gcsMaterial(distance, uniforms, smooth) };
}

// ---------------------------------------------------------------------------------- sections

/**
 * The section transforms of `instanceCount` poses of one GCS model as a float texture: a
 * SectionTransforms (buffers in wasm memory) and a DataTexture whose `image.data` is its texel
 * view (no copy; re-pointed after wasm memory growth). Write poses into `skins` (J × 16 floats per
 * instance), then `update()` once per frame: one wasm call, one texture upload.
 */
export class GpuSections {
  readonly transforms: SectionTransforms;
  readonly texture: THREE.DataTexture;
  readonly uniforms: GcsUniforms;
  readonly smooth: boolean;

  constructor(readonly deformer: GcsDeformer, instanceCount = 1, maxWidth = 2048) {
    this.transforms = new SectionTransforms(deformer, instanceCount, maxWidth);
    const t = this.transforms;
    this.texture = new THREE.DataTexture(t.texels, t.width, t.height, THREE.RGBAFormat, THREE.FloatType);
    this.texture.minFilter = THREE.NearestFilter;
    this.texture.magFilter = THREE.NearestFilter;
    this.texture.generateMipmaps = false;
    this.texture.needsUpdate = true;
    this.uniforms = { gcsSections: { value: this.texture }, gcsBase: { value: 0 }, gcsStride: { value: t.sectionCount * GPU_TEXELS_PER_SECTION } };
    this.smooth = deformer.blendOther() !== null;
  }

  get instanceCount(): number {
    return this.transforms.instanceCount;
  }

  /** Every instance's skin matrices (a view on wasm memory). */
  get skins(): Float32Array {
    return this.transforms.skins;
  }

  /** Bytes one update() uploads: the whole texture (width × height × 16). */
  get bytesPerUpdate(): number {
    return this.transforms.width * this.transforms.height * 16;
  }

  /** Section transforms of every instance from `skins`, then the texture is flagged for upload. No allocation. */
  update(): void {
    this.transforms.compute();
    const texels = this.transforms.texels; // re-created after memory growth
    const image = this.texture.image as { data: Float32Array };
    if (image.data !== texels) image.data = texels;
    this.texture.needsUpdate = true;
  }

  dispose(): void {
    this.texture.dispose();
    this.transforms.dispose();
  }
}

/**
 * Static per-vertex section data of a GCS deformer's output mesh: `gcsSection` (plain mode) or
 * `gcsBlend` = (section, other section, factor) (smooth mode), as float attributes.
 */
export function sectionAttributes(deformer: GcsDeformer): { name: 'gcsSection' | 'gcsBlend'; attribute: THREE.BufferAttribute } {
  const section = deformer.sectionOfVertex();
  const other = deformer.blendOther(), factor = deformer.blendFactor();
  if (!other || !factor) return { name: 'gcsSection', attribute: new THREE.BufferAttribute(Float32Array.from(section), 1) };
  const blend = new Float32Array(3 * section.length);
  for (let o = 0; o < section.length; o++) {
    blend[3 * o] = section[o];
    blend[3 * o + 1] = other[o];
    blend[3 * o + 2] = factor[o];
  }
  return { name: 'gcsBlend', attribute: new THREE.BufferAttribute(blend, 3) };
}
