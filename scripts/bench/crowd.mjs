// The crowd bench (part of `npm run bench`): per character and frame, the skinning CPU time and the
// bytes uploaded to the GPU, CPU backend vs the GPU backend's two paths, for 1, 10 and 100 default
// humans (17 k vertices), in the same run.
//   CPU ms: in node, the same code the demo's crowd mode runs per frame (web/demo/crowd.ts): every
//     character posed from a baked clip at its own time, then GPU backend: GcsCrowd.update() (one
//     wasm call: the joint poses of every character on the joint-level path, the default; their
//     section transforms on the section-level path); CPU backend: one GCS deformer per character
//     deforms its 17 k vertices. Rendering excluded. Median over many frames.
//   bytes: the demo's crowd page (?crowd=N&backend=…) in headless Chromium, counted on the WebGL
//     upload calls (texSubImage2D, bufferSubData, …) during renderer.render() — what the browser
//     really sends.
//   WebGPURenderer: gcs-skin/webgpu's GcsCrowd (TSL node materials) on the joint-level path, CPU ms
//     in node as above and bytes from the crowd page with &renderer=webgpu. Headless Chromium has
//     no GPU, so WebGPURenderer runs its WebGL2 fallback there and the same WebGL calls are counted
//     (real WebGPU, counted on its queue by the demo, is not measured here). Software rendering (SwiftShader) gives no GPU times; its CPU ms are printed
//     as a cross-check (performance.now() is coarse in a page).
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { GcsCrowd, bakeClip } from '../../dist/crowd.js';
import { GcsCrowd as WebGPUCrowd } from '../../dist/webgpu.js';
import { rigInputFromSkinnedMesh } from '../../dist/three.js';
import { timeFrames } from '../../dist/measure.js';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
export const CROWD_SIZES = [1, 10, 100];
export const CROWD_TARGETS = { bytes: 8 * 1024, ms: 0.01 };

/** Node: skinning CPU ms per frame for n characters on each backend. */
function cpuTimes(gcs, human, n, quick) {
  const clips = ['walk', 'run'].map((name) => bakeClip(human.mesh, human.clips.find((c) => c.name === name), 60));
  const walkers = Array.from({ length: n }, (_, i) => ({ clip: clips[i % 3 === 2 ? 1 : 0], phase: (i * 0.37) % 4, speed: 0.85 + ((i * 0.13) % 0.3) }));
  const dt = 1 / 60;
  const timing = { minSamples: quick ? 30 : 120, minMs: quick ? 100 : 400, maxMs: quick ? 1500 : 6000, warmup: 10 };
  // GPU backend, both paths.
  const gpuRun = (gpuPath, Crowd = GcsCrowd) => {
    const crowd = new Crowd(gcs, human.mesh, n, { gpuPath });
    if (crowd.sections.path !== gpuPath) throw new Error(`the crowd runs the ${crowd.sections.path} path, not ${gpuPath}`);
    const timing_ = timeFrames(240, (f) => {
      const t = f * dt;
      for (let i = 0; i < n; i++) crowd.setBakedPose(i, walkers[i].clip, t * walkers[i].speed + walkers[i].phase);
      crowd.update();
    }, timing);
    const out = { timing: timing_, sections: crowd.deformer.sectionCount, joints: crowd.jointCount, textureBytes: crowd.bytesPerFrame };
    crowd.dispose();
    return out;
  };
  const joints = gpuRun('joints');
  const sectionLevel = gpuRun('sections');
  const webgpu = gpuRun('joints', WebGPUCrowd);
  // CPU backend: a deformer per character, as GcsCharacter / the demo.
  const rig = gcs.createRig(rigInputFromSkinnedMesh(human.mesh));
  const deformers = Array.from({ length: n }, () => rig.buildGcs({}));
  const J = rig.jointCount, scratch = new Float32Array(J * 16);
  const cpu = timeFrames(240, (f) => {
    const t = f * dt;
    for (let i = 0; i < n; i++) {
      const w = walkers[i], c = w.clip;
      let k = Math.floor((t * w.speed + w.phase) * c.fps) % c.frames;
      if (k < 0) k += c.frames;
      const s = k * J * 16;
      for (let q = 0; q < J * 16; q++) scratch[q] = c.data[s + q];
      deformers[i].deform(scratch);
    }
  }, { ...timing, minSamples: quick ? 10 : 40, maxMs: quick ? 2000 : 8000 });
  for (const d of deformers) d.dispose();
  rig.dispose();
  return { gpu: joints.timing, gpuSections: sectionLevel.timing, gpuWebgpu: webgpu.timing, cpu, sections: joints.sections, joints: joints.joints,
    textureBytes: joints.textureBytes, sectionTextureBytes: sectionLevel.textureBytes };
}

/** Chromium: bytes uploaded per frame by the demo's crowd page, and its own CPU ms, per backend and size. */
async function browserBytes(sizes, quick, log) {
  const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
  if (!existsSync(chromiumPath)) return { skipped: `no Chromium at ${chromiumPath}: bytes uploaded not measured (set CHROMIUM=/path)` };
  const { build, preview } = await import('vite');
  const { chromium } = await import('playwright-core');
  const configFile = join(root, 'web/demo/vite.config.ts');
  const dist = mkdtempSync(join(tmpdir(), 'gcs-crowd-bench-'));
  await build({ configFile, logLevel: 'error', build: { outDir: dist, emptyOutDir: true } });
  const server = await preview({ configFile, logLevel: 'error', build: { outDir: dist }, preview: { host: '127.0.0.1', port: 0 } });
  const url = server.resolvedUrls.local[0];
  const context = await chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'gcs-chromium-')), {
    executablePath: chromiumPath, headless: true, viewport: { width: 480, height: 270 },
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  const out = {};
  const runs = { cpu: 'backend=cpu', gpu: 'backend=gpu&path=joints', gpuSections: 'backend=gpu&path=sections', gpuWebgpu: 'backend=gpu&path=joints&renderer=webgpu' };
  try {
    for (const [backend, params] of Object.entries(runs)) {
      for (const n of sizes) {
        const page = await context.newPage();
        const errors = [];
        page.on('pageerror', (e) => errors.push(e.message));
        await page.goto(`${url}?crowd=${n}&${params}`);
        await page.waitForFunction(() => window.__crowd !== undefined && window.__crowd.frame() > 2, null, { timeout: 300000 });
        const frames = n >= 100 ? 3 : quick ? 5 : 10;
        const m = await page.evaluate((f) => window.__crowd.measure(f), frames);
        if (errors.length) throw new Error(`crowd page (${n}, ${backend}): ${errors.join('; ')}`);
        out[`${backend}-${n}`] = m;
        log(`bench: crowd page ${backend} × ${n}: ${m.bytesPerFrame} bytes/frame, ${m.msPerFrame.toFixed(2)} ms skinning (page clock)`);
        await page.close();
      }
    }
  } finally {
    await context.close();
    await new Promise((r) => server.httpServer.close(r));
    rmSync(dist, { recursive: true, force: true });
  }
  return out;
}

/** The whole crowd bench: rows per size (`gpu`: the joint-level path, the default; `gpuSections`: the section-level path), targets met/missed on the default path. */
export async function crowdBench(gcs, human, { quick = false, log = console.log, sizes = CROWD_SIZES } = {}) {
  const rows = [];
  for (const n of sizes) {
    log(`bench: crowd of ${n} (node, CPU time)…`);
    const t = cpuTimes(gcs, human, n, quick);
    rows.push({ characters: n, sections: t.sections, joints: t.joints, vertices: human.mesh.geometry.getAttribute('position').count,
      gpu: { path: 'joints', msPerFrame: t.gpu.medianMs, msPerCharacter: t.gpu.medianMs / n, p95Ms: t.gpu.p95Ms, textureBytes: t.textureBytes },
      gpuSections: { path: 'sections', msPerFrame: t.gpuSections.medianMs, msPerCharacter: t.gpuSections.medianMs / n, p95Ms: t.gpuSections.p95Ms, textureBytes: t.sectionTextureBytes },
      gpuWebgpu: { path: 'joints', renderer: 'WebGPURenderer', msPerFrame: t.gpuWebgpu.medianMs, msPerCharacter: t.gpuWebgpu.medianMs / n, p95Ms: t.gpuWebgpu.p95Ms, textureBytes: t.textureBytes },
      cpu: { msPerFrame: t.cpu.medianMs, msPerCharacter: t.cpu.medianMs / n, p95Ms: t.cpu.p95Ms } });
  }
  const browser = await browserBytes(sizes, quick, log);
  for (const r of rows) {
    for (const b of ['cpu', 'gpu', 'gpuSections', 'gpuWebgpu']) {
      const m = browser[`${b}-${r.characters}`];
      r[b].bytesPerFrame = m ? m.bytesPerFrame : null;
      r[b].bytesPerCharacter = m ? m.bytesPerFrame / r.characters : null;
      r[b].pageMsPerFrame = m ? m.msPerFrame : null;
      if (m?.renderer) r[b].rendererLabel = m.renderer;
    }
  }
  const at = (n) => rows.find((r) => r.characters === n) ?? rows[rows.length - 1];
  const worstBytes = Math.max(...rows.map((r) => r.gpu.bytesPerCharacter ?? NaN));
  const worstMs = Math.max(...rows.map((r) => r.gpu.msPerCharacter));
  const sectionNote = (key) => `section-level path: ${rows.map((r) => key === 'ms' ? `${r.gpuSections.msPerCharacter.toPrecision(3)} ms` : r.gpuSections.bytesPerCharacter === null ? 'n/a' : `${(r.gpuSections.bytesPerCharacter / 1024).toFixed(1)} KB`).join(' / ')}`;
  const targets = [
    { name: 'GPU backend bytes uploaded per character-frame (17 k vertices)', value: Number.isNaN(worstBytes) ? null : worstBytes, unit: 'bytes',
      goal: '≤ 8 KB', met: Number.isNaN(worstBytes) ? null : worstBytes <= CROWD_TARGETS.bytes,
      note: browser.skipped ?? `joint-level path, worst of ${sizes.join(', ')} characters (${sectionNote('bytes')})` },
    { name: 'GPU backend CPU ms per character-frame (17 k vertices)', value: worstMs, unit: 'ms', goal: '≤ 0.01 ms', met: worstMs <= CROWD_TARGETS.ms,
      note: `joint-level path, worst of ${sizes.join(', ')} characters; ${at(100).gpu.msPerCharacter.toPrecision(3)} ms at ${at(100).characters} (${sectionNote('ms')})` },
  ];
  return { rows, browser: browser.skipped ? { skipped: browser.skipped } : {}, targets };
}
