// The page of tests/browser/webgpu.test.ts: gcs-skin/webgpu on three.js's WebGPURenderer (its
// WebGL2 backend here: forceWebGL, no GPU in headless Chromium), read back as pixels.
//   check: GPU backend (TSL) vs CPU backend, same frames, same camera (GCS, LBS or DQS); the pose differs from the rest pose;
//   glslVsTsl: the same pose drawn by gcs-skin/three (GLSL, WebGLRenderer) and gcs-skin/webgpu (TSL, WebGPURenderer);
//   crowd: GcsCrowd on WebGPURenderer, drawn and moving, one draw call per skin;
//   the "never silently wrong" cases: each entry drawn by the other renderer, custom and node materials;
//   velocity: a velocity MRT pass (pass + mrt({ output, velocity })) over our skin and three.js's own;
//   normalMapped: a character with MikkTSpace tangents and a normal map, ours against three.js's skinning.
import * as THREE from 'three/webgpu';
import { WebGLRenderer, WebGLRenderTarget } from 'three';
import { WebGLNodesHandler } from 'three/addons/tsl/WebGLNodesHandler.js';
import { initGcsSkin, type GcsOptions } from '../../../web/lib/index.js';
import * as WebGL from '../../../web/lib/three.js';
import { GcsCrowd as WebGLCrowd } from '../../../web/lib/crowd.js';
import { bakeClip, GcsCharacter, GcsCrowd, writeSkinMatrices } from '../../../web/lib/webgpu.js';
import { mrt, output, pass, velocity as velocityNode } from 'three/tsl';
import type { GpuPath } from '../../../web/lib/gpu.js';
import { load, stage as stageAt, type Loaded } from '../fixture-scene.js';
import { NodePass } from '../../../web/lib/gpu/node-pass.js';
import type { TslNodePass } from '../../../web/lib/gpu/node-pass-tsl.js';

const W = 384, H = 384;
const stage = (root: THREE.Object3D) => stageAt(root, W, H);
const gcsReady = initGcsSkin();

/** Warnings gcs-skin printed (console.warn lines starting with 'gcs-skin:'). */
const warnings: string[] = [];
const warn = console.warn.bind(console);
console.warn = (...args: unknown[]) => {
  if (typeof args[0] === 'string' && args[0].startsWith('gcs-skin:')) warnings.push(args[0]);
  warn(...args);
};

let webgpu: THREE.WebGPURenderer | null = null;
async function gpuRenderer(): Promise<THREE.WebGPURenderer> {
  if (webgpu) return webgpu;
  const r = new THREE.WebGPURenderer({ forceWebGL: true, antialias: false });
  r.setSize(W, H);
  r.setPixelRatio(1);
  await r.init();
  document.body.append(r.domElement);
  webgpu = r;
  return r;
}

function glRenderer(handler = false): WebGLRenderer {
  const r = new WebGLRenderer({ antialias: false });
  r.setSize(W, H);
  r.setPixelRatio(1);
  if (handler) r.setNodesHandler(new WebGLNodesHandler());
  return r;
}

type AnyRenderer = THREE.WebGPURenderer | WebGLRenderer;

/** Draws into a render target and reads the pixels back (rows bottom-up on both renderers). */
async function draw(renderer: AnyRenderer, scene: THREE.Scene, camera: THREE.Camera): Promise<Uint8Array> {
  if ((renderer as THREE.WebGPURenderer).isWebGPURenderer) {
    const r = renderer as THREE.WebGPURenderer;
    const target = new THREE.RenderTarget(W, H);
    r.setRenderTarget(target);
    r.setClearColor(0x000000, 1);
    r.render(scene, camera);
    const pixels = await r.readRenderTargetPixelsAsync(target, 0, 0, W, H);
    r.setRenderTarget(null);
    target.dispose();
    return new Uint8Array(pixels.buffer, pixels.byteOffset, pixels.byteLength).slice();
  }
  const r = renderer as WebGLRenderer;
  const target = new WebGLRenderTarget(W, H);
  r.setRenderTarget(target);
  r.setClearColor(0x000000, 1);
  r.clear();
  r.render(scene, camera);
  const out = new Uint8Array(4 * W * H);
  r.readRenderTargetPixels(target, 0, 0, W, H, out);
  r.setRenderTarget(null);
  target.dispose();
  return out;
}

/** Share of pixels of which a channel differs by more than `by` (of 255): of the image, and of the pixels either picture covers. */
function differing(a: Uint8Array, b: Uint8Array, by = 8): { image: number; covered: number } {
  let n = 0, covered = 0;
  for (let o = 0; o < a.length; o += 4) {
    if (a[o] + a[o + 1] + a[o + 2] > 0 || b[o] + b[o + 1] + b[o + 2] > 0) covered++;
    if (Math.abs(a[o] - b[o]) > by || Math.abs(a[o + 1] - b[o + 1]) > by || Math.abs(a[o + 2] - b[o + 2]) > by) n++;
  }
  return { image: n / (a.length / 4), covered: n / Math.max(1, covered) };
}

function coverage(a: Uint8Array): number {
  let n = 0;
  for (let o = 0; o < a.length; o += 4) if (a[o] + a[o + 1] + a[o + 2] > 0) n++;
  return n / (a.length / 4);
}

function play(loaded: Loaded, clipName?: string): THREE.AnimationMixer {
  const mixer = new THREE.AnimationMixer(loaded.root);
  mixer.clipAction(loaded.clips.find((c) => c.name === clipName) ?? loaded.clips[0]).play();
  return mixer;
}

export interface CheckResult {
  backends: string[]; paths: string[]; notes: string[];
  /** per frame: GPU vs CPU backend pictures */
  vsCpu: { image: number; covered: number }[];
  /** per frame: the GPU picture vs the unanimated one */
  vsRest: { image: number; covered: number }[];
  coverage: number;
  warnings: string[];
}

/** gcs-skin/webgpu's GPU backend against its CPU backend on WebGPURenderer, frame by frame. */
async function check(model: string, gcsOptions: GcsOptions, times: number[], clipName?: string, gpuPath: GpuPath | 'auto' = 'auto', method: 'gcs' | 'lbs' | 'dqs' = 'gcs'): Promise<CheckResult> {
  const gcs = await gcsReady;
  const renderer = await gpuRenderer();
  warnings.length = 0;
  const loaded = await load(model);
  const { scene, camera } = stage(loaded.root);
  const character = new GcsCharacter(gcs, loaded.root, { gcs: gcsOptions, backend: 'gpu', gpuPath, method });
  const result: CheckResult = {
    backends: character.skins.map((s) => s.backend), paths: character.skins.map((s) => s.gpuPath ?? 'none'), notes: character.skins.map((s) => s.backendNote),
    vsCpu: [], vsRest: [], coverage: 0, warnings,
  };
  character.update();
  const rest = await draw(renderer, scene, camera);
  const mixer = play(loaded, clipName);
  for (const t of times) {
    mixer.setTime(t);
    character.rebuild(undefined, { backend: 'gpu' });
    character.update();
    const gpu = await draw(renderer, scene, camera);
    result.backends = character.skins.map((s) => s.backend); // still 'gpu' after drawing: no fallback happened
    character.rebuild(undefined, { backend: 'cpu' });
    character.update();
    const cpu = await draw(renderer, scene, camera);
    result.vsCpu.push(differing(gpu, cpu));
    result.vsRest.push(differing(gpu, rest));
    result.coverage = Math.max(result.coverage, coverage(gpu));
  }
  character.dispose();
  return result;
}

/**
 * One pose drawn by gcs-skin/three's GPU backend (GLSL) on WebGLRenderer and by gcs-skin/webgpu's
 * (TSL) on WebGPURenderer, with MeshNormalMaterial (colour = view-space normal, no lighting
 * model that differs between the renderers): the two shaders' positions and normals, compared.
 */
async function glslVsTsl(model: string, gcsOptions: GcsOptions, time: number, clipName?: string, gpuPath: GpuPath | 'auto' = 'auto'): Promise<{ diff: { image: number; covered: number }; coverage: number; backends: string[] }> {
  const gcs = await gcsReady;
  const renderers = { glsl: glRenderer(), tsl: await gpuRenderer() };
  const pictures: Uint8Array[] = [];
  const backends: string[] = [];
  for (const which of ['glsl', 'tsl'] as const) {
    const loaded = await load(model);
    const { scene, camera } = stage(loaded.root);
    const material = new THREE.MeshNormalMaterial();
    loaded.root.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) (o as THREE.SkinnedMesh).material = material; });
    const Character = which === 'glsl' ? WebGL.GcsCharacter : GcsCharacter;
    const character = new Character(gcs, loaded.root, { gcs: gcsOptions, backend: 'gpu', gpuPath });
    const mixer = play(loaded, clipName);
    mixer.setTime(time);
    character.update();
    pictures.push(await draw(renderers[which], scene, camera));
    backends.push(character.backend);
    character.dispose();
  }
  renderers.glsl.dispose();
  // MeshNormalNodeMaterial writes its colour sRGB-decoded (so that both look alike on screen);
  // in a linear render target the GLSL picture is compared after the same decoding.
  const decode = Array.from({ length: 256 }, (_, v) => Math.round(255 * new THREE.Color().setRGB(v / 255, 0, 0, THREE.SRGBColorSpace).r));
  const decoded = pictures[0].map((v, i) => (i % 4 === 3 ? v : decode[v]));
  return { diff: differing(decoded, pictures[1]), coverage: coverage(pictures[1]), backends };
}

export interface CrowdResult { drawCalls: number; coverage: number; moving: number; bytesPerFrame: number; jointCount: number; path: string }

/** The WebGL2 backend keeps no draw-call count: counts the backend's draws of `mesh` until stop(). */
function countDraws(renderer: THREE.WebGPURenderer, mesh: THREE.Object3D): { count: number; stop(): void } {
  const backend = (renderer as unknown as { backend: { draw(o: { object: THREE.Object3D }, ...rest: unknown[]): void } }).backend;
  const backendDraw = backend.draw;
  const counter = { count: 0, stop: () => { backend.draw = backendDraw; } };
  backend.draw = function (renderObject, ...rest) {
    if (renderObject.object === mesh) counter.count++;
    return backendDraw.call(this, renderObject, ...rest);
  };
  return counter;
}

/** A GcsCrowd of `count` of a character's first skin, set out in a grid in view, and its clip baked. */
async function crowdScene(model: string, count: number, clipName?: string, gcsOptions: GcsOptions = {}) {
  const gcs = await gcsReady;
  const loaded = await load(model);
  let source: THREE.SkinnedMesh | null = null;
  loaded.root.traverse((o) => { if (!source && (o as THREE.SkinnedMesh).isSkinnedMesh) source = o as THREE.SkinnedMesh; });
  const skinned = source! as THREE.SkinnedMesh;
  const clip = loaded.clips.find((c) => c.name === clipName) ?? loaded.clips[0];
  const baked = bakeClip(skinned, clip, 30);
  const group = new THREE.Group();
  const c = new GcsCrowd(gcs, skinned, count, { gcs: gcsOptions });
  group.add(c.mesh);
  loaded.root.updateMatrixWorld(true);
  const height = new THREE.Box3().setFromObject(skinned).getSize(new THREE.Vector3()).y || 1;
  const side = Math.ceil(Math.sqrt(count));
  const m = new THREE.Matrix4();
  for (let i = 0; i < count; i++) {
    m.makeTranslation((i % side - side / 2) * height * 0.6, 0, Math.floor(i / side) * height * 0.6);
    c.mesh.setMatrixAt(i, m.multiply(skinned.matrixWorld));
  }
  c.mesh.instanceMatrix.needsUpdate = true;
  const { scene, camera } = stage(group);
  camera.position.multiplyScalar(1.2);
  return { c, baked, scene, camera };
}

/** `count` instances of a character on WebGPURenderer, each at its own clip time; two frames. */
async function crowd(model: string, count: number, clipName?: string): Promise<CrowdResult> {
  const renderer = await gpuRenderer();
  const { c, baked, scene, camera } = await crowdScene(model, count, clipName);
  const frame = async (t: number) => {
    for (let i = 0; i < count; i++) c.setBakedPose(i, baked, t + i * 0.13);
    c.update();
    return draw(renderer, scene, camera);
  };
  const calls = countDraws(renderer, c.mesh);
  const a = await frame(0.2);
  calls.stop();
  const b = await frame(0.6);
  const result = { drawCalls: calls.count, coverage: coverage(a), moving: differing(a, b).image, bytesPerFrame: c.bytesPerFrame, jointCount: c.jointCount, path: c.sections.path };
  c.dispose();
  return result;
}

export interface InfluencesResult {
  backends: string[]; paths: string[]; tableSlots: number[];
  /** the GPU backend (TSL) vs the CPU backend, same pose */
  vsCpu: { image: number; covered: number };
  /** the GPU backend vs the CPU backend of the same file without joints_1/weights_1 (what three's own skinning reads) */
  vsFour: { image: number; covered: number };
  /** the crowd's instance 0 (one instanced TSL draw, placed where the source stands) vs the CPU backend */
  crowdVsCpu: { image: number; covered: number };
  coverage: number;
}

/**
 * A character with more than 4 influences per vertex on WebGPURenderer at one pose: gcs-skin/webgpu's
 * GPU backend and a GcsCrowd against its CPU backend, and against the CPU backend of the same file
 * read without its second set of influences.
 */
async function influences(model: string, gcsOptions: GcsOptions, time: number, gpuPath: GpuPath): Promise<InfluencesResult> {
  const gcs = await gcsReady;
  const renderer = await gpuRenderer();
  const picture = async (backend: 'gpu' | 'cpu', dropSecondSet: boolean, asCrowd = false) => {
    const loaded = await load(model);
    let source: THREE.SkinnedMesh | undefined;
    loaded.root.traverse((o) => { if (!source && (o as THREE.SkinnedMesh).isSkinnedMesh) source = o as THREE.SkinnedMesh; });
    if (dropSecondSet) { source!.geometry.deleteAttribute('joints_1'); source!.geometry.deleteAttribute('weights_1'); }
    const { scene, camera } = stage(loaded.root);
    play(loaded).setTime(time);
    loaded.root.updateMatrixWorld(true);
    if (asCrowd) {
      const c = new GcsCrowd(gcs, source!, 1, { gcs: gcsOptions, gpuPath });
      writeSkinMatrices(source!, c.skins, 0);
      c.update();
      c.mesh.setMatrixAt(0, source!.matrixWorld);
      source!.visible = false;
      scene.add(c.mesh);
      const pixels = await draw(renderer, scene, camera);
      c.dispose();
      return { pixels, backends: ['gpu'], paths: [c.sections.path], tableSlots: [c.sections.tableSlots] };
    }
    const character = new GcsCharacter(gcs, loaded.root, { gcs: gcsOptions, backend, gpuPath });
    character.update();
    const pixels = await draw(renderer, scene, camera);
    const out = { pixels, backends: character.skins.map((s) => s.backend), paths: character.skins.map((s) => s.gpuPath ?? 'none'), tableSlots: character.skins.map((s) => s.gpuSections?.tableSlots ?? 0) };
    character.dispose();
    return out;
  };
  const gpu = await picture('gpu', false), cpu = await picture('cpu', false), four = await picture('cpu', true), crowded = await picture('gpu', false, true);
  return {
    backends: gpu.backends, paths: [...gpu.paths, ...crowded.paths], tableSlots: [...gpu.tableSlots, ...crowded.tableSlots],
    vsCpu: differing(gpu.pixels, cpu.pixels), vsFour: differing(gpu.pixels, four.pixels), crowdVsCpu: differing(crowded.pixels, cpu.pixels), coverage: coverage(gpu.pixels),
  };
}

export interface FallbackResult {
  before: string; after: string; note: string; warnings: string[];
  /** the first frame vs the CPU backend's picture: drawn right, or (firstCoverage 0) not at all */
  firstVsCpu: { image: number; covered: number };
  /** the second frame vs the CPU backend's picture (the fallback draws right) */
  vsCpu: { image: number; covered: number };
  /** the first frame's coverage: nothing, or the right picture; never the bind pose */
  firstCoverage: number;
  error: string;
}

type Case = 'three-on-webgpu' | 'webgpu-on-webgl' | 'webgpu-on-webgl-handler' | 'webgpu-custom-shader' | 'webgpu-node-position' | 'webgpu-node-plain';

/** The "never silently wrong" cases, each on CesiumMan at t = 1 s. */
async function fallback(model: string, which: Case): Promise<FallbackResult> {
  const gcs = await gcsReady;
  warnings.length = 0;
  const loaded = await load(model);
  const { scene, camera } = stage(loaded.root);
  const mixer = play(loaded);
  mixer.setTime(1);
  let renderer: AnyRenderer = await gpuRenderer();
  let character: WebGL.GcsCharacter;
  if (which === 'three-on-webgpu') {
    character = new WebGL.GcsCharacter(gcs, loaded.root, { backend: 'gpu' });
  } else {
    if (which === 'webgpu-on-webgl') renderer = glRenderer();
    if (which === 'webgpu-on-webgl-handler') renderer = glRenderer(true);
    loaded.root.traverse((o) => {
      const mesh = o as THREE.SkinnedMesh;
      if (!mesh.isSkinnedMesh) return;
      if (which === 'webgpu-custom-shader') {
        mesh.material = new THREE.ShaderMaterial({ vertexShader: 'void main() { gl_Position = vec4(position, 1.0); }', fragmentShader: 'void main() { gl_FragColor = vec4(1.0); }' });
      } else if (which === 'webgpu-node-position' || which === 'webgpu-node-plain' || which === 'webgpu-on-webgl-handler') {
        // (with the handler: node materials on both backends, so both pictures go through the handler's lighting)
        const material = new THREE.MeshStandardNodeMaterial({ color: 0xc08060 });
        if (which === 'webgpu-node-position') material.positionNode = THREE.TSL.positionLocal.mul(1.01);
        mesh.material = material;
      }
    });
    character = new GcsCharacter(gcs, loaded.root, { backend: 'gpu' });
  }
  const before = character.backend;
  character.update();
  let error = '';
  let first: Uint8Array | null = null, second: Uint8Array | null = null, cpu: Uint8Array | null = null;
  let after = character.skins.map((s) => s.backend).join(',');
  let note = character.skins.map((s) => s.backendNote).join(' | ');
  if (which !== 'webgpu-custom-shader') { // WebGPURenderer draws no ShaderMaterial at all
    try {
      first = await draw(renderer, scene, camera);
      character.update();
      second = await draw(renderer, scene, camera);
      after = character.skins.map((s) => s.backend).join(',');
      note = character.skins.map((s) => s.backendNote).join(' | ');
      character.rebuild(undefined, { backend: 'cpu' });
      character.update();
      cpu = await draw(renderer, scene, camera);
    } catch (e) {
      error = `${String(e)} ${(e as Error).stack?.split('\n').slice(1, 4).join(' ')}`;
    }
  }
  character.dispose();
  if (!(renderer as THREE.WebGPURenderer).isWebGPURenderer) renderer.dispose();
  return {
    before, after: after.split(',')[0], note, warnings: [...warnings],
    vsCpu: second && cpu ? differing(second, cpu) : { image: -1, covered: -1 },
    firstVsCpu: first && cpu ? differing(first, cpu) : { image: -1, covered: -1 },
    firstCoverage: first ? coverage(first) : -1, error,
  };
}

/** A crowd drawn by the other renderer: the next update() throws a GcsError naming the fix. */
async function crowdOnWrongRenderer(model: string, entry: 'webgpu' | 'three'): Promise<{ error: string; code: string; warnings: string[] }> {
  const gcs = await gcsReady;
  warnings.length = 0;
  const loaded = await load(model);
  let source: THREE.SkinnedMesh | null = null;
  loaded.root.traverse((o) => { if (!source && (o as THREE.SkinnedMesh).isSkinnedMesh) source = o as THREE.SkinnedMesh; });
  const c = entry === 'webgpu' ? new GcsCrowd(gcs, source!, 4) : new WebGLCrowd(gcs, source!, 4);
  const { scene, camera } = stage(c.mesh);
  const renderer: AnyRenderer = entry === 'webgpu' ? glRenderer() : await gpuRenderer();
  c.update();
  await draw(renderer, scene, camera);
  let error = '', code = '';
  try {
    c.update();
  } catch (e) {
    error = (e as Error).message;
    code = (e as { code?: string }).code ?? '';
  }
  c.dispose();
  if (!(renderer as THREE.WebGPURenderer).isWebGPURenderer) renderer.dispose();
  return { error, code, warnings: [...warnings] };
}

/** The next browser frame: WebGPURenderer counts frames (frameId) by requestAnimationFrame, as velocity does. */
const nextFrame = () => new Promise<void>((resolve) => requestAnimationFrame(() => requestAnimationFrame(() => resolve())));

/** A scene drawn through a velocity MRT pass: its colour and its velocity (NDC per frame), read back as floats. */
function velocityPass(renderer: THREE.WebGPURenderer, scene: THREE.Scene, camera: THREE.Camera) {
  const scenePass = pass(scene, camera, { type: THREE.FloatType });
  scenePass.setMRT(mrt({ output, velocity: velocityNode }));
  const pipeline = new THREE.RenderPipeline(renderer);
  pipeline.outputNode = scenePass;
  const colourTexture = scenePass.getTexture('output'), velocityTexture = scenePass.getTexture('velocity');
  return {
    async draw(): Promise<{ colour: Float32Array; velocity: Float32Array }> {
      pipeline.render();
      const target = scenePass.renderTarget;
      const colour = await renderer.readRenderTargetPixelsAsync(target, 0, 0, W, H, target.textures.indexOf(colourTexture)) as Float32Array;
      const velocity = await renderer.readRenderTargetPixelsAsync(target, 0, 0, W, H, target.textures.indexOf(velocityTexture)) as Float32Array;
      return { colour: colour.slice(), velocity: velocity.slice() };
    },
    dispose(): void {
      pipeline.dispose();
      scenePass.dispose();
    },
  };
}

export interface VelocityResult {
  backends: string[];
  /** share of the pixels either skin covers where the two velocities differ by more than 1 px or 10 % */
  vsThree: number;
  /** share of our skin's pixels that move more than 1 px (the comparison is not of two still pictures) */
  moving: number;
  /** the largest velocity of our skin's pixels, in pixels, walking and then paused */
  largest: number;
  pausedLargest: number;
  /** three's skinning paused, for scale */
  threePausedLargest: number;
}

/**
 * A walking character drawn through a velocity MRT pass by our skin (`kind`: the GPU backend on a
 * path, GPU DQS, the CPU backend, or a one-instance crowd) and by three.js's own skinning of the same clip,
 * two frames `dt` apart; then our skin paused (the same time drawn again).
 */
async function velocity(model: string, kind: 'joints' | 'sections' | 'cpu' | 'crowd' | 'dqs', time: number, dt: number, gcsOptions: GcsOptions = {}, clipName?: string): Promise<VelocityResult> {
  const gcs = await gcsReady;
  const renderer = await gpuRenderer();
  const ours = await load(model), three = await load(model);
  const { scene: oursScene, camera } = stage(ours.root);
  const { scene: threeScene } = stage(three.root);
  let character: GcsCharacter | null = null, crowd: GcsCrowd | null = null, baked: ReturnType<typeof bakeClip> | null = null;
  const oursMixer = play(ours, clipName), threeMixer = play(three, clipName);
  if (kind === 'crowd') {
    let source: THREE.SkinnedMesh | null = null;
    ours.root.traverse((o) => { if (!source && (o as THREE.SkinnedMesh).isSkinnedMesh) source = o as THREE.SkinnedMesh; });
    const skinned = source! as THREE.SkinnedMesh;
    baked = bakeClip(skinned, ours.clips.find((c) => c.name === clipName) ?? ours.clips[0], 1 / dt);
    crowd = new GcsCrowd(gcs, skinned, 1, { gcs: gcsOptions });
    ours.root.updateMatrixWorld(true);
    crowd.mesh.setMatrixAt(0, skinned.matrixWorld);
    crowd.mesh.instanceMatrix.needsUpdate = true;
    skinned.visible = false;
    oursScene.add(crowd.mesh);
  } else {
    character = kind === 'dqs' ? new GcsCharacter(gcs, ours.root, { backend: 'gpu', method: 'dqs' })
      : new GcsCharacter(gcs, ours.root, { gcs: gcsOptions, backend: kind === 'cpu' ? 'cpu' : 'gpu', gpuPath: kind === 'cpu' ? 'auto' : kind });
  }
  const pose = (t: number) => {
    threeMixer.setTime(t);
    if (crowd) {
      crowd.setBakedPose(0, baked!, t);
      crowd.update();
    } else {
      oursMixer.setTime(t);
      character!.update();
    }
  };
  const oursPass = velocityPass(renderer, oursScene, camera), threePass = velocityPass(renderer, threeScene, camera);
  const px = (v: Float32Array, o: number) => Math.hypot(v[o] * W / 2, v[o + 1] * H / 2); // NDC → pixels
  pose(time);
  await oursPass.draw();
  await threePass.draw();
  await nextFrame();
  pose(time + dt);
  const a = await oursPass.draw(), b = await threePass.draw();
  let covered = 0, differ = 0, mine = 0, moving = 0, largest = 0;
  for (let o = 0; o < a.colour.length; o += 4) {
    const inA = a.colour[o + 3] > 0 && a.colour[o] + a.colour[o + 1] + a.colour[o + 2] > 0;
    const inB = b.colour[o + 3] > 0 && b.colour[o] + b.colour[o + 1] + b.colour[o + 2] > 0;
    if (!inA && !inB) continue;
    covered++;
    const va = inA ? px(a.velocity, o) : 0, vb = inB ? px(b.velocity, o) : 0;
    const d = Math.hypot((inA ? a.velocity[o] : 0) - (inB ? b.velocity[o] : 0), (inA ? a.velocity[o + 1] : 0) - (inB ? b.velocity[o + 1] : 0)) * W / 2;
    if (d > Math.max(1, 0.1 * Math.max(va, vb))) differ++;
    if (inA) {
      mine++;
      if (va > 1) moving++;
      largest = Math.max(largest, va);
    }
  }
  await nextFrame();
  pose(time + dt);
  const still = await oursPass.draw(), threeStill = await threePass.draw();
  let pausedLargest = 0, threePausedLargest = 0;
  for (let o = 0; o < still.colour.length; o += 4) {
    if (still.colour[o] + still.colour[o + 1] + still.colour[o + 2] > 0) pausedLargest = Math.max(pausedLargest, px(still.velocity, o));
    if (threeStill.colour[o] + threeStill.colour[o + 1] + threeStill.colour[o + 2] > 0) threePausedLargest = Math.max(threePausedLargest, px(threeStill.velocity, o));
  }
  const backends = character ? character.skins.map((s) => s.backend) : ['gpu'];
  oursPass.dispose();
  threePass.dispose();
  character?.dispose();
  crowd?.dispose();
  return { backends, vsThree: differ / Math.max(1, covered), moving: moving / Math.max(1, mine), largest, pausedLargest, threePausedLargest };
}

/** A tangent-space normal map of round bumps (8 × 8 per uv square), strong enough to light visibly. */
function bumpMap(): THREE.DataTexture {
  const size = 64, data = new Uint8Array(4 * size * size);
  for (let y = 0; y < size; y++) for (let x = 0; x < size; x++) {
    const u = (x / size) * 2 * Math.PI, v = (y / size) * 2 * Math.PI;
    const n = new THREE.Vector3(-0.8 * Math.cos(u) * Math.sin(v), -0.8 * Math.sin(u) * Math.cos(v), 1).normalize();
    data.set([(n.x * 0.5 + 0.5) * 255, (n.y * 0.5 + 0.5) * 255, (n.z * 0.5 + 0.5) * 255, 255], 4 * (y * size + x));
  }
  const texture = new THREE.DataTexture(data, size, size);
  texture.wrapS = texture.wrapT = THREE.RepeatWrapping;
  texture.repeat.set(8, 8);
  texture.needsUpdate = true;
  return texture;
}

/** Every skinned mesh under `root` wears one normal-mapped material (textures of the file dropped). */
function wearNormalMap(root: THREE.Object3D, normalMap: THREE.Texture | null): void {
  const material = new THREE.MeshStandardMaterial({ color: 0xc8c0b0, roughness: 0.45, metalness: 0, normalMap });
  root.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) (o as THREE.SkinnedMesh).material = material; });
}

export interface NormalMappedResult {
  tangents: boolean[];
  /** our LBS (CPU backend, tangents deformed by the core) vs three.js's skinning, same pose */
  lbsVsThree: { image: number; covered: number };
  /** three.js's skinning with and without the normal map: the map shows */
  mapShows: { image: number; covered: number };
  /** our GCS GPU backend (each path) vs our GCS CPU backend, normal-mapped */
  gpuVsCpu: { image: number; covered: number }[];
  coverage: number;
}

/** A character with tangents and a normal map, posed at `time`, drawn by `which` renderer. */
async function normalMapped(model: string, which: 'webgl' | 'webgpu', time: number): Promise<NormalMappedResult> {
  const gcs = await gcsReady;
  const renderer = which === 'webgpu' ? await gpuRenderer() : glRenderer();
  const Character = which === 'webgpu' ? GcsCharacter : WebGL.GcsCharacter;
  const map = bumpMap();
  const ours = await load(model), three = await load(model), flat = await load(model);
  wearNormalMap(ours.root, map);
  wearNormalMap(three.root, map);
  wearNormalMap(flat.root, null);
  const { scene: oursScene, camera } = stage(ours.root);
  const { scene: threeScene } = stage(three.root);
  const { scene: flatScene } = stage(flat.root);
  for (const loaded of [ours, three, flat]) play(loaded).setTime(time);
  const character = new Character(gcs, ours.root, { method: 'lbs' });
  character.update();
  const lbs = await draw(renderer, oursScene, camera);
  const reference = await draw(renderer, threeScene, camera);
  const plain = await draw(renderer, flatScene, camera);
  const result: NormalMappedResult = {
    tangents: character.skins.map((s) => s.deformsTangents), lbsVsThree: differing(lbs, reference), mapShows: differing(reference, plain),
    gpuVsCpu: [], coverage: coverage(reference),
  };
  for (const gpuPath of ['joints', 'sections'] as const) {
    character.rebuild('gcs', { backend: 'cpu' });
    character.update();
    const cpu = await draw(renderer, oursScene, camera);
    character.rebuild('gcs', { backend: 'gpu', gpuPath });
    character.update();
    result.gpuVsCpu.push(differing(await draw(renderer, oursScene, camera), cpu));
  }
  character.dispose();
  if (which === 'webgl') (renderer as WebGLRenderer).dispose();
  return result;
}

export interface NodePassResult {
  nodes: number; rows: number;
  /** the largest difference of a texel entry, TSL pass vs GLSL pass, and the largest translation (scale) */
  largest: number; scale: number;
  /** node-pass runs: after the first frame, that frame drawn again, the next frame */
  runs: number[];
  /** the crowd's vertex shader: whether it still holds the node maths, and how many texels it loads */
  vertexNodeMaths: boolean; vertexLoads: number;
  /** texture size queries in the vertex shader (three.js's per-load row flip on the WebGL2 backend asks one per load) */
  vertexSizeQueries: number;
  drawCalls: number; coverage: number;
}

/**
 * A crowd of `count` on WebGPURenderer, every instance at its own clip time: the TSL node pass's
 * four targets read back against the GLSL node pass (node-pass.ts, on a WebGLRenderer) from the
 * same joint poses, node by node (the TSL targets' rows count from the top on the WebGL2 backend,
 * WebGPU's convention; the GLSL pass's from the bottom); how often the pass runs; what the vertex
 * shader still computes.
 */
async function nodePass(model: string, count: number, gcsOptions: GcsOptions, clipName?: string): Promise<NodePassResult> {
  const renderer = await gpuRenderer();
  const { c, baked, scene, camera } = await crowdScene(model, count, clipName, gcsOptions);
  const pass = (Array.isArray(c.mesh.material) ? c.mesh.material[0] : c.mesh.material).userData.gcsNodePass as TslNodePass;
  const calls = countDraws(renderer, c.mesh);
  const runs: number[] = [];
  const pose = (t: number) => { for (let i = 0; i < count; i++) c.setBakedPose(i, baked, t + i * 0.13); c.update(); };
  pose(0.3);
  const picture = await draw(renderer, scene, camera);
  calls.stop();
  runs.push(pass.runs);
  await draw(renderer, scene, camera);
  runs.push(pass.runs);
  pose(0.7);
  await draw(renderer, scene, camera);
  runs.push(pass.runs);
  const vertexShader = (await renderer.debug.getShaderAsync(scene, camera, c.mesh)).vertexShader ?? '';
  // The GLSL pass from the same GpuSections (joint poses of the last update()), on a WebGLRenderer.
  const gl = glRenderer();
  const glsl = new NodePass(c.sections, true);
  glsl.render(gl);
  // The TSL pass's rows of its page (counted from the top, its first at pass.firstRow) against the GLSL pass's own target.
  const page = pass.target!, { width, height: rows } = glsl.target!;
  let largest = 0, scale = 0;
  const nodes = count * c.sections.deformer.sectionCount;
  for (let t = 0; t < 4; t++) {
    const ours = await renderer.readRenderTargetPixelsAsync(page, 0, 0, page.width, page.height, t) as Float32Array;
    const theirs = new Float32Array(4 * width * rows);
    gl.readRenderTargetPixels(glsl.target!, 0, 0, width, rows, theirs, undefined, t);
    for (let n = 0; n < nodes; n++) {
      const at = pass.offset.value + n, x = n % width, y = Math.floor(n / width);
      const a = 4 * ((page.height - 1 - Math.floor(at / page.width)) * page.width + at % page.width), b = 4 * (y * width + x);
      for (let k = 0; k < 4; k++) {
        largest = Math.max(largest, Math.abs(ours[a + k] - theirs[b + k]));
        if (t < 3 && k === 3) scale = Math.max(scale, Math.abs(theirs[b + k]));
      }
    }
  }
  glsl.dispose();
  gl.dispose();
  c.dispose();
  return {
    nodes, rows, largest, scale, runs,
    vertexNodeMaths: /gcsNodeBlend|gcsRotation|gcsNormalTexel/.test(vertexShader),
    vertexLoads: (vertexShader.match(/texelFetch/g) ?? []).length,
    vertexSizeQueries: (vertexShader.match(/textureSize/g) ?? []).length,
    drawCalls: calls.count, coverage: coverage(picture),
  };
}

export interface DqsPassResult {
  backends: string[];
  /** joints the pass holds (two texels each) and the rows of its targets */
  joints: number; rows: number;
  /** the largest |TSL − GLSL| over every texel of the four targets, and the largest |translation| for scale */
  largest: number; scale: number;
  /** joints whose scale part the pass found a uniform scale (u > 0: their vertices take the quaternion-only path) */
  rigid: number;
  /** the joint pass's runs after the rest pose, the first frame, that frame drawn again, the next frame */
  runs: number[];
  /** the vertex shader: whether it still computes the joint parts (the per-vertex node maths, or the pass's own functions) */
  vertexJointMaths: boolean;
  /** GPU (TSL, joint pass) vs CPU backend pictures, and GPU vs the unanimated picture */
  vsCpu: { image: number; covered: number }; vsRest: { image: number; covered: number }; coverage: number;
}

/**
 * DQS on WebGPURenderer: the TSL joint pass's four targets read back against the GLSL joint pass
 * (node-pass.ts, on a WebGLRenderer) from the same joint poses, texel by texel; how often it runs;
 * the picture against the CPU backend's. `boneScale`: the first bone's scale multiplied by it (a
 * non-uniform scale puts a scale part that is not s·I in the joints below it: the vertex stage's
 * scale blend instead of the quaternion-only path).
 */
async function dqsPass(model: string, times: [number, number], clipName?: string, boneScale?: [number, number, number]): Promise<DqsPassResult> {
  const gcs = await gcsReady;
  const renderer = await gpuRenderer();
  const loaded = await load(model);
  const { scene, camera } = stage(loaded.root);
  const character = new GcsCharacter(gcs, loaded.root, { backend: 'gpu', method: 'dqs' });
  character.update();
  const rest = await draw(renderer, scene, camera);
  let bone: THREE.Object3D | undefined;
  loaded.root.traverse((o) => { if (!bone && (o as THREE.Bone).isBone) bone = o; });
  const baseScale = bone!.scale.clone();
  const mixer = play(loaded, clipName);
  const pose = (t: number) => {
    bone!.scale.copy(baseScale);
    mixer.setTime(t);
    if (boneScale) bone!.scale.multiply(new THREE.Vector3(...boneScale));
    character.update();
  };
  const skin = character.skins[0];
  const material = (Array.isArray(skin.mesh.material) ? skin.mesh.material[0] : skin.mesh.material) as THREE.Material;
  const pass = material.userData.gcsNodePass as TslNodePass;
  const runs = [pass.runs];
  pose(times[0]);
  const gpu = await draw(renderer, scene, camera);
  runs.push(pass.runs);
  await draw(renderer, scene, camera);
  runs.push(pass.runs);
  pose(times[1]);
  await draw(renderer, scene, camera);
  runs.push(pass.runs);
  const vertexShader = (await renderer.debug.getShaderAsync(scene, camera, skin.mesh)).vertexShader ?? '';
  // The GLSL pass from the same GpuSections (joint poses of the last update()), on a WebGLRenderer.
  const gl = glRenderer();
  const glsl = new NodePass(pass.sections, true);
  glsl.render(gl);
  // The TSL pass's row of its page (counted from the top: pass.offset) against the GLSL pass's own target.
  const page = pass.target!, { width, height: rows } = glsl.target!;
  const joints = pass.sections.uniforms.gcsStride.value / 4;
  let largest = 0, scale = 0, rigid = 0;
  for (let t = 0; t < 4; t++) {
    const ours = await renderer.readRenderTargetPixelsAsync(page, 0, 0, page.width, page.height, t) as Float32Array;
    const theirs = new Float32Array(4 * width * rows);
    gl.readRenderTargetPixels(glsl.target!, 0, 0, width, rows, theirs, undefined, t);
    for (let n = 0; n < 2 * joints; n++) {
      const x = n % width, y = Math.floor(n / width);
      const a = 4 * ((page.height - 1 - pass.offset.value - y) * page.width + x), b = 4 * (y * width + x);
      for (let k = 0; k < 4; k++) largest = Math.max(largest, Math.abs(ours[a + k] - theirs[b + k]));
      if (t === 1 && n % 2 === 0) for (let k = 0; k < 3; k++) scale = Math.max(scale, Math.abs(theirs[b + k]));
      if (t === 2 && n % 2 === 0 && theirs[b] > 0) rigid++;
    }
  }
  glsl.dispose();
  gl.dispose();
  const backends = character.skins.map((s) => s.backend); // still 'gpu' after drawing: no fallback happened
  // The first frame again, on the CPU backend.
  character.rebuild(undefined, { backend: 'cpu' });
  pose(times[0]);
  const cpu = await draw(renderer, scene, camera);
  character.dispose();
  return {
    backends, joints, rows, largest, scale, rigid, runs,
    vertexJointMaths: /gcsNodeBlend|gcsDqsJointTexels|gcsRigidScale/.test(vertexShader),
    vsCpu: differing(gpu, cpu), vsRest: differing(gpu, rest), coverage: coverage(gpu),
  };
}

declare global {
  interface Window { __webgpu: { check: typeof check; glslVsTsl: typeof glslVsTsl; crowd: typeof crowd; fallback: typeof fallback; crowdOnWrongRenderer: typeof crowdOnWrongRenderer; influences: typeof influences; velocity: typeof velocity; normalMapped: typeof normalMapped; nodePass: typeof nodePass; dqsPass: typeof dqsPass } }
}
window.__webgpu = { check, glslVsTsl, crowd, fallback, crowdOnWrongRenderer, influences, velocity, normalMapped, nodePass, dqsPass };

