// The demo's crowd mode (?crowd=N): N copies of the default human (17 k vertices), each walking or
// running at its own phase, deformed by GCS on the GPU backend (one GcsCrowd: one instanced draw,
// one per-frame texture: the joint poses, or on the section-level path the section transforms) or
// on the CPU backend (one wasm deformer and one mesh per character, as GcsCharacter does),
// switchable. On screen: the CPU time of a frame's skinning (posing every
// character + section transforms or vertex deformation; rendering excluded) and the bytes the
// frame uploads to the GPU, counted on the WebGL calls themselves. The page's parts: crowd-scene
// (stage), crowd-layout (grid, framing), crowd-cpu (the CPU backend), crowd-uploads (the byte
// meter), crowd-readout (the figures).
//
// URL: ?crowd=N (1 … 500; default 100) &backend=gpu|cpu &path=joints|sections (the GPU path)
//      &renderer=webgl|webgpu (WebGLRenderer + gcs-skin/crowd, or WebGPURenderer + gcs-skin/webgpu)
//      &smooth=0 (the stepped plain mode) &shadows=1 &paused=1
//      &vertices=V (the human's vertex count, default 17,023)
import * as THREE from 'three';
import Stats from 'three/addons/libs/stats.module.js';
import GUI from 'three/addons/libs/lil-gui.module.min.js';
import { initGcsSkin, type GcsSkin, type Rig } from '../lib/index.js';
import { bakeClip, GcsCrowd, type BakedClip } from '../lib/crowd.js';
import { rigInputFromSkinnedMesh } from '../lib/three.js';
import { humanFromData, type Human, type HumanData } from '../lib/human/index.js';
import { CpuCrowd, type Walker } from './crowd-cpu.js';
import { CrowdLayout } from './crowd-layout.js';
import { CrowdReadout } from './crowd-readout.js';
import { createStage, fitShadow } from './crowd-scene.js';
import { UploadCounter } from './crowd-uploads.js';
import { humanDataInWorker } from './human-data.js';
import { applySidebar } from './layout.js';
import { addRendererSwitch, createRenderer, rendererKind, rendererLabel } from './renderer.js';

export const MAX_CROWD = 500;
/** The CPU backend keeps a deformer (about 1.4 MB of wasm memory at 17 k vertices) per character. */
export const MAX_CPU_CROWD = 200;

type Backend = 'gpu' | 'cpu';
type Path = 'joints' | 'sections';
const PATH_NAMES: Record<Path, string> = { joints: 'joint poses', sections: 'section transforms' };
const query = new URLSearchParams(location.search);

/** True when the page was opened with ?crowd. */
export function crowdRequested(): boolean {
  return query.has('crowd');
}

function clampCount(n: number): number {
  return Math.max(1, Math.min(MAX_CROWD, Math.round(Number.isFinite(n) ? n : 100)));
}

const median = (a: number[]) => { const s = [...a].sort((x, y) => x - y); return s.length ? s[Math.floor(s.length / 2)] : NaN; };

interface CrowdParams {
  characters: number;
  backend: Backend;
  path: Path;
  smooth: boolean;
  shadows: boolean;
  paused: boolean;
}

/** Starts the crowd page; resolves once the first frames are drawn. */
export async function startCrowd(): Promise<void> {
  const params: CrowdParams = {
    characters: clampCount(Number(query.get('crowd') || 100)),
    backend: query.get('backend') === 'cpu' ? 'cpu' : 'gpu',
    path: query.get('path') === 'sections' ? 'sections' : 'joints',
    smooth: query.get('smooth') !== '0', // the default: no steps
    shadows: query.get('shadows') === '1',
    paused: query.get('paused') === '1',
  };
  const status = document.getElementById('status')!;
  status.hidden = false;
  status.textContent = 'building… generating the human character';
  for (const id of ['hint', 'credit']) document.getElementById(id)?.remove();
  const page = await CrowdPage.create(params);
  page.addGui();
  page.build();
  status.hidden = true;
  page.start();
  page.exposeHooks();
  await new Promise<void>((resolve) => { const f = page.frame; const wait = () => (page.frame > f + 1 ? resolve() : setTimeout(wait, 16)); wait(); });
}

/** The page's stage, the human and its clips, the crowd of the current count and backend, the frame loop. */
class CrowdPage {
  private gpuCrowd: GcsCrowd | null = null;
  private cpuCrowd: CpuCrowd | null = null;
  private walkers: Walker[] = [];
  private count = 0;
  private backend: Backend;
  private note = '';
  private time = 0;
  frame = 0;
  private readonly waiters: { frames: number; resolve: (r: CrowdMeasure) => void; start: number }[] = [];
  private readonly clock = new THREE.Timer();
  private readonly stats = new Stats();
  private readonly readout = new CrowdReadout();
  private readonly layout: CrowdLayout;
  private readonly stage: ReturnType<typeof createStage>;
  private readonly counter: UploadCounter;
  private gui: GUI | null = null;

  private constructor(
    private readonly params: CrowdParams,
    private readonly kind: ReturnType<typeof rendererKind>,
    private readonly renderer: Awaited<ReturnType<typeof createRenderer>>,
    /** GcsCrowd of gcs-skin/crowd, or of gcs-skin/webgpu under WebGPURenderer (node materials, TSL). */
    private readonly Crowd: typeof GcsCrowd,
    private readonly gcs: GcsSkin,
    private readonly human: { source: THREE.SkinnedMesh; material: THREE.MeshStandardMaterial; rig: Rig; clips: BakedClip[]; vertexCount: number },
  ) {
    this.backend = params.backend;
    this.counter = new UploadCounter(renderer);
    this.stage = createStage(renderer);
    this.layout = new CrowdLayout(this.stage.camera, this.stage.controls);
    document.body.append(this.stats.dom);
    this.clock.connect(document);
  }

  /** The renderer (the picture left of the control column, as in the comparison views), the core and the human. */
  static async create(params: CrowdParams): Promise<CrowdPage> {
    const kind = rendererKind();
    const renderer = await createRenderer(kind);
    renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    renderer.setSize(applySidebar(), window.innerHeight);
    renderer.shadowMap.enabled = params.shadows;
    document.body.prepend(renderer.domElement);
    const Crowd: typeof GcsCrowd = kind === 'webgpu' ? (await import('../lib/webgpu.js')).GcsCrowd : GcsCrowd;
    const vertices = query.has('vertices') ? Number(query.get('vertices')) : undefined;
    const [gcs, data] = await Promise.all([initGcsSkin(), humanDataInWorker({ vertices })]) as [GcsSkin, HumanData];
    const human: Human = humanFromData(data);
    const source = human.mesh;
    const material = new THREE.MeshStandardMaterial({ color: 0xd9a58a, roughness: 0.62, metalness: 0 });
    source.material = material;
    source.castShadow = true;
    const rig = gcs.createRig(rigInputFromSkinnedMesh(source));
    const clips = ['walk', 'run'].map((name) => bakeClip(source, human.clips.find((c) => c.name === name)!, 60));
    const vertexCount = source.geometry.getAttribute('position').count;
    return new CrowdPage(params, kind, renderer, Crowd, gcs, { source, material, rig, clips, vertexCount });
  }

  /** (Re)builds the crowd for the current count and backend. */
  build(): void {
    const { params, layout, renderer } = this;
    this.gpuCrowd?.dispose();
    this.cpuCrowd?.dispose();
    this.gpuCrowd = this.cpuCrowd = null;
    const wanted = params.characters;
    const backend = this.backend = params.backend;
    const count = this.count = layout.count = backend === 'cpu' ? Math.min(wanted, MAX_CPU_CROWD) : wanted;
    this.note = count < wanted ? `CPU backend: ${MAX_CPU_CROWD} characters at most (a deformer of ~1.4 MB wasm memory each)` : '';
    let seed = 12345;
    const random = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 4294967296);
    this.walkers = Array.from({ length: count }, (_, i) => ({ clip: i % 3 === 2 ? 1 : 0, phase: random() * 4, speed: 0.85 + 0.3 * random() }));
    const p = new THREE.Vector3();
    if (backend === 'gpu') {
      const placement = new THREE.Matrix4();
      const crowd = this.gpuCrowd = new this.Crowd(this.gcs, this.human.source, count, { gcs: { smooth: params.smooth }, gpuPath: params.path });
      crowd.mesh.castShadow = true;
      for (let i = 0; i < count; i++) crowd.mesh.setMatrixAt(i, placement.makeTranslation(layout.positionOf(i, p)));
      crowd.mesh.instanceMatrix.needsUpdate = true;
      this.stage.scene.add(crowd.mesh);
    } else {
      const crowd = this.cpuCrowd = new CpuCrowd(this.human.rig, count, this.human.material, params.smooth);
      crowd.group.children.forEach((m, i) => {
        layout.positionOf(i, m.position);
        m.castShadow = true;
      });
      this.stage.scene.add(crowd.group);
    }
    layout.frame();
    fitShadow(this.stage.sun, layout.halfSide);
    renderer.shadowMap.enabled = params.shadows;
    this.readout.reset();
  }

  /** Per frame: pose every character at its own time, then the backend's skinning. Timed (CPU). */
  private skinning(): void {
    const { clips } = this.human;
    if (this.gpuCrowd) {
      for (let i = 0; i < this.count; i++) {
        const w = this.walkers[i];
        this.gpuCrowd.setBakedPose(i, clips[w.clip], this.time * w.speed + w.phase);
      }
      this.gpuCrowd.update();
    } else if (this.cpuCrowd) {
      for (let i = 0; i < this.count; i++) {
        const w = this.walkers[i];
        this.cpuCrowd.pose(i, clips[w.clip], this.time * w.speed + w.phase);
      }
    }
  }

  addGui(): void {
    const { params, renderer } = this;
    const gui = this.gui = new GUI({ title: 'Crowd' });
    addRendererSwitch(gui, this.kind);
    gui.add(params, 'characters', 1, MAX_CROWD, 1).name('characters').onFinishChange(() => this.build());
    gui.add(params, 'backend', { 'GPU (vertex shader)': 'gpu', 'CPU (wasm, every vertex)': 'cpu' }).name('backend').onChange(() => this.build());
    gui.add(params, 'path', { 'joint poses': 'joints', 'section transforms': 'sections' }).name('GPU path').onChange(() => this.build());
    gui.add(params, 'smooth').name('smooth (no steps)').onChange(() => this.build());
    gui.add(params, 'shadows').onChange(() => { renderer.shadowMap.enabled = params.shadows; });
    gui.add(params, 'paused');
  }

  private measureLast(frames: number): CrowdMeasure {
    const last = this.readout.last(frames);
    const ms = median(last.ms), bytes = median(last.bytes);
    return { renderer: rendererLabel(this.renderer), characters: this.count, backend: this.backend, path: this.gpuCrowd?.sections.path ?? null,
      joints: this.human.rig.jointCount, frames: last.ms.length, msPerFrame: ms, bytesPerFrame: bytes, msPerCharacter: ms / this.count,
      bytesPerCharacter: bytes / this.count, vertices: this.human.vertexCount,
      sections: this.gpuCrowd?.deformer.sectionCount ?? this.cpuCrowd?.deformers[0]?.sectionCount ?? 0 };
  }

  /** The resize handler and the frame loop: skinning (timed), render, the readout, pending measures. */
  start(): void {
    const { renderer, stage, layout, readout, counter, params } = this;
    window.addEventListener('resize', () => {
      const width = applySidebar();
      stage.camera.aspect = width / window.innerHeight;
      stage.camera.updateProjectionMatrix();
      renderer.setSize(width, window.innerHeight);
      layout.frame();
    });
    renderer.setAnimationLoop((now: number) => {
      this.clock.update(now);
      if (!params.paused) this.time += this.clock.getDelta();
      const t0 = performance.now();
      this.skinning();
      const ms = performance.now() - t0;
      stage.controls.update();
      counter.bytes = 0;
      renderer.render(stage.scene, stage.camera);
      this.frame++;
      readout.add(ms, counter.bytes);
      for (let k = this.waiters.length - 1; k >= 0; k--) {
        const w = this.waiters[k];
        if (this.frame - w.start >= w.frames) {
          this.waiters.splice(k, 1);
          w.resolve(this.measureLast(w.frames));
        }
      }
      if (readout.shows(this.frame)) {
        const head = `<b>${this.count}</b> characters × ${this.human.vertexCount.toLocaleString('en')} vertices · ${rendererLabel(renderer)} · <b>${this.backend.toUpperCase()}</b> backend` +
          `${this.gpuCrowd ? ` (${PATH_NAMES[this.gpuCrowd.sections.path]})` : ''}${params.smooth ? ' (smooth)' : ''}`;
        readout.show(head, this.count, this.note);
      }
      this.stats.update();
    });
  }

  /** window.__crowd: what the browser tests and the crowd bench read and drive. */
  exposeHooks(): void {
    const { params, renderer } = this;
    Object.assign(window, {
      __crowd: {
        frame: () => this.frame,
        count: () => this.count,
        backend: () => this.backend,
        /** Characters drawn: instances of the GPU crowd's one mesh, or the CPU backend's meshes. */
        drawn: () => (this.gpuCrowd ? this.gpuCrowd.mesh.count : this.cpuCrowd ? this.cpuCrowd.group.children.length : 0),
        /** WebGLRenderer's count; WebGPURenderer's WebGL2 fallback counts none (its `drawCalls` stays 0). */
        drawCalls: () => { const r = renderer.info.render as { calls: number; drawCalls?: number }; return r.drawCalls ?? r.calls; },
        renderer: () => rendererLabel(renderer),
        readout: () => this.readout.element.textContent ?? '',
        set: (n: number, b: Backend = params.backend, path: Path = params.path) => {
          params.characters = clampCount(n); params.backend = b; params.path = path;
          this.gui?.controllersRecursive().forEach((c) => c.updateDisplay());
          this.build();
        },
        /** Medians over the next `frames` frames: skinning CPU ms and bytes uploaded, per frame and per character. */
        measure: (frames: number) => new Promise<CrowdMeasure>((resolve) => this.waiters.push({ frames, resolve, start: this.frame })),
        pause: (t?: number) => { params.paused = true; if (t !== undefined) this.time = t; },
        /** The characters' extent on the page (px): their boxes as the camera projects them. */
        screenBounds: () => this.layout.screenBounds(renderer),
      },
    });
  }
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
