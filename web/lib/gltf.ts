/**
 * The glTF reader's browser-safe half, shared by the command line (@gcs-skin/cli) and the demo:
 * a GLB/glTF container sniffed and parsed, its buffers gathered and the whole JSON validated
 * against the reader's limits before any loader sees it, errors as GltfError with a code, and
 * names made safe to print. No node module and no three.js; the readers of compressed meshes
 * (gltf-transform, draco, meshopt) are @gcs-skin/cli's.
 *
 *   const { json, buffers } = await readValidatedGltf(bytes, 'model.glb', readExternal);
 *
 * @module gcs-skin/gltf
 */
export { readValidatedGltf, decodeBufferPath, type ExternalReader, type ValidatedGltf } from './gltf/buffers.js';
export { restoreZeroWeights, zeroWeightVertices } from './gltf/accessors.js';
export { sniffGltf } from './gltf/container.js';
export { GltfError, loaderFailure, n, type GltfErrorCode } from './gltf/error.js';
export type { BufferData, GltfJson } from './gltf/json.js';
export { LIMITS, READ_EXTENSIONS } from './gltf/limits.js';
export { printable, shownName } from './gltf/shown-name.js';
