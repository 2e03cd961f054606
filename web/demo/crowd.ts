// The demo's crowd mode (?crowd=N): N copies of the default human (17 k vertices), each walking or
// running at its own phase, deformed by GCS on the GPU backend (one GcsCrowd: one instanced draw,
// one per-frame texture: the joint poses, or on the section-level path the section transforms) or
// on the CPU backend (one wasm deformer and one mesh per character, as GcsCharacter does), switchable. On screen: the CPU time of a frame's skinning (posing every
// character + section transforms or vertex deformation; rendering excluded) and the bytes the
// frame uploads to the GPU, counted on the WebGL calls themselves.
//
// URL: ?crowd=N (1 … 500; default 100) &backend=gpu|cpu &path=joints|sections (the GPU path)
//      &renderer=webgl|webgpu (WebGLRenderer + gcs-skin/crowd, or WebGPURenderer + gcs-skin/webgpu)
//      &smooth=0 (the stepped plain mode) &shadows=1 &paused=1
//      &vertices=V (the human's vertex count, default 17,023)
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import Stats from 'three/addons/libs/stats.module.js';
import GUI from 'three/addons/libs/lil-gui.module.min.js';
import { initGcsSkin, type GcsDeformer, type GcsSkin, type Rig } from '../lib/index.js';
import { bakeClip, GcsCrowd, type BakedClip } from '../lib/crowd.js';
import { rigInputFromSkinnedMesh } from '../lib/three.js';
import { humanFromData, type Human, type HumanData } from '../lib/human/index.js';
import { distanceToFit } from './fit-box.js';
import { humanDataInWorker } from './human-data.js';
import { applySidebar, sidebarWidth } from './layout.js';
import { SteadyFigure } from './steady-figure.js';
import { addRendererSwitch, createRenderer, glContext, rendererKind, rendererLabel, type DemoRenderer } from './renderer.js';

export const MAX_CROWD = 500;
/** The CPU backend keeps a deformer (about 1.4 MB of wasm memory at 17 k vertices) per character. */
export const MAX_CPU_CROWD = 200;
const SPACING = 1.1;
/** A walking human's reach around its feet and its height (world units): what framing keeps in the picture. */
const CHARACTER_RADIUS = 0.5;
const CHARACTER_HEIGHT = 1.85;
/** From the crowd's centre, where the camera looks from. */
const VIEW_DIRECTION = new THREE.Vector3(0.55, 0.45, 0.95).normalize();

type Backend = 'gpu' | 'cpu';
type Path = 'joints' | 'sections';
const PATH_NAMES: Record<Path, string> = { joints: 'joint poses', sections: 'section transforms' };
const query = new URLSearchParams(location.search);

/** True when the page was opened with ?crowd. */
export function crowdRequested(): boolean {
  return query.has('crowd');
}

/**
 * Bytes uploaded to the GPU, counted on the calls that upload (textures and buffers): WebGL's
 * (WebGLRenderer, or WebGPURenderer's WebGL2 fallback) or, on real WebGPU, the device queue's.
 */
class UploadCounter {
  bytes = 0;
  constructor(renderer: DemoRenderer) {
    const gl = glContext(renderer);
    if (gl) this.countGl(gl);
    else this.countQueue((renderer as unknown as { backend: { device: { queue: object } } }).backend.device.queue);
  }

  private countQueue(queue: object): void {
    const q = queue as unknown as Record<string, (...a: unknown[]) => unknown>;
    const writeBuffer = q.writeBuffer.bind(queue), writeTexture = q.writeTexture.bind(queue);
    q.writeBuffer = (...a: unknown[]) => {
      const data = a[2] as ArrayBufferView | ArrayBuffer;
      this.bytes += (a[4] as number | undefined) ?? data.byteLength;
      return writeBuffer(...a);
    };
    q.writeTexture = (...a: unknown[]) => {
      const layout = a[2] as { bytesPerRow?: number }, size = a[3] as { height?: number; depthOrArrayLayers?: number } & number[];
      this.bytes += (layout.bytesPerRow ?? 0) * (size.height ?? size[1] ?? 1) * (size.depthOrArrayLayers ?? size[2] ?? 1);
      return writeTexture(...a);
    };
  }

  private countGl(gl: WebGL2RenderingContext): void {
    const channels: Record<number, number> = { [gl.RGBA]: 4, [gl.RGB]: 3, [gl.RG]: 2, [gl.RED]: 1, [gl.RGBA_INTEGER]: 4, [gl.RED_INTEGER]: 1, [gl.LUMINANCE]: 1, [gl.ALPHA]: 1, [gl.LUMINANCE_ALPHA]: 2 };
    const size: Record<number, number> = { [gl.FLOAT]: 4, [gl.HALF_FLOAT]: 2, [gl.UNSIGNED_BYTE]: 1, [gl.BYTE]: 1, [gl.UNSIGNED_SHORT]: 2, [gl.SHORT]: 2, [gl.UNSIGNED_INT]: 4, [gl.INT]: 4 };
    const texel = (format: number, type: number) => (channels[format] ?? 4) * (size[type] ?? 1);
    const g = gl as unknown as Record<string, (...a: unknown[]) => unknown>;
    const wrap = (name: string, count: (a: unknown[]) => number) => {
      const f = g[name].bind(gl);
      g[name] = (...a: unknown[]) => {
        this.bytes += count(a);
        return f(...a);
      };
    };
    const view = (x: unknown) => (ArrayBuffer.isView(x) ? x : null);
    // texSubImage2D(target, level, x, y, w, h, format, type, data…) / (target, level, x, y, format, type, source)
    wrap('texSubImage2D', (a) => (a.length >= 9 ? (a[4] as number) * (a[5] as number) * texel(a[6] as number, a[7] as number)
      : (((a[6] as { width?: number }).width ?? 0) * ((a[6] as { height?: number }).height ?? 0) * texel(a[4] as number, a[5] as number))));
    wrap('texImage2D', (a) => (a.length >= 9 && a[8] ? (a[3] as number) * (a[4] as number) * texel(a[6] as number, a[7] as number) : 0));
    wrap('texSubImage3D', (a) => (a[10] ? (a[5] as number) * (a[6] as number) * (a[7] as number) * texel(a[8] as number, a[9] as number) : 0));
    wrap('bufferSubData', (a) => {
      const v = view(a[2]);
      if (!v) return 0;
      const bpe = (v as unknown as { BYTES_PER_ELEMENT?: number }).BYTES_PER_ELEMENT ?? 1;
      return a[4] ? (a[4] as number) * bpe : v.byteLength - ((a[3] as number) ?? 0) * bpe;
    });
    wrap('bufferData', (a) => view(a[1])?.byteLength ?? 0);
  }
}

/** One character's animation state: which baked clip, its phase and speed. */
interface Walker {
  clip: number;
  phase: number;
  speed: number;
}

/** The CPU backend: a GCS deformer and a mesh per character (vertex buffers uploaded each frame). */
class CpuCrowd {
  readonly group = new THREE.Group();
  readonly deformers: GcsDeformer[] = [];
  private readonly scratch: Float32Array;
  constructor(rig: Rig, count: number, material: THREE.Material, smooth: boolean) {
    this.scratch = new Float32Array(rig.jointCount * 16);
    for (let i = 0; i < count; i++) {
      const d = rig.buildGcs({ smooth });
      this.deformers.push(d);
      const g = new THREE.BufferGeometry();
      g.setIndex(new THREE.BufferAttribute(d.indices, 1));
      g.setAttribute('position', new THREE.BufferAttribute(d.positions, 3).setUsage(THREE.DynamicDrawUsage));
      g.setAttribute('normal', new THREE.BufferAttribute(d.normals, 3).setUsage(THREE.DynamicDrawUsage));
      const mesh = new THREE.Mesh(g, material);
      mesh.frustumCulled = false;
      this.group.add(mesh);
    }
  }
  pose(i: number, clip: BakedClip, time: number): void {
    const n = clip.jointCount * 16;
    let f = Math.floor(time * clip.fps) % clip.frames;
    if (f < 0) f += clip.frames;
    const src = clip.data, s = f * n, dst = this.scratch;
    for (let k = 0; k < n; k++) dst[k] = src[s + k];
    const d = this.deformers[i];
    d.deform(dst);
    const g = (this.group.children[i] as THREE.Mesh).geometry;
    const p = g.getAttribute('position') as THREE.BufferAttribute, nrm = g.getAttribute('normal') as THREE.BufferAttribute;
    const pos = d.positions, nor = d.normals; // views re-created after memory growth
    if (p.array !== pos) p.array = pos;
    if (nrm.array !== nor) nrm.array = nor;
    p.needsUpdate = true;
    nrm.needsUpdate = true;
  }
  dispose(): void {
    for (const d of this.deformers) d.dispose();
    for (const m of this.group.children) (m as THREE.Mesh).geometry.dispose();
    this.group.removeFromParent();
  }
}

function clampCount(n: number): number {
  return Math.max(1, Math.min(MAX_CROWD, Math.round(Number.isFinite(n) ? n : 100)));
}

/** Starts the crowd page; resolves once the first frames are drawn. */
export async function startCrowd(): Promise<void> {
  const params = {
    characters: clampCount(Number(query.get('crowd') || 100)),
    backend: (query.get('backend') === 'cpu' ? 'cpu' : 'gpu') as Backend,
    path: (query.get('path') === 'sections' ? 'sections' : 'joints') as Path,
    smooth: query.get('smooth') !== '0', // the default: no steps
    shadows: query.get('shadows') === '1',
    paused: query.get('paused') === '1',
  };
  const status = document.getElementById('status')!;
  status.hidden = false;
  status.textContent = 'building… generating the human character';
  for (const id of ['hint', 'credit']) document.getElementById(id)?.remove();
  const kind = rendererKind();
  const renderer = await createRenderer(kind);
  renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
  // The picture left of the control column (opaque), as in the comparison views.
  renderer.setSize(applySidebar(), window.innerHeight);
  renderer.shadowMap.enabled = params.shadows;
  document.body.prepend(renderer.domElement);
  const counter = new UploadCounter(renderer);
  // WebGPURenderer draws the crowd with gcs-skin/webgpu's GcsCrowd (node materials, TSL).
  const Crowd: typeof GcsCrowd = kind === 'webgpu' ? (await import('../lib/webgpu.js')).GcsCrowd : GcsCrowd;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x242a35);
  scene.fog = new THREE.Fog(0x242a35, 18, 60);
  scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x3a3024, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 2.2);
  sun.position.set(6, 12, 8);
  sun.castShadow = true;
  sun.shadow.mapSize.set(2048, 2048);
  scene.add(sun, sun.target);
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(200, 200), new THREE.MeshStandardMaterial({ color: 0x3b4350, roughness: 0.95 }));
  ground.rotation.x = -Math.PI / 2;
  ground.receiveShadow = true;
  scene.add(ground);
  const camera = new THREE.PerspectiveCamera(40, (window.innerWidth - sidebarWidth()) / window.innerHeight, 0.1, 200);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.enableDamping = true;
  const stats = new Stats();
  document.body.append(stats.dom);
  const readout = document.createElement('div');
  readout.className = 'readout';
  readout.style.left = '10px';
  readout.dataset.view = 'crowd';
  document.getElementById('readouts')!.append(readout);

  const vertices = query.has('vertices') ? Number(query.get('vertices')) : undefined;
  const [gcs, data] = await Promise.all([initGcsSkin(), humanDataInWorker({ vertices })]) as [GcsSkin, HumanData];
  const human: Human = humanFromData(data);
  const source = human.mesh;
  const material = new THREE.MeshStandardMaterial({ color: 0xd9a58a, roughness: 0.62, metalness: 0 });
  source.material = material;
  source.castShadow = true;
  const rig = gcs.createRig(rigInputFromSkinnedMesh(source));
  const clips = ['walk', 'run'].map((name) => bakeClip(source, human.clips.find((c) => c.name === name)!, 60));

  let gpuCrowd: GcsCrowd | null = null;
  let cpuCrowd: CpuCrowd | null = null;
  let walkers: Walker[] = [];
  let count = 0;
  let backend: Backend = params.backend;
  let note = '';
  const placement = new THREE.Matrix4();
  const positionOf = (i: number, n: number, out: THREE.Vector3) => {
    const side = Math.ceil(Math.sqrt(n));
    const row = Math.floor(i / side), col = i % side;
    // A staggered grid, facing the camera, centred on the origin.
    return out.set((col - (side - 1) / 2) * SPACING + (row % 2) * SPACING * 0.35, 0, (row - (Math.ceil(n / side) - 1) / 2) * SPACING);
  };

  /** (Re)builds the crowd for the current count and backend. */
  const build = () => {
    gpuCrowd?.dispose();
    cpuCrowd?.dispose();
    gpuCrowd = cpuCrowd = null;
    const wanted = params.characters;
    backend = params.backend;
    count = backend === 'cpu' ? Math.min(wanted, MAX_CPU_CROWD) : wanted;
    note = count < wanted ? `CPU backend: ${MAX_CPU_CROWD} characters at most (a deformer of ~1.4 MB wasm memory each)` : '';
    let seed = 12345;
    const random = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 4294967296);
    walkers = Array.from({ length: count }, (_, i) => ({ clip: i % 3 === 2 ? 1 : 0, phase: random() * 4, speed: 0.85 + 0.3 * random() }));
    const p = new THREE.Vector3();
    if (backend === 'gpu') {
      gpuCrowd = new Crowd(gcs, source, count, { gcs: { smooth: params.smooth }, gpuPath: params.path });
      gpuCrowd.mesh.castShadow = true;
      for (let i = 0; i < count; i++) gpuCrowd.mesh.setMatrixAt(i, placement.makeTranslation(positionOf(i, count, p)));
      gpuCrowd.mesh.instanceMatrix.needsUpdate = true;
      scene.add(gpuCrowd.mesh);
    } else {
      cpuCrowd = new CpuCrowd(rig, count, material, params.smooth);
      cpuCrowd.group.children.forEach((m, i) => {
        m.position.copy(positionOf(i, count, p));
        m.castShadow = true;
      });
      scene.add(cpuCrowd.group);
    }
    const side = Math.ceil(Math.sqrt(count)) * SPACING;
    frameCrowd();
    sun.shadow.camera.left = sun.shadow.camera.bottom = -side;
    sun.shadow.camera.right = sun.shadow.camera.top = side;
    sun.shadow.camera.updateProjectionMatrix();
    renderer.shadowMap.enabled = params.shadows;
    samples.length = 0;
    steadyMs.reset();
    steadyBytes.reset();
    readoutDue = true;
  };

  /** Every character's box (its ground square, its height), world units. */
  const characterBoxes = (each: (box: THREE.Box3) => void) => {
    const p = new THREE.Vector3(), box = new THREE.Box3();
    for (let i = 0; i < count; i++) {
      positionOf(i, count, p);
      box.min.set(p.x - CHARACTER_RADIUS, 0, p.z - CHARACTER_RADIUS);
      box.max.set(p.x + CHARACTER_RADIUS, CHARACTER_HEIGHT, p.z + CHARACTER_RADIUS);
      each(box);
    }
  };

  /** Points the camera at the crowd and backs off until every character fits the picture (left of the controls). */
  const frameCrowd = () => {
    const all = new THREE.Box3();
    characterBoxes((b) => all.union(b));
    const centre = all.getCenter(new THREE.Vector3());
    const tanV = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) * 0.9;
    const distance = distanceToFit(all, VIEW_DIRECTION, tanV * camera.aspect * 0.95, tanV);
    camera.position.copy(centre).addScaledVector(VIEW_DIRECTION, distance);
    controls.target.copy(centre);
    controls.update();
  };

  /** The characters' extent on the page (px), their boxes projected by the camera onto the canvas. */
  const screenBounds = () => {
    camera.updateMatrixWorld();
    const canvas = renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector3();
    let left = Infinity, right = -Infinity, top = Infinity, bottom = -Infinity;
    characterBoxes((b) => {
      for (let i = 0; i < 8; i++) {
        p.set(i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z).project(camera);
        const px = canvas.left + (p.x + 1) / 2 * canvas.width, py = canvas.top + (1 - p.y) / 2 * canvas.height;
        left = Math.min(left, px); right = Math.max(right, px); top = Math.min(top, py); bottom = Math.max(bottom, py);
      }
    });
    return { left, right, top, bottom };
  };

  // Per frame: pose every character at its own time, then the backend's skinning. Timed (CPU).
  let time = 0;
  const skinning = (): void => {
    if (gpuCrowd) {
      for (let i = 0; i < count; i++) {
        const w = walkers[i];
        gpuCrowd.setBakedPose(i, clips[w.clip], time * w.speed + w.phase);
      }
      gpuCrowd.update();
    } else if (cpuCrowd) {
      for (let i = 0; i < count; i++) {
        const w = walkers[i];
        cpuCrowd.pose(i, clips[w.clip], time * w.speed + w.phase);
      }
    }
  };

  const samples: { ms: number; bytes: number }[] = [];
  let frame = 0;
  // The readout's figures: steady medians, "warming up" before (the first frames upload whole buffers).
  const steadyMs = new SteadyFigure(), steadyBytes = new SteadyFigure();
  let readoutDue = true; // a rebuild shows its settings at once, its figures when steady
  const waiters: { frames: number; resolve: (r: CrowdMeasure) => void; start: number }[] = [];
  const fmtBytes = (b: number) => (b >= 1e6 ? `${(b / 1e6).toFixed(2)} MB` : b >= 1e3 ? `${(b / 1e3).toFixed(1)} KB` : `${b.toFixed(0)} B`);
  const clock = new THREE.Timer();
  clock.connect(document);

  const gui = new GUI({ title: 'Crowd' });
  addRendererSwitch(gui, kind);
  gui.add(params, 'characters', 1, MAX_CROWD, 1).name('characters').onFinishChange(() => build());
  gui.add(params, 'backend', { 'GPU (vertex shader)': 'gpu', 'CPU (wasm, every vertex)': 'cpu' }).name('backend').onChange(() => build());
  gui.add(params, 'path', { 'joint poses': 'joints', 'section transforms': 'sections' }).name('GPU path').onChange(() => build());
  gui.add(params, 'smooth').name('smooth (no steps)').onChange(() => build());
  gui.add(params, 'shadows').onChange(() => { renderer.shadowMap.enabled = params.shadows; });
  gui.add(params, 'paused');

  build();
  status.hidden = true;

  const onResize = () => {
    const width = applySidebar();
    camera.aspect = width / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(width, window.innerHeight);
    frameCrowd();
  };
  window.addEventListener('resize', onResize);

  renderer.setAnimationLoop((now: number) => {
    clock.update(now);
    if (!params.paused) time += clock.getDelta();
    const t0 = performance.now();
    skinning();
    const ms = performance.now() - t0;
    controls.update();
    counter.bytes = 0;
    renderer.render(scene, camera);
    const bytes = counter.bytes;
    frame++;
    samples.push({ ms, bytes });
    if (samples.length > 240) samples.shift();
    for (let k = waiters.length - 1; k >= 0; k--) {
      const w = waiters[k];
      if (frame - w.start >= w.frames) {
        waiters.splice(k, 1);
        w.resolve(measureLast(w.frames));
      }
    }
    steadyMs.add(ms);
    steadyBytes.add(bytes);
    if (readoutDue || frame % 10 === 1) {
      readoutDue = false;
      const head = `<b>${count}</b> characters × ${source.geometry.getAttribute('position').count.toLocaleString('en')} vertices · ${rendererLabel(renderer)} · <b>${backend.toUpperCase()}</b> backend` +
        `${gpuCrowd ? ` (${PATH_NAMES[gpuCrowd.sections.path]})` : ''}${params.smooth ? ' (smooth)' : ''}`;
      const perFrame = steadyMs.value(), uploaded = steadyBytes.value();
      const figures = Number.isNaN(perFrame) || Number.isNaN(uploaded)
        ? 'skinning CPU and uploads per frame: <b>warming up…</b>'
        : `skinning CPU <b>${perFrame.toFixed(2)} ms</b>/frame (${(perFrame / count * 1000).toFixed(1)} µs per character)` +
          ` · uploaded <b>${fmtBytes(uploaded)}</b>/frame (${fmtBytes(uploaded / count)} per character)`;
      readout.innerHTML = `${head}<br>${figures}${note ? `<br><span class="criterion">${note}</span>` : ''}`;
    }
    stats.update();
  });

  const median = (a: number[]) => { const s = [...a].sort((x, y) => x - y); return s.length ? s[Math.floor(s.length / 2)] : NaN; };
  const measureLast = (frames: number): CrowdMeasure => {
    const last = samples.slice(-frames);
    const ms = median(last.map((s) => s.ms)), bytes = median(last.map((s) => s.bytes));
    return { renderer: rendererLabel(renderer), characters: count, backend, path: gpuCrowd?.sections.path ?? null, joints: rig.jointCount, frames: last.length, msPerFrame: ms, bytesPerFrame: bytes, msPerCharacter: ms / count, bytesPerCharacter: bytes / count,
      vertices: source.geometry.getAttribute('position').count, sections: gpuCrowd?.deformer.sectionCount ?? cpuCrowd?.deformers[0]?.sectionCount ?? 0 };
  };

  Object.assign(window, {
    __crowd: {
      frame: () => frame,
      count: () => count,
      backend: () => backend,
      /** Characters drawn: instances of the GPU crowd's one mesh, or the CPU backend's meshes. */
      drawn: () => (gpuCrowd ? gpuCrowd.mesh.count : cpuCrowd ? cpuCrowd.group.children.length : 0),
      /** WebGLRenderer's count; WebGPURenderer's WebGL2 fallback counts none (its `drawCalls` stays 0). */
      drawCalls: () => { const r = renderer.info.render as { calls: number; drawCalls?: number }; return r.drawCalls ?? r.calls; },
      renderer: () => rendererLabel(renderer),
      readout: () => readout.textContent ?? '',
      set: (n: number, b: Backend = params.backend, path: Path = params.path) => { params.characters = clampCount(n); params.backend = b; params.path = path; gui.controllersRecursive().forEach((c) => c.updateDisplay()); build(); },
      /** Medians over the next `frames` frames: skinning CPU ms and bytes uploaded, per frame and per character. */
      measure: (frames: number) => new Promise<CrowdMeasure>((resolve) => waiters.push({ frames, resolve, start: frame })),
      pause: (t?: number) => { params.paused = true; if (t !== undefined) time = t; },
      /** The characters' extent on the page (px): their boxes as the camera projects them. */
      screenBounds,
    },
  });
  await new Promise<void>((resolve) => { const f = frame; const wait = () => (frame > f + 1 ? resolve() : setTimeout(wait, 16)); wait(); });
}

export interface CrowdMeasure {
  /** rendererLabel(): which renderer (and WebGPURenderer's backend) drew */
  renderer: string;
  characters: number;
  backend: Backend;
  /** GPU backend: its path; null on the CPU backend. */
  path: Path | null;
  joints: number;
  frames: number;
  msPerFrame: number;
  bytesPerFrame: number;
  msPerCharacter: number;
  bytesPerCharacter: number;
  vertices: number;
  sections: number;
}
