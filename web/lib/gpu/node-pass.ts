/**
 * The node pass (joint-level path, WebGLRenderer): once per frame, every node's transform, normal
 * matrix and renormalisation flag from the joint poses, for every instance in one draw, into float
 * render targets that the vertex stage reads (glsl.ts, NODE_PARS). A node depends only on its
 * joints and the frame: computed here once, not once per vertex that uses it.
 *
 * Every pass a renderer draws shares one set of targets (node-atlas.ts): its rows of a page, and
 * one render of the page per frame for every skin that changed, not one per skin.
 *
 * It runs at the first draw of the skin after `GpuSections.update()` (the mesh's onBeforeShadow or
 * onBeforeRender, whichever three.js calls first: shadow maps are drawn before the scene), so
 * shadow, depth and colour passes of that frame read the same texture, and a frame drawn twice
 * computes it once.
 */
import * as THREE from 'three';
import { checkObject } from '../arguments.js';
import { dqsPassShaders, nodePassShaders } from './glsl.js';
import { GPU_NODE_TEXTURES } from './layout.js';
import { NodePage, PagedPass, PAGE_WIDTH, type PassKind } from './node-atlas.js';
import { floatTexture, type GcsUniforms, type GpuSections } from './sections.js';

/** The extension float render targets need in WebGL2 (RGBA32F colour attachments). */
export const FLOAT_TARGET_EXTENSION = 'EXT_color_buffer_float';

/**
 * What the vertex stage reads: the node textures (gcsNodes0 … gcsNodes3), instance 0's first node
 * (gcsBase) and nodes per instance (gcsStride); for DQS, the first row of its joint texels (gcsFirstRow).
 */
export type NodeUniforms = GcsUniforms;

type Renderer = THREE.WebGLRenderer;

/**
 * Kind 'nodes' (GCS, joint-level path): every node's transform and normal matrix once per frame,
 * blended from the parts its joint pass wrote, into float render targets that the vertex stage
 * reads (see the module comment). Kind 'joints' (a GCS node pass's own, and GPU DQS's): two texels
 * per joint, one row per instance (DQS_TEXELS_PER_JOINT: its rotation quaternion, dual part and
 * uniform scale, then the rows of K = Rᵀ·S).
 */
export class NodePass extends PagedPass<NodePage> {
  /** The uniforms the vertex stage reads: the page's textures as gcsNodes0…, gcsBase, gcsStride and gcsFirstRow. */
  readonly uniforms: NodeUniforms;
  /** The mesh that draws this pass's fragments into its page. */
  readonly quad: THREE.Mesh;
  /** GCS: the joint pass whose parts the node pass reads (drawn first); null for a joint pass. */
  readonly jointPass: NodePass | null;
  /** @internal The first row's uniform (the node pass reads its joint pass's). */
  readonly firstRowUniform = { value: 0 };
  private readonly material: THREE.ShaderMaterial;
  private readonly geometry = new THREE.BufferGeometry();
  private readonly ownPage: boolean;
  /** A crowd's placements folded into its nodes: the instance matrices, their texture, and the version it holds. */
  private readonly placements: { matrices: THREE.BufferAttribute; texture: THREE.DataTexture; version: number } | null;

  /**
   * @param sections The GPU sections whose joint poses and section table the pass reads.
   * @param ownPage A page of its own, exactly its rows and columns, instead of a share of the
   * renderer's (gcs-skin/webgpu under WebGLNodesHandler reads it as a texture of one row).
   * @param kind 'joints': the joint pass (GPU DQS's, and what a GCS node pass reads); 'nodes': the node pass (GCS), with its joint pass.
   * @param placements A crowd's instance matrices (16 floats per instance), folded into each instance's nodes (kind 'nodes'):
   * its vertex stage, patched with placedInNodes, places nothing. The pass runs again when they change (their `version`).
   * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
   */
  constructor(sections: GpuSections, ownPage = false, kind: PassKind = sections?.method === 'dqs' ? 'joints' : 'nodes', placements: THREE.BufferAttribute | null = null) {
    checkObject(sections, 'sections', 'NodePass');
    checkObject(sections.deformer, 'sections.deformer', 'NodePass');
    super(sections, kind);
    const writesJoints = kind === 'joints', S = this.perInstance;
    const u = sections.uniforms;
    this.uniforms = { gcsBase: { value: 0 }, gcsStride: { value: S }, gcsFirstRow: this.firstRowUniform };
    for (let t = 0; t < GPU_NODE_TEXTURES; t++) this.uniforms[`gcsNodes${t}`] = { value: null };
    this.jointPass = writesJoints ? null : new NodePass(sections, ownPage, 'joints');
    const parts: Record<string, THREE.IUniform> = this.jointPass ? {
      gcsTable: u.gcsTable!, gcsJointRow: this.jointPass.firstRowUniform,
      gcsJointParts0: this.jointPass.uniforms.gcsNodes0!, gcsJointParts1: this.jointPass.uniforms.gcsNodes1!, gcsJointParts2: this.jointPass.uniforms.gcsNodes2!,
    } : {};
    if (placements !== null) checkObject(placements, 'placements', 'NodePass');
    this.placements = placements && !writesJoints ? { matrices: placements, texture: placementTexture(sections.instanceCount), version: -1 } : null;
    this.material = new THREE.ShaderMaterial({
      ...(writesJoints ? dqsPassShaders(sections.tableSlots) : nodePassShaders(sections.tableSlots, this.placements !== null)),
      uniforms: {
        ...(this.placements ? { gcsPlacements: { value: this.placements.texture } } : {}),
        gcsJoints: u.gcsJoints!, gcsCompactJoints: u.gcsCompactJoints ?? { value: null }, gcsCompactPoses: u.gcsCompactPoses ?? { value: 0 }, ...parts,
        gcsNodeCount: { value: sections.instanceCount * S }, gcsSectionCount: { value: S },
        gcsJointStride: u.gcsStride, gcsTargetWidth: { value: PAGE_WIDTH },
        gcsFirstRow: this.firstRowUniform, gcsRect: { value: new THREE.Vector4() },
      },
      depthTest: false, depthWrite: false, blending: THREE.NoBlending, side: THREE.DoubleSide, glslVersion: THREE.GLSL3,
    });
    // Six vertices, no attributes read (gl_VertexID places them): two triangles over the pass's rows.
    this.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(18), 3));
    this.quad = new THREE.Mesh(this.geometry, this.material);
    this.ownPage = ownPage;
    if (ownPage) new NodePage(this.columns, this.rows).add(this);
  }

  /** The float render target (GPU_NODE_TEXTURES textures) this pass draws into, shared with other passes; null before its first draw. */
  get target(): THREE.WebGLRenderTarget | null {
    return this.page?.target ?? null;
  }

  /** The first row of this pass's texels in `target`. */
  get firstRow(): number {
    return this.firstRowUniform.value;
  }

  /** Why `renderer` cannot run the node pass (no float render targets), or null. */
  static unsupported(renderer: unknown): string | null {
    const r = renderer as Renderer & { isWebGLRenderer?: boolean };
    if (!r?.isWebGLRenderer || r.extensions.has(FLOAT_TARGET_EXTENSION)) return null;
    return `this WebGLRenderer has no ${FLOAT_TARGET_EXTENSION} (float render targets), which the joint-level path's node pass draws into`;
  }

  /**
   * Writes every node of every instance for the current joint poses, unless already written since
   * the last GpuSections.update() — with every other stale pass of the renderer, in one render of
   * their page. Restores the renderer's render target (and cube face, mip level). Returns why the
   * pass cannot run (more rows than a page holds), or null.
   */
  render(renderer: Renderer): string | null {
    const why = this.jointPass?.render(renderer) ?? (this.ownPage ? null : this.seat(renderer)); // the parts this pass reads, first
    if (why) return why;
    const p = this.placements;
    if (p && p.version !== p.matrices.version) {
      // The instances the texture holds (a longer attribute's rest is not drawn); no allocation.
      const data = p.texture.image.data as Float32Array, matrices = p.matrices.array as Float32Array;
      if (matrices.length <= data.length) data.set(matrices);
      else for (let i = 0; i < data.length; i++) data[i] = matrices[i];
      p.texture.needsUpdate = true;
      p.version = p.matrices.version;
      this.lost();
    }
    if (this.stale()) this.page!.run(renderer);
    return null;
  }

  /** @internal This pass's rows start at `firstRow` of `page`: its quad, its fragments' numbering and the vertex stage's reads follow. */
  place(page: NodePage, firstRow: number): void {
    this.page = page;
    const { width, height } = page.target;
    const u = this.material.uniforms;
    u.gcsTargetWidth.value = width;
    (u.gcsRect.value as THREE.Vector4).set(-1, 2 * firstRow / height - 1, 2 * this.columns / width - 1, 2 * (firstRow + this.rows) / height - 1);
    this.firstRowUniform.value = firstRow;
    this.uniforms.gcsBase.value = firstRow * width;
    page.target.textures.forEach((texture, t) => { this.uniforms[`gcsNodes${t}`]!.value = texture; });
  }

  /** Frees the pass's rows (its page with the last), material and geometry. */
  dispose(): void {
    if (this.ownPage) this.page?.dispose();
    this.leave();
    this.material.dispose();
    this.geometry.dispose();
    this.placements?.texture.dispose();
    this.jointPass?.dispose();
  }
}

/** `count` instance matrices as an RGBA32F texture, four texels (columns) per instance, rows of PAGE_WIDTH (a multiple of 4). */
function placementTexture(count: number): THREE.DataTexture {
  const width = Math.min(PAGE_WIDTH, 4 * count), height = Math.ceil(4 * count / width);
  return floatTexture(new Float32Array(4 * width * height), width, height);
}
