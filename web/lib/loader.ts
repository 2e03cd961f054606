// Instantiates the standalone gcs-skin.wasm (no emscripten JS glue) in node, vitest and browsers.
import { checkCoreExports } from './core-check.js';

/** Where to find the wasm binary: a URL or path, its bytes, or a compiled module. */
export type WasmSource = URL | string | ArrayBuffer | Uint8Array | WebAssembly.Module;

/** The raw exports of the core (see wasm/include/gcs_skin.h). Pointers are byte offsets. */
export interface CoreExports {
  memory: WebAssembly.Memory;
  _initialize(): void;
  gcs_version(): number;
  gcs_last_error_code(): number;
  gcs_last_error_message(): number;
  gcs_alloc(bytes: number): number;
  gcs_free(ptr: number): void;
  gcs_copy_bytes(dst: number, src: number, bytes: number): void;
  gcs_rig_create(pos: number, nrm: number, vc: number, idx: number, ic: number, joints: number,
    weights: number, influences: number, parents: number, ibm: number, jc: number): number;
  gcs_rig_destroy(rig: number): void;
  gcs_rig_vertex_count(rig: number): number;
  gcs_rig_joint_count(rig: number): number;
  gcs_rig_height(rig: number): number;
  gcs_build_gcs(rig: number, sections: number, criterion: number, width: number, smooth: number, twist: number, centres: number): number;
  gcs_build_lbs(rig: number): number;
  gcs_build_dqs(rig: number): number;
  gcs_build_classic(rig: number, contours: number, rays: number, bulge: number): number;
  gcs_deformer_destroy(d: number): void;
  gcs_deformer_kind(d: number): number;
  gcs_deformer_deform(d: number, skin: number, jointCount: number): number;
  gcs_deformer_set_morph_targets(d: number, deltas: number, normalDeltas: number, targets: number, vertices: number): number;
  gcs_deformer_set_morph_influences(d: number, influences: number, targets: number): number;
  gcs_deformer_set_tangents(d: number, tangents: number, vertices: number): number;
  gcs_deformer_tangents(d: number): number;
  gcs_deformer_keep_previous_positions(d: number, keep: number): number;
  gcs_deformer_previous_positions(d: number): number;
  gcs_deformer_vertex_count(d: number): number;
  gcs_deformer_positions(d: number): number;
  gcs_deformer_normals(d: number): number;
  gcs_deformer_index_count(d: number): number;
  gcs_deformer_indices(d: number): number;
  gcs_deformer_source_vertex(d: number): number;
  gcs_deformer_gather(d: number, source: number, sourceCount: number, strideBytes: number, itemBytes: number, out: number): number;
  gcs_deformer_stat(d: number, stat: number): number;
  gcs_gcs_section_of_vertex(d: number): number;
  gcs_gcs_section_info(d: number): number;
  gcs_gcs_section_matrices(d: number): number;
  gcs_gcs_blend_other(d: number): number;
  gcs_gcs_blend_factor(d: number): number;
  gcs_gcs_blend_third(d: number): number;
  gcs_gcs_blend_third_factor(d: number): number;
  gcs_gcs_compute_sections(d: number, skin: number, jointCount: number, instances: number, out: number): number;
  gcs_gcs_section_influences(d: number): number;
  gcs_gcs_section_influence_slots(d: number): number;
  gcs_gcs_section_centres(d: number): number;
  gcs_gcs_compute_joint_poses(d: number, skin: number, jointCount: number, instances: number, out: number): number;
  gcs_classic_set_bulge(d: number, bulge: number): number;
  gcs_classic_part_count(d: number): number;
  gcs_classic_parts(d: number): number;
  gcs_classic_contour_of_vertex(d: number): number;
  gcs_classic_source_of_vertex(d: number): number;
  gcs_classic_detail_loss(d: number, which: number): number;
}

const isNode = typeof process !== 'undefined' && !!process.versions?.node && typeof window === 'undefined';

async function readBytes(source: URL | string): Promise<ArrayBuffer | Uint8Array> {
  const url = typeof source === 'string' ? new URL(source, isNode ? `file://${process.cwd()}/` : location.href) : source;
  if (url.protocol === 'file:') {
    const fs = await import(/* @vite-ignore */ 'node:fs/promises');
    const { fileURLToPath } = await import(/* @vite-ignore */ 'node:url');
    return fs.readFile(fileURLToPath(url));
  }
  const response = await fetch(url);
  if (!response.ok) throw new Error(`HTTP ${response.status} for ${url}`);
  return response.arrayBuffer();
}

/** Compiles and instantiates the core. Throws a plain Error when the binary cannot be had. */
export async function instantiateCore(source?: WasmSource): Promise<CoreExports> {
  let module: WebAssembly.Module;
  if (source instanceof WebAssembly.Module) {
    module = source;
  } else if (source instanceof ArrayBuffer || source instanceof Uint8Array) {
    module = await WebAssembly.compile(source as BufferSource);
  } else {
    const bytes = await readBytes(source ?? new URL('./gcs-skin.wasm', import.meta.url));
    module = await WebAssembly.compile(bytes as BufferSource);
  }
  let exports: CoreExports | undefined;
  const imports = {
    // Memory growth is noticed lazily: every view is checked against memory.buffer before use.
    env: { emscripten_notify_memory_growth: () => {} },
    wasi_snapshot_preview1: {
      proc_exit: (code: number) => {
        throw new Error(`gcs-skin core aborted (exit ${code})`);
      },
    },
  };
  const instance = await WebAssembly.instantiate(module, imports);
  checkCoreExports(instance.exports);
  exports = unsignedResults(instance.exports as unknown as CoreExports);
  exports._initialize();
  return exports;
}

// Functions whose result is a pointer or a uint32 (tests/lib/boundary.test.ts checks the list
// against the header). wasm returns i32, which JavaScript reads as signed: above 2 GiB of memory a
// pointer would come back negative (and typed-array views on it throw RangeError). `>>> 0` reads it
// as the unsigned value the C API means.
export const UNSIGNED_RESULTS = [
  'gcs_version', 'gcs_last_error_message', 'gcs_alloc', 'gcs_rig_create', 'gcs_rig_vertex_count', 'gcs_rig_joint_count',
  'gcs_build_gcs', 'gcs_build_lbs', 'gcs_build_dqs', 'gcs_build_classic', 'gcs_deformer_kind',
  'gcs_deformer_vertex_count', 'gcs_deformer_positions', 'gcs_deformer_normals', 'gcs_deformer_tangents', 'gcs_deformer_previous_positions', 'gcs_deformer_index_count',
  'gcs_deformer_indices', 'gcs_deformer_source_vertex', 'gcs_gcs_section_of_vertex', 'gcs_gcs_section_info',
  'gcs_gcs_section_matrices', 'gcs_gcs_blend_other', 'gcs_gcs_blend_factor', 'gcs_gcs_blend_third', 'gcs_gcs_blend_third_factor', 'gcs_gcs_section_influences', 'gcs_gcs_section_influence_slots', 'gcs_gcs_section_centres', 'gcs_classic_part_count', 'gcs_classic_parts', 'gcs_classic_contour_of_vertex', 'gcs_classic_source_of_vertex',
] as const;

function unsignedResults(raw: CoreExports): CoreExports {
  const core = { ...raw } as CoreExports;
  const table = core as unknown as Record<string, (...args: number[]) => number>;
  const source = raw as unknown as Record<string, (...args: number[]) => number>;
  for (const name of UNSIGNED_RESULTS) {
    const f = source[name];
    table[name] = (...args: number[]) => f(...args) >>> 0;
  }
  return core;
}
