// ?bench=gpu: what a frame costs on the GPU, ours against three.js's own skinning, in one page.
// N characters drawn by three.js's SkinnedMesh and by each GPU path and method of gcs-skin, every
// method's frame interleaved with the others' (same clip times, same layout, same pixels covered),
// timed by EXT_disjoint_timer_query_webgl2 where the browser has it (GPU time), and always by
// render + a one-pixel read-back (the frame's wall time: CPU work, upload, draw and, on a software
// rasteriser such as SwiftShader, the shaders themselves). `npm run bench:gpu` drives it headless.
//
//   ?bench=gpu&model=human|<glTF URL>&n=8&w=640&h=360&frames=40&clip=Run&methods=three,gpu,crowd,...
//   &renderer=webgpu   three/webgpu's WebGPURenderer instead (three.js's SkinnedMesh on it against
//                      gcs-skin/webgpu); &forceWebGL=1 its WebGL2 backend (headless Chromium has no WebGPU)
//
// Results: the page's table, and window.__benchGpu (a promise of the rows) for scripts.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { clone as cloneSkinned } from 'three/addons/utils/SkeletonUtils.js';
import { initGcsSkin, type DeformerKind, type GcsSkin } from '../lib/index.js';
import { GcsCharacter, writeSkinMatrices, type GcsCharacterOptions } from '../lib/three.js';
import { GcsCrowd } from '../lib/crowd.js';
import { createHuman } from '../lib/human/index.js';
import { glContext, rendererLabel, type DemoRenderer } from './renderer.js';

const query = new URLSearchParams(location.search);

/** One way of drawing the N characters. */
interface Method {
  name: string;
  /** What it is, for the table. */
  label: string;
  make(gcs: GcsSkin, sources: THREE.Object3D[]): Drawn;
}

/** A method's characters in their own scene: pose (untimed: the animation system's share, the same for all), then frame (timed). */
interface Drawn {
  scene: THREE.Scene;
  /** Per frame after the skeletons are posed: the library's own per-frame work (nothing for three.js: its skinning runs in render()). */
  update(): void;
  /** Bytes sent to the GPU per character and frame for the skinning. */
  bytesPerCharacter(): number;
  /** Why a gcs-skin build did not run on the GPU ('' when it did). */
  note(): string;
  dispose(): void;
}

/** Rows of a grid, one character per cell, all in view. */
function layout(roots: THREE.Object3D[], spacing: number): void {
  const cols = Math.ceil(Math.sqrt(roots.length));
  roots.forEach((r, i) => r.position.set(((i % cols) - (cols - 1) / 2) * spacing, 0, -Math.floor(i / cols) * spacing));
}

/** gcs-skin/three's classes, or gcs-skin/webgpu's under WebGPURenderer (set by run() before any method is made). */
const entry: { Character: typeof GcsCharacter; Crowd: typeof GcsCrowd } = { Character: GcsCharacter, Crowd: GcsCrowd };

/** `updates`: update() calls that reach the characters (then none: the frozen pose, no node pass; the vertex stage's share of the cost). */
function characters(options: GcsCharacterOptions, updates = Infinity): (gcs: GcsSkin, sources: THREE.Object3D[]) => Drawn {
  return (gcs, sources) => {
    let left = updates;
    const scene = stageScene();
    const list = sources.map((root) => {
      scene.add(root);
      return new entry.Character(gcs, root, options);
    });
    return {
      scene,
      update: () => { if (left-- > 0) for (const c of list) c.update(); },
      bytesPerCharacter: () => list.reduce((n, c) => n + c.skins.reduce((m, s) => m + s.bytesPerFrame, 0), 0) / list.length,
      note: () => [...new Set(list.flatMap((c) => c.skins.map((s) => s.backendNote)).filter(Boolean))].join('; '),
      dispose: () => { for (const c of list) c.dispose(); },
    };
  };
}

/** One GcsCrowd per skin of the character, each instance posed from one source's skeleton. */
function crowd(gcs: GcsSkin, sources: THREE.Object3D[]): Drawn {
  const scene = stageScene();
  const skinsOf = (root: THREE.Object3D) => {
    const out: THREE.SkinnedMesh[] = [];
    root.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) out.push(o as THREE.SkinnedMesh); });
    return out;
  };
  const perSource = sources.map(skinsOf);
  const crowds = perSource[0].map((skin) => new entry.Crowd(gcs, skin, sources.length));
  for (const root of sources) {
    scene.add(root);
    for (const s of skinsOf(root)) s.visible = false; // posed by the mixer, drawn by the crowd
  }
  const tmp = new THREE.Matrix4();
  for (const c of crowds) scene.add(c.mesh);
  return {
    scene,
    update: () => {
      for (let k = 0; k < crowds.length; k++) {
        const c = crowds[k];
        for (let i = 0; i < sources.length; i++) {
          const skin = perSource[i][k];
          if (k === 0) sources[i].updateMatrixWorld(true);
          writeSkinMatrices(skin, c.skins, c.offsetOf(i), tmp);
          c.mesh.setMatrixAt(i, skin.matrixWorld);
        }
        c.mesh.instanceMatrix.needsUpdate = true;
        c.update();
      }
    },
    bytesPerCharacter: () => crowds.reduce((n, c) => n + c.bytesPerFrame, 0) / sources.length,
    note: () => '',
    dispose: () => { for (const c of crowds) c.dispose(); },
  };
}

function threeSkinning(_gcs: GcsSkin, sources: THREE.Object3D[]): Drawn {
  const scene = stageScene();
  for (const root of sources) scene.add(root);
  let bones = 0;
  for (const root of sources) root.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) bones += (o as THREE.SkinnedMesh).skeleton.bones.length; });
  return { scene, update: () => {}, bytesPerCharacter: () => (bones * 64) / sources.length, note: () => '', dispose: () => {} };
}

/** The floor: the same meshes unskinned, in the bind pose (what any skinning adds to). */
function bindPose(_gcs: GcsSkin, sources: THREE.Object3D[]): Drawn {
  const scene = stageScene();
  for (const root of sources) {
    scene.add(root);
    const skins: THREE.SkinnedMesh[] = [];
    root.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) skins.push(o as THREE.SkinnedMesh); });
    for (const s of skins) {
      const still = new THREE.Mesh(s.geometry, s.material);
      still.matrixAutoUpdate = false;
      still.matrix.copy(s.matrix);
      s.parent!.add(still);
      s.visible = false;
    }
  }
  return { scene, update: () => {}, bytesPerCharacter: () => 0, note: () => '', dispose: () => {} };
}

const gpu = (method: DeformerKind, extra: GcsCharacterOptions = {}) => characters({ backend: 'gpu', method, ...extra });

const METHODS: Method[] = [
  { name: 'three', label: "three.js SkinnedMesh (LBS)", make: threeSkinning },
  { name: 'bind', label: 'bind pose, no skinning (floor)', make: bindPose },
  { name: 'gpu', label: "GcsCharacter, backend 'gpu' (default: node pass)", make: gpu('gcs') },
  { name: 'crowd', label: 'GcsCrowd (node pass)', make: crowd },
  // The warm-up's 3 frames pose them; then the same nodes are drawn: the default's frame without its node pass.
  { name: 'vertex', label: "GcsCharacter 'gpu', vertex stage only (no pass)", make: characters({ backend: 'gpu', method: 'gcs' }, 3) },
  { name: 'plain', label: "GcsCharacter 'gpu', smooth: false", make: gpu('gcs', { gcs: { smooth: false } }) },
  { name: 'sections', label: "GcsCharacter 'gpu', gpuPath: 'sections'", make: gpu('gcs', { gpuPath: 'sections' }) },
  { name: 'dqs', label: "DQS, backend 'gpu'", make: gpu('dqs') },
  { name: 'lbs', label: "LBS, backend 'gpu'", make: gpu('lbs') },
];

function stageScene(): THREE.Scene {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1b2029);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2));
  const sun = new THREE.DirectionalLight(0xffffff, 2);
  sun.position.set(2, 4, 3);
  scene.add(sun);
  return scene;
}

async function loadModel(model: string): Promise<{ make(): THREE.Object3D; clips: THREE.AnimationClip[] }> {
  if (model === 'human') {
    const first = createHuman();
    return {
      clips: first.clips,
      make: () => { const g = new THREE.Group(); g.add(createHuman().mesh); return g; },
    };
  }
  const gltf = await new GLTFLoader().loadAsync(model);
  return { clips: gltf.animations, make: () => cloneSkinned(gltf.scene) };
}

export interface BenchRow {
  method: string; label: string; msPerFrame: number; ratio: number; gpuMs: number | null; bytesPerCharacter: number;
  /** CPU ms per character-frame of the library's own update() (nothing for three.js). */
  updateMsPerCharacter: number; note: string;
}

export interface BenchResult { model: string; n: number; width: number; height: number; frames: number; timer: boolean; renderer: string; rows: BenchRow[] }

const median = (xs: number[]): number => { const s = [...xs].sort((a, b) => a - b); return s.length ? s[s.length >> 1] : NaN; };

async function run(): Promise<BenchResult> {
  const model = query.get('model') ?? 'human';
  const n = Math.max(1, Math.min(256, Number(query.get('n') ?? 8)));
  const width = Number(query.get('w') ?? 640), height = Number(query.get('h') ?? 360);
  const frames = Math.max(3, Number(query.get('frames') ?? 40));
  const wanted = (query.get('methods') ?? METHODS.map((m) => m.name).join(',')).split(',');
  const methods = METHODS.filter((m) => wanted.includes(m.name));

  let renderer: DemoRenderer;
  if (query.get('renderer') === 'webgpu') {
    const webgpu = await import('three/webgpu');
    const entryModule = await import('../lib/webgpu.js');
    entry.Character = entryModule.GcsCharacter;
    entry.Crowd = entryModule.GcsCrowd;
    renderer = new webgpu.WebGPURenderer({ antialias: false, powerPreference: 'high-performance', forceWebGL: query.get('forceWebGL') === '1' });
    await renderer.init();
  } else {
    renderer = new THREE.WebGLRenderer({ antialias: false, powerPreference: 'high-performance' });
  }
  renderer.setPixelRatio(1);
  renderer.setSize(width, height);
  document.body.replaceChildren(renderer.domElement);
  const gl = glContext(renderer);
  const timerExt = gl?.getExtension('EXT_disjoint_timer_query_webgl2') as { TIME_ELAPSED_EXT: number; GPU_DISJOINT_EXT: number } | null;
  const debug = gl?.getExtension('WEBGL_debug_renderer_info');
  const rendererName = `${rendererLabel(renderer)}: ${gl ? (debug ? String(gl.getParameter(debug.UNMASKED_RENDERER_WEBGL)) : String(gl.getParameter(gl.RENDERER))) : 'WebGPU'}`;
  const waitForGpu = gpuWait(renderer, gl);

  const gcs = await initGcsSkin();
  const { make, clips } = await loadModel(model);
  const clip = clips.find((c) => c.name === query.get('clip')) ?? clips.find((c) => /run|walk/i.test(c.name)) ?? clips[0];

  // Each method gets its own N characters (its own skeletons), laid out alike, each posed by its own mixer at the same times.
  const runs = methods.map((m) => {
    const sources = Array.from({ length: n }, make);
    const size = new THREE.Box3().setFromObject(sources[0]).getSize(new THREE.Vector3());
    layout(sources, Math.max(size.x, size.z, size.y * 0.5) * 1.2);
    const mixers = sources.map((root) => { const mixer = new THREE.AnimationMixer(root); mixer.clipAction(clip).play(); return mixer; });
    return { method: m, sources, mixers, drawn: m.make(gcs, sources), times: [] as number[], gpuTimes: [] as number[], updateTimes: [] as number[] };
  });
  const first = runs[0].sources;
  const box = new THREE.Box3();
  for (const r of first) box.expandByObject(r);
  const centre = box.getCenter(new THREE.Vector3()), extent = box.getSize(new THREE.Vector3()).length();
  const camera = new THREE.PerspectiveCamera(40, width / height, extent / 100, extent * 10);
  camera.position.copy(centre).add(new THREE.Vector3(0, 0.35, 1).normalize().multiplyScalar(extent * 1.05));
  camera.lookAt(centre);

  const pose = (r: (typeof runs)[number], f: number) => r.mixers.forEach((m, i) => m.setTime(f / 30 + i * 0.137));
  const frame = async (r: (typeof runs)[number]): Promise<{ ms: number; update: number }> => {
    const t0 = performance.now();
    r.drawn.update();
    const t1 = performance.now();
    renderer.render(r.drawn.scene, camera);
    await waitForGpu();
    return { ms: performance.now() - t0, update: t1 - t0 };
  };
  // Warm-up: compile every program, first uploads.
  for (const r of runs) for (let f = 0; f < 3; f++) { pose(r, f); r.sources.forEach((s) => s.updateMatrixWorld(true)); await frame(r); }
  for (let f = 0; f < frames; f++) {
    // Interleaved, the order rotated each frame.
    for (let k = 0; k < runs.length; k++) {
      const r = runs[(k + f) % runs.length];
      pose(r, f);
      let query: WebGLQuery | null = null;
      if (gl && timerExt) { query = gl.createQuery(); gl.beginQuery(timerExt.TIME_ELAPSED_EXT, query!); }
      const t = await frame(r);
      if (gl && timerExt && query) {
        gl.endQuery(timerExt.TIME_ELAPSED_EXT);
        await new Promise((res) => setTimeout(res, 0));
        for (let tries = 0; tries < 100 && !gl.getQueryParameter(query, gl.QUERY_RESULT_AVAILABLE); tries++) await new Promise((res) => setTimeout(res, 1));
        if (!gl.getParameter(timerExt.GPU_DISJOINT_EXT) && gl.getQueryParameter(query, gl.QUERY_RESULT_AVAILABLE)) r.gpuTimes.push(gl.getQueryParameter(query, gl.QUERY_RESULT) / 1e6);
        gl.deleteQuery(query);
      }
      r.times.push(t.ms);
      r.updateTimes.push(t.update);
    }
  }
  const base = median(runs[0].times);
  const rows: BenchRow[] = runs.map((r) => ({
    method: r.method.name, label: r.method.label, msPerFrame: median(r.times), ratio: median(r.times) / base,
    gpuMs: r.gpuTimes.length ? median(r.gpuTimes) : null, bytesPerCharacter: r.drawn.bytesPerCharacter(),
    updateMsPerCharacter: median(r.updateTimes) / n, note: r.drawn.note(),
  }));
  for (const r of runs) r.drawn.dispose();
  renderer.dispose();
  return { model, n, width, height, frames, timer: !!timerExt, renderer: rendererName, rows };
}

/**
 * What waits until the GPU has drawn the frame: on WebGL2 a one-pixel readPixels from the canvas
 * (a read-back waits for every draw into it; the renderer's read binding restored), on WebGPU the
 * queue's submitted work.
 */
function gpuWait(renderer: DemoRenderer, gl: WebGL2RenderingContext | null): () => Promise<void> {
  if (!gl) {
    const device = (renderer as unknown as { backend: { device: { queue: { onSubmittedWorkDone(): Promise<void> } } } }).backend.device;
    return () => device.queue.onSubmittedWorkDone();
  }
  const pixel = new Uint8Array(4);
  return async () => {
    const bound = gl.getParameter(gl.READ_FRAMEBUFFER_BINDING) as WebGLFramebuffer | null;
    if (bound) gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    if (bound) gl.bindFramebuffer(gl.READ_FRAMEBUFFER, bound);
  };
}

/** Runs the bench and shows its table on the page. */
export function startBench(): Promise<BenchResult> {
  const result = run();
  (window as unknown as { __benchGpu: Promise<BenchResult> }).__benchGpu = result;
  void result.then((r) => {
    const pre = document.createElement('pre');
    pre.style.cssText = 'position:fixed;left:8px;top:8px;margin:0;padding:8px;background:rgba(12,15,21,.85);color:#e8ecf2;font:12px monospace;z-index:9';
    pre.textContent = [`${r.model} ×${r.n}, ${r.width}×${r.height}, ${r.frames} frames, ${r.renderer}${r.timer ? '' : ' (no timer query: wall time of render + 1-pixel read-back)'}`,
      ...r.rows.map((x) => `${x.label.padEnd(52)} ${x.msPerFrame.toFixed(2).padStart(8)} ms  ×${x.ratio.toFixed(2)}  ${(x.bytesPerCharacter / 1024).toFixed(2)} KB/char  ${x.updateMsPerCharacter.toFixed(4)} ms/char${x.note ? `  (${x.note})` : ''}`)].join('\n');
    document.body.append(pre);
  }, (e) => { document.body.textContent = `bench failed: ${String(e)}`; });
  return result;
}
