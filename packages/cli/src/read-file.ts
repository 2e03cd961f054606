// Every file the command line and the node API read (a model, its external buffers) is read here,
// the same guarded way: opened non-blocking (a FIFO never waits for a writer), its type checked on
// the open handle before a byte is read (only regular files: FIFOs, devices, sockets and
// directories are refused), its size checked against the caller's limit before it is read, and
// at most the bytes needed: first a head for the caller to sniff (a file that is not glTF costs
// 64 KiB however large it is), then the rest, never past the limit. Standard input, by any of its
// names ('-', /dev/stdin, /dev/fd/0), is read as bytes, up to the same limit.
import { constants, type Stats } from 'node:fs';
import { open } from 'node:fs/promises';
import { resolve } from 'node:path';

/** The paths that name standard input: '-' and the system's names for file descriptor 0. */
const STANDARD_INPUT = new Set(['/dev/stdin', '/dev/fd/0', '/proc/self/fd/0']);

/** Whether `path` names standard input ('-', /dev/stdin, /dev/fd/0, /proc/self/fd/0, however written): read it with readStandardInput. */
export function namesStandardInput(path: string): boolean {
  return path === '-' || STANDARD_INPUT.has(resolve(path));
}

/** Why a file was not read: 'type' (not a regular file), 'size' (past the limit) or 'io' (the system's error). */
export class FileRefused extends Error {
  constructor(readonly kind: 'type' | 'size' | 'io', message: string, readonly size = 0) {
    super(message);
    this.name = 'FileRefused';
  }
}

/** Bytes read first, for the caller's sniff. */
const HEAD_BYTES = 64 * 1024;

/** "a directory", "a FIFO (named pipe)", … */
function kindOf(stat: Stats): string {
  if (stat.isDirectory()) return 'a directory';
  if (stat.isFIFO()) return 'a FIFO (named pipe)';
  if (stat.isCharacterDevice()) return 'a character device';
  if (stat.isBlockDevice()) return 'a block device';
  if (stat.isSocket()) return 'a socket';
  return 'not a regular file';
}

/** The system's error as a few words. */
export function systemReason(e: unknown): string {
  const err = e as NodeJS.ErrnoException;
  const known: Record<string, string> = {
    ENOENT: 'no such file', EISDIR: 'it is a directory', EACCES: 'permission denied', EPERM: 'permission denied',
    ENOTDIR: 'a part of its path is not a folder', ELOOP: 'a link loop, or a link where none may be', ENXIO: 'no reader or device behind it',
    ENOSPC: 'no space left on the device', EROFS: 'a read-only file system', EMFILE: 'too many open files', ENAMETOOLONG: 'its name is too long',
  };
  return (err?.code && known[err.code]) || String(err?.message ?? e).replace(/\s*\n\s*/g, ' ');
}

export interface ReadOptions {
  /** Bytes the file may have: a larger one is refused ('size') before it is read. */
  maxBytes: number;
  /** Read at most this many bytes of a larger file instead of refusing it (a buffer read up to its declared byteLength). */
  truncateAt?: number;
  /** Refuse a symbolic link at the last step of `path` (the caller resolved links itself). */
  noFollow?: boolean;
  /** Called with the first bytes and the file's size before the rest is read; throws to stop there. */
  sniff?: (head: Uint8Array, size: number) => void;
}

/** The bytes of the regular file at `path`, read as ReadOptions says. Throws FileRefused. */
export async function readRegularFile(path: string, options: ReadOptions): Promise<Uint8Array> {
  const flags = constants.O_RDONLY | constants.O_NONBLOCK | (options.noFollow ? constants.O_NOFOLLOW : 0);
  const handle = await open(path, flags).catch((e) => { throw new FileRefused('io', systemReason(e)); });
  try {
    const stat = await handle.stat();
    if (!stat.isFile()) throw new FileRefused('type', `it is ${kindOf(stat)}, not a regular file`);
    const wanted = Math.min(stat.size, options.truncateAt ?? Infinity);
    const tooLarge = () => new FileRefused('size', `it has ${stat.size.toLocaleString('en-US')} bytes`, stat.size);
    if (wanted > options.maxBytes && !options.sniff) throw tooLarge();
    const bytes = new Uint8Array(Math.min(wanted, options.maxBytes + 1));
    let at = 0;
    const fill = async (end: number) => {
      while (at < end) {
        const { bytesRead } = await handle.read(bytes, at, end - at, at);
        if (!bytesRead) return false; // the file shrank meanwhile: what was read is all there is
        at += bytesRead;
      }
      return true;
    };
    if (options.sniff) {
      // What the head says comes first: 1.9 GB of zeros is NOT_GLTF, not TOO_LARGE.
      await fill(Math.min(wanted, HEAD_BYTES));
      options.sniff(bytes.subarray(0, at), stat.size);
      if (wanted > options.maxBytes) throw tooLarge();
    }
    await fill(wanted);
    return bytes.subarray(0, at);
  } finally {
    await handle.close();
  }
}

/** Standard input as bytes, at most `maxBytes` (more is refused as 'size', the rest never read). */
export async function readStandardInput(maxBytes: number): Promise<Uint8Array> {
  const chunks: Uint8Array[] = [];
  let length = 0;
  for await (const chunk of process.stdin as AsyncIterable<Uint8Array>) {
    length += chunk.byteLength;
    if (length > maxBytes) {
      process.stdin.destroy();
      throw new FileRefused('size', `it has more than ${maxBytes.toLocaleString('en-US')} bytes`, length);
    }
    chunks.push(chunk);
  }
  const out = new Uint8Array(length);
  let at = 0;
  for (const c of chunks) { out.set(c, at); at += c.byteLength; }
  return out;
}
