// Renders the default human walking (three views) in headless Chromium and writes
// docs/human-walk.png. Usage: node scripts/screenshot-human.mjs [out.png] [--clip walk] [--pose stand]
import { createServer } from 'vite';
import { chromium } from 'playwright-core';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.join(path.dirname(fileURLToPath(import.meta.url)), '..');
const args = process.argv.slice(2);
const flag = (name, def) => { const i = args.indexOf(name); return i >= 0 ? args.splice(i, 2)[1] : def; };
const clip = flag('--clip', 'walk');
const pose = flag('--pose', 'stand');
const out = path.resolve(args[0] ?? path.join(root, 'docs', 'human-walk.png'));

const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'human-shot-'));
fs.writeFileSync(path.join(dir, 'index.html'), `<!doctype html><html><body style="margin:0;background:#fff">
<canvas id="c" width="1200" height="700"></canvas><script type="module" src="./main.js"></script></body></html>`);
fs.writeFileSync(path.join(dir, 'main.js'), `
import * as THREE from 'three';
import { createHuman } from '${path.join(root, 'web/lib/human/index.ts')}';
const W = 1200, H = 700;
const renderer = new THREE.WebGLRenderer({ canvas: document.getElementById('c'), antialias: true });
renderer.setSize(W, H, false);
renderer.shadowMap.enabled = true;
renderer.setScissorTest(true);
const views = [
  { phase: 0.12, yaw: -0.55, label: 'front 3/4' },
  { phase: 0.37, yaw: -Math.PI / 2, label: 'side' },
  { phase: 0.62, yaw: -2.6, label: 'back 3/4' },
];
const t0 = performance.now();
const human = createHuman({ pose: ${JSON.stringify(pose)} });
const buildMs = performance.now() - t0;
views.forEach((v, i) => {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xe9edf2);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8a7f70, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 2.2);
  sun.position.set(2, 4, 3); sun.castShadow = true;
  sun.shadow.mapSize.set(1024, 1024);
  Object.assign(sun.shadow.camera, { left: -1.5, right: 1.5, top: 2.2, bottom: -0.5 });
  scene.add(sun);
  const ground = new THREE.Mesh(new THREE.CircleGeometry(1.6, 48), new THREE.MeshStandardMaterial({ color: 0xcfd5dc }));
  ground.rotation.x = -Math.PI / 2; ground.receiveShadow = true; scene.add(ground);
  const h = i === 0 ? human : createHuman({ pose: ${JSON.stringify(pose)} });
  h.mesh.castShadow = true;
  h.mesh.rotation.y = v.yaw;
  scene.add(h.mesh);
  const mixer = new THREE.AnimationMixer(h.mesh);
  const c = h.clips.find((c) => c.name === ${JSON.stringify(clip)});
  mixer.clipAction(c).play();
  mixer.setTime(v.phase * c.duration);
  const cam = new THREE.PerspectiveCamera(30, (W / 3) / H, 0.1, 20);
  cam.position.set(0, 1.0, 4.1); cam.lookAt(0, 0.88, 0);
  renderer.setViewport(i * W / 3, 0, W / 3, H);
  renderer.setScissor(i * W / 3, 0, W / 3, H);
  renderer.render(scene, cam);
});
const d = human.data;
window.__done = { vertices: d.positions.length / 3, triangles: d.indices.length / 3, buildMs };
`);

const server = await createServer({
  root: dir,
  logLevel: 'error',
  configFile: false,
  resolve: { alias: { three: path.join(root, 'node_modules/three') } },
  server: { port: 5199, strictPort: false, fs: { allow: [dir, root] } },
});
await server.listen();
const url = server.resolvedUrls.local[0];
const ctx = await chromium.launchPersistentContext(fs.mkdtempSync(path.join(os.tmpdir(), 'human-chrome-')), {
  executablePath: '/usr/bin/chromium',
  headless: true,
  viewport: { width: 1200, height: 700 },
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  const page = await ctx.newPage();
  page.on('console', (m) => console.log('[page]', m.text()));
  page.on('pageerror', (e) => console.error('[page error]', e.message));
  await page.goto(url);
  const info = await page.waitForFunction(() => window.__done, null, { timeout: 120000 }).then((h) => h.jsonValue());
  fs.mkdirSync(path.dirname(out), { recursive: true });
  await page.locator('#c').screenshot({ path: out });
  console.log(`wrote ${out}`, info);
} finally {
  await ctx.close();
  await server.close();
  fs.rmSync(dir, { recursive: true, force: true });
}
