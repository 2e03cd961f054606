/**
 * The glTF reader's browser-safe half, shared by the command line (@gcs-skin/cli) and the demo:
 * a GLB/glTF container sniffed and parsed, its buffers gathered and the whole JSON validated
 * against the reader's limits before any loader sees it, errors as GltfError with a code, and
 * names made safe to print. No node module and no three.js; the readers of compressed meshes
 * (gltf-transform, draco, meshopt) are @gcs-skin/cli's.
 *
 *   const { json, buffers } = await readValidatedGltf(bytes, 'model.glb', readExternal);
 *
 * This face checks its arguments (GcsError INVALID_ARGUMENT / OUT_OF_RANGE) before the readers
 * in gltf/ run, which trust their callers inside the library.
 *
 * @module gcs-skin/gltf
 */
import type * as THREE from 'three';
import { checkCount, checkFinite, checkFunction, checkList, checkMethods, checkObject, checkString } from './arguments.js';
import { asGiven, GcsError } from './errors.js';
import * as accessors from './gltf/accessors.js';
import * as buffers from './gltf/buffers.js';
import * as container from './gltf/container.js';
import * as errors from './gltf/error.js';
import type { BufferData, GltfJson } from './gltf/json.js';
import * as names from './gltf/shown-name.js';

export type { ExternalReader, ValidatedGltf } from './gltf/buffers.js';
export { GltfError, loaderFailure, type GltfErrorCode } from './gltf/error.js';
export type { BufferData, GltfJson } from './gltf/json.js';
export { LIMITS, READ_EXTENSIONS } from './gltf/limits.js';

/** Bytes: a Uint8Array. */
function checkBytes(value: unknown, name: string, fn: string): void {
  if (!(value instanceof Uint8Array)) throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be a Uint8Array; got ${asGiven(value)}`);
}

/**
 * Splits and validates the bytes of a .glb or .gltf (`file` names it in messages), reading its
 * external buffers through `external` (null: bytes with no folder, so a buffer in a file of its
 * own is an UNREADABLE error).
 * @throws GltfError for anything wrong in the file; GcsError `INVALID_ARGUMENT` for arguments of the wrong kind.
 */
export async function readValidatedGltf(bytes: Uint8Array, file: string, external: buffers.ExternalReader | null): Promise<buffers.ValidatedGltf> {
  checkBytes(bytes, 'bytes', 'readValidatedGltf');
  checkString(file, 'file', 'readValidatedGltf');
  if (external !== null) checkFunction(external, 'external', 'readValidatedGltf');
  return buffers.readValidatedGltf(bytes, file, external);
}

/**
 * A buffer's relative URI as a path inside the .gltf's folder (percent-decoded).
 * @throws GltfError `UNREADABLE` for a path that leaves the folder or is not relative; GcsError `INVALID_ARGUMENT` for arguments of the wrong kind.
 */
export function decodeBufferPath(uri: string, file: string, i: number): string {
  checkString(uri, 'uri', 'decodeBufferPath');
  checkString(file, 'file', 'decodeBufferPath');
  checkCount(i, 'i', 'decodeBufferPath', 2 ** 31);
  return buffers.decodeBufferPath(uri, file, i);
}

/**
 * Whether `head` (the first bytes of a file of `size` bytes) starts as a glTF does.
 * @throws GltfError when it starts as something else; GcsError `INVALID_ARGUMENT` for arguments of the wrong kind.
 */
export function sniffGltf(head: Uint8Array, size: number, file: string): boolean {
  checkBytes(head, 'head', 'sniffGltf');
  checkCount(size, 'size', 'sniffGltf', Number.MAX_SAFE_INTEGER);
  checkString(file, 'file', 'sniffGltf');
  return container.sniffGltf(head, size, file);
}

/**
 * The vertices of each skinned primitive ("mesh/primitive") whose weights are all zero, read before
 * a loader binds them to the first joint.
 * @throws GcsError `INVALID_ARGUMENT` for arguments of the wrong kind.
 */
export function zeroWeightVertices(json: GltfJson, data: readonly (BufferData | undefined)[]): Map<string, number[]> {
  checkObject(json, 'json', 'zeroWeightVertices');
  checkList(data, 'buffers', 'zeroWeightVertices');
  return accessors.zeroWeightVertices(json, data);
}

/**
 * Gives the vertices of `zeroWeights` their all-zero weights back after three's GLTFLoader bound
 * them to the first joint (`associations`: the loader parser's map from objects to their glTF mesh
 * and primitive).
 * @throws GcsError `INVALID_ARGUMENT` for arguments of the wrong kind.
 */
export function restoreZeroWeights(
  meshes: readonly THREE.SkinnedMesh[], associations: Map<object, { meshes?: number; primitives?: number }>, zeroWeights: Map<string, number[]>,
): void {
  checkList(meshes, 'meshes', 'restoreZeroWeights');
  if (!(associations instanceof Map)) throw new GcsError('INVALID_ARGUMENT', `restoreZeroWeights: associations must be a Map; got ${asGiven(associations)}`);
  if (!(zeroWeights instanceof Map)) throw new GcsError('INVALID_ARGUMENT', `restoreZeroWeights: zeroWeights must be a Map; got ${asGiven(zeroWeights)}`);
  if (zeroWeights.size) for (const mesh of meshes) checkMethods((mesh as { geometry?: unknown } | null)?.geometry, 'a mesh\'s geometry', 'restoreZeroWeights', ['getAttribute']);
  accessors.restoreZeroWeights(meshes, associations, zeroWeights);
}

/**
 * A number with thousands separators, as messages show counts.
 * @throws GcsError `INVALID_ARGUMENT` for a value that is not a finite number.
 */
export function n(x: number): string {
  checkFinite(x, 'x', 'n');
  return errors.n(x);
}

/**
 * `s` with control and format characters shown as escapes: safe to print on a terminal or a page.
 * @throws GcsError `INVALID_ARGUMENT` for a value that is not a string.
 */
export function printable(s: string): string {
  checkString(s, 's', 'printable');
  return names.printable(s);
}

/**
 * A name as messages show it: printable, at most `max` characters (an ellipsis where cut).
 * @throws GcsError `INVALID_ARGUMENT` for a value that is not a string, or a bad `max`.
 */
export function shownName(s: string, max?: number): string {
  checkString(s, 's', 'shownName');
  if (max !== undefined) checkCount(max, 'max', 'shownName', 2 ** 20, 1);
  return names.shownName(s, max);
}
