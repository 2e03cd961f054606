// A small validator of glTF 2.0 files, run on the bytes before @gltf-transform/core and three's
// GLTFLoader see them: by the CLI and the node API (packages/cli/src/gltf-node.ts) and by the demo page
// (web/demo/load-gltf.ts), through buffers.ts. Browser-safe: no node module. It is not the Khronos validator: it checks what
// would otherwise crash those loaders with a message about their internals ("Invalid typed array
// length", "Offset is outside the bounds of the DataView", "Maximum call stack size exceeded"),
// be read as something else (a wrong magic read as JSON), or be silently repaired (a node with two
// parents re-parented). Every failure is a GltfError: a `code`, the file, `where` (a JSON path such
// as "/accessors/3", or a byte offset) and one sentence naming the file, what is wrong and where.
// The codes are listed in docs/report-json.md ("Errors").
//
// Checked:
// - the GLB container: the 12-byte header (magic 'glTF', version 2, total length = file size), the
//   chunks (8-byte headers, lengths inside the file, JSON first, at most one BIN);
// - the JSON: syntax, asset.version 2.x, no required extension but the three compression ones the
//   loader decodes (KHR_mesh_quantization, EXT_meshopt_compression, KHR_draco_mesh_compression),
//   whose own references (compressed buffer views, Draco attribute ids) are checked too;
// - buffers: the declared byteLength against the data (BIN chunk, data: URI or external file);
// - buffer views inside their buffers, accessors (count, type, componentType, byte stride, sparse
//   parts) inside their buffer views;
// - references between objects (accessor → buffer view, node → mesh/skin/children, …) exist;
// - mesh primitives: attributes of one count;
// - the node graph: no node its own child, no cycle, one parent at most, scene roots are roots;
// - skins: joints non-empty, unique, existing nodes (their hierarchy is the node graph's, acyclic
//   by the above); inverse bind matrices MAT4 FLOAT, one per joint; a skinned node has a mesh whose
//   every primitive has JOINTS_0 and WEIGHTS_0;
// - animations: samplers' times SCALAR FLOAT, finite, from 0, never going back; values finite, of
//   the path's type, one per key; interpolation and target paths known;
// - the limits (LIMITS), before anything is allocated: counts of objects, vertices, hierarchy and
//   JSON depth, and the bytes the loaders would allocate against the bytes the file has;
// - sparse indices below their accessor's count, increasing (read from the data: accessors.ts).
//
// One checker per collection (check-*.ts) over a shared ValidationContext, run in the order below:
// each may rely on what the ones before it checked (a reference resolved, the graph acyclic).
import { checkAnimations } from './check-animations.js';
import { checkAccessors, checkBuffers, checkBufferViews, checkDeclaredBytes, checkSparseIndices } from './check-data.js';
import { checkMaterials, checkMeshes } from './check-meshes.js';
import { checkInstancing, checkNodeGraph, checkNodes, checkScenes, checkSkins } from './check-nodes.js';
import { GltfError } from './error.js';
import type { BufferData, GltfJson } from './json.js';
import { READ_EXTENSIONS } from './limits.js';
import { shownName } from './shown-name.js';
import { isObject, ValidationContext } from './validation-context.js';

/**
 * Checks the structure of glTF JSON against the data it has (`buffers[i]`: the data of buffer i,
 * or undefined when the buffer has no data to check, e.g. an extension's fallback buffer).
 * Throws the first GltfError found.
 */
export function validateGltfJson(json: GltfJson, file: string, buffers: (BufferData | undefined)[]): void {
  checkAsset(json, file);
  const ctx = new ValidationContext(json, file, buffers);
  checkBuffers(ctx);
  checkBufferViews(ctx);
  checkAccessors(ctx);
  checkDeclaredBytes(ctx);
  checkSparseIndices(ctx);
  checkMeshes(ctx);
  checkNodes(ctx);
  checkInstancing(ctx);
  checkNodeGraph(ctx);
  checkScenes(ctx);
  checkSkins(ctx);
  checkAnimations(ctx);
  checkMaterials(ctx);
}

/** asset.version 2.x, and no required extension but those the loader reads. */
function checkAsset(json: GltfJson, file: string): void {
  const version = isObject(json.asset) ? json.asset.version : undefined;
  if (typeof version !== 'string')
    throw new GltfError('NOT_GLTF', file, '/asset/version', `${file} is not glTF: its JSON has no asset.version`);
  if (!/^2\./.test(version))
    throw new GltfError('NOT_GLTF', file, '/asset/version', `${file} is glTF ${version}, not 2.0: only glTF 2.0 is read`);
  const required = json.extensionsRequired;
  if (required !== undefined) {
    if (!Array.isArray(required)) throw new GltfError('BAD_STRUCTURE', file, '/extensionsRequired', `${file}: 'extensionsRequired' is not an array`);
    const unread = required.filter((x: unknown) => !READ_EXTENSIONS.includes(x as string));
    if (unread.length)
      throw new GltfError('UNSUPPORTED', file, '/extensionsRequired',
        // The first one named (capped and escaped: the names are the file's), the list of ours short: one line.
        `${file} requires the glTF extension ${shownName(String(unread[0]))}${unread.length > 1 ? ` and ${unread.length - 1} more` : ''}, ` +
        'which this loader does not read (it reads quantization, meshopt, Draco, KTX2)');
  }
}
