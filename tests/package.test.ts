// Packaging: the two `npm pack` tarballs, installed into empty folders (no access to this
// repository's sources). A library user's `npm install gcs-skin three` gets gcs-skin and three and
// nothing else (the sizes are printed), imports and deforms in node through the `exports` map;
// with @gcs-skin/cli beside it the command line reads compressed glTF files and
// `@gcs-skin/cli/gltf` poses a character; `npx gcs-skin report` works from an empty folder with
// nothing installed (both packages served by a local registry, as if published); and a three.js
// app that has its own three gets no second copy.
import { execFileSync, spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import { NodeIO } from '@gltf-transform/core';
import { EXTMeshoptCompression, KHRMeshQuantization } from '@gltf-transform/extensions';
import { meshopt, quantize } from '@gltf-transform/functions';
import { MeshoptEncoder } from 'meshoptimizer';
import { npm, packTarballs, ROOT, sizeOf, userEnv, type Tarballs } from './helpers/pack.js';
import { quoted, quotes } from './helpers/readme.js';
import { startRegistry, upstreamRegistry } from './helpers/registry.js';
import { installedSizes } from '../scripts/install-size.mjs';

const npx = process.platform === 'win32' ? 'npx.cmd' : 'npx';
/** The readers only the command line needs: a library user must not get them. */
const CLI_ONLY = ['@gltf-transform/core', '@gltf-transform/extensions', 'draco3dgltf', 'meshoptimizer', 'ktx-parse', 'property-graph'];
let dir: string;
let packed: Tarballs;

/** npm install in `cwd`; asserts success and that no install script of gcs-skin runs or is warned about. */
function install(cwd: string, ...specs: string[]) {
  const r = spawnSync(npm, ['install', '--no-audit', '--no-fund', '--prefer-offline', '--foreground-scripts', ...specs], { cwd, env: userEnv(), encoding: 'utf8' });
  expect(r.status, r.stderr).toBe(0);
  expect(`${r.stdout}\n${r.stderr}`).not.toMatch(/gcs-skin[^\n]*(prepare|install|postinstall)|install script/i);
  return r;
}

/** A fresh app folder (package.json only). */
function app(name: string): string {
  const a = join(dir, name);
  mkdirSync(a, { recursive: true });
  writeFileSync(join(a, 'package.json'), JSON.stringify({ name, private: true, type: 'module' }));
  return a;
}

const versionOf = (pkg: string) => JSON.parse(readFileSync(join(ROOT, 'node_modules', pkg, 'package.json'), 'utf8')).version as string;
const lastJson = (out: string) => JSON.parse(out.trim().split('\n').pop()!);

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-skin-pack-'));
  // A version no earlier run left in npm's npx cache (npx reuses an install of the same version).
  const base = JSON.parse(readFileSync(join(ROOT, 'package.json'), 'utf8')).version;
  packed = packTarballs(dir, `${base}-test.${Date.now()}`);
}, 240000);
afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe("a library user: `npm install gcs-skin three` in an empty folder", () => {
  let a: string;
  beforeAll(() => {
    a = app('app');
    install(a, packed.library, `three@${versionOf('three')}`);
  }, 240000);

  test('installs gcs-skin and three, nothing else (sizes printed), and none of the command line', () => {
    const sizes = installedSizes(a) as { packages: Record<string, number>; total: number };
    console.log(`package sizes: ${JSON.stringify({
      tarballs: { 'gcs-skin': sizeOf(packed.library), '@gcs-skin/cli': sizeOf(packed.cli) },
      'npm install gcs-skin three': sizes,
    })}`);
    expect(Object.keys(sizes.packages).sort()).toEqual(['gcs-skin', 'three']);
    // As the README quotes them (MB of 10^6 bytes on disk, the tarball in kB of 1000): within 5 % or the quote's rounding.
    const [library, three, tarball] = quoted(/([\d.]+) MB of gcs-skin beside three's ([\d.]+) MB, where it was [\d.]+ MB with the glTF\s+decoders\s+\(tarball (\d+) KB/);
    const measured = { library: sizes.packages['gcs-skin'] / 1e6, three: sizes.packages.three / 1e6, tarball: sizeOf(packed.library) / 1000 };
    expect({ library: quotes(library, measured.library), three: quotes(three, measured.three), tarball: quotes(tarball, measured.tarball) },
      `README: ${library} MB, three ${three} MB, tarball ${tarball} KB; measured ${JSON.stringify(measured)}`).toEqual({ library: true, three: true, tarball: true });
    for (const name of CLI_ONLY) expect(existsSync(join(a, 'node_modules', name)), name).toBe(false);
    // The library's files only: no command-line modules (they are @gcs-skin/cli's).
    expect(existsSync(join(a, 'node_modules/gcs-skin/dist/cli'))).toBe(false);
    expect(existsSync(join(a, 'node_modules/gcs-skin/dist/human/cli.js'))).toBe(false);
    expect(existsSync(join(a, 'node_modules/gcs-skin/dist/gltf.js'))).toBe(true); // gcs-skin/gltf, the glTF validator: the demo's and the CLI's
    expect(existsSync(join(a, 'node_modules/gcs-skin/dist/gcs-skin.wasm'))).toBe(true);
    const manifest = JSON.parse(readFileSync(join(a, 'node_modules/gcs-skin/package.json'), 'utf8'));
    expect(manifest.sideEffects).toBe(false);
    expect(manifest.dependencies ?? {}).toEqual({});
  });

  test('installs with no install script, its peer three once, and imports and deforms', () => {
    const installed = JSON.parse(readFileSync(join(a, 'node_modules/gcs-skin/package.json'), 'utf8'));
    expect(Object.keys(installed.scripts ?? {}).filter((k) => /^(pre|post)?install$|^prepare$/.test(k))).toEqual([]);
    // three: the app's, at the top, once (no copy under gcs-skin).
    expect(existsSync(join(a, 'node_modules/three/package.json'))).toBe(true);
    expect(existsSync(join(a, 'node_modules/gcs-skin/node_modules/three'))).toBe(false);
    // The MIT licence its package.json names, as a file.
    expect(installed.license).toBe('MIT');
    expect(readFileSync(join(a, 'node_modules/gcs-skin/LICENSE'), 'utf8')).toMatch(/^MIT License\n[\s\S]*Permission is hereby granted, free of charge/);
    // The types carry no @internal members.
    expect(readFileSync(join(a, 'node_modules/gcs-skin/dist/index.d.ts'), 'utf8')).not.toMatch(/@internal|refreshViews|copyIn/);
    writeFileSync(join(a, 'main.mjs'), `
    import { initGcsSkin, GcsError } from 'gcs-skin';
    const gcs = await initGcsSkin();
    // Two rings of a bar, one joint each.
    const positions = [], joints = [], weights = [];
    for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) {
      const a = k * Math.PI / 2;
      positions.push(Math.cos(a) * 0.1, r * 0.5, Math.sin(a) * 0.1);
      joints.push(r < 2 ? 0 : 1, 0, 0, 0); weights.push(1, 0, 0, 0);
    }
    const indices = [];
    for (let r = 0; r < 3; r++) for (let k = 0; k < 4; k++) {
      const a = r * 4 + k, b = r * 4 + (k + 1) % 4; indices.push(a, b, a + 4, b, b + 4, a + 4);
    }
    const id = [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1];
    const rig = gcs.createRig({ positions, indices, joints, weights, parents: [-1, 0],
      inverseBindMatrices: [...id, 1,0,0,0, 0,1,0,0, 0,0,1,0, 0,-0.75,0,1] });
    const d = rig.buildGcs({ sections: 4 });
    const paper = rig.buildGcs({ sections: 4, criterion: 'axial' });
    d.deform([...id, ...id]);
    let code = null;
    try { rig.buildGcs({ sections: 1 }); } catch (e) { code = e instanceof GcsError ? e.code : String(e); }
    console.log(JSON.stringify({ vertices: d.vertexCount, sections: d.sectionCount, paperSections: paper.sectionCount, first: Array.from(d.positions.slice(0, 3)), code }));
  `);
    const out = execFileSync(process.execPath, ['main.mjs'], { cwd: a, env: userEnv(), encoding: 'utf8' });
    const result = JSON.parse(out.trim().split('\n').pop()!);
    expect(result.vertices).toBe(16);
    expect(result.sections).toBe(2); // weights criterion: two rigid cores (every weight is 1.0)
    expect(result.paperSections).toBeGreaterThan(2); // the paper's rule: a shared section and inner ones
    expect(result.first.every(Number.isFinite)).toBe(true);
    expect(result.code).toBe('SECTION_COUNT');
  });

  test('gcs-skin/webgpu resolves through the exports map: GcsCharacter, GcsCrowd and SkinDeformer for WebGPURenderer, no internals in its types', () => {
    writeFileSync(join(a, 'webgpu.mjs'), `
    import * as webgpu from 'gcs-skin/webgpu';
    import * as three from 'gcs-skin/three';
    import * as crowd from 'gcs-skin/crowd';
    console.log(JSON.stringify({
      names: Object.keys(webgpu).sort(),
      subclasses: webgpu.GcsCharacter.prototype instanceof three.GcsCharacter && webgpu.GcsCrowd.prototype instanceof crowd.GcsCrowd && webgpu.SkinDeformer.prototype instanceof three.SkinDeformer,
    }));
  `);
    const result = JSON.parse(execFileSync(process.execPath, ['webgpu.mjs'], { cwd: a, env: userEnv(), encoding: 'utf8' }).trim().split('\n').pop()!);
    expect(result.names).toEqual(expect.arrayContaining(['GcsCharacter', 'GcsCrowd', 'SkinDeformer', 'bakeClip', 'writeSkinMatrices']));
    expect(result.subclasses).toBe(true);
    for (const file of ['webgpu.d.ts', 'three.d.ts', 'crowd.d.ts', 'three/options.d.ts', 'three/skin-deformer.d.ts', 'three/character.d.ts'])
      expect(readFileSync(join(a, 'node_modules/gcs-skin/dist', file), 'utf8')).not.toMatch(/@internal|gpuKit\?:|warned\?:/);
  });

  test('gcs-skin/human builds a character in the lean install; humanToGlb names the package it needs', () => {
    writeFileSync(join(a, 'human.mjs'), `
    import { createHuman, humanToGlb } from 'gcs-skin/human';
    const human = createHuman({ vertices: 2000 });
    let code = null, message = '';
    try { await humanToGlb(human); } catch (e) { code = e.code; message = e.message; }
    console.log(JSON.stringify({ vertices: human.mesh.geometry.getAttribute('position').count, code, message }));
  `);
    const r = lastJson(execFileSync(process.execPath, ['human.mjs'], { cwd: a, env: userEnv(), encoding: 'utf8' }));
    expect(r.vertices).toBeGreaterThan(1900);
    expect(r.code).toBe('MISSING_PACKAGE');
    expect(r.message).toMatch(/@gltf-transform\/core/);
  });
});

describe('the command line: `npm install -D @gcs-skin/cli` beside it', () => {
  let a: string;
  beforeAll(() => {
    a = app('cli-app');
    install(a, packed.library, `three@${versionOf('three')}`);
    install(a, '-D', packed.cli);
  }, 240000);

  test('npx gcs-skin human, then npx gcs-skin report on meshopt-compressed and quantized copies', async () => {
    const human = spawnSync(npx, ['gcs-skin', 'human', '--vertices', '3000', '-o', 'h.glb'], { cwd: a, env: userEnv(), encoding: 'utf8' });
    expect(human.status, human.stderr).toBe(0);
    expect(human.stdout).toMatch(/^wrote h\.glb: \d+ vertices/);
    expect(human.stderr).not.toContain('npm exec'); // the installed @gcs-skin/cli, not a fetched one
    // The compressed copies are written with this checkout's gltf-transform (a devDependency).
    await MeshoptEncoder.ready;
    const io = new NodeIO().registerExtensions([KHRMeshQuantization, EXTMeshoptCompression]).registerDependencies({ 'meshopt.encoder': MeshoptEncoder });
    io.setLogger({ debug() {}, info() {}, warn() {}, error() {}, verbosity: 0 } as never);
    for (const [name, transform] of [['h-meshopt.glb', meshopt({ encoder: MeshoptEncoder })], ['h-quantized.glb', quantize()]] as const) {
      const doc = await io.read(join(a, 'h.glb'));
      await doc.transform(transform);
      await io.write(join(a, name), doc);
    }
    for (const file of ['h-meshopt.glb', 'h-quantized.glb']) {
      const r = spawnSync(npx, ['gcs-skin', 'report', file, '--clip', 'walk', '--frames', '6', '--time-ms', '5', '--json'], { cwd: a, env: userEnv(), encoding: 'utf8' });
      expect(r.status, `${file}: ${r.stderr}`).toBe(0);
      const report = JSON.parse(r.stdout);
      expect(report.meshes[0].counts.vertices).toBeGreaterThan(2900);
      expect(report.meshes[0].methods.gcs.fidelity.nonFinite).toBe(0);
      expect(report.meshes[0].methods.gcs.fidelity.dqsP95).toBeLessThan(1);
    }
    // @gcs-skin/cli/gltf's types show nothing of three.
    expect(readFileSync(join(a, 'node_modules/@gcs-skin/cli/dist/gltf.d.ts'), 'utf8')).not.toMatch(/three/i);
  }, 120000);

  test("the command line's build holds its own modules only, and imports the library by its name", () => {
    const cliDist = join(a, 'node_modules/@gcs-skin/cli/dist');
    const files = readdirSync(cliDist, { recursive: true, encoding: 'utf8' }).map((f) => f.split('\\').join('/'));
    expect(files).toContain('report.js');
    // No copy of the library (nor its wasm): gcs-skin, @gcs-skin/cli's peer, is the one installed beside it.
    expect(files.filter((f) => f.startsWith('lib/') || f.endsWith('.wasm'))).toEqual([]);
    for (const f of files.filter((f) => f.endsWith('.js'))) {
      const text = readFileSync(join(cliDist, f), 'utf8');
      const specifiers = [...text.matchAll(/\bfrom\s*['"]([^'"]+)['"]|\bimport\s*\(\s*['"]([^'"]+)['"]/g)].map((m) => m[1] ?? m[2]);
      // Its own modules (./x.js), node's, three's, the glTF decoders', and the library's public entries.
      for (const spec of specifiers) expect(spec, `${f} imports ${spec}`).toMatch(/^(\.\/[\w-]+\.js|node:.+|three(\/.+)?|@gltf-transform\/\w+|meshoptimizer|draco3dgltf(\/.+)?|gcs-skin(\/(three|measure|human|gltf))?)$/);
    }
    const manifest = JSON.parse(readFileSync(join(a, 'node_modules/@gcs-skin/cli/package.json'), 'utf8'));
    expect(manifest.peerDependencies['gcs-skin']).toBe(packed.version);
  });


  test('@gcs-skin/cli/gltf poses a character and initGcsSkin deforms it', () => {
    // The ten-line example of docs/node.md.
    writeFileSync(join(a, 'pose.mjs'), `
    import { initGcsSkin } from 'gcs-skin';
    import { loadCharacter } from '@gcs-skin/cli/gltf';
    const gcs = await initGcsSkin();
    const character = await loadCharacter('h-meshopt.glb');
    const { rigInput, clip, height } = character.meshes[0];
    const deformer = gcs.createRig(rigInput).buildGcs({ sections: 6 });
    const walk = clip('walk');
    deformer.deform(walk.sample(0.5 * walk.duration));
    console.log(JSON.stringify({ finite: deformer.positions.every(Number.isFinite), sections: deformer.sectionCount, height, clips: character.clipNames }));
  `);
    const r = lastJson(execFileSync(process.execPath, ['pose.mjs'], { cwd: a, env: userEnv(), encoding: 'utf8' }));
    expect(r.finite).toBe(true);
    expect(r.sections).toBeGreaterThan(0);
    expect(r.height).toBeGreaterThan(1.5);
    expect(r.clips).toEqual(['idle', 'walk', 'run']);
  });
});

describe('`npx gcs-skin report` in an empty folder, nothing installed (a local registry serves both packages)', () => {
  let reason: string | null = null;
  beforeAll(async () => {
    try {
      const r = await fetch(`${upstreamRegistry()}three`, { method: 'HEAD', signal: AbortSignal.timeout(10000) });
      if (!r.ok) reason = `the registry answered ${r.status}`;
    } catch (e) {
      reason = `no registry to fetch three and the readers from (${(e as Error).message})`;
    }
    if (reason) console.log(`npx test skipped: ${reason}`);
  }, 20000);

  test('npx fetches gcs-skin, whose bin fetches @gcs-skin/cli of the same version: human, then report', async (ctx) => {
    if (reason) ctx.skip();
    const registry = await startRegistry([packed.library, packed.cli]);
    const empty = join(dir, 'empty');
    mkdirSync(empty);
    // npx asks before it installs (on a terminal; elsewhere it warns and goes on, unless an npmrc
    // says yes=false, as this machine's does): the user's answer is yes.
    const env = userEnv({ npm_config_registry: registry.url, npm_config_yes: 'true', npm_config_prefer_offline: 'true', npm_config_update_notifier: 'false' });
    try {
      const t0 = performance.now();
      // As typed by a user.
      const human = await run(npx, ['gcs-skin', 'human', '--vertices', '3000', '-o', 'h.glb'], { cwd: empty, env });
      expect(human.status, human.stderr).toBe(0);
      expect(human.stdout).toMatch(/^wrote h\.glb: \d+ vertices/);
      expect(human.stderr).toContain(`@gcs-skin/cli@${packed.version} through npm exec`);
      const report = await run(npx, ['gcs-skin', 'report', 'h.glb', '--frames', '4', '--time-ms', '5', '--json'], { cwd: empty, env });
      expect(report.status, report.stderr).toBe(0);
      const json = JSON.parse(report.stdout);
      expect(json.meshes[0].counts.vertices).toBeGreaterThan(2900);
      expect(json.meshes[0].methods.gcs.fidelity.nonFinite).toBe(0);
      console.log(`npx gcs-skin human + report from an empty folder: ${Math.round(performance.now() - t0)} ms`);
      expect(readdirSync(empty)).toEqual(['h.glb']); // nothing installed in the folder
      expect(registry.served).toEqual(expect.arrayContaining(['gcs-skin', '@gcs-skin/cli']));
    } finally {
      await registry.close();
      removeNpxInstalls(env, packed.version);
    }
  }, 240000);
});

/** A child process, awaited without blocking this process's event loop (the local registry answers from it). */
function run(cmd: string, args: string[], options: { cwd: string; env: NodeJS.ProcessEnv }): Promise<{ status: number | null; stdout: string; stderr: string }> {
  return new Promise((resolveRun, reject) => {
    const child = spawn(cmd, args, { ...options, stdio: ['ignore', 'pipe', 'pipe'] });
    let stdout = '', stderr = '';
    child.stdout.on('data', (d) => (stdout += d));
    child.stderr.on('data', (d) => (stderr += d));
    child.once('error', reject);
    child.once('close', (status) => resolveRun({ status, stdout, stderr }));
  });
}

/** Removes the npx cache's installs of this run's test version (npm keeps them in <cache>/_npx). */
function removeNpxInstalls(env: NodeJS.ProcessEnv, version: string) {
  const npxCache = join(execFileSync(npm, ['config', 'get', 'cache'], { env, encoding: 'utf8' }).trim(), '_npx');
  if (!existsSync(npxCache)) return;
  for (const entry of readdirSync(npxCache)) {
    const manifest = join(npxCache, entry, 'package.json');
    if (existsSync(manifest) && readFileSync(manifest, 'utf8').includes(version)) rmSync(join(npxCache, entry), { recursive: true, force: true });
  }
}

test('without its peer three (npm --legacy-peer-deps, as yarn berry installs), the command line names the missing package', () => {
  const a = app('no-peer');
  install(a, '--legacy-peer-deps', packed.library, packed.cli);
  expect(existsSync(join(a, 'node_modules/three'))).toBe(false);
  const r = spawnSync(npx, ['gcs-skin', 'human', '-o', 'h.glb'], { cwd: a, env: userEnv(), encoding: 'utf8' });
  expect(r.status).toBe(1);
  expect(r.stderr.trim()).toBe("gcs-skin: cannot load human: the package 'three' is not installed; install it beside @gcs-skin/cli (npm install three)");
}, 240000);

test('a three.js app with its own three gets no second copy', () => {
  const a = app('three-app');
  install(a, 'three@0.170.0');
  install(a, packed.library, packed.cli);
  expect(JSON.parse(readFileSync(join(a, 'node_modules/three/package.json'), 'utf8')).version).toBe('0.170.0');
  for (const pkg of ['gcs-skin', '@gcs-skin/cli']) expect(existsSync(join(a, 'node_modules', pkg, 'node_modules/three'))).toBe(false);
  const tree = spawnSync(npm, ['ls', 'three', '--all', '--parseable'], { cwd: a, env: userEnv(), encoding: 'utf8' });
  expect(tree.stdout.trim().split('\n').filter((l) => l.endsWith('/three'))).toEqual([join(a, 'node_modules/three')]);
  // And the library and the command line's module run with that three.
  writeFileSync(join(a, 'main.mjs'), `
    import * as THREE from 'three';
    import { GcsCharacter } from 'gcs-skin/three';
    import { loadCharacter } from '@gcs-skin/cli/gltf';
    console.log(THREE.REVISION);
  `);
  expect(execFileSync(process.execPath, ['main.mjs'], { cwd: a, env: userEnv(), encoding: 'utf8' }).trim()).toBe('170');
}, 240000);
