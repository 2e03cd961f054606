// The shapes glTF reading passes around: parsed JSON (nothing trusted) and a buffer's data.

/** glTF JSON, as parsed (nothing trusted). */
// eslint-disable-next-line @typescript-eslint/no-explicit-any
export type GltfJson = Record<string, any>;

/** How a buffer's data is had: its length, and where it came from for messages. */
export interface BufferData {
  /** Bytes the data has (a file's size, a data: URI's decoded length, the BIN chunk's length). */
  byteLength: number;
  /** The data itself, when the values some checks read (key times, sparse indices) can be read. */
  bytes?: Uint8Array;
  /** e.g. "the GLB's BIN chunk", "its file 'model.bin'", "its data: URI". */
  source: string;
}
