// A small validator of glTF 2.0 files, run on the bytes before @gltf-transform/core and three's
// GLTFLoader see them: by the CLI and the node API (gltf-node.ts) and by the demo page
// (web/demo/load-gltf.ts), through gltf-buffers.ts. Browser-safe: no node module. It is not the Khronos validator: it checks what
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
// - sparse indices below their accessor's count, increasing (read from the data: gltf-accessors.ts).

import { accessorReader, sparseReader } from './gltf-accessors.js';

/** What is wrong with a glTF file (docs/report-json.md, "Errors"). */
export type GltfErrorCode =
  | 'UNREADABLE'      // the file, or a buffer's external file, cannot be read
  | 'NOT_GLTF'        // neither binary glTF (magic 'glTF') nor a glTF 2.0 JSON document
  | 'TRUNCATED'       // shorter than its GLB header, or a buffer's data shorter than its byteLength
  | 'BAD_CONTAINER'   // GLB version or chunk layout wrong
  | 'BAD_JSON'        // the JSON (chunk) does not parse
  | 'BAD_STRUCTURE'   // a property of the wrong type or value (count, type, stride, matrix, …)
  | 'BAD_REFERENCE'   // an index to an object the file does not have
  | 'OUT_OF_BOUNDS'   // an accessor past its buffer view, a buffer view past its buffer
  | 'NODE_CYCLE'      // a node its own child or ancestor (joint hierarchies included)
  | 'NODE_HIERARCHY'  // a node with two parents, a scene root that is someone's child
  | 'BAD_SKIN'        // a skin or skinned node that cannot be skinned
  | 'UNSUPPORTED'     // a required extension the loader does not read (all but READ_EXTENSIONS)
  | 'TOO_LARGE'       // a count past its limit (LIMITS), or more data declared than the file's bytes can hold
  | 'BAD_URI'         // a buffer uri that does not decode (bad %-escape, malformed data: URI)
  | 'OUTSIDE_FOLDER'  // a buffer uri that leads out of the glTF's folder, or to something not a regular file
  | 'BAD_DATA'        // values that cannot be used: non-finite key times, sparse indices past the count
  | 'LOAD_FAILED'     // passed these checks but the loaders still failed (their message follows)
  | 'NO_SKINNED_MESH'; // loadCharacter (gcs-skin/gltf): the file has no skinned mesh

/** A glTF file that cannot be loaded, with a stable `code` and a one-line sentence. */
export class GltfError extends Error {
  readonly code: GltfErrorCode;
  /** The file as given. */
  readonly file: string;
  /** Where: a JSON path ("/nodes/3/children"), "byte N" in the file, or "" for the whole file. */
  readonly where: string;
  constructor(code: GltfErrorCode, file: string, where: string, message: string) {
    super(message);
    this.name = 'GltfError';
    this.code = code;
    this.file = file;
    this.where = where;
  }
}

/** glTF JSON, as parsed (nothing trusted). */
// eslint-disable-next-line @typescript-eslint/no-explicit-any
export type GltfJson = Record<string, any>;


/** A split glTF file: the JSON, and the GLB's BIN chunk if any. */
export interface GltfContainer {
  json: GltfJson;
  /** The BIN chunk of a .glb (undefined for a JSON .gltf or a GLB without one). */
  bin?: Uint8Array;
  glb: boolean;
}

/** The required extensions the loaders read (geometry decoded by gltf-node.ts and the demo; KTX2 textures by the demo, dropped in node); any other is UNSUPPORTED. */
export const READ_EXTENSIONS: readonly string[] = ['KHR_mesh_quantization', 'EXT_meshopt_compression', 'KHR_draco_mesh_compression', 'KHR_texture_basisu'];

const GLB_MAGIC = 0x46546c67; // 'glTF'
const CHUNK_JSON = 0x4e4f534a;
const CHUNK_BIN = 0x004e4942;

/**
 * What a file may declare, checked on the JSON before a loader allocates or loops over anything:
 * work and memory then grow with the bytes a file has, not with the counts its header claims.
 */
export const LIMITS = {
  /** Vertices of one primitive: the core's GCS_MAX_VERTICES (wasm/include/gcs_skin.h). */
  vertices: 16_777_216,
  /** Nodes: three makes an Object3D of each (skinned characters have hundreds). */
  nodes: 8_192,
  /** Entries of any other top-level array (accessors, meshes, animations, …) and of a mesh's primitives or an animation's channels. */
  items: 262_144,
  /** Depth of the node hierarchy: the loaders walk it recursively. */
  nodeDepth: 1_024,
  /** Nesting of the JSON (extras included): deeper would overflow the loaders' recursive copies. */
  jsonDepth: 128,
  /**
   * Bytes the loaders allocate for accessors and meshopt-decoded views: at most this floor plus
   * `expansion` × the bytes of buffer data the file has (accessors sharing a view, zero-filled
   * and sparse accessors, decompression: real files stay well under 4×).
   */
  expandedFloor: 32 * 2 ** 20,
  expansion: 16,
  /**
   * Vertices the nodes instance (a mesh used by several nodes counts once per node): at most this
   * many uses per vertex of the meshes used (skinned meshes), or `instancedFloor` in all (others:
   * a prop repeated many times).
   */
  instancing: 4,
  instancedFloor: 1_048_576,
} as const;

/** Nesting depth of a JSON value, counted iteratively up to `limit` + 1 (then it stops looking). */
export function nestingDepth(value: unknown, limit: number): number {
  let deepest = 0;
  const stack: [unknown, number][] = [[value, 1]];
  while (stack.length) {
    const [v, depth] = stack.pop()!;
    if (!v || typeof v !== 'object') continue;
    if (depth > deepest) deepest = depth;
    if (deepest > limit) return deepest;
    for (const child of Array.isArray(v) ? v : Object.values(v)) if (child && typeof child === 'object') stack.push([child, depth + 1]);
  }
  return deepest;
}

/** 1,234,567 */
export const n = (x: number) => x.toLocaleString('en-US');
const plural = (x: number, one: string, many = one.endsWith('sh') ? `${one}es` : `${one}s`) => `${n(x)} ${x === 1 ? one : many}`;

function looksLikeJson(bytes: Uint8Array): boolean {
  let i = 0;
  if (bytes[0] === 0xef && bytes[1] === 0xbb && bytes[2] === 0xbf) i = 3; // UTF-8 BOM
  while (i < bytes.length && (bytes[i] === 0x20 || bytes[i] === 0x09 || bytes[i] === 0x0a || bytes[i] === 0x0d)) i++;
  return bytes[i] === 0x7b; // '{'
}

function showBytes(bytes: Uint8Array, count = 4): string {
  const head = [...bytes.subarray(0, count)];
  const hex = head.map((b) => b.toString(16).padStart(2, '0')).join(' ');
  const text = head.map((b) => (b >= 0x20 && b < 0x7f ? String.fromCharCode(b) : '.')).join('');
  return `${hex} ('${text}')`;
}

function parseJsonText(bytes: Uint8Array, file: string, where: string, what: string): GltfJson {
  let text: string;
  try {
    text = new TextDecoder('utf-8', { fatal: true }).decode(bytes);
  } catch {
    throw new GltfError('BAD_JSON', file, where, `${what} is not UTF-8 text`);
  }
  let json: unknown;
  try {
    json = JSON.parse(text.replace(/^\uFEFF/, ''));
  } catch (e) {
    throw new GltfError('BAD_JSON', file, where, `${what} is not valid JSON (${(e as Error).message.replace(/\s*\n\s*/g, ' ')})`);
  }
  if (!json || typeof json !== 'object' || Array.isArray(json))
    throw new GltfError('NOT_GLTF', file, where, `${what} is not a JSON object, so not glTF`);
  const depth = nestingDepth(json, LIMITS.jsonDepth);
  if (depth > LIMITS.jsonDepth)
    throw new GltfError('TOO_LARGE', file, where, `${what} nests objects or arrays more than ${LIMITS.jsonDepth} deep, past any glTF (loaders would overflow their stack)`);
  return json as GltfJson;
}

/**
 * Splits the bytes of a .glb or .gltf into its JSON and BIN chunk, checking the GLB container.
 * Binary or JSON is decided by the content (magic 'glTF', or a JSON object), not the file name.
 */
export function parseGltfContainer(bytes: Uint8Array, file: string): GltfContainer {
  const size = bytes.byteLength;
  const magic = size >= 4 ? new DataView(bytes.buffer, bytes.byteOffset, 4).getUint32(0, true) : -1;
  if (magic !== GLB_MAGIC) {
    if (looksLikeJson(bytes)) return { json: parseJsonText(bytes, file, '', file), glb: false };
    if (size === 0) throw new GltfError('NOT_GLTF', file, '', `${file} is empty: not a glTF file`);
    throw new GltfError('NOT_GLTF', file, 'byte 0',
      `${file} is not a glTF file: it starts with ${showBytes(bytes)}, neither the binary glTF magic 'glTF' nor a JSON object`);
  }
  if (size < 12) throw new GltfError('TRUNCATED', file, 'byte 0', `${file} is truncated: it has ${plural(size, 'byte')}, fewer than the 12-byte binary glTF header`);
  const view = new DataView(bytes.buffer, bytes.byteOffset, size);
  const version = view.getUint32(4, true);
  if (version !== 2)
    throw new GltfError('BAD_CONTAINER', file, 'byte 4', `${file} is binary glTF version ${version}, not 2: only glTF 2.0 is read`);
  const total = view.getUint32(8, true);
  if (total > size) throw new GltfError('TRUNCATED', file, 'byte 8', `${file} is truncated: its header says ${n(total)} bytes but the file has ${n(size)}`);
  if (total < size)
    throw new GltfError('BAD_CONTAINER', file, 'byte 8',
      `${file} has ${plural(size - total, 'byte')} more than its header says: the header says ${n(total)} bytes but the file has ${n(size)}`);
  let json: GltfJson | undefined;
  let bin: Uint8Array | undefined;
  let offset = 12;
  for (let chunk = 0; offset < total; chunk++) {
    if (offset + 8 > total)
      throw new GltfError('BAD_CONTAINER', file, `byte ${offset}`,
        `${file} is not a valid binary glTF: chunk ${chunk} at byte ${n(offset)} has no room for its 8-byte header (the file ends at ${n(total)})`);
    const length = view.getUint32(offset, true);
    const type = view.getUint32(offset + 4, true);
    const name = type === CHUNK_JSON ? 'JSON' : type === CHUNK_BIN ? 'BIN' : `0x${type.toString(16).padStart(8, '0')}`;
    const start = offset + 8;
    if (start + length > total)
      throw new GltfError('BAD_CONTAINER', file, `byte ${offset}`,
        `${file} is not a valid binary glTF: its ${name} chunk (chunk ${chunk}, at byte ${n(offset)}) says ${n(length)} bytes but only ${n(total - start)} remain in the file`);
    const data = bytes.subarray(start, start + length);
    if (chunk === 0) {
      if (type !== CHUNK_JSON)
        throw new GltfError('BAD_CONTAINER', file, `byte ${offset}`, `${file} is not a valid binary glTF: its first chunk is of type ${name}, not JSON`);
      json = parseJsonText(data, file, `byte ${start}`, `the JSON chunk of ${file}`);
    } else if (type === CHUNK_JSON) {
      throw new GltfError('BAD_CONTAINER', file, `byte ${offset}`, `${file} is not a valid binary glTF: it has a second JSON chunk (chunk ${chunk}, at byte ${n(offset)})`);
    } else if (type === CHUNK_BIN) {
      if (chunk !== 1 || bin)
        throw new GltfError('BAD_CONTAINER', file, `byte ${offset}`, `${file} is not a valid binary glTF: its BIN chunk is chunk ${chunk}, not the second one`);
      bin = data;
    } // other chunk types: ignored, as the specification asks
    offset = start + length;
  }
  if (!json) throw new GltfError('BAD_CONTAINER', file, 'byte 12', `${file} is not a valid binary glTF: it has no JSON chunk`);
  return { json, bin, glb: true };
}

/** How a buffer's data is had: its length, and where it came from for messages. */
export interface BufferData {
  byteLength: number;
  /** The data itself, when the values some checks read (key times, sparse indices) can be read. */
  bytes?: Uint8Array;
  /** e.g. "the GLB's BIN chunk", "its file 'model.bin'", "its data: URI". */
  source: string;
}

const COMPONENT: Record<number, { name: string; size: number }> = {
  5120: { name: 'BYTE', size: 1 }, 5121: { name: 'UNSIGNED_BYTE', size: 1 }, 5122: { name: 'SHORT', size: 2 },
  5123: { name: 'UNSIGNED_SHORT', size: 2 }, 5125: { name: 'UNSIGNED_INT', size: 4 }, 5126: { name: 'FLOAT', size: 4 },
};
const TYPE_COMPONENTS: Record<string, number> = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };

/** Bytes of one element; matrix columns start on 4-byte boundaries (glTF 2.0 §3.6.2.4). */
function elementBytes(type: string, size: number): number {
  if (type === 'MAT2' && size === 1) return 8;
  if (type === 'MAT3' && size === 1) return 12;
  if (type === 'MAT3' && size === 2) return 24;
  return TYPE_COMPONENTS[type] * size;
}

const INTERPOLATIONS = ['LINEAR', 'STEP', 'CUBICSPLINE'];
const PATH_TYPES: Record<string, string> = { translation: 'VEC3', rotation: 'VEC4', scale: 'VEC3', weights: 'SCALAR' };
const TARGET_PATHS = Object.keys(PATH_TYPES);

const isIndex = (x: unknown): x is number => Number.isInteger(x) && (x as number) >= 0;
const isObject = (x: unknown): x is GltfJson => !!x && typeof x === 'object' && !Array.isArray(x);

/**
 * Checks the structure of glTF JSON against the data it has (`buffers[i]`: the data of buffer i,
 * or undefined when the buffer has no data to check, e.g. an extension's fallback buffer).
 * Throws the first GltfError found.
 */
export function validateGltfJson(json: GltfJson, file: string, buffers: (BufferData | undefined)[]): void {
  function fail(code: GltfErrorCode, where: string, what: string): never {
    throw new GltfError(code, file, where, `${file}: ${what}`);
  }
  const list = (name: string): GltfJson[] => {
    const a = json[name];
    if (a === undefined) return [];
    if (!Array.isArray(a)) fail('BAD_STRUCTURE', `/${name}`, `'${name}' is not an array`);
    const limit = name === 'nodes' ? LIMITS.nodes : LIMITS.items;
    if (a.length > limit) fail('TOO_LARGE', `/${name}`, `it has ${n(a.length)} ${name}, more than the ${n(limit)} this loader reads`);
    a.forEach((x: unknown, i: number) => { if (!isObject(x)) fail('BAD_STRUCTURE', `/${name}/${i}`, `${name}[${i}] is not an object`); });
    return a;
  };
  const named = (kind: string, i: number, def: GltfJson | undefined) =>
    typeof def?.name === 'string' && def.name ? `${kind} ${i} '${def.name}'` : `${kind} ${i}`;

  // asset and extensions
  const version = isObject(json.asset) ? json.asset.version : undefined;
  if (typeof version !== 'string')
    throw new GltfError('NOT_GLTF', file, '/asset/version', `${file} is not glTF: its JSON has no asset.version`);
  if (!/^2\./.test(version))
    throw new GltfError('NOT_GLTF', file, '/asset/version', `${file} is glTF ${version}, not 2.0: only glTF 2.0 is read`);
  const required = json.extensionsRequired;
  if (required !== undefined) {
    if (!Array.isArray(required)) fail('BAD_STRUCTURE', '/extensionsRequired', `'extensionsRequired' is not an array`);
    const unread = required.filter((x: unknown) => !READ_EXTENSIONS.includes(x as string));
    if (unread.length)
      throw new GltfError('UNSUPPORTED', file, '/extensionsRequired',
        `${file} requires the glTF extension${unread.length > 1 ? 's' : ''} ${unread.join(', ')}, which this loader does not read` +
        ` (it reads ${READ_EXTENSIONS.join(', ')})`);
  }

  const accessors = list('accessors'), bufferViews = list('bufferViews'), bufferDefs = list('buffers');
  const meshes = list('meshes'), nodes = list('nodes'), skins = list('skins'), scenes = list('scenes');
  const animations = list('animations'), materials = list('materials'), textures = list('textures');
  const images = list('images'), samplers = list('samplers'), cameras = list('cameras');

  /** Checks that `value` at `where` is an index into `array` (named `kind`), if present or required. */
  function ref(value: unknown, array: unknown[], kind: string, where: string, owner: string, required = false): void {
    if (value === undefined && !required) return;
    if (!isIndex(value)) fail('BAD_STRUCTURE', where, `${owner} refers to ${kind} ${JSON.stringify(value) ?? 'undefined'}, not an index`);
    if (value >= array.length)
      fail('BAD_REFERENCE', where, `${owner} refers to ${kind} ${value}, but the file has ${array.length ? `only ${plural(array.length, kind)}` : `no ${kind}`}`);
  }

  // Where each accessor is used, for messages.
  const use: string[] = [];
  const noteUse = (a: unknown, what: string) => { if (isIndex(a) && use[a] === undefined) use[a] = what; };
  meshes.forEach((m, mi) => {
    if (!Array.isArray(m.primitives)) return;
    m.primitives.forEach((p: GltfJson, pi: number) => {
      if (!isObject(p)) return;
      const where = `${named('mesh', mi, m)} primitive ${pi}`;
      if (isObject(p.attributes)) for (const [k, a] of Object.entries(p.attributes)) noteUse(a, `${k} of ${where}`);
      noteUse(p.indices, `indices of ${where}`);
    });
  });
  skins.forEach((s, si) => noteUse(s.inverseBindMatrices, `inverse bind matrices of ${named('skin', si, s)}`));
  animations.forEach((a, ai) => {
    if (Array.isArray(a.samplers)) a.samplers.forEach((s: GltfJson, i: number) => {
      if (!isObject(s)) return;
      noteUse(s.input, `times of ${named('animation', ai, a)} sampler ${i}`);
      noteUse(s.output, `values of ${named('animation', ai, a)} sampler ${i}`);
    });
  });
  const accessorName = (i: number) => `accessor ${i}${use[i] ? ` (${use[i]})` : ''}`;

  // buffers
  bufferDefs.forEach((b, i) => {
    const where = `/buffers/${i}`;
    if (!isIndex(b.byteLength)) fail('BAD_STRUCTURE', `${where}/byteLength`, `buffer ${i}'s byteLength is ${JSON.stringify(b.byteLength)}, not a whole number`);
    const data = buffers[i];
    if (data && b.byteLength > data.byteLength)
      throw new GltfError('TRUNCATED', file, where,
        `${file} is truncated: buffer ${i} says ${n(b.byteLength)} bytes but ${data.source} has ${n(data.byteLength)}`);
  });

  // buffer views
  bufferViews.forEach((v, i) => {
    const where = `/bufferViews/${i}`;
    ref(v.buffer, bufferDefs, 'buffer', `${where}/buffer`, `buffer view ${i}`, true);
    const offset = v.byteOffset ?? 0;
    if (!isIndex(offset)) fail('BAD_STRUCTURE', `${where}/byteOffset`, `buffer view ${i}'s byteOffset is ${JSON.stringify(offset)}, not a whole number`);
    if (!isIndex(v.byteLength) || v.byteLength < 1)
      fail('BAD_STRUCTURE', `${where}/byteLength`, `buffer view ${i}'s byteLength is ${JSON.stringify(v.byteLength)}, not a whole number ≥ 1`);
    if (v.byteStride !== undefined && (!Number.isInteger(v.byteStride) || v.byteStride < 4 || v.byteStride > 252))
      fail('BAD_STRUCTURE', `${where}/byteStride`, `buffer view ${i}'s byteStride is ${JSON.stringify(v.byteStride)}, not a whole number from 4 to 252`);
    const meshopt = v.extensions?.EXT_meshopt_compression;
    if (meshopt !== undefined) {
      // The compressed bytes: inside their buffer; decoded, count × byteStride bytes, inside this view.
      const mw = `${where}/extensions/EXT_meshopt_compression`;
      if (!isObject(meshopt)) fail('BAD_STRUCTURE', mw, `the EXT_meshopt_compression of buffer view ${i} is not an object`);
      ref(meshopt.buffer, bufferDefs, 'buffer', `${mw}/buffer`, `the compressed data of buffer view ${i}`, true);
      const mo = meshopt.byteOffset ?? 0;
      for (const [key, value] of [['byteOffset', mo], ['byteLength', meshopt.byteLength], ['byteStride', meshopt.byteStride], ['count', meshopt.count]] as const)
        if (!isIndex(value)) fail('BAD_STRUCTURE', `${mw}/${key}`, `the compressed data of buffer view ${i} has ${key} ${JSON.stringify(value)}, not a whole number`);
      const data = buffers[meshopt.buffer];
      const have = data ? Math.min(data.byteLength, bufferDefs[meshopt.buffer].byteLength) : bufferDefs[meshopt.buffer].byteLength;
      if (mo + meshopt.byteLength > have)
        fail('OUT_OF_BOUNDS', mw,
          `the compressed data of buffer view ${i} (bytes ${n(mo)} to ${n(mo + meshopt.byteLength)} of buffer ${meshopt.buffer}) goes past the end of its buffer, which has ${n(have)} bytes`);
      if (meshopt.count * meshopt.byteStride > v.byteLength)
        fail('OUT_OF_BOUNDS', mw,
          `buffer view ${i} decompresses to ${plural(meshopt.count, 'element')} of ${n(meshopt.byteStride)} bytes, more than its byteLength ${n(v.byteLength)}`);
    }
    const size = bufferDefs[v.buffer].byteLength;
    if (offset + v.byteLength > size)
      fail('OUT_OF_BOUNDS', where,
        `buffer view ${i} (bytes ${n(offset)} to ${n(offset + v.byteLength)} of buffer ${v.buffer}) goes past the end of its buffer, which has ${n(size)} bytes`);
  });

  // accessors
  /** Checks that `count` elements of `bytes` each, `stride` apart from `offset`, fit in buffer view `bv`. */
  const fits = (where: string, what: string, bv: number, offset: number, count: number, bytes: number, stride: number) => {
    const need = offset + stride * (count - 1) + bytes;
    const have = bufferViews[bv].byteLength;
    if (need > have)
      fail('OUT_OF_BOUNDS', where,
        `${what} has count ${n(count)}, too many for buffer view ${bv}: ${plural(count, 'element')} of ${n(bytes)} bytes` +
        `${stride !== bytes ? `, ${n(stride)} apart,` : ''} from byte ${n(offset)} need ${n(need)} bytes but the view has ${n(have)}`);
  };
  accessors.forEach((a, i) => {
    const where = `/accessors/${i}`;
    const name = accessorName(i);
    const component = COMPONENT[a.componentType];
    if (!component) fail('BAD_STRUCTURE', `${where}/componentType`, `${name} has componentType ${JSON.stringify(a.componentType)}, not a glTF component type`);
    if (!(a.type in TYPE_COMPONENTS)) fail('BAD_STRUCTURE', `${where}/type`, `${name} has type ${JSON.stringify(a.type)}, not SCALAR, VEC2-4 or MAT2-4`);
    if (!isIndex(a.count) || a.count < 1) fail('BAD_STRUCTURE', `${where}/count`, `${name} has count ${JSON.stringify(a.count)}, not a whole number ≥ 1`);
    const offset = a.byteOffset ?? 0;
    if (!isIndex(offset)) fail('BAD_STRUCTURE', `${where}/byteOffset`, `${name} has byteOffset ${JSON.stringify(offset)}, not a whole number`);
    const bytes = elementBytes(a.type, component.size);
    if (a.bufferView !== undefined) {
      ref(a.bufferView, bufferViews, 'buffer view', `${where}/bufferView`, name);
      const stride = bufferViews[a.bufferView].byteStride ?? bytes;
      if (stride < bytes)
        fail('BAD_STRUCTURE', where, `${name} has ${n(bytes)}-byte elements but buffer view ${a.bufferView}'s byteStride is ${stride}`);
      fits(where, name, a.bufferView, offset, a.count, bytes, stride);
    } else if (offset !== 0) {
      fail('BAD_STRUCTURE', `${where}/byteOffset`, `${name} has a byteOffset but no buffer view`);
    }
    if (a.sparse !== undefined) {
      const s = a.sparse;
      const sw = `${where}/sparse`;
      if (!isObject(s) || !isObject(s.indices) || !isObject(s.values)) fail('BAD_STRUCTURE', sw, `the sparse part of ${name} lacks indices or values`);
      if (!isIndex(s.count) || s.count < 1 || s.count > a.count)
        fail('BAD_STRUCTURE', `${sw}/count`, `the sparse count of ${name} is ${JSON.stringify(s.count)}, not from 1 to its count ${n(a.count)}`);
      const ic = COMPONENT[s.indices.componentType];
      if (![5121, 5123, 5125].includes(s.indices.componentType))
        fail('BAD_STRUCTURE', `${sw}/indices/componentType`, `the sparse indices of ${name} have componentType ${JSON.stringify(s.indices.componentType)}, not an unsigned integer type`);
      for (const [part, size] of [['indices', ic.size], ['values', bytes]] as const) {
        const p = s[part];
        ref(p.bufferView, bufferViews, 'buffer view', `${sw}/${part}/bufferView`, `the sparse ${part} of ${name}`, true);
        const po = p.byteOffset ?? 0;
        if (!isIndex(po)) fail('BAD_STRUCTURE', `${sw}/${part}/byteOffset`, `the sparse ${part} of ${name} have byteOffset ${JSON.stringify(po)}, not a whole number`);
        fits(`${sw}/${part}`, `the sparse ${part} of ${name}`, p.bufferView, po, s.count, size, size);
      }
    }
  });

  // What the loaders will allocate (accessors, sparse parts, meshopt-decoded views), against the data the file has.
  let present = 0;
  bufferDefs.forEach((b, i) => { if (buffers[i]) present += Math.min(b.byteLength, buffers[i]!.byteLength); });
  let expanded = 0, largest = -1, largestBytes = 0;
  accessors.forEach((a, i) => {
    const size = elementBytes(a.type, COMPONENT[a.componentType].size);
    const bytes = a.count * size + (a.sparse ? a.sparse.count * (size + COMPONENT[a.sparse.indices.componentType].size) : 0);
    expanded += bytes;
    if (bytes > largestBytes) { largest = i; largestBytes = bytes; }
  });
  for (const v of bufferViews) if (v.extensions?.EXT_meshopt_compression) expanded += v.byteLength;
  const allowed = LIMITS.expandedFloor + LIMITS.expansion * present;
  if (expanded > allowed)
    fail('TOO_LARGE', largest >= 0 ? `/accessors/${largest}` : '/bufferViews',
      `its accessors declare ${n(expanded)} bytes of data${largest >= 0 ? ` (the largest, ${accessorName(largest)}, ${plural(accessors[largest].count, 'element')})` : ''}` +
      ` but the file has ${n(present)} bytes of buffer data: more than ${n(LIMITS.expandedFloor)} + ${LIMITS.expansion} × its data, refused before loading`);

  // Sparse indices: below the accessor's count and increasing (else the loaders write past their arrays or skip values).
  accessors.forEach((a, i) => {
    const sparse = sparseReader(json, buffers, a);
    if (!sparse) return;
    for (let k = 0, previous = -1; k < sparse.count; k++) {
      const index = sparse.index(k);
      if (index >= a.count)
        fail('BAD_DATA', `/accessors/${i}/sparse/indices`, `sparse index ${k} of ${accessorName(i)} is ${n(index)}, past its count ${n(a.count)}`);
      if (index <= previous)
        fail('BAD_DATA', `/accessors/${i}/sparse/indices`, `the sparse indices of ${accessorName(i)} do not increase: index ${k} is ${n(index)} after ${n(previous)}`);
      previous = index;
    }
  });

  // meshes
  meshes.forEach((m, mi) => {
    const mesh = named('mesh', mi, m);
    if (!Array.isArray(m.primitives) || !m.primitives.length) fail('BAD_STRUCTURE', `/meshes/${mi}/primitives`, `${mesh} has no primitives`);
    if (m.primitives.length > LIMITS.items)
      fail('TOO_LARGE', `/meshes/${mi}/primitives`, `${mesh} has ${n(m.primitives.length)} primitives, more than the ${n(LIMITS.items)} this loader reads`);
    m.primitives.forEach((p: GltfJson, pi: number) => {
      const where = `/meshes/${mi}/primitives/${pi}`;
      const prim = `${mesh} primitive ${pi}`;
      if (!isObject(p) || !isObject(p.attributes)) fail('BAD_STRUCTURE', where, `${prim} has no attributes`);
      let first: [string, number] | undefined;
      for (const [k, a] of Object.entries(p.attributes)) {
        ref(a, accessors, 'accessor', `${where}/attributes/${k}`, `${prim}'s ${k}`, true);
        const count = accessors[a as number].count;
        if (!first) {
          first = [k, count];
          if (count > LIMITS.vertices)
            fail('TOO_LARGE', `${where}/attributes/${k}`, `${prim} has ${plural(count, 'vertex', 'vertices')}, more than the ${n(LIMITS.vertices)} gcs-skin takes`);
        }
        else if (count !== first[1])
          fail('BAD_STRUCTURE', `${where}/attributes/${k}`,
            `${prim}'s ${k} (accessor ${a}) has ${plural(count, 'element')} but its ${first[0]} has ${n(first[1])}: every attribute has one per vertex`);
      }
      ref(p.indices, accessors, 'accessor', `${where}/indices`, `${prim}'s indices`);
      const draco = p.extensions?.KHR_draco_mesh_compression;
      if (draco !== undefined) {
        const dw = `${where}/extensions/KHR_draco_mesh_compression`;
        if (!isObject(draco) || !isObject(draco.attributes)) fail('BAD_STRUCTURE', dw, `the KHR_draco_mesh_compression of ${prim} has no attributes`);
        ref(draco.bufferView, bufferViews, 'buffer view', `${dw}/bufferView`, `the Draco data of ${prim}`, true);
        for (const [k, id] of Object.entries(draco.attributes)) {
          if (!isIndex(id)) fail('BAD_STRUCTURE', `${dw}/attributes/${k}`, `the Draco attribute id of ${prim}'s ${k} is ${JSON.stringify(id)}, not a whole number`);
          if (p.attributes[k] === undefined)
            fail('BAD_STRUCTURE', `${dw}/attributes/${k}`, `${prim} has Draco data for ${k} but no ${k} attribute`);
        }
      }
      ref(p.material, materials, 'material', `${where}/material`, prim);
      if (p.targets !== undefined) {
        if (!Array.isArray(p.targets)) fail('BAD_STRUCTURE', `${where}/targets`, `${prim}'s morph targets are not an array`);
        p.targets.forEach((t: GltfJson, ti: number) => {
          if (!isObject(t)) fail('BAD_STRUCTURE', `${where}/targets/${ti}`, `${prim}'s morph target ${ti} is not an object`);
          for (const [k, a] of Object.entries(t)) ref(a, accessors, 'accessor', `${where}/targets/${ti}/${k}`, `${prim}'s morph target ${ti} ${k}`, true);
        });
      }
    });
  });

  // nodes: references and transforms
  const numbers = (x: unknown, length: number) => Array.isArray(x) && x.length === length && x.every((v) => typeof v === 'number' && Number.isFinite(v));
  nodes.forEach((d, i) => {
    const where = `/nodes/${i}`;
    const node = named('node', i, d);
    ref(d.mesh, meshes, 'mesh', `${where}/mesh`, node);
    ref(d.skin, skins, 'skin', `${where}/skin`, node);
    ref(d.camera, cameras, 'camera', `${where}/camera`, node);
    if (d.children !== undefined) {
      if (!Array.isArray(d.children)) fail('BAD_STRUCTURE', `${where}/children`, `the children of ${node} are not an array`);
      d.children.forEach((c: unknown, k: number) => ref(c, nodes, 'node', `${where}/children/${k}`, `child ${k} of ${node}`, true));
    }
    for (const [key, length] of [['matrix', 16], ['translation', 3], ['rotation', 4], ['scale', 3]] as const)
      if (d[key] !== undefined && !numbers(d[key], length))
        fail('BAD_STRUCTURE', `${where}/${key}`, `the ${key} of ${node} is not ${length} finite numbers`);
  });

  // Instances: every node using a mesh repeats its work in the loaders (an object per node and
  // primitive) and, skinned, in whatever builds deformers on it (the report, the demo).
  const meshVertices = meshes.map((m) => (m.primitives as GltfJson[]).reduce((sum, p) => {
    const first = Object.values(p.attributes)[0];
    return sum + (first === undefined ? 0 : accessors[first as number].count);
  }, 0));
  const used = new Set<number>(), skinnedUsed = new Set<number>();
  let instanced = 0, skinnedInstanced = 0;
  for (const d of nodes) {
    if (d.mesh === undefined) continue;
    used.add(d.mesh);
    instanced += meshVertices[d.mesh];
    if (d.skin !== undefined) { skinnedUsed.add(d.mesh); skinnedInstanced += meshVertices[d.mesh]; }
  }
  const distinct = (set: Set<number>) => [...set].reduce((sum, m) => sum + meshVertices[m], 0);
  if (skinnedInstanced > LIMITS.instancing * distinct(skinnedUsed))
    fail('TOO_LARGE', '/nodes',
      `its skinned nodes instance ${n(skinnedInstanced)} vertices from meshes of ${n(distinct(skinnedUsed))}: more than ${LIMITS.instancing} uses per skinned mesh vertex`);
  if (instanced > Math.max(LIMITS.instancing * distinct(used), LIMITS.instancedFloor))
    fail('TOO_LARGE', '/nodes',
      `its nodes instance ${n(instanced)} vertices from meshes of ${n(distinct(used))}: more than ${LIMITS.instancing} uses per vertex (or ${n(LIMITS.instancedFloor)} in all)`);

  // the node graph
  const nodeName = (i: number) => named('node', i, nodes[i]);
  const children = nodes.map((d) => (d.children ?? []) as number[]);
  children.forEach((cs, i) => {
    const seen = new Set<number>();
    cs.forEach((c, k) => {
      if (c === i) fail('NODE_CYCLE', `/nodes/${i}/children/${k}`, `${nodeName(i)} is its own child (a cycle in the node hierarchy)`);
      if (seen.has(c)) fail('NODE_HIERARCHY', `/nodes/${i}/children`, `${nodeName(i)} lists ${nodeName(c)} twice among its children`);
      seen.add(c);
    });
  });
  const jointOf = new Map<number, number[]>();
  skins.forEach((s, si) => {
    if (Array.isArray(s.joints)) for (const j of s.joints) if (isIndex(j)) jointOf.set(j, [...(jointOf.get(j) ?? []), si]);
  });
  const cycle = findCycle(children);
  if (cycle) {
    const shown = cycle.length > 9 ? [...cycle.slice(0, 4), -1, ...cycle.slice(-4)] : cycle;
    const path = [...shown, cycle[0]].map((i) => (i < 0 ? '…' : nodeName(i))).join(' → ');
    const skinsIn = [...new Set(cycle.flatMap((i) => jointOf.get(i) ?? []))];
    const joints = skinsIn.length ? ` (joints of ${skinsIn.map((si) => named('skin', si, skins[si])).join(', ')})` : '';
    fail('NODE_CYCLE', `/nodes/${cycle[0]}/children`, `the node hierarchy has a cycle: ${path}${joints}`);
  }
  const parent = new Array<number>(nodes.length).fill(-1);
  children.forEach((cs, i) => cs.forEach((c) => {
    if (parent[c] >= 0)
      fail('NODE_HIERARCHY', `/nodes/${i}/children`,
        `${nodeName(c)} has two parents, ${nodeName(parent[c])} and ${nodeName(i)}: a glTF node has at most one`);
    parent[c] = i;
  }));

  // Depth of the hierarchy (acyclic by now): each node's is its parent's + 1, walked from each root down.
  const depth = new Int32Array(nodes.length);
  for (let r = 0; r < nodes.length; r++) {
    if (parent[r] >= 0) continue;
    const stack = [r];
    depth[r] = 1;
    while (stack.length) {
      const v = stack.pop()!;
      if (depth[v] > LIMITS.nodeDepth)
        fail('TOO_LARGE', `/nodes/${v}`, `the node hierarchy is more than ${n(LIMITS.nodeDepth)} levels deep (at ${nodeName(v)}), past what the loaders walk`);
      for (const c of children[v]) { depth[c] = depth[v] + 1; stack.push(c); }
    }
  }

  // scenes
  ref(json.scene, scenes, 'scene', '/scene', 'the file');
  scenes.forEach((s, si) => {
    const where = `/scenes/${si}/nodes`;
    if (s.nodes === undefined) return;
    if (!Array.isArray(s.nodes)) fail('BAD_STRUCTURE', where, `the nodes of ${named('scene', si, s)} are not an array`);
    s.nodes.forEach((r: unknown, k: number) => {
      ref(r, nodes, 'node', `${where}/${k}`, named('scene', si, s), true);
      if (parent[r as number] >= 0)
        fail('NODE_HIERARCHY', `${where}/${k}`,
          `${named('scene', si, s)} lists ${nodeName(r as number)} as a root, but it is a child of ${nodeName(parent[r as number])}`);
    });
  });

  // skins and skinned nodes
  skins.forEach((s, si) => {
    const where = `/skins/${si}`;
    const skin = named('skin', si, s);
    if (!Array.isArray(s.joints) || !s.joints.length) fail('BAD_SKIN', `${where}/joints`, `${skin} has no joints`);
    const seen = new Set<number>();
    s.joints.forEach((j: unknown, k: number) => {
      ref(j, nodes, 'node', `${where}/joints/${k}`, `joint ${k} of ${skin}`, true);
      if (seen.has(j as number)) fail('BAD_SKIN', `${where}/joints/${k}`, `${skin} lists ${nodeName(j as number)} twice among its joints (joints ${s.joints.indexOf(j)} and ${k})`);
      seen.add(j as number);
    });
    ref(s.skeleton, nodes, 'node', `${where}/skeleton`, `the skeleton of ${skin}`);
    if (s.inverseBindMatrices !== undefined) {
      ref(s.inverseBindMatrices, accessors, 'accessor', `${where}/inverseBindMatrices`, `the inverse bind matrices of ${skin}`);
      const a = accessors[s.inverseBindMatrices];
      if (a.type !== 'MAT4' || a.componentType !== 5126)
        fail('BAD_SKIN', `${where}/inverseBindMatrices`,
          `the inverse bind matrices of ${skin} (accessor ${s.inverseBindMatrices}) are ${a.type} of ${COMPONENT[a.componentType].name}, not MAT4 of FLOAT`);
      if (a.count < s.joints.length)
        fail('BAD_SKIN', `${where}/inverseBindMatrices`,
          `${skin} has ${plural(s.joints.length, 'joint')} but ${plural(a.count, 'inverse bind matrix', 'inverse bind matrices')} (accessor ${s.inverseBindMatrices})`);
    }
  });
  nodes.forEach((d, i) => {
    if (d.skin === undefined) return;
    const skin = named('skin', d.skin, skins[d.skin]);
    if (d.mesh === undefined) fail('BAD_SKIN', `/nodes/${i}/skin`, `${nodeName(i)} has ${skin} but no mesh to skin`);
    const m = meshes[d.mesh];
    m.primitives.forEach((p: GltfJson, pi: number) => {
      const missing = ['JOINTS_0', 'WEIGHTS_0'].filter((k) => p.attributes[k] === undefined);
      if (missing.length)
        fail('BAD_SKIN', `/meshes/${d.mesh}/primitives/${pi}/attributes`,
          `${nodeName(i)} has ${skin} but its ${named('mesh', d.mesh, m)} primitive ${pi} has no ${missing.join(' or ')} attribute: no vertex says which joints move it`);
    });
  });

  /**
   * Key times (accessor `ai`, FLOAT) finite, from 0 on and never decreasing (three's interpolants
   * search them in order: a time going back plays wrong poses silently), where readable.
   */
  const checkTimes = (ai: number, where: string, what: string) => {
    const a = accessors[ai];
    const dense = accessorReader(json, buffers, a), sparse = sparseReader(json, buffers, a);
    const bad = (k: number, t: number, why: string) =>
      fail('BAD_DATA', where, `key ${n(k)} of ${what} (accessor ${ai}) is at time ${t}: ${why}`);
    if (sparse) for (let k = 0; k < sparse.count; k++) { const t = sparse.value(k, 0); if (!Number.isFinite(t)) bad(sparse.index(k), t, 'key times are finite seconds'); }
    if (!dense || sparse) return; // the order of sparse-patched times is left to the loaders
    let previous = 0;
    for (let k = 0; k < a.count; k++) {
      const t = dense(k, 0);
      if (!Number.isFinite(t)) bad(k, t, 'key times are finite seconds');
      if (t < previous) bad(k, t, k ? `before key ${n(k - 1)} at ${previous}: key times never go back` : 'key times start at 0 or later');
      previous = t;
    }
  };
  /** Animated values (accessor `ai`) all finite where they are floats and readable. */
  const checkValues = (ai: number, where: string, what: string) => {
    const a = accessors[ai];
    const read = a.componentType === 5126 && !a.sparse ? accessorReader(json, buffers, a) : null;
    if (!read) return;
    const size = TYPE_COMPONENTS[a.type];
    for (let k = 0; k < a.count; k++)
      for (let c = 0; c < size; c++) {
        const v = read(k, c);
        if (!Number.isFinite(v)) fail('BAD_DATA', where, `value ${n(k)} of ${what} (accessor ${ai}) is ${v}: animated values are finite`);
      }
  };

  // animations
  animations.forEach((a, ai) => {
    const where = `/animations/${ai}`;
    const anim = named('animation', ai, a);
    const ss = Array.isArray(a.samplers) ? a.samplers : fail('BAD_STRUCTURE', `${where}/samplers`, `${anim} has no samplers array`);
    if (!Array.isArray(a.channels)) fail('BAD_STRUCTURE', `${where}/channels`, `${anim} has no channels array`);
    for (const [key, length] of [['samplers', ss.length], ['channels', a.channels.length]] as const)
      if (length > LIMITS.items) fail('TOO_LARGE', `${where}/${key}`, `${anim} has ${n(length)} ${key}, more than the ${n(LIMITS.items)} this loader reads`);
    ss.forEach((s: GltfJson, i: number) => {
      const sw = `${where}/samplers/${i}`;
      if (!isObject(s)) fail('BAD_STRUCTURE', sw, `sampler ${i} of ${anim} is not an object`);
      ref(s.input, accessors, 'accessor', `${sw}/input`, `the input of sampler ${i} of ${anim}`, true);
      ref(s.output, accessors, 'accessor', `${sw}/output`, `the output of sampler ${i} of ${anim}`, true);
      if (s.interpolation !== undefined && !INTERPOLATIONS.includes(s.interpolation))
        fail('BAD_STRUCTURE', `${sw}/interpolation`, `sampler ${i} of ${anim} has interpolation ${JSON.stringify(s.interpolation)}, not ${INTERPOLATIONS.join(', ')}`);
      const input = accessors[s.input];
      if (input.type !== 'SCALAR' || input.componentType !== 5126)
        fail('BAD_STRUCTURE', `${sw}/input`, `the key times of sampler ${i} of ${anim} (accessor ${s.input}) are ${input.type} of ${COMPONENT[input.componentType].name}, not SCALAR of FLOAT`);
      checkTimes(s.input, `${sw}/input`, `sampler ${i} of ${anim}`);
      checkValues(s.output, `${sw}/output`, `sampler ${i} of ${anim}`);
    });
    a.channels.forEach((c: GltfJson, i: number) => {
      if (!isObject(c) || !isObject(c.target)) fail('BAD_STRUCTURE', `${where}/channels/${i}`, `channel ${i} of ${anim} has no target`);
      ref(c.sampler, ss, 'sampler', `${where}/channels/${i}/sampler`, `channel ${i} of ${anim}`, true);
      ref(c.target.node, nodes, 'node', `${where}/channels/${i}/target/node`, `channel ${i} of ${anim}`);
      if (!TARGET_PATHS.includes(c.target.path))
        fail('BAD_STRUCTURE', `${where}/channels/${i}/target/path`,
          `channel ${i} of ${anim} animates ${JSON.stringify(c.target.path) ?? 'nothing'}, not ${TARGET_PATHS.join(', ')}`);
      // The values must be what the path takes, one per key (three per key for CUBICSPLINE: in-tangent,
      // value, out-tangent; weights: one per morph target): three's interpolants read them by stride, and
      // a rotation fed 3-vectors makes its mixer loop forever.
      const sampler = ss[c.sampler], input = accessors[sampler.input], output = accessors[sampler.output];
      const perKey = sampler.interpolation === 'CUBICSPLINE' ? 3 : 1;
      const type = PATH_TYPES[c.target.path as string];
      const sw = `${where}/samplers/${c.sampler}/output`;
      if (output.type !== type)
        fail('BAD_STRUCTURE', sw, `channel ${i} of ${anim} animates ${c.target.path} with ${output.type} values (accessor ${sampler.output}), not ${type}`);
      const keys = input.count * perKey;
      if (c.target.path === 'weights' ? output.count % keys !== 0 : output.count !== keys)
        fail('BAD_STRUCTURE', sw,
          `channel ${i} of ${anim} has ${plural(input.count, 'key')} but ${plural(output.count, 'value')} (accessor ${sampler.output}): ` +
          `${c.target.path === 'weights' ? 'a multiple of ' : ''}${n(keys)} expected${perKey > 1 ? ' (CUBICSPLINE: 3 per key)' : ''}`);
    });
  });

  // textures, images, materials (loaded then dropped, but a bad index would crash the loader)
  images.forEach((im, i) => ref(im.bufferView, bufferViews, 'buffer view', `/images/${i}/bufferView`, `image ${i}`));
  textures.forEach((t, i) => {
    ref(t.source, images, 'image', `/textures/${i}/source`, `texture ${i}`);
    ref(t.sampler, samplers, 'sampler', `/textures/${i}/sampler`, `texture ${i}`);
  });
  materials.forEach((m, i) => {
    const infos: [string, unknown][] = [
      ['normalTexture', m.normalTexture], ['occlusionTexture', m.occlusionTexture], ['emissiveTexture', m.emissiveTexture],
      ['pbrMetallicRoughness/baseColorTexture', m.pbrMetallicRoughness?.baseColorTexture],
      ['pbrMetallicRoughness/metallicRoughnessTexture', m.pbrMetallicRoughness?.metallicRoughnessTexture],
    ];
    for (const [key, info] of infos)
      if (info !== undefined) {
        if (!isObject(info)) fail('BAD_STRUCTURE', `/materials/${i}/${key}`, `the ${key} of ${named('material', i, m)} is not an object`);
        ref(info.index, textures, 'texture', `/materials/${i}/${key}/index`, `the ${key} of ${named('material', i, m)}`, true);
      }
  });
}

/** A cycle of the directed graph `children` (as a list of nodes, each the parent of the next), or null. Iterative. */
export function findCycle(children: readonly (readonly number[])[]): number[] | null {
  const state = new Uint8Array(children.length); // 0 unseen, 1 on the current path, 2 done
  for (let root = 0; root < children.length; root++) {
    if (state[root]) continue;
    const path = [root], next = [0];
    state[root] = 1;
    while (path.length) {
      const v = path[path.length - 1];
      const k = next[next.length - 1]++;
      if (k >= children[v].length) {
        state[v] = 2;
        path.pop();
        next.pop();
        continue;
      }
      const c = children[v][k];
      if (state[c] === 1) return path.slice(path.indexOf(c));
      if (state[c] === 0) {
        state[c] = 1;
        path.push(c);
        next.push(0);
      }
    }
  }
  return null;
}
