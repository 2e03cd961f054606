// GltfError: what is wrong with a glTF file, as a stable code and one sentence; and the number
// formatting its sentences share.

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
  | 'NO_SKINNED_MESH'; // loadCharacter (@gcs-skin/cli/gltf): the file has no skinned mesh

/** A glTF file that cannot be loaded, with a stable `code` and a one-line sentence. */
export class GltfError extends Error {
  /** What went wrong, stable across versions (docs/report-json.md, Errors). */
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

/** 1,234,567 */
export const n = (x: number) => x.toLocaleString('en-US');
export const plural = (x: number, one: string, many = one.endsWith('sh') ? `${one}es` : `${one}s`) => `${n(x)} ${x === 1 ? one : many}`;

/**
 * What a loader's failure says in a LOAD_FAILED sentence: the loader's own message, but never an
 * engine's (a TypeError or RangeError thrown inside a loader or decoder: "Invalid typed array
 * length: 50008" says nothing a user can act on).
 */
export function loaderFailure(e: unknown): string {
  if (e instanceof TypeError || e instanceof RangeError || e instanceof SyntaxError || e instanceof ReferenceError)
    return 'the loader failed inside on data the checks let through (please report the file)';
  const message = (e as Error)?.message;
  return typeof message === 'string' && message ? message.replace(/\s*\n\s*/g, ' ') : 'the loader failed without saying why';
}
