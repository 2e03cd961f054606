/**
 * The node pass (joint-level path, WebGLRenderer): once per frame, every node's transform, normal
 * matrix and renormalisation flag from the joint poses, for every instance in one draw, into a
 * float render target that the vertex stage reads (glsl.ts, NODE_PARS). A node depends only on its
 * joints and the frame: computed here once, not once per vertex that uses it.
 *
 * It runs at the first draw of the skin after `GpuSections.update()` (the mesh's onBeforeShadow or
 * onBeforeRender, whichever three.js calls first: shadow maps are drawn before the scene), so
 * shadow, depth and colour passes of that frame read the same texture, and a frame drawn twice
 * computes it once.
 */
import * as THREE from 'three';
import { checkObject } from '../arguments.js';
import { dqsPassShaders, nodePassShaders } from './glsl.js';
import { DQS_TEXELS_PER_JOINT, GPU_NODE_TEXTURES, GPU_TEXELS_PER_JOINT } from './layout.js';
import type { GcsUniforms, GpuSections } from './sections.js';

/** The widest row of the node textures: WebGL2's guaranteed 2048. */
const MAX_WIDTH = 2048;

/** The extension float render targets need in WebGL2 (RGBA32F colour attachments). */
export const FLOAT_TARGET_EXTENSION = 'EXT_color_buffer_float';

/** What the vertex stage reads: the node textures (gcsNodes0 … gcsNodes3), instance 0's first node, nodes per instance. */
export type NodeUniforms = GcsUniforms;

type Renderer = THREE.WebGLRenderer;

/**
 * Computes every node's transform and normal matrix once per frame into float render targets that
 * the joint-level vertex stage reads (see the module comment). For GPU DQS (sections of method
 * 'dqs') it is the joint pass: two texels per joint, one row per instance (DQS_TEXELS_PER_JOINT:
 * its rotation quaternion, dual part and uniform scale, then the rows of K = Rᵀ·S), which the DQS
 * vertex stage blends.
 */
export class NodePass {
  /** The float render target (GPU_NODE_TEXTURES textures, one texel per node of every instance) the pass draws into. */
  readonly target: THREE.WebGLRenderTarget;
  /** The uniforms the vertex stage reads: the target's textures as gcsNodes0…, gcsBase and gcsStride. */
  readonly uniforms: NodeUniforms;
  private readonly material: THREE.ShaderMaterial;
  private readonly scene = new THREE.Scene();
  private readonly camera = new THREE.Camera();
  private readonly geometry = new THREE.BufferGeometry();
  /** The GpuSections.version the target holds (−1: none yet). */
  private drawn = -1;

  /**
   * @param sections The GPU sections whose joint poses and section table the pass reads.
   * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
   */
  constructor(readonly sections: GpuSections) {
    checkObject(sections, 'sections', 'NodePass');
    checkObject(sections.deformer, 'sections.deformer', 'NodePass');
    // DQS: the joint pass, two texels per joint (q, dual part, uniform scale; K), one row per
    // instance (2 · GCS_MAX_JOINTS = MAX_WIDTH). GCS: one texel per section, rows of MAX_WIDTH.
    const dqs = sections.method === 'dqs';
    const deformer = sections.deformer, N = sections.instanceCount;
    const S = dqs ? sections.uniforms.gcsStride.value as number / GPU_TEXELS_PER_JOINT : deformer.sectionCount;
    const nodes = N * S * (dqs ? DQS_TEXELS_PER_JOINT : 1);
    const width = dqs ? S * DQS_TEXELS_PER_JOINT : Math.min(MAX_WIDTH, nodes), height = Math.ceil(nodes / width);
    // One texel per node in each of four float targets: the node pass computes a node once and writes it whole.
    this.target = new THREE.WebGLRenderTarget(width, height, {
      type: THREE.FloatType, format: THREE.RGBAFormat, minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
      depthBuffer: false, stencilBuffer: false, generateMipmaps: false, count: GPU_NODE_TEXTURES,
    });
    const u = sections.uniforms;
    this.material = new THREE.ShaderMaterial({
      ...(dqs ? dqsPassShaders(sections.tableSlots) : nodePassShaders(sections.tableSlots)),
      uniforms: {
        gcsJoints: u.gcsJoints!, ...(dqs ? {} : { gcsTable: u.gcsTable! }),
        gcsNodeCount: { value: nodes }, gcsSectionCount: { value: S },
        gcsJointStride: u.gcsStride, gcsTargetWidth: { value: width },
      },
      depthTest: false, depthWrite: false, blending: THREE.NoBlending, glslVersion: THREE.GLSL3,
    });
    // Three vertices, no attributes read (gl_VertexID places them): one triangle over the target.
    this.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(9), 3));
    const quad = new THREE.Mesh(this.geometry, this.material);
    quad.frustumCulled = false;
    this.scene.add(quad);
    this.uniforms = { gcsBase: { value: 0 }, gcsStride: { value: S } };
    this.target.textures.forEach((texture, t) => { this.uniforms[`gcsNodes${t}`] = { value: texture }; });
  }

  /** Why `renderer` cannot run the node pass (no float render targets), or null. */
  static unsupported(renderer: unknown): string | null {
    const r = renderer as Renderer & { isWebGLRenderer?: boolean };
    if (!r?.isWebGLRenderer || r.extensions.has(FLOAT_TARGET_EXTENSION)) return null;
    return `this WebGLRenderer has no ${FLOAT_TARGET_EXTENSION} (float render targets), which the joint-level path's node pass draws into`;
  }

  /**
   * Writes every node of every instance for the current joint poses, unless already written since
   * the last GpuSections.update(). Restores the renderer's render target (and cube face, mip level).
   */
  render(renderer: Renderer): void {
    const version = this.sections.version;
    if (this.drawn === version) return;
    this.drawn = version;
    const target = renderer.getRenderTarget(), face = renderer.getActiveCubeFace(), level = renderer.getActiveMipmapLevel();
    const autoClear = renderer.autoClear;
    renderer.autoClear = false; // every texel is written
    renderer.setRenderTarget(this.target);
    renderer.render(this.scene, this.camera);
    renderer.setRenderTarget(target, face, level);
    renderer.autoClear = autoClear;
  }

  /** Frees the render target, the pass's material and its geometry. */
  dispose(): void {
    this.target.dispose();
    this.material.dispose();
    this.geometry.dispose();
  }
}
