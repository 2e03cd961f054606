// Packaging: the `npm pack` tarball, installed into an empty folder, imports and deforms in node
// through the package's `exports` map (no access to this repository's sources).
import { execFileSync, spawnSync } from 'node:child_process';
import { cpSync, mkdtempSync, readFileSync, readdirSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { expect, test } from 'vitest';

const root = resolve(__dirname, '..');
const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';

test('the npm tarball installs into an empty folder, imports and deforms', () => {
  const dir = mkdtempSync(join(tmpdir(), 'gcs-skin-pack-'));
  // Pack from a copy of the package sources: `prepack` rebuilds dist/ there, never under the
  // feet of other test files that use this checkout's dist/.
  const src = join(dir, 'src');
  for (const entry of ['package.json', 'tsconfig.json', 'README.md', 'bin', 'web/lib', 'wasm/include', 'scripts/build-lib.mjs'])
    cpSync(join(root, entry), join(src, entry), { recursive: true });
  symlinkSync(join(root, 'node_modules'), join(src, 'node_modules'));
  execFileSync(npm, ['pack', '--silent', '--pack-destination', dir], { cwd: src, stdio: ['ignore', 'pipe', 'pipe'] });
  const tarball = readdirSync(dir).find((f) => f.endsWith('.tgz'));
  expect(tarball).toBeDefined();
  const app = join(dir, 'app');
  execFileSync('mkdir', ['-p', app]);
  writeFileSync(join(app, 'package.json'), JSON.stringify({ name: 'app', private: true, type: 'module' }));
  // No install script runs in a consumer's install (dist/ ships built): npm warns about none.
  const install = spawnSync(npm, ['install', '--no-audit', '--no-fund', '--prefer-offline', '--foreground-scripts', join(dir, tarball!)], { cwd: app, encoding: 'utf8' });
  expect(install.status).toBe(0);
  expect(`${install.stdout}\n${install.stderr}`).not.toMatch(/gcs-skin@[^\n]*(prepare|install|postinstall)|install script/i);
  const installed = JSON.parse(readFileSync(join(app, 'node_modules/gcs-skin/package.json'), 'utf8'));
  expect(Object.keys(installed.scripts ?? {}).filter((k) => /^(pre|post)?install$|^prepare$/.test(k))).toEqual([]);
  // The types carry no @internal members.
  expect(readFileSync(join(app, 'node_modules/gcs-skin/dist/index.d.ts'), 'utf8')).not.toMatch(/@internal|refreshViews|copyIn/);
  writeFileSync(join(app, 'main.mjs'), `
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
  const out = execFileSync(process.execPath, ['main.mjs'], { cwd: app, encoding: 'utf8' });
  const result = JSON.parse(out.trim().split('\n').pop()!);
  expect(result.vertices).toBe(16);
  expect(result.sections).toBe(2); // weights criterion: two rigid cores (every weight is 1.0)
  expect(result.paperSections).toBeGreaterThan(2); // the paper's rule: a shared section and inner ones
  expect(result.first.every(Number.isFinite)).toBe(true);
  expect(result.code).toBe('SECTION_COUNT');
}, 240000);
