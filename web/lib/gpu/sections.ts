/**
 * The GPU path's data, whichever renderer draws it: the per-frame texture of joint poses or
 * section transforms (wasm memory viewed by a float DataTexture, no copy), the static section
 * table, and the per-vertex section attributes (layout.ts; docs/gpu.md).
 */
import * as THREE from 'three';
import { checkMethods, checkObject } from '../arguments.js';
import { GcsError } from '../errors.js';
import { COMPACT_FLOATS_PER_JOINT, JointPoses, SectionTransforms, type GcsDeformer, type PoseTexels } from '../index.js';
import { keepLive } from '../three/live-views.js';
import { BLEND_ATTRIBUTE, BLEND_THIRD_ATTRIBUTE, SECTION_ATTRIBUTE, tableTexelsPerSection, type GpuMethod, type GpuPath, type TableSlots } from './layout.js';

/** LBS / DQS on the GPU: the method and the influences per vertex the shader blends (4, or 8). */
export interface SkinningOptions { method: 'lbs' | 'dqs'; slots: TableSlots }

/** The uniforms a patched material reads; shared by every material of one skin. */
export interface GcsUniforms {
  /** Path 'sections': the section transforms (per frame). */
  gcsSections?: {
    /** The uniform's value. */
    value: THREE.DataTexture;
  };
  /** Path 'joints': the joint poses (per frame). */
  gcsJoints?: {
    /** The uniform's value. */
    value: THREE.DataTexture;
  };
  /** Path 'joints' read by a pass (GCS, DQS): the joint poses in the compact format (per frame, see GpuSections.compactTexture). */
  gcsCompactJoints?: {
    /** The uniform's value. */
    value: THREE.DataTexture;
  };
  /** 1 where this frame's joint poses are in the compact format (gcsCompactJoints), 0 where in the full one (gcsJoints). */
  gcsCompactPoses?: {
    /** The uniform's value. */
    value: number;
  };
  /** Path 'joints': each section's joints and weights (static). */
  gcsTable?: {
    /** The uniform's value. */
    value: THREE.DataTexture;
  };
  /** Texel of instance 0's first section or joint. */
  gcsBase: {
    /** The uniform's value. */
    value: number;
  };
  /** Texels per instance (sections × 3, or joints × 4). */
  gcsStride: {
    /** The uniform's value. */
    value: number;
  };
  [name: string]: THREE.IUniform | undefined;
}

/**
 * What the GPU needs per frame for `instanceCount` poses of one GCS model, as a float texture:
 * path 'joints' (default for the weights criterion) the joint poses (JointPoses) plus a static
 * texture of each section's joints and weights, uploaded once; path 'sections' (any criterion;
 * the default for 'y' and 'axial') the section transforms (SectionTransforms). The per-frame
 * buffers live in wasm memory and the DataTexture's `image.data` views them (no copy; re-pointed
 * after wasm memory growth). Write poses into `skins` (J × 16 floats per instance), then
 * `update()` once per frame: one wasm call, one texture upload. Asking for 'joints' on a model
 * built with the 'y' or 'axial' criterion is GcsError 'INVALID_ARGUMENT'.
 */
export class GpuSections {
  /** Which GPU path runs: 'joints' (joint poses, the weights criterion) or 'sections' (section transforms). */
  readonly path: GpuPath;
  /** The per-frame buffers in wasm memory (JointPoses or SectionTransforms). */
  readonly transforms: PoseTexels;
  /** The per-frame texture (joint poses or section transforms); path 'joints': the full format's. */
  readonly texture: THREE.DataTexture;
  /**
   * GCS and DQS on path 'joints' (read by their passes only): the joint poses in the compact
   * format, uploaded instead of `texture` on a frame whose every joint is rigid with unit scale
   * (JointPoses.compactFormat; uniform gcsCompactPoses = 1): COMPACT_FLOATS_PER_JOINT floats per
   * joint, joint j of instance k at float (k·J + j)·6, i.e. 1.5 texels, the first texels of the
   * same wasm buffer. Null for LBS (each vertex reads its joints' matrix rows: the full format
   * always) and path 'sections'.
   */
  readonly compactTexture: THREE.DataTexture | null;
  /** Path 'joints': the static texture of each section's joints, weights and centre of rotation; null otherwise. */
  readonly table: THREE.DataTexture | null;
  /** Path 'joints': joints per section in `table` (4, or 8 where a section blends more); 4 otherwise. */
  readonly tableSlots: TableSlots;
  /** The uniforms every patched material of this skin shares. */
  readonly uniforms: GcsUniforms;
  /** Whether the model blends sections (smooth mode): the shader then reads two or three per vertex. */
  readonly smooth: boolean;
  /** Counts update() calls: what a node pass computed from is told apart from what it must recompute. */
  version = 0;
  /** Velocity: the per-frame texels as the previous frame drew them (see previousTexture). */
  private previous: PreviousPoses | null = null;

  /** What the vertex stage runs: GCS, or LBS / DQS of each vertex's own joints (joint poses only, no table). */
  readonly method: GpuMethod;
  /** LBS / DQS: `deformer` is a GCS build of the same rig kept for its joint poses only, freed with this. */
  private readonly ownsDeformer: boolean;

  /**
   * @param deformer The GCS model (it stays the caller's).
   * @param instanceCount Poses the texture holds (1, or a crowd's count).
   * @param maxWidth The widest texture row (WebGL2 guarantees 2048).
   * @param path 'joints' or 'sections' (default: 'joints' for the weights criterion, else 'sections').
   * @throws GcsError `INVALID_ARGUMENT` for 'joints' on a 'y' or 'axial' model, `OUT_OF_RANGE` for a bad count or width.
   * @param skinning LBS or DQS of each vertex's own joints instead of GCS (the deformer is then kept for its joint poses only, and freed with this).
   * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
   */
  constructor(readonly deformer: GcsDeformer, instanceCount = 1, maxWidth = 2048, path?: GpuPath, skinning?: SkinningOptions) {
    checkObject(deformer, 'deformer', 'GpuSections');
    if (path !== undefined && path !== 'joints' && path !== 'sections') throw new GcsError('INVALID_ARGUMENT', `the GPU path must be 'joints' or 'sections'; got '${String(path)}'`);
    this.method = skinning?.method ?? 'gcs';
    this.ownsDeformer = skinning !== undefined;
    this.path = skinning ? 'joints' : path ?? (deformer.jointLevel ? 'joints' : 'sections');
    const compact = this.path === 'joints' && skinning?.method !== 'lbs';
    this.transforms = this.path === 'joints' ? new JointPoses(deformer, instanceCount, maxWidth, compact) : new SectionTransforms(deformer, instanceCount, maxWidth);
    const t = this.transforms;
    this.texture = floatTexture(t.texels, t.width, t.height);
    keepLive(this.texture.image as { data: ArrayBufferView }, 'data', () => (t.disposed ? null : t.texels)); // live after memory growth
    this.compactTexture = null;
    let base: GcsUniforms = { gcsBase: { value: 0 }, gcsStride: { value: t.texelsPerInstance } };
    if (compact) {
      const size = compactSize(t, maxWidth);
      this.compactTexture = floatTexture(t.texels.subarray(0, size.floats), size.width, size.height);
      keepLive(this.compactTexture.image as { data: ArrayBufferView }, 'data', () => (t.disposed ? null : t.texels.subarray(0, size.floats)));
      base = { ...base, gcsCompactJoints: { value: this.compactTexture }, gcsCompactPoses: { value: (t as JointPoses).compactFormat ? 1 : 0 } };
    }
    this.tableSlots = 4;
    if (skinning) {
      this.tableSlots = skinning.slots;
      this.table = null;
      this.uniforms = { gcsJoints: { value: this.texture }, ...base };
    } else if (this.path === 'joints') {
      this.tableSlots = deformer.sectionInfluenceSlots === 8 ? 8 : 4;
      const table = sectionTable(deformer);
      const texels = table.length / 4, width = Math.min(maxWidth, texels), height = Math.ceil(texels / width);
      const data = new Float32Array(width * height * 4);
      data.set(table);
      this.table = floatTexture(data, width, height);
      this.uniforms = { gcsJoints: { value: this.texture }, gcsTable: { value: this.table }, ...base };
    } else {
      this.table = null;
      this.uniforms = { gcsSections: { value: this.texture }, ...base };
    }
    this.smooth = !skinning && deformer.blendOther() !== null;
  }

  /** Poses the texture holds. */
  get instanceCount(): number {
    return this.transforms.instanceCount;
  }

  /** Every instance's skin matrices (a view on wasm memory). */
  get skins(): Float32Array {
    return this.transforms.skins;
  }

  /**
   * Bytes one update() uploads: the whole per-frame texture (width × height × 16) of the format
   * it wrote (compactTexture's on a compact frame), twice while velocity is drawn.
   */
  get bytesPerUpdate(): number {
    const image = (this.uniforms.gcsCompactPoses?.value ? this.compactTexture! : this.texture).image as { width: number; height: number };
    return image.width * image.height * 16 * (this.previous ? 2 : 1);
  }

  /**
   * Velocity (motion vectors): a texture of the per-frame texels as they were drawn the frame
   * before, as three.js keeps its skeletons' previous bone matrices. Made on first use (a shader
   * that needs previous positions), then kept by advanceFrame; until a frame has passed it holds
   * this frame's texels (no motion).
   */
  previousTexture(): THREE.DataTexture {
    if (!this.previous) {
      const t = this.transforms, format = this.uniforms.gcsCompactPoses?.value ?? 0;
      const texture = floatTexture(Float32Array.from(t.texels), t.width, t.height), drawn = Float32Array.from(t.texels);
      const compact = this.compactTexture?.image as { width: number; height: number } | undefined;
      const floats = compact ? compact.width * compact.height * 4 : 0;
      const shown = texture.image.data as Float32Array;
      this.previous = {
        texture, drawn, frameId: -1, format: { value: format }, drawnFormat: format,
        compactTexture: compact ? floatTexture(shown.subarray(0, floats), compact.width, compact.height) : null,
        compactViews: compact ? new Map([[shown, shown.subarray(0, floats)], [drawn, drawn.subarray(0, floats)]]) : null,
      };
    }
    return this.previous.texture;
  }

  /**
   * @internal The compact twin of `texture` (`previous`: of previousTexture()) and the uniform value saying
   * whether the frame it shows is compact (1) or full (0): what a reader of the joint poses takes
   * on a compact frame. Null where there is no compact format (LBS, path 'sections').
   */
  compactPoses(previous = false): { texture: THREE.DataTexture; format: { value: number } } | null {
    if (!previous) return this.compactTexture ? { texture: this.compactTexture, format: this.uniforms.gcsCompactPoses! } : null;
    this.previousTexture();
    const p = this.previous!;
    return p.compactTexture ? { texture: p.compactTexture, format: p.format } : null;
  }

  /**
   * Once per rendered frame (three.js's frameId), before the draw: the previous texture shows what
   * the last frame drew and the texels drawn now are kept for the next. One copy, no allocation.
   */
  advanceFrame(frameId: number): void {
    const p = this.previous;
    if (!p || p.frameId === frameId) return;
    p.frameId = frameId;
    const image = p.texture.image as { data: Float32Array };
    const drawn = p.drawn;
    p.drawn = image.data;
    image.data = drawn;
    p.drawn.set(this.transforms.texels);
    p.format.value = p.drawnFormat;
    p.drawnFormat = this.uniforms.gcsCompactPoses?.value ?? 0;
    if (p.compactTexture) {
      (p.compactTexture.image as { data: Float32Array }).data = p.compactViews!.get(drawn)!;
      p.compactTexture.needsUpdate = p.format.value === 1;
      p.texture.needsUpdate = p.format.value === 0;
    } else p.texture.needsUpdate = true;
  }

  /** Joint poses or section transforms of every instance from `skins`, then the texture is flagged for upload. No allocation. */
  update(): void {
    this.transforms.compute();
    this.version++;
    const texels = this.transforms.texels; // re-created after memory growth
    const image = this.texture.image as { data: Float32Array };
    if (image.data !== texels) image.data = texels;
    const compact = this.uniforms.gcsCompactPoses;
    if (compact) {
      compact.value = (this.transforms as JointPoses).compactFormat ? 1 : 0;
      if (compact.value) {
        this.compactTexture!.needsUpdate = true; // only the compact texels go up; the full texture is not read this frame
        return;
      }
    }
    this.texture.needsUpdate = true;
  }

  /** Frees the textures and the wasm buffers (the deformer stays the caller's). */
  dispose(): void {
    this.texture.dispose();
    this.compactTexture?.dispose();
    this.previous?.texture.dispose();
    this.previous?.compactTexture?.dispose();
    this.table?.dispose();
    this.transforms.dispose();
    if (this.ownsDeformer) this.deformer.dispose();
  }
}

/**
 * The joint-level path's static table (weights criterion; layout.ts, tableTexelsPerSection): per
 * section its joints and weights (gcs_gcs_section_influences), then its centre of rotation
 * (gcs_gcs_section_centres).
 */
export function sectionTable(deformer: GcsDeformer): Float32Array {
  const influences = deformer.sectionInfluences(), centres = deformer.sectionCentres();
  if (!influences || !centres) throw new GcsError('INVALID_ARGUMENT', 'the joint-level table exists for the weights criterion only');
  const slots = deformer.sectionInfluenceSlots as TableSlots, perSection = 4 * tableTexelsPerSection(slots);
  const table = new Float32Array(deformer.sectionCount * perSection);
  for (let s = 0; s < deformer.sectionCount; s++) {
    table.set(influences.subarray(2 * slots * s, 2 * slots * (s + 1)), perSection * s);
    table.set(centres.subarray(4 * s, 4 * s + 4), perSection * s + 2 * slots);
  }
  return table;
}

/** Velocity: the per-frame texels as drawn the frame before, and their format. */
interface PreviousPoses {
  texture: THREE.DataTexture;
  /** The texels drawn this frame, shown by `texture` from the next. */
  drawn: Float32Array;
  frameId: number;
  /** Compact-capable sections: the previous frame's compact texture, its format uniform, and each full array's compact view (made once: no allocation per frame). */
  compactTexture: THREE.DataTexture | null;
  format: { value: number };
  drawnFormat: number;
  compactViews: Map<Float32Array, Float32Array> | null;
}

/**
 * The compact texture's size: instanceCount · J · COMPACT_FLOATS_PER_JOINT floats in RGBA texels,
 * at most `maxWidth` wide, its rows as even as they can be (less than a row of padding uploaded
 * with a crowd's last one).
 */
function compactSize(t: PoseTexels, maxWidth: number): { width: number; height: number; floats: number } {
  const texels = Math.ceil(t.instanceCount * t.jointCount * COMPACT_FLOATS_PER_JOINT / 4);
  const height = Math.ceil(texels / maxWidth), width = Math.ceil(texels / height);
  return { width, height, floats: width * height * 4 };
}

/** An RGBA32F texture read with texelFetch (nearest, no mipmaps). */
export function floatTexture(data: Float32Array, width: number, height: number): THREE.DataTexture {
  const texture = new THREE.DataTexture(data, width, height, THREE.RGBAFormat, THREE.FloatType);
  texture.minFilter = THREE.NearestFilter;
  texture.magFilter = THREE.NearestFilter;
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  return texture;
}

/** A static per-vertex attribute of the GPU backend's geometry. */
export interface SectionAttribute {
  /** The attribute's name in the geometry and the shader. */
  name: typeof SECTION_ATTRIBUTE | typeof BLEND_ATTRIBUTE | typeof BLEND_THIRD_ATTRIBUTE;
  /** Its values, one or more floats per vertex. */
  attribute: THREE.BufferAttribute;
}

/**
 * Static per-vertex section data of a GCS deformer's output mesh, as float attributes:
 * `gcsSection` (plain mode), or `gcsBlend` = (section, other section, factor) and `gcsBlendThird`
 * = (third section, factor) (smooth mode).
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function sectionAttributes(deformer: GcsDeformer): SectionAttribute[] {
  checkMethods(deformer, 'deformer', 'sectionAttributes', ['sectionOfVertex', 'blendOther', 'blendFactor', 'blendThird', 'blendThirdFactor']);
  const section = deformer.sectionOfVertex();
  const other = deformer.blendOther(), factor = deformer.blendFactor();
  const third = deformer.blendThird(), thirdFactor = deformer.blendThirdFactor();
  if (!other || !factor || !third || !thirdFactor) return [{ name: SECTION_ATTRIBUTE, attribute: new THREE.BufferAttribute(Float32Array.from(section), 1) }];
  const blend = new Float32Array(3 * section.length), blendThird = new Float32Array(2 * section.length);
  for (let o = 0; o < section.length; o++) {
    blend[3 * o] = section[o];
    blend[3 * o + 1] = other[o];
    blend[3 * o + 2] = factor[o];
    blendThird[2 * o] = third[o];
    blendThird[2 * o + 1] = thirdFactor[o];
  }
  return [
    { name: BLEND_ATTRIBUTE, attribute: new THREE.BufferAttribute(blend, 3) },
    { name: BLEND_THIRD_ATTRIBUTE, attribute: new THREE.BufferAttribute(blendThird, 2) },
  ];
}
