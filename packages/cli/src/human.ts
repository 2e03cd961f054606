// `gcs-skin human [--vertices N] [--pose stand|tpose] [--no-seams] -o out.glb`
import { closeSync, constants, fstatSync, ftruncateSync, openSync, writeSync } from 'node:fs';
import { printable } from 'gcs-skin/gltf';
import { walkArguments, wholeNumber } from './args.js';
import { systemReason } from './read-file.js';
import { createHuman, DEFAULT_VERTICES, humanToGlb, MAX_VERTICES, MIN_VERTICES } from 'gcs-skin/human';

export const usage = `usage: gcs-skin human [--vertices N] [--pose stand|tpose] [--no-seams] -o out.glb
  --vertices N   vertex count, ${MIN_VERTICES}..${MAX_VERTICES} (default ${DEFAULT_VERTICES})
  --pose P       bind pose: stand (arms down, default) or tpose
  --no-seams     one welded closed surface (no UV-seam vertex copies)
  -o, --out F    output .glb file (required)`;

class UsageError extends Error {}

function parse(argv: string[]) {
  const opts: { vertices?: number; pose?: 'stand' | 'tpose'; seams: boolean; out?: string } = { seams: true };
  let help = false;
  walkArguments(argv, (message) => new UsageError(message), (a, value) => {
    if (a === '--vertices' || a === '-n') {
      opts.vertices = wholeNumber(a, value(), MIN_VERTICES, MAX_VERTICES);
    } else if (a === '--pose') {
      const v = value();
      if (v !== 'stand' && v !== 'tpose') throw new UsageError(`--pose must be stand or tpose (got '${v}')`);
      opts.pose = v;
    } else if (a === '--no-seams') opts.seams = false;
    else if (a === '-o' || a === '--out') opts.out = value();
    else if (a === '-h' || a === '--help') return help = true; // the rest unread
    else throw new UsageError(`unknown argument '${a}'`);
  });
  if (help) { process.stdout.write(usage + '\n'); return null; }
  if (!opts.out) throw new UsageError('missing -o out.glb');
  return opts;
}

/** Run the subcommand; resolves to the process exit code. */
export async function run(argv: string[]): Promise<number> {
  let opts;
  try {
    opts = parse(argv);
    if (!opts) return 0;
    const t0 = performance.now();
    const human = createHuman({ vertices: opts.vertices, pose: opts.pose, seams: opts.seams });
    const glb = await humanToGlb(human);
    const failed = writeRegularFile(opts.out!, glb);
    if (failed) {
      process.stderr.write(`gcs-skin human: cannot write '${printable(opts.out!)}': ${failed} [UNWRITABLE]\n`);
      return 2;
    }
    const d = human.data;
    process.stdout.write(`wrote ${printable(opts.out!)}: ${d.positions.length / 3} vertices, ${d.indices.length / 3} triangles, ` +
      `${d.jointNames.length} joints, clips ${human.clips.map((c) => c.name).join('/')}, ${(glb.length / 1024).toFixed(0)} KiB ` +
      `(${(performance.now() - t0).toFixed(0)} ms)\n`);
    return 0;
  } catch (e) {
    if (e instanceof UsageError || e instanceof RangeError) {
      process.stderr.write(`gcs-skin human: ${e.message}\n${usage}\n`);
      return 2;
    }
    throw e;
  }
}

/**
 * Writes `bytes` to the regular file `path` (created or replaced): opened non-blocking (a FIFO
 * with no reader fails at once instead of hanging), refused unless it is a regular file (a
 * directory, /dev/full, a device), then written whole. Returns why it failed, or null.
 */
function writeRegularFile(path: string, bytes: Uint8Array): string | null {
  let fd = -1;
  try {
    fd = openSync(path, constants.O_WRONLY | constants.O_CREAT | constants.O_NONBLOCK, 0o644);
    if (!fstatSync(fd).isFile()) return 'it is not a regular file';
    ftruncateSync(fd, 0);
    for (let at = 0; at < bytes.length;) at += writeSync(fd, bytes, at, bytes.length - at);
    return null;
  } catch (e) {
    return (e as NodeJS.ErrnoException).code === 'ENOENT' ? 'its folder does not exist' : systemReason(e);
  } finally {
    if (fd >= 0) closeSync(fd);
  }
}
