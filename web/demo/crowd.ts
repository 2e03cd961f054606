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
import { initGcsSkin, type GcsSkin } from '../lib/index.js';
import { bakeClip, GcsCrowd } from '../lib/crowd.js';
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
  const { scene, sun, camera, controls } = createStage(renderer);
  const layout = new CrowdLayout(camera, controls);
  const stats = new Stats();
  document.body.append(stats.dom);
  const readout = new CrowdReadout();

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

  let gpuCrowd: GcsCrowd | null = null;
  let cpuCrowd: CpuCrowd | null = null;
  let walkers: Walker[] = [];
  let count = 0;
  let backend: Backend = params.backend;
  let note = '';

  /** (Re)builds the crowd for the current count and backend. */
  const build = () => {
    gpuCrowd?.dispose();
    cpuCrowd?.dispose();
    gpuCrowd = cpuCrowd = null;
    const wanted = params.characters;
    backend = params.backend;
    count = layout.count = backend === 'cpu' ? Math.min(wanted, MAX_CPU_CROWD) : wanted;
    note = count < wanted ? `CPU backend: ${MAX_CPU_CROWD} characters at most (a deformer of ~1.4 MB wasm memory each)` : '';
    let seed = 12345;
    const random = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 4294967296);
    walkers = Array.from({ length: count }, (_, i) => ({ clip: i % 3 === 2 ? 1 : 0, phase: random() * 4, speed: 0.85 + 0.3 * random() }));
    const p = new THREE.Vector3();
    if (backend === 'gpu') {
      const placement = new THREE.Matrix4();
      gpuCrowd = new Crowd(gcs, source, count, { gcs: { smooth: params.smooth }, gpuPath: params.path });
      gpuCrowd.mesh.castShadow = true;
      for (let i = 0; i < count; i++) gpuCrowd.mesh.setMatrixAt(i, placement.makeTranslation(layout.positionOf(i, p)));
      gpuCrowd.mesh.instanceMatrix.needsUpdate = true;
      scene.add(gpuCrowd.mesh);
    } else {
      cpuCrowd = new CpuCrowd(rig, count, material, params.smooth);
      cpuCrowd.group.children.forEach((m, i) => {
        layout.positionOf(i, m.position);
        m.castShadow = true;
      });
      scene.add(cpuCrowd.group);
    }
    layout.frame();
    fitShadow(sun, layout.halfSide);
    renderer.shadowMap.enabled = params.shadows;
    readout.reset();
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

  let frame = 0;
  const waiters: { frames: number; resolve: (r: CrowdMeasure) => void; start: number }[] = [];
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

  window.addEventListener('resize', () => {
    const width = applySidebar();
    camera.aspect = width / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(width, window.innerHeight);
    layout.frame();
  });

  const measureLast = (frames: number): CrowdMeasure => {
    const last = readout.last(frames);
    const ms = median(last.ms), bytes = median(last.bytes);
    return { renderer: rendererLabel(renderer), characters: count, backend, path: gpuCrowd?.sections.path ?? null, joints: rig.jointCount, frames: last.ms.length, msPerFrame: ms, bytesPerFrame: bytes, msPerCharacter: ms / count, bytesPerCharacter: bytes / count,
      vertices: vertexCount, sections: gpuCrowd?.deformer.sectionCount ?? cpuCrowd?.deformers[0]?.sectionCount ?? 0 };
  };

  renderer.setAnimationLoop((now: number) => {
    clock.update(now);
    if (!params.paused) time += clock.getDelta();
    const t0 = performance.now();
    skinning();
    const ms = performance.now() - t0;
    controls.update();
    counter.bytes = 0;
    renderer.render(scene, camera);
    frame++;
    readout.add(ms, counter.bytes);
    for (let k = waiters.length - 1; k >= 0; k--) {
      const w = waiters[k];
      if (frame - w.start >= w.frames) {
        waiters.splice(k, 1);
        w.resolve(measureLast(w.frames));
      }
    }
    if (readout.shows(frame)) {
      const head = `<b>${count}</b> characters × ${vertexCount.toLocaleString('en')} vertices · ${rendererLabel(renderer)} · <b>${backend.toUpperCase()}</b> backend` +
        `${gpuCrowd ? ` (${PATH_NAMES[gpuCrowd.sections.path]})` : ''}${params.smooth ? ' (smooth)' : ''}`;
      readout.show(head, count, note);
    }
    stats.update();
  });

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
      readout: () => readout.element.textContent ?? '',
      set: (n: number, b: Backend = params.backend, path: Path = params.path) => { params.characters = clampCount(n); params.backend = b; params.path = path; gui.controllersRecursive().forEach((c) => c.updateDisplay()); build(); },
      /** Medians over the next `frames` frames: skinning CPU ms and bytes uploaded, per frame and per character. */
      measure: (frames: number) => new Promise<CrowdMeasure>((resolve) => waiters.push({ frames, resolve, start: frame })),
      pause: (t?: number) => { params.paused = true; if (t !== undefined) time = t; },
      /** The characters' extent on the page (px): their boxes as the camera projects them. */
      screenBounds: () => layout.screenBounds(renderer),
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
