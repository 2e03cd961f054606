// `gcs-skin human [--vertices N] [--pose stand|tpose] [--no-seams] -o out.glb`
import { writeFileSync } from 'node:fs';
import { createHuman, DEFAULT_VERTICES, humanToGlb, MAX_VERTICES, MIN_VERTICES } from '../../../web/lib/human/index.js';

export const usage = `usage: gcs-skin human [--vertices N] [--pose stand|tpose] [--no-seams] -o out.glb
  --vertices N   vertex count, ${MIN_VERTICES}..${MAX_VERTICES} (default ${DEFAULT_VERTICES})
  --pose P       bind pose: stand (arms down, default) or tpose
  --no-seams     one welded closed surface (no UV-seam vertex copies)
  -o, --out F    output .glb file (required)`;

class UsageError extends Error {}

function parse(argv: string[]) {
  const opts: { vertices?: number; pose?: 'stand' | 'tpose'; seams: boolean; out?: string } = { seams: true };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const value = () => {
      const v = argv[++i];
      if (v === undefined) throw new UsageError(`${a} needs a value`);
      return v;
    };
    if (a === '--vertices' || a === '-n') {
      const v = value();
      if (!/^\d+$/.test(v)) throw new UsageError(`--vertices must be an integer (got '${v}')`);
      opts.vertices = Number(v);
    } else if (a === '--pose') {
      const v = value();
      if (v !== 'stand' && v !== 'tpose') throw new UsageError(`--pose must be stand or tpose (got '${v}')`);
      opts.pose = v;
    } else if (a === '--no-seams') opts.seams = false;
    else if (a === '-o' || a === '--out') opts.out = value();
    else if (a === '-h' || a === '--help') { process.stdout.write(usage + '\n'); return null; }
    else throw new UsageError(`unknown argument '${a}'`);
  }
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
    writeFileSync(opts.out!, glb);
    const d = human.data;
    process.stdout.write(`wrote ${opts.out}: ${d.positions.length / 3} vertices, ${d.indices.length / 3} triangles, ` +
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
