// The bytes of a .glb or .gltf split into JSON and BIN chunk, the GLB container and the JSON
// text checked (magic, version, lengths, chunk order, UTF-8, syntax, nesting depth).
import { GltfError, n, plural } from './error.js';
import type { GltfJson } from './json.js';
import { LIMITS } from './limits.js';

/** A split glTF file: the JSON, and the GLB's BIN chunk if any. */
export interface GltfContainer {
  json: GltfJson;
  /** The BIN chunk of a .glb (undefined for a JSON .gltf or a GLB without one). */
  bin?: Uint8Array;
  glb: boolean;
}

const GLB_MAGIC = 0x46546c67; // 'glTF'
const CHUNK_JSON = 0x4e4f534a;
const CHUNK_BIN = 0x004e4942;

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
