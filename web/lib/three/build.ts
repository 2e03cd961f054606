// The build transaction of a SkinDeformer: prepareBuild makes the next deformer and the geometry
// around it without showing them; SkinDeformer.commit shows one, discardBuild frees one never shown
// (GcsCharacter.rebuild prepares every skin before it commits any: all or nothing).
import * as THREE from 'three';
import { asGiven, GcsError } from '../errors.js';
import { ClassicDeformer, type ClassicOptions, type Deformer, type DeformerKind, type GcsDeformer, type GcsOptions, type Rig } from '../index.js';
import { transferSurfaceAttributes } from '../surface-attributes.js';
import { bindGeometry, identitySkin, influenceAttributes, remapAttribute, SKINNING_ATTRIBUTES, type VertexAttribute } from '../gpu/bind.js';
import { rigInputFromSkinnedMesh } from './rig-input.js';
import { disposeGpuMaterials, type GpuMaterialKit, type GpuMaterials } from '../gpu/kit.js';
import type { GpuPath } from '../gpu/layout.js';
import { GpuSections } from '../gpu/sections.js';
import { keepAttributeLive } from './live-views.js';
import { morphData } from './morph-data.js';
import type { Backend, RebuildOptions, SkinDeformerOptions } from './options.js';

/** A deformer and the geometry around it, built but not yet shown (rebuilds are all-or-nothing). */
export interface PendingBuild {
  method: DeformerKind;
  gcs: GcsOptions;
  classic: ClassicOptions;
  deformer: Deformer;
  geometry: THREE.BufferGeometry;
  /** Per morph target, the largest delta length; null without morphs. */
  maxDelta: Float32Array | null;
  /** The GPU backend's state, or null (CPU). */
  gpu: GpuBuild | null;
  /** Why 'gpu' was asked for and 'cpu' runs, or ''. */
  note: string;
  /** The backend asked for. */
  backend: Backend;
  /** The GPU path asked for. */
  gpuPath: GpuPath | 'auto';
}

/** The GPU backend of one build: section texture, patched materials, the geometry raycasts test. */
export interface GpuBuild {
  sections: GpuSections;
  materials: GpuMaterials;
  raycast: THREE.BufferGeometry;
  /** LBS / DQS: each vertex's joints and weights (static attributes); null for GCS. */
  influences: VertexAttribute[] | null;
}

/** What a build reads of its SkinDeformer (nothing here is changed by a build). */
export interface BuildSource {
  readonly source: THREE.SkinnedMesh;
  readonly rig: Rig;
  /** The source's tangents (xyz, w) in its vertex order, handed to each CPU build's deformer; null without or 'drop'. */
  readonly tangents: Float32Array | null;
  /** The options of the current build (what `options` of prepareBuild do not change). */
  readonly options: SkinDeformerOptions;
  /** The material drawn by the CPU backend. */
  readonly baseMaterial: THREE.Material | THREE.Material[];
  readonly kit: GpuMaterialKit;
  /** The output mesh (its current material decides multi-material groups). */
  readonly mesh: THREE.Mesh;
  /** The bounds every geometry of the skin shares (updated per frame by the deformer). */
  readonly box: THREE.Box3;
  readonly sphere: THREE.Sphere;
}

/** Builds the next deformer and its geometry without showing them; on a failure nothing is left allocated. */
export function prepareBuild(from: BuildSource, method: DeformerKind, options: RebuildOptions = {}): PendingBuild {
  const gcsOptions = { ...from.options.gcs, ...options.gcs };
  const classicOptions = { ...from.options.classic, ...options.classic };
  const backend = options.backend ?? from.options.backend ?? 'cpu';
  if (backend !== 'cpu' && backend !== 'gpu') throw new GcsError('INVALID_ARGUMENT', `backend must be 'cpu' or 'gpu'; got ${asGiven(backend)}`);
  const note = backend === 'gpu' ? gpuUnsupported(from, method) : '';
  const onGpu = backend === 'gpu' && !note;
  const gpuPath = options.gpuPath ?? from.options.gpuPath ?? 'auto';
  if (gpuPath !== 'auto' && gpuPath !== 'joints' && gpuPath !== 'sections')
    throw new GcsError('INVALID_ARGUMENT', `gpuPath must be 'auto', 'joints' or 'sections'; got ${asGiven(gpuPath)}`);
  const build = (rig: Rig) => method === 'gcs' ? rig.buildGcs(gcsOptions)
    : method === 'classic' ? rig.buildClassic(classicOptions) : rig.build(method);
  const deformer = build(from.rig);
  let gpu: GpuBuild | null = null;
  try {
    const keepsVertices = deformer.keepsVertices;
    const morph = method === 'classic' ? null : morphData(from.source.geometry);
    if (morph) deformer.setMorphTargets(morph.positions, morph.normals);
    if (onGpu) {
      gpu = prepareGpu(from, deformer, method, gpuPath === 'auto' ? undefined : gpuPath);
      const geometry = makeGeometry(from, deformer, keepsVertices, gpu);
      return { method, gcs: gcsOptions, classic: classicOptions, deformer, geometry, maxDelta: morph?.maxDelta ?? null, gpu, note, backend, gpuPath };
    }
    // The same deform call turns them (the classic model resamples and takes none).
    if (from.tangents && keepsVertices) deformer.setTangents(from.tangents);
    const geometry = makeGeometry(from, deformer, keepsVertices, null);
    return { method, gcs: gcsOptions, classic: classicOptions, deformer, geometry, maxDelta: morph?.maxDelta ?? null, gpu: null, note, backend, gpuPath };
  } catch (e) {
    if (gpu) disposeGpu(gpu);
    deformer.dispose();
    throw e;
  }
}

/** Frees a prepared build that will not be shown. */
export function discardBuild(next: PendingBuild): void {
  if (next.gpu) disposeGpu(next.gpu);
  next.deformer.dispose();
  next.geometry.dispose();
}

/** Frees a GPU build: its wasm buffers, texture, GCS materials and raycast geometry. */
export function disposeGpu(gpu: GpuBuild): void {
  gpu.sections.dispose();
  disposeGpuMaterials(gpu.materials);
  gpu.raycast.dispose();
}

/** Why this build cannot run on the GPU, or ''. */
function gpuUnsupported(from: BuildSource, method: DeformerKind): string {
  if (!from.kit.methods.has(method)) return `the GPU backend of ${from.kit.entry} runs ${[...from.kit.methods].map((m) => `'${m}'`).join(', ')}; '${method}' runs on the CPU`;
  for (const m of Array.isArray(from.baseMaterial) ? from.baseMaterial : [from.baseMaterial]) {
    const reason = from.kit.support(m);
    if (reason) return reason;
  }
  return '';
}

/**
 * The per-frame texture (joint poses or section transforms) and the GCS materials of a GPU build.
 * LBS and DQS: the joint poses (of a GCS build of the same rig, kept for them alone) and each
 * vertex's joints and weights; the vertex stage blends them.
 */
function prepareGpu(from: BuildSource, deformer: Deformer, method: DeformerKind, path?: GpuPath): GpuBuild {
  let sections: GpuSections, influences: VertexAttribute[] | null = null;
  if (method === 'lbs' || method === 'dqs') {
    const skin = influenceAttributes(rigInputFromSkinnedMesh(from.source), deformer.sourceVertex!);
    influences = skin.attributes;
    const poses = from.rig.buildGcs({ sections: 3, smooth: false });
    try {
      sections = new GpuSections(poses, 1, 2048, 'joints', { method, slots: skin.slots });
    } catch (e) {
      poses.dispose();
      throw e;
    }
  } else {
    sections = new GpuSections(deformer as GcsDeformer, 1, 2048, path);
  }
  const materials = from.kit.build(from.baseMaterial, sections, null);
  const raycast = new THREE.BufferGeometry();
  raycast.setIndex(new THREE.BufferAttribute(deformer.indices, 1));
  raycast.setAttribute('position', keepAttributeLive(new THREE.BufferAttribute(deformer.positions, 3), deformer, 'positions'));
  raycast.boundingBox = from.box;
  raycast.boundingSphere = from.sphere;
  return { sections, materials, raycast, influences };
}

/** The output geometry of a build: the deformer's buffers (CPU) or the bind pose with section data (GPU), and the source's other attributes. */
function makeGeometry(from: BuildSource, deformer: Deformer, keepsVertices: boolean, gpu: GpuBuild | null): THREE.BufferGeometry {
  const src = from.source.geometry;
  const indices = deformer.indices;
  let geometry: THREE.BufferGeometry;
  if (gpu) {
    // The bind pose, uploaded once, with the section data; three.js morphs in the shader, before GCS.
    geometry = bindGeometry(deformer, from.rig.jointCount, src, { tangents: from.options.tangents !== 'drop', morphs: true }, gpu.influences ?? undefined);
  } else {
    geometry = new THREE.BufferGeometry();
    geometry.setIndex(new THREE.BufferAttribute(indices, 1));
    geometry.setAttribute('position', keepAttributeLive(new THREE.BufferAttribute(deformer.positions, 3).setUsage(THREE.DynamicDrawUsage), deformer, 'positions'));
    geometry.setAttribute('normal', keepAttributeLive(new THREE.BufferAttribute(deformer.normals, 3).setUsage(THREE.DynamicDrawUsage), deformer, 'normals'));
    if (keepsVertices) {
      for (const [name, attr] of Object.entries(src.attributes))
        if (!SKINNING_ATTRIBUTES.has(name)) geometry.setAttribute(name, remapAttribute(attr, deformer));
      // The deformer's own tangent output (xyz turned, w carried), drawn in place like positions.
      const tangents = deformer.tangents;
      if (tangents) geometry.setAttribute('tangent', keepAttributeLive(new THREE.BufferAttribute(tangents, 4).setUsage(THREE.DynamicDrawUsage), deformer, 'tangents'));
    } else if (deformer instanceof ClassicDeformer) {
      // Resampled: the source's uv, colours and custom attributes from the closest source point.
      deformer.deform(identitySkin(from.rig.jointCount));
      transferSurfaceAttributes(src, geometry, deformer.positions, deformer.sourceOfVertex, SKINNING_ATTRIBUTES);
    }
  }
  // Groups (multi-material) and the draw range count index entries: they carry over when the
  // deformer kept the triangles in order (GCS, LBS, DQS remap vertex ids only; checked here).
  // (Checked only when there are groups, a draw range or several materials: a slider drag rebuilds
  // every frame, and the check reads every index.)
  const ranged = src.groups.length > 0 || src.drawRange.start !== 0 || src.drawRange.count !== Infinity || Array.isArray(from.mesh.material);
  let sameOrder = keepsVertices;
  if (keepsVertices && ranged) {
    const sourceVertex = deformer.sourceVertex!; // a copy: read only here (a slider drag rebuilds every frame)
    const srcIndex = src.index;
    if (srcIndex && indices.length !== srcIndex.count) sameOrder = false;
    const order = srcIndex?.array; // an index attribute is never interleaved
    for (let i = 0; i < indices.length && sameOrder; i++)
      sameOrder = sourceVertex[indices[i]] === (order ? order[i] : i);
  }
  if (sameOrder) {
    for (const g of src.groups) geometry.addGroup(g.start, g.count, g.materialIndex);
    geometry.setDrawRange(src.drawRange.start, src.drawRange.count);
  } else if (Array.isArray(from.mesh.material)) {
    geometry.addGroup(0, Infinity, 0); // resampled triangles: the first material for all
  }
  geometry.boundingBox = from.box;
  geometry.boundingSphere = from.sphere;
  return geometry;
}
