// Packaging: the `npm pack` tarball, installed into an empty folder, imports and deforms in node
// through the package's `exports` map (no access to this repository's sources); its command line
// works there with nothing else installed (three, a peer dependency, is installed by npm ≥ 7),
// reads compressed glTF files, and `gcs-skin/gltf` poses a character for `initGcsSkin`. In a
// three.js app that has its own three, the install adds no second copy.
import { execFileSync, spawnSync } from 'node:child_process';
import { cpSync, existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import { NodeIO } from '@gltf-transform/core';
import { EXTMeshoptCompression, KHRMeshQuantization } from '@gltf-transform/extensions';
import { meshopt, quantize } from '@gltf-transform/functions';
import { MeshoptEncoder } from 'meshoptimizer';

const root = resolve(__dirname, '..');
const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';
const npx = process.platform === 'win32' ? 'npx.cmd' : 'npx';
let dir: string;
let tarball: string;

/** npm install in `cwd`; asserts success and that no install script of gcs-skin runs or is warned about. */
function install(cwd: string, ...specs: string[]) {
  const r = spawnSync(npm, ['install', '--no-audit', '--no-fund', '--prefer-offline', '--foreground-scripts', ...specs], { cwd, encoding: 'utf8' });
  expect(r.status, r.stderr).toBe(0);
  expect(`${r.stdout}\n${r.stderr}`).not.toMatch(/gcs-skin@[^\n]*(prepare|install|postinstall)|install script/i);
  return r;
}

/** A fresh app folder (package.json only). */
function app(name: string): string {
  const a = join(dir, name);
  mkdirSync(a, { recursive: true });
  writeFileSync(join(a, 'package.json'), JSON.stringify({ name, private: true, type: 'module' }));
  return a;
}

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-skin-pack-'));
  // Pack from a copy of the package sources: `prepack` rebuilds dist/ there, never under the
  // feet of other test files that use this checkout's dist/.
  const src = join(dir, 'src');
  for (const entry of ['package.json', 'tsconfig.json', 'README.md', 'LICENSE', 'bin', 'docs/node.md', 'docs/report-json.md', 'web/lib', 'wasm/include', 'scripts/build-lib.mjs'])
    cpSync(join(root, entry), join(src, entry), { recursive: true });
  symlinkSync(join(root, 'node_modules'), join(src, 'node_modules'));
  execFileSync(npm, ['pack', '--silent', '--pack-destination', dir], { cwd: src, stdio: ['ignore', 'pipe', 'pipe'] });
  const name = readdirSync(dir).find((f) => f.endsWith('.tgz'));
  expect(name).toBeDefined();
  tarball = join(dir, name!);
}, 240000);
afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe('the npm tarball, alone in an empty folder', () => {
  let a: string;
  beforeAll(() => {
    a = app('app');
    install(a, tarball);
  }, 240000);

  test('installs with no install script, its peer three once, and imports and deforms', () => {
    const installed = JSON.parse(readFileSync(join(a, 'node_modules/gcs-skin/package.json'), 'utf8'));
    expect(Object.keys(installed.scripts ?? {}).filter((k) => /^(pre|post)?install$|^prepare$/.test(k))).toEqual([]);
    // three: installed by npm as gcs-skin's peer, at the top, once.
    expect(existsSync(join(a, 'node_modules/three/package.json'))).toBe(true);
    expect(existsSync(join(a, 'node_modules/gcs-skin/node_modules/three'))).toBe(false);
    // The MIT licence its package.json names, as a file.
    expect(installed.license).toBe('MIT');
    expect(readFileSync(join(a, 'node_modules/gcs-skin/LICENSE'), 'utf8')).toMatch(/^MIT License\n[\s\S]*Permission is hereby granted, free of charge/);
    // The types carry no @internal members.
    expect(readFileSync(join(a, 'node_modules/gcs-skin/dist/index.d.ts'), 'utf8')).not.toMatch(/@internal|refreshViews|copyIn/);
    // gcs-skin/gltf's types show nothing of three.
    expect(readFileSync(join(a, 'node_modules/gcs-skin/dist/cli/gltf.d.ts'), 'utf8')).not.toMatch(/three/i);
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
    const out = execFileSync(process.execPath, ['main.mjs'], { cwd: a, encoding: 'utf8' });
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
    const result = JSON.parse(execFileSync(process.execPath, ['webgpu.mjs'], { cwd: a, encoding: 'utf8' }).trim().split('\n').pop()!);
    expect(result.names).toEqual(expect.arrayContaining(['GcsCharacter', 'GcsCrowd', 'SkinDeformer', 'bakeClip', 'writeSkinMatrices']));
    expect(result.subclasses).toBe(true);
    for (const file of ['webgpu.d.ts', 'three.d.ts', 'crowd.d.ts'])
      expect(readFileSync(join(a, 'node_modules/gcs-skin/dist', file), 'utf8')).not.toMatch(/@internal|gpuKit\?:|warned\?:/);
  });

  test('npx gcs-skin human, then npx gcs-skin report on meshopt-compressed and quantized copies', async () => {
    const human = spawnSync(npx, ['gcs-skin', 'human', '--vertices', '3000', '-o', 'h.glb'], { cwd: a, encoding: 'utf8' });
    expect(human.status, human.stderr).toBe(0);
    expect(human.stdout).toMatch(/^wrote h\.glb: \d+ vertices/);
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
      const r = spawnSync(npx, ['gcs-skin', 'report', file, '--clip', 'walk', '--frames', '6', '--time-ms', '5', '--json'], { cwd: a, encoding: 'utf8' });
      expect(r.status, `${file}: ${r.stderr}`).toBe(0);
      const report = JSON.parse(r.stdout);
      expect(report.meshes[0].counts.vertices).toBeGreaterThan(2900);
      expect(report.meshes[0].methods.gcs.fidelity.nonFinite).toBe(0);
      expect(report.meshes[0].methods.gcs.fidelity.dqsP95).toBeLessThan(1);
    }
  }, 120000);

  test('gcs-skin/gltf poses a character and initGcsSkin deforms it', () => {
    // The ten-line example of docs/node.md.
    writeFileSync(join(a, 'pose.mjs'), `
    import { initGcsSkin } from 'gcs-skin';
    import { loadCharacter } from 'gcs-skin/gltf';
    const gcs = await initGcsSkin();
    const character = await loadCharacter('h-meshopt.glb');
    const { rigInput, clip, height } = character.meshes[0];
    const deformer = gcs.createRig(rigInput).buildGcs({ sections: 6 });
    const walk = clip('walk');
    deformer.deform(walk.sample(0.5 * walk.duration));
    console.log(JSON.stringify({ finite: deformer.positions.every(Number.isFinite), sections: deformer.sectionCount, height, clips: character.clipNames }));
  `);
    const out = execFileSync(process.execPath, ['pose.mjs'], { cwd: a, encoding: 'utf8' });
    const r = JSON.parse(out.trim().split('\n').pop()!);
    expect(r.finite).toBe(true);
    expect(r.sections).toBeGreaterThan(0);
    expect(r.height).toBeGreaterThan(1.5);
    expect(r.clips).toEqual(['idle', 'walk', 'run']);
  });
});

test('a three.js app with its own three gets no second copy', () => {
  const a = app('three-app');
  install(a, 'three@0.170.0');
  install(a, tarball);
  expect(JSON.parse(readFileSync(join(a, 'node_modules/three/package.json'), 'utf8')).version).toBe('0.170.0');
  expect(existsSync(join(a, 'node_modules/gcs-skin/node_modules/three'))).toBe(false);
  const tree = spawnSync(npm, ['ls', 'three', '--all', '--parseable'], { cwd: a, encoding: 'utf8' });
  expect(tree.stdout.trim().split('\n').filter((l) => l.endsWith('/three'))).toEqual([join(a, 'node_modules/three')]);
  // And the adapter runs with that three.
  writeFileSync(join(a, 'main.mjs'), `
    import * as THREE from 'three';
    import { loadCharacter } from 'gcs-skin/gltf';
    console.log(THREE.REVISION);
  `);
  expect(execFileSync(process.execPath, ['main.mjs'], { cwd: a, encoding: 'utf8' }).trim()).toBe('170');
}, 240000);
