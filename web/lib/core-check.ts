// What the wrapper checks of a wasm module before it calls into it, and the sentences it loads
// with: a module that is not gcs-skin's, or whose load failed, is told in our words, never the
// engine's ("exports._initialize is not a function").
import { VERSION, versionNumber } from './version.js';

/** Every function gcs_skin.h declares (tests/lib/hostile-exports.test.ts checks this list against the header). */
export const CORE_FUNCTIONS = [
  'gcs_alloc', 'gcs_build_classic', 'gcs_build_dqs', 'gcs_build_gcs', 'gcs_build_lbs', 'gcs_classic_contour_of_vertex',
  'gcs_classic_detail_loss', 'gcs_classic_part_count', 'gcs_classic_parts', 'gcs_classic_set_bulge', 'gcs_classic_source_of_vertex',
  'gcs_copy_bytes', 'gcs_deformer_deform', 'gcs_deformer_destroy', 'gcs_deformer_gather', 'gcs_deformer_index_count',
  'gcs_deformer_indices', 'gcs_deformer_keep_previous_positions', 'gcs_deformer_kind', 'gcs_deformer_normals',
  'gcs_deformer_positions', 'gcs_deformer_previous_positions', 'gcs_deformer_set_morph_influences',
  'gcs_deformer_set_morph_targets', 'gcs_deformer_set_tangents', 'gcs_deformer_source_vertex', 'gcs_deformer_stat',
  'gcs_deformer_tangents', 'gcs_deformer_vertex_count', 'gcs_free', 'gcs_gcs_blend_factor', 'gcs_gcs_blend_other',
  'gcs_gcs_blend_third', 'gcs_gcs_blend_third_factor', 'gcs_gcs_compute_joint_poses', 'gcs_gcs_compute_joint_poses_compact', 'gcs_gcs_compute_sections',
  'gcs_gcs_section_centres', 'gcs_gcs_section_influence_slots', 'gcs_gcs_section_influences', 'gcs_gcs_section_info',
  'gcs_gcs_section_matrices', 'gcs_gcs_section_of_vertex', 'gcs_heap_in_use', 'gcs_last_error_code', 'gcs_last_error_message', 'gcs_rig_create',
  'gcs_rig_destroy', 'gcs_rig_height', 'gcs_rig_joint_count', 'gcs_rig_vertex_count', 'gcs_version',
] as const;

/** A load failure in our words (initGcsSkin wraps it as GcsError 'WASM_LOAD'). */
export class CoreLoadError extends Error {}

/**
 * Refuses, before anything is called, a module that lacks what the wrapper uses: its memory,
 * `_initialize` and every gcs_* function (a module built from other sources, or another program).
 */
export function checkCoreExports(exports: WebAssembly.Exports): void {
  if (!(exports.memory instanceof WebAssembly.Memory))
    throw new CoreLoadError('the module exports no memory: it is not gcs-skin.wasm');
  const missing = ['_initialize', ...CORE_FUNCTIONS].filter((name) => typeof exports[name] !== 'function');
  // Another version may have other functions: initGcsSkin then says which version it is.
  const version = exports.gcs_version;
  if (missing.length && typeof version === 'function' && version() !== versionNumber(VERSION)) return;
  if (missing.length)
    throw new CoreLoadError(`the module lacks ${missing.length === 1 ? 'the export' : `${missing.length} exports, first`} '${missing[0]}': it is not gcs-skin.wasm (or from a version with other functions)`);
}

/** Where a load failed, as our sentence (the engine's own wording is left out). */
export function loadFailure(error: unknown): string {
  if (error instanceof CoreLoadError) return error.message;
  const message = (error as Error)?.message;
  if (typeof message === 'string' && /^HTTP \d+ for /.test(message)) return message; // the loader's own (a failed fetch)
  if (error instanceof WebAssembly.CompileError) return 'the bytes are not a WebAssembly module (they do not compile)';
  if (error instanceof WebAssembly.LinkError) return 'the module imports what gcs-skin does not provide: it is not gcs-skin.wasm';
  if (error instanceof WebAssembly.RuntimeError) return 'the module failed while starting: it is not gcs-skin.wasm, or it is damaged';
  const code = (error as { code?: unknown })?.code;
  if (code === 'ENOENT') return 'the file does not exist';
  if (typeof code === 'string') return `the file cannot be read (${code})`;
  return 'the binary could not be fetched or read';
}

/** The kinds of `wasm` initGcsSkin takes: refused by type before anything is read. */
export function checkWasmSource(source: unknown): void {
  if (source === undefined || typeof source === 'string' || source instanceof URL || source instanceof ArrayBuffer
    || source instanceof Uint8Array || source instanceof WebAssembly.Module) return;
  throw new CoreLoadError('wasm must be a URL, a path, an ArrayBuffer, a Uint8Array or a WebAssembly.Module');
}
