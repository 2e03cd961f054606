// A hostile corpus, made here (no checked-in binaries): files crafted to read what they should not
// (buffers outside the glTF's folder, devices, pipes), to make the loaders work or allocate far
// beyond the bytes they hold (huge declared counts, a million nodes, deep hierarchies and JSON), or
// to smuggle values and terminal escapes. Each goes through the real command (`node
// bin/gcs-skin.mjs report`, a child process) and must end in one line with its code in brackets,
// within 5 s of CPU time and a memory bound, and never echo a byte of a file it refused. Files at the limits
// (LIMITS) are accepted and still bounded. Runs on packages/cli/dist and the dist/ it imports: `npm run build:lib` first (npm test does).
import { spawnSync, type SpawnSyncOptions } from 'node:child_process';
import { chmodSync, closeSync, existsSync, ftruncateSync, mkdirSync, mkdtempSync, openSync, rmSync, statSync, symlinkSync, writeFileSync, writeSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { loadCharacter } from '../../packages/cli/src/gltf.js';
import { GltfError } from '../../packages/cli/src/gltf-node.js';
import { LIMITS } from '../../web/lib/gltf/limits.js';
import { compressGlb } from '../helpers/compressed-gltf.js';
import { packGlb, splitGlb, writeGlbVariant, type Json } from '../helpers/glb.js';

const ROOT = join(import.meta.dirname, '../..');
const BIN = join(ROOT, 'bin/gcs-skin.mjs');
const BUILT = join(ROOT, 'dist/gltf/validate.js'); // the library's build, which packages/cli/dist imports as gcs-skin/gltf

/**
 * Time bound per file: CPU seconds of the whole child (node's own start included), so that a
 * machine busy with other work does not fail it; a hang still fails, at WALL_SECONDS of wall time.
 * Resident memory bounds, MB.
 */
const SECONDS = 5;
const WALL_SECONDS = 30;
const REFUSED_MB = 250; // refused on the JSON, before any loader: node + three + the JSON
const LOADED_MB = 450; // accepted at a limit and loaded

/** A secret beside the glTF's folder: its bytes must never come back. */
const SECRET = 'TOP-SECRET-0123456789';

let dir: string; // holds secret.txt and model/
let folder: string; // the glTF files' own folder
let human: { json: Json; bin: Uint8Array };

interface Outcome { status: number | null; stdout: string; stderr: string; ms: number; cpuMs: number; maxRssMb: number }

/** `gcs-skin report FILE ...args` in a child process: exit status, output, wall and CPU time, peak resident memory. */
function report(file: string, ...args: string[]): Outcome {
  return command(['report', file, '--frames', '1', '--time-ms', '1', ...args]);
}

/** `gcs-skin ARGS` in a child process (`input`: its standard input, else none), measured as report() says. */
function command(argv: string[], input?: Uint8Array): Outcome {
  // The child writes its peak RSS (KB) and CPU time (µs) on fd 3 as it exits, keeping stderr for the one line.
  const runner = `import { writeSync } from 'node:fs';
process.on('exit', () => { const u = process.resourceUsage(); writeSync(3, u.maxRSS + ' ' + (u.userCPUTime + u.systemCPUTime)); });
process.argv.splice(1, 0, 'gcs-skin'); // the script's place in argv, which -e leaves out
await import(${JSON.stringify(new URL(`file://${BIN}`).href)});`;
  const t0 = performance.now();
  const options: SpawnSyncOptions = { encoding: 'utf8', timeout: WALL_SECONDS * 1000, stdio: [input ? 'pipe' : 'ignore', 'pipe', 'pipe', 'pipe'], input };
  const r = spawnSync(process.execPath, ['--input-type=module', '-e', runner, ...argv], options) as ReturnType<typeof spawnSync> & { stdout: string; stderr: string };
  const ms = performance.now() - t0;
  const [rssKb, cpuUs] = String(r.output[3] || '0 0').split(' ').map(Number);
  return { status: r.status, stdout: r.stdout, stderr: r.stderr, ms, cpuMs: cpuUs / 1000, maxRssMb: rssKb / 1024 };
}

/** One line `gcs-skin report: ... [CODE]` on stderr, exit 2, nothing on stdout, within the time and memory bounds. */
function expectRefused(file: string, code: string, mb = REFUSED_MB): string {
  return expectRefusedBy(report(file), file, code, mb);
}

function expectRefusedBy(r: Outcome, file: string, code: string, mb = REFUSED_MB, cmd = 'report'): string {
  const where = `${file}: ${JSON.stringify(r.stderr.slice(0, 400))}`;
  expect(r.status, where).toBe(2);
  expect(r.stdout, where).toBe('');
  expect(r.stderr.endsWith('\n'), where).toBe(true);
  const line = r.stderr.slice(0, -1);
  expect(line.split('\n'), where).toHaveLength(1);
  expect(line, where).toMatch(new RegExp(`^gcs-skin ${cmd}: .* \\[${code}\\]$`));
  expect(line).not.toContain(SECRET);
  expect(line).not.toMatch(/[\x00-\x1f\x7f]/);
  expect(line.length, `${where}: ${line.length} characters`).toBeLessThanOrEqual(200);
  expectBounded(r, where, mb);
  console.log(`hostile: ${file.slice(file.startsWith(folder) ? folder.length + 1 : 0).padEnd(28)} ${code.padEnd(15)} ${String(line.length).padStart(4)} chars ${r.cpuMs.toFixed(0).padStart(5)} ms CPU ${r.ms.toFixed(0).padStart(5)} ms wall ${r.maxRssMb.toFixed(0).padStart(4)} MB`);
  return line;
}

/** Within the CPU-time and memory bounds. */
function expectBounded(r: Outcome, where: string, mb: number): void {
  expect(r.cpuMs, `${where}: ${r.cpuMs.toFixed(0)} ms CPU`).toBeGreaterThan(0);
  expect(r.cpuMs, `${where}: ${r.cpuMs.toFixed(0)} ms CPU`).toBeLessThan(SECONDS * 1000);
  expect(r.maxRssMb, `${where}: ${r.maxRssMb.toFixed(0)} MB`).toBeGreaterThan(0);
  expect(r.maxRssMb, `${where}: ${r.maxRssMb.toFixed(0)} MB`).toBeLessThan(mb);
}

/** Writes a .gltf (JSON) into the model folder; returns its path. */
function gltf(name: string, json: Json): string {
  const file = join(folder, name);
  writeFileSync(file, JSON.stringify({ asset: { version: '2.0' }, ...json }));
  return file;
}

/** A .gltf whose one buffer (4 bytes) is at `uri`. */
const bufferAt = (name: string, uri: string) => gltf(name, { buffers: [{ byteLength: 4, uri }] });

/** A 4-byte buffer as a data: URI, for files that need one to be loaded at all. */
const SMALL_BUFFER = { byteLength: 4, uri: 'data:application/octet-stream;base64,AAAAAA==' };

/** The default human as .glb with its JSON and BIN changed by `edit`. */
function humanVariant(name: string, edit: (json: Json, bin: DataView) => void): string {
  return writeGlbVariant(join(folder, name), human, edit);
}

beforeAll(async () => {
  if (!existsSync(BUILT) || statSync(BUILT).mtimeMs < statSync(join(ROOT, 'web/lib/gltf/validate.ts')).mtimeMs)
    throw new Error('dist/ (what packages/cli/dist imports) is missing or older than web/lib: run `npm run build:lib` first');
  dir = mkdtempSync(join(tmpdir(), 'gcs-hostile-'));
  folder = join(dir, 'model');
  mkdirSync(folder);
  writeFileSync(join(dir, 'secret.txt'), SECRET);
  human = splitGlb(await humanToGlb(createHuman({ vertices: 2000 })));
});
afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe('no file read outside the glTF\'s folder', () => {
  it.each([
    ['dotdot.gltf', '../secret.txt'],
    ['dotdot-encoded.gltf', '..%2Fsecret.txt'],
    ['dotdot-inner.gltf', 'sub/../../secret.txt'],
    ['absolute.gltf', '/etc/passwd'],
    ['proc.gltf', '/proc/self/environ'],
    ['dev-zero.gltf', '/dev/zero'],
    ['file-url.gltf', 'file:///etc/passwd'],
    ['http-url.gltf', 'http://127.0.0.1:9/x.bin'],
  ])('%s (uri %s): OUTSIDE_FOLDER', (name, uri) => {
    expect(expectRefused(bufferAt(name, uri), 'OUTSIDE_FOLDER')).toContain("buffers are read from the glTF's folder only");
  });

  it('links inside the folder that lead out of it (to the secret, to /dev/zero) are refused after following them', () => {
    symlinkSync(join(dir, 'secret.txt'), join(folder, 'secret-link.bin'));
    symlinkSync('/dev/zero', join(folder, 'zero-link.bin'));
    expectRefused(bufferAt('link-secret.gltf', 'secret-link.bin'), 'OUTSIDE_FOLDER');
    expectRefused(bufferAt('link-zero.gltf', 'zero-link.bin'), 'OUTSIDE_FOLDER');
  });

  it('a named pipe inside the folder is not a regular file: refused without waiting for a writer', () => {
    const made = spawnSync('mkfifo', [join(folder, 'pipe.bin')]);
    if (made.status !== 0) return console.log('hostile: no mkfifo here, the pipe case is skipped');
    expect(expectRefused(bufferAt('pipe.gltf', 'pipe.bin'), 'OUTSIDE_FOLDER')).toMatch(/not a regular file/);
  });

  it('a buffer file larger than its byteLength is read only up to byteLength (a 64 MB file, 4 bytes declared)', () => {
    writeFileSync(join(folder, 'big.bin'), new Uint8Array(64 * 2 ** 20));
    const r = report(bufferAt('big.gltf', 'big.bin'));
    expect(r.stderr).toMatch(/has no skinned mesh.*\[NO_SKINNED_MESH\]\n$/);
    expect(r.maxRssMb).toBeLessThan(REFUSED_MB);
  });

  it('loadCharacter refuses the same files (no bytes of them as morph data or anywhere else)', async () => {
    const json = structuredClone(human.json);
    json.buffers = [{ byteLength: human.bin.length, uri: 'human.bin' }];
    writeFileSync(join(folder, 'human.bin'), human.bin);
    json.buffers.push({ byteLength: SECRET.length, uri: '../secret.txt' });
    const file = gltf('exfiltrate.gltf', json);
    await expect(loadCharacter(file)).rejects.toSatisfy((e) => e instanceof GltfError && e.code === 'OUTSIDE_FOLDER' && !e.message.includes(SECRET));
    // The same file with the second buffer inside the folder loads: the refusal is about the place only.
    json.buffers[1].uri = 'human.bin';
    json.buffers[1].byteLength = 4;
    const character = await loadCharacter(gltf('inside.gltf', json));
    expect(character.meshes).toHaveLength(1);
  });
});

describe('URIs that do not decode: our error, not the engine\'s URIError', () => {
  it.each([
    ['bad-escape.gltf', 'model%E0%A4%A.bin'],
    ['data-no-comma.gltf', 'data:application/octet-stream;base64'],
    ['data-not-base64.gltf', 'data:application/octet-stream;base64,@@@@'],
    ['data-bad-percent.gltf', 'data:application/octet-stream,%zz%'],
  ])('%s: BAD_URI', (name, uri) => {
    expectRefused(bufferAt(name, uri), 'BAD_URI');
  });
});

describe('no unbounded work from a few bytes: counts checked on the JSON first', () => {
  it('an index accessor of 2^31−1 entries with no buffer view (sparse, as in the review): TOO_LARGE', () => {
    const file = gltf('huge-index.gltf', {
      buffers: [{ byteLength: 8, uri: 'data:application/octet-stream;base64,AAAAAAAAAAA=' }],
      bufferViews: [{ buffer: 0, byteLength: 4 }, { buffer: 0, byteOffset: 4, byteLength: 4 }],
      accessors: [{ componentType: 5125, type: 'SCALAR', count: 2 ** 31 - 1, sparse: { count: 1, indices: { bufferView: 0, componentType: 5125 }, values: { bufferView: 1 } } }],
      meshes: [{ primitives: [{ attributes: {}, indices: 0 }] }],
    });
    expect(statSync(file).size).toBeLessThan(2500);
    expect(expectRefused(file, 'TOO_LARGE')).toMatch(/declare 8,589,934,5\d\d bytes/);
  });

  it('30 M-vertex attributes: TOO_LARGE before anything is allocated', () => {
    const count = 30_000_000;
    expectRefused(gltf('30M-vertices.gltf', {
      buffers: [SMALL_BUFFER],
      accessors: [{ componentType: 5126, type: 'VEC3', count }, { componentType: 5121, type: 'VEC4', count }, { componentType: 5126, type: 'VEC4', count }],
      meshes: [{ primitives: [{ attributes: { POSITION: 0, JOINTS_0: 1, WEIGHTS_0: 2 } }] }],
    }), 'TOO_LARGE');
  });

  it('a meshopt-compressed view that decodes to 360 MB from a few bytes: TOO_LARGE', () => {
    expectRefused(gltf('meshopt-bomb.gltf', {
      extensionsUsed: ['EXT_meshopt_compression'], extensionsRequired: ['EXT_meshopt_compression'],
      buffers: [SMALL_BUFFER, { byteLength: 360_000_000, extensions: { EXT_meshopt_compression: { fallback: true } } }],
      bufferViews: [{ buffer: 1, byteLength: 360_000_000, byteStride: 12,
        extensions: { EXT_meshopt_compression: { buffer: 0, byteLength: 4, byteStride: 12, count: 30_000_000, mode: 'ATTRIBUTES' } } }],
    }), 'TOO_LARGE');
  });

  it('an animation of 100 M keys: TOO_LARGE', () => {
    const file = gltf('100M-keys.gltf', {
      buffers: [SMALL_BUFFER],
      accessors: [{ componentType: 5126, type: 'SCALAR', count: 100_000_000, min: [0], max: [0] }, { componentType: 5126, type: 'VEC3', count: 100_000_000 }],
      nodes: [{}],
      animations: [{ samplers: [{ input: 0, output: 1 }], channels: [{ sampler: 0, target: { node: 0, path: 'translation' } }] }],
    });
    expect(statSync(file).size).toBeLessThan(2700);
    expectRefused(file, 'TOO_LARGE');
  });

  it('many accessors sharing one view (1.3 GB declared from 64 KB): TOO_LARGE', () => {
    const json = structuredClone(human.json);
    const view = json.accessors[0];
    json.accessors.push(...Array.from({ length: 5000 }, () => ({ ...view })));
    const file = join(folder, 'aliases.glb');
    writeFileSync(file, packGlb(json, human.bin));
    expectRefused(file, 'TOO_LARGE');
  });

  it('one skinned mesh instanced by 5,000 nodes (a 350 KB file: a deformer build each): TOO_LARGE', () => {
    const file = humanVariant('instances.glb', (json) => {
      const skinned = json.nodes.find((d: Json) => d.skin !== undefined);
      for (let i = 0; i < 5_000; i++) {
        json.nodes.push({ mesh: skinned.mesh, skin: skinned.skin });
        json.scenes[0].nodes.push(json.nodes.length - 1);
      }
    });
    expect(expectRefused(file, 'TOO_LARGE')).toMatch(/skinned nodes instance 10,027,005 vertices from meshes of 2,005/);
  });

  it('a million empty nodes, and one node past the limit: TOO_LARGE', () => {
    const nodes = (count: number) => ({ nodes: Array.from({ length: count }, () => ({})) });
    // Parsing the JSON of a million objects (3 MB) takes most of the memory here.
    expectRefused(gltf('1M-nodes.gltf', nodes(1_000_000)), 'TOO_LARGE', LOADED_MB);
    expectRefused(gltf('nodes-past-limit.gltf', nodes(LIMITS.nodes + 1)), 'TOO_LARGE');
  });

  it('a hierarchy 100,000 deep and JSON nested 1,000,000 deep: TOO_LARGE, not "Maximum call stack size exceeded"', () => {
    const depth = 10_000;
    expectRefused(gltf('deep-nodes.gltf', {
      nodes: Array.from({ length: depth }, (_, i) => (i < depth - 1 ? { children: [i + 1] } : {})), scenes: [{ nodes: [0] }],
    }), 'TOO_LARGE');
    const file = join(folder, 'deep-json.gltf');
    writeFileSync(file, `{"asset":{"version":"2.0"},"extras":${'['.repeat(1_000_000)}${']'.repeat(1_000_000)}}`);
    expectRefused(file, 'TOO_LARGE');
  });

  it('at the limits the files are accepted and still bounded: the node limit, the depth limit, the zero-filled floor', () => {
    const at = (name: string, json: Json) => {
      const r = report(gltf(name, json));
      expect(r.status, r.stderr).toBe(2);
      expect(r.stderr).not.toMatch(/TOO_LARGE/);
      expectBounded(r, name, LOADED_MB);
      console.log(`hostile: ${name.padEnd(28)} accepted        ${r.cpuMs.toFixed(0).padStart(5)} ms CPU ${r.ms.toFixed(0).padStart(5)} ms wall ${r.maxRssMb.toFixed(0).padStart(4)} MB: ${r.stderr.trim().slice(-60)}`);
    };
    at('nodes-at-limit.gltf', { buffers: [SMALL_BUFFER], nodes: Array.from({ length: LIMITS.nodes }, () => ({})), scenes: [{ nodes: Array.from({ length: LIMITS.nodes }, (_, i) => i) }] });
    const depth = LIMITS.nodeDepth;
    at('depth-at-limit.gltf', { buffers: [SMALL_BUFFER], nodes: Array.from({ length: depth }, (_, i) => (i < depth - 1 ? { children: [i + 1] } : {})), scenes: [{ nodes: [0] }] });
    // A skinned mesh whose zero-filled attributes (no buffer view) fill the allowance of a 4-byte file.
    const count = Math.floor((LIMITS.expandedFloor + LIMITS.expansion * 4) / (12 + 4 + 16));
    at('zero-filled-at-limit.gltf', {
      buffers: [SMALL_BUFFER],
      accessors: [{ componentType: 5126, type: 'VEC3', count, min: [0, 0, 0], max: [0, 0, 0] }, { componentType: 5121, type: 'VEC4', count }, { componentType: 5126, type: 'VEC4', count }],
      meshes: [{ primitives: [{ attributes: { POSITION: 0, JOINTS_0: 1, WEIGHTS_0: 2 } }] }],
      skins: [{ joints: [1] }], nodes: [{ mesh: 0, skin: 0 }, {}], scenes: [{ nodes: [0, 1] }],
    });
  });
});

describe('values the loaders would take silently', () => {
  it('a NaN key time: BAD_DATA', () => {
    const line = expectRefused(humanVariant('nan-time.glb', (json, bin) => {
      const times = json.accessors[json.animations[0].samplers[0].input];
      bin.setFloat32(json.bufferViews[times.bufferView].byteOffset + times.byteOffset + 4 * 3, NaN, true);
    }), 'BAD_DATA');
    expect(line).toMatch(/key 3 of sampler 0 of animation 0 'idle' .* is at time NaN/);
  });

  it('a sparse index past its accessor\'s count: BAD_DATA', () => {
    const line = expectRefused(humanVariant('sparse-past-count.glb', (json) => {
      const data = new Uint8Array(16);
      new DataView(data.buffer).setUint32(0, 5000, true);
      json.buffers.push({ byteLength: 16, uri: `data:application/octet-stream;base64,${Buffer.from(data).toString('base64')}` });
      const b = json.buffers.length - 1;
      json.bufferViews.push({ buffer: b, byteLength: 4 }, { buffer: b, byteOffset: 4, byteLength: 12 });
      const v = json.bufferViews.length;
      json.accessors[0].sparse = { count: 1, indices: { bufferView: v - 2, componentType: 5125 }, values: { bufferView: v - 1 } };
    }), 'BAD_DATA');
    expect(line).toMatch(/sparse index 0 of accessor 0 .* is 5,000, past its count 2,005/);
  });

  it('key times that go back or start below 0, a NaN animated value: BAD_DATA', () => {
    const times = (json: Json) => json.accessors[json.animations[0].samplers[0].input];
    const at = (json: Json, k: number) => { const a = times(json); return json.bufferViews[a.bufferView].byteOffset + a.byteOffset + 4 * k; };
    expect(expectRefused(humanVariant('times-back.glb', (json, bin) => { bin.setFloat32(at(json, 5), 0.0625, true); }), 'BAD_DATA'))
      .toMatch(/key 5 of sampler 0 .* is at time 0.0625: before key 4 at .*: key times never go back/);
    expect(expectRefused(humanVariant('time-negative.glb', (json, bin) => { bin.setFloat32(at(json, 0), -1e30, true); }), 'BAD_DATA'))
      .toMatch(/key 0 .* key times start at 0 or later/);
    expect(expectRefused(humanVariant('nan-value.glb', (json, bin) => {
      const values = json.accessors[json.animations[0].samplers[0].output];
      bin.setFloat32(json.bufferViews[values.bufferView].byteOffset + values.byteOffset + 4, NaN, true);
    }), 'BAD_DATA')).toMatch(/value 0 of sampler 0 .* is NaN/);
  });

  it('a rotation fed 3-vectors (three\'s mixer then looped forever) and too few values for the keys: BAD_STRUCTURE', () => {
    expect(expectRefused(humanVariant('rotation-vec3.glb', (json) => { json.animations[0].channels[1].sampler = 0; }), 'BAD_STRUCTURE'))
      .toMatch(/animates rotation with VEC3 values \(accessor \d+\), not VEC4/);
    expect(expectRefused(humanVariant('values-short.glb', (json) => {
      const s = json.animations[0].samplers[0];
      json.accessors.push({ ...json.accessors[s.output], count: json.accessors[s.output].count - 1 });
      s.output = json.accessors.length - 1;
    }), 'BAD_STRUCTURE')).toMatch(/has 121 keys but 120 values/);
  });

  it('an unknown animation path is one line (BAD_STRUCTURE), not a warning per frame', () => {
    expectRefused(humanVariant('bad-path.glb', (json) => { json.animations[0].channels[0].target.path = 'pointer'; }), 'BAD_STRUCTURE');
  });

  it('an unknown required extension: UNSUPPORTED', () => {
    expectRefused(humanVariant('unknown-ext.glb', (json) => { json.extensionsRequired = ['KHR_hostile']; json.extensionsUsed = ['KHR_hostile']; }), 'UNSUPPORTED');
  });
});

describe('terminal escapes in names are printed as escapes', () => {
  const ESCAPES = '\x1b]0;pwned\x07\x1b[2J\x1b[31mred\r\nsecond line\u202e';

  it('mesh and clip names with ESC, BEL, CR/LF and a bidi override: the text report prints them escaped', () => {
    const file = humanVariant('escapes.glb', (json) => {
      json.meshes[0].name = `Body${ESCAPES}`;
      json.nodes.find((n: Json) => n.mesh === 0).name = `Body${ESCAPES}`;
      json.animations[0].name = `idle${ESCAPES}`;
    });
    const r = report(file, '--wide'); // --wide: the per-clip tables name each clip
    expect(r.status, r.stderr).toBe(0);
    expect(r.stdout).not.toMatch(/[\x00-\x09\x0b-\x1f\x7f\u202e]/);
    // three sanitises node names (brackets dropped, white space, CR/LF included, to '_'): the escapes are still there, on one line.
    const lines = r.stdout.split('\n');
    const mesh = lines.findIndex((l) => l.startsWith('mesh '));
    expect(lines[mesh]).toMatch(/^mesh 'Body\\x1b0;pwned\\x07\\x1b2J\\x1b31mred__second_line\\u202e': /);
    expect(lines[mesh + 1]).toMatch(/^fidelity over/);
    expect(r.stdout).toContain("clip 'idle\\x1b]0;pwned\\x07\\x1b[2J\\x1b[31mred\\r\\nsecond line\\u202e' (");
    // An error line naming the clip stays one line.
    const missing = report(file, '--clip', `x${ESCAPES}`);
    expect(missing.stderr.trimEnd().split('\n')).toHaveLength(1);
    expect(missing.stderr).toMatch(/\[NO_CLIP\]\n$/);
    expect(missing.stderr.slice(0, -1)).not.toMatch(/[\x00-\x1f\x7f]/);
  });
});

// Second round (issue 28): the model file itself, compressed data that lies, keys that reach a
// prototype, names a megabyte long, write errors of `human -o`, and numbers read too kindly.
describe('the model file itself: a regular file only, its size checked before reading, no more read than needed', () => {
  it('a FIFO, /dev/zero and a directory as the model: refused by type, at once', () => {
    const made = spawnSync('mkfifo', [join(folder, 'model-pipe.glb')]);
    if (made.status === 0) expect(expectRefused(join(folder, 'model-pipe.glb'), 'UNREADABLE')).toMatch(/a FIFO \(named pipe\), not a regular file \(give '-' to read standard input\)/);
    expect(expectRefused('/dev/zero', 'UNREADABLE')).toMatch(/a character device, not a regular file/);
    expect(expectRefused(folder, 'UNREADABLE')).toMatch(/a directory, not a regular file/);
  });

  it('standard input by any name: -, /dev/stdin and /dev/fd/0 read a piped model alike', () => {
    for (const name of ['-', '/dev/stdin', '/dev/fd/0']) {
      const piped = command(['report', name, '--frames', '1', '--time-ms', '1', '--json'], packGlb(human.json, human.bin));
      expect(piped.status, `${name}: ${piped.stderr}`).toBe(0);
      expect(JSON.parse(piped.stdout).meshes.length, name).toBe(1);
    }
  });

  it('a 1.9 GB sparse file: its first bytes are read (NOT_GLTF), or its size refuses it (TOO_LARGE), never the whole', () => {
    const sparse = (name: string, head?: Uint8Array) => {
      const file = join(folder, name);
      const fd = openSync(file, 'w');
      ftruncateSync(fd, 1.9e9);
      if (head) writeSync(fd, head, 0, head.length, 0);
      closeSync(fd);
      return file;
    };
    expectRefused(sparse('zeros.glb'), 'NOT_GLTF');
    const header = new Uint8Array(12);
    new DataView(header.buffer).setUint32(0, 0x46546c67, true);
    new DataView(header.buffer).setUint32(4, 2, true);
    new DataView(header.buffer).setUint32(8, 1.9e9, true);
    expect(expectRefused(sparse('huge.glb', header), 'TOO_LARGE')).toMatch(/1,900,000,000 bytes, past the 536,870,912/);
    rmSync(join(folder, 'zeros.glb'));
    rmSync(join(folder, 'huge.glb'));
  });

  it('- reads standard input as bytes: a .glb reports; a .gltf with a buffer in a file of its own is refused (no folder)', () => {
    const ok = command(['report', '-', '--frames', '1', '--time-ms', '1', '--json'], packGlb(human.json, human.bin));
    expect(ok.status, ok.stderr).toBe(0);
    expect(JSON.parse(ok.stdout).file).toBe('-');
    const json = structuredClone(human.json);
    json.buffers = [{ byteLength: human.bin.length, uri: 'human.bin' }];
    const refused = command(['report', '-', '--frames', '1'], new TextEncoder().encode(JSON.stringify(json)));
    expect(expectRefusedBy(refused, '-', 'UNREADABLE')).toMatch(/standard input: buffer 0 is in the file 'human\.bin', which cannot be resolved without the \.gltf's folder/);
  });

  it('a link to the model inside its folder still reads (legal but unusual)', () => {
    writeFileSync(join(folder, 'real.glb'), packGlb(human.json, human.bin));
    symlinkSync(join(folder, 'real.glb'), join(folder, 'link.glb'));
    const r = report(join(folder, 'link.glb'));
    expect(r.status, r.stderr).toBe(0);
    expect(r.stderr).toBe('');
  });
});

describe('compressed data that lies: refused before decoding, or by what the decoder returns', () => {
  let compressed: Record<string, { json: Json; bin: Uint8Array }>;
  beforeAll(async () => {
    compressed = {};
    const glb = packGlb(human.json, human.bin);
    for (const how of ['draco', 'draco-sequential', 'meshopt'] as const) compressed[how] = splitGlb(await compressGlb(glb, how));
  });
  const declare = (vertices: number, indices?: number) => (json: Json) => {
    const p = json.meshes[0].primitives[0];
    for (const a of Object.values(p.attributes) as number[]) json.accessors[a].count = vertices;
    if (indices !== undefined) json.accessors[p.indices].count = indices;
  };
  const variant = (name: string, source: { json: Json; bin: Uint8Array }, edit: (json: Json, bin: DataView) => void) =>
    writeGlbVariant(join(folder, name), source, edit);

  it('Draco whose header declares more than its accessors (3 vertices declared): BAD_DATA before the decoder runs', () => {
    expect(expectRefused(variant('draco-liar.glb', compressed.draco, declare(3, 3)), 'BAD_DATA')).toMatch(/declares [\d,]+ triangles where its indices declare 1/);
    expect(expectRefused(variant('draco-seq-liar.glb', compressed['draco-sequential'], declare(100)), 'BAD_DATA')).toMatch(/declares [\d,]+ vertices where its accessors declare 100/);
  });

  it('Draco edgebreaker that decodes to more vertices than declared: BAD_DATA from the decoded count', () => {
    expect(expectRefused(variant('draco-seam-liar.glb', compressed.draco, declare(100)), 'BAD_DATA')).toMatch(/decodes to [\d,]+ vertices where its accessors declare 100/);
  });

  it('a corrupt meshopt stream: BAD_DATA in our words, not "Invalid typed array length"', () => {
    const line = expectRefused(variant('meshopt-corrupt.glb', compressed.meshopt, (json, bin) => {
      for (const v of json.bufferViews) {
        const m = v.extensions?.EXT_meshopt_compression;
        if (m && m.buffer === 0) for (let k = m.byteOffset + 1; k < m.byteOffset + m.byteLength - 1; k++) bin.setUint8(k, 0xff);
      }
    }), 'BAD_DATA');
    expect(line).toMatch(/its meshopt data does not decode/);
  });
});

describe('keys and names from the file: never a prototype, never a megabyte line', () => {
  it.each([
    ['attr-constructor.glb', (json: Json) => { json.meshes[0].primitives[0].attributes.constructor = json.meshes[0].primitives[0].attributes.POSITION; }, 'constructor'],
    ['extras-proto.glb', (json: Json) => { json.nodes[0].extras = JSON.parse('{"__proto__": {"isSkinnedMesh": true}}'); }, '__proto__'],
    ['ext-tostring.glb', (json: Json) => { json.meshes[0].extensions = { toString: {} }; }, 'toString'],
  ])('%s: BAD_STRUCTURE naming the key', (name, edit, key) => {
    const line = expectRefused(humanVariant(name, edit), 'BAD_STRUCTURE');
    expect(line).toContain(`uses the key '${key}'`);
    expect(line.length).toBeLessThanOrEqual(200);
  });

  it('a 1 MB node name and a 1 MB uri: the line stays short (48 characters of a name, then …)', () => {
    const big = 'N'.repeat(2 ** 20);
    const line = expectRefused(humanVariant('long-name.glb', (json) => {
      json.nodes[0].name = big;
      json.nodes[0].children = [...(json.nodes[0].children ?? []), 0]; // its own child: the message names it
    }), 'NODE_CYCLE');
    expect(line).toContain(`'${'N'.repeat(47)}…'`);
    expect(line.length).toBeLessThanOrEqual(200);
    expect(expectRefused(bufferAt('long-uri.gltf', `${'u'.repeat(2 ** 20)}%zz`), 'BAD_URI').length).toBeLessThanOrEqual(200);
  });

  it('JOINTS_0 of FLOAT: the accessor is blamed, not a joint', () => {
    const line = expectRefused(humanVariant('joints-float.glb', (json) => {
      json.accessors[json.meshes[0].primitives[0].attributes.JOINTS_0].componentType = 5126;
    }), 'BAD_STRUCTURE');
    expect(line).toMatch(/accessor \d+ \(JOINTS_0 of mesh 0 'Human' primitive 0\) is VEC4 FLOAT, not VEC4 UNSIGNED_BYTE\/SHORT/);
    expect(line.length).toBeLessThanOrEqual(200);
    expect(line).not.toMatch(/joint \d{3,}/);
  });
});

describe('numbers read strictly', () => {
  it.each(['0x3', '1e9', 'NaN', ' 7', '+5', '3.0'])('--frames %j: refused, naming the flag', (value) => {
    const r = report(join(folder, 'none.glb'), '--frames', value);
    expect(r.status).toBe(2);
    expect(r.stderr.split('\n')[0]).toMatch(/^gcs-skin report: --frames takes a whole number from 1 to 10000 in decimal digits; got '.*'$/);
  });
  it('human --vertices 0x3000: refused, naming the flag', () => {
    const r = command(['human', '--vertices', '0x3000', '-o', join(folder, 'h.glb')]);
    expect(r.status).toBe(2);
    expect(r.stderr).toMatch(/^gcs-skin human: --vertices takes a whole number from \d+ to \d+ in decimal digits; got '0x3000'/);
  });
});

describe('gcs-skin human -o: write errors are one line with a code', () => {
  it.each([
    ['a directory', () => folder, /it is not a regular file|it is a directory/],
    ['/dev/full', () => '/dev/full', /not a regular file/],
    ['a missing folder', () => join(folder, 'no-such-folder', 'out.glb'), /its folder does not exist/],
    ['a name with escape bytes in a missing folder', () => join(folder, 'no\x1b[2Jsuch', 'out.glb'), /no\\x1b\[2Jsuch/],
  ])('%s: exit 2, [UNWRITABLE]', (_, out, reason) => {
    const r = command(['human', '--vertices', '2000', '-o', out()]);
    expectRefusedBy(r, out(), 'UNWRITABLE', LOADED_MB, 'human');
    expect(r.stderr).toMatch(reason);
  });

  it('a read-only file: exit 2, [UNWRITABLE] (skipped as root, who may write it)', (ctx) => {
    if (process.getuid?.() === 0) return ctx.skip();
    const file = join(folder, 'read-only.glb');
    writeFileSync(file, 'x');
    chmodSync(file, 0o444);
    expectRefusedBy(command(['human', '--vertices', '2000', '-o', file]), file, 'UNWRITABLE', LOADED_MB, 'human');
  });

  it('the "wrote" line prints the name escaped', () => {
    const out = join(folder, 'bell\x07.glb');
    const r = command(['human', '--vertices', '2000', '-o', out]);
    expect(r.status, r.stderr).toBe(0);
    expect(r.stdout).toContain('bell\\x07.glb');
    expect(r.stdout).not.toMatch(/[\x00-\x09\x0b-\x1f]/);
  });
});
