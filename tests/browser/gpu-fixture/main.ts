// The page of tests/browser/gpu.test.ts: draws GCS on the GPU backend and reads back what the
// vertex shader computed, to compare with the CPU backend on the same frames.
//   positions and normals: the GLSL of gcs-skin/gpu (patchVertexShader, the same function the
//     patched materials use) in a Points pass over every vertex, with the skin's own section
//     texture and attributes, written to an RGBA32F render target and read back;
//   pictures: the character drawn by its patched source material (GPU backend) and by the CPU
//     backend, same frame, same camera, read back as pixels.
import * as THREE from 'three';
import { initGcsSkin, type GcsDeformer, type GcsOptions } from '../../../web/lib/index.js';
import { GcsCharacter, rigInputFromSkinnedMesh, writeSkinMatrices, type Backend } from '../../../web/lib/three.js';
import { GcsCrowd } from '../../../web/lib/crowd.js';
import { patchVertexShader, type GpuPath, type GpuSections } from '../../../web/lib/gpu.js';
import type { GpuMethod, TableSlots } from '../../../web/lib/gpu/layout.js';
import type { NodePass } from '../../../web/lib/gpu/node-pass.js';
import { firstFour } from '../../helpers/influences.js';
import { load, stage } from '../fixture-scene.js';

const W = 512, H = 512;
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setSize(W, H);
renderer.setPixelRatio(1);
document.body.append(renderer.domElement);
const gcsReady = initGcsSkin();

const READ_VERTEX = /* glsl */ `
#include <common>
#include <skinning_pars_vertex>
uniform int readWidth;
uniform int readHeight;
uniform int readWhat;
varying vec4 vOut;
void main() {
	#include <beginnormal_vertex>
	#include <skinbase_vertex>
	#include <skinnormal_vertex>
	#include <begin_vertex>
	#include <skinning_vertex>
	vOut = readWhat == 0 ? vec4( transformed, 1.0 ) : vec4( objectNormal, 0.0 );
	int x = gl_VertexID % readWidth, y = gl_VertexID / readWidth;
	gl_Position = vec4( ( float( x ) + 0.5 ) / float( readWidth ) * 2.0 - 1.0, ( float( y ) + 0.5 ) / float( readHeight ) * 2.0 - 1.0, 0.0, 1.0 );
	gl_PointSize = 1.0;
}`;
const READ_FRAGMENT = /* glsl */ `
varying vec4 vOut;
void main() { gl_FragColor = vOut; }`;

/**
 * What the vertex shader computes for every vertex of a GPU-backend mesh: positions and normals,
 * float32. `uniforms`: what its material's vertex stage reads (joint-level path: the node texture,
 * written by the node pass when the mesh was last drawn).
 */
function readBack(mesh: THREE.Mesh, uniforms: Record<string, THREE.IUniform | undefined>, smooth: boolean, path: GpuPath, method: GpuMethod = 'gcs', slots: TableSlots = 4): { positions: Float32Array; normals: Float32Array } {
  const src = mesh.geometry;
  const V = src.getAttribute('position').count;
  const rw = 1024, rh = Math.ceil(V / rw);
  const points = new THREE.BufferGeometry(); // not indexed: gl_VertexID is the vertex
  for (const name of ['position', 'normal', 'gcsSection', 'gcsBlend', 'gcsBlendThird', 'gcsInfluences0', 'gcsWeights0', 'gcsInfluences1', 'gcsWeights1']) {
    const a = src.getAttribute(name);
    if (a) points.setAttribute(name, a);
  }
  const material = new THREE.ShaderMaterial({
    uniforms: { ...(uniforms as Record<string, THREE.IUniform>), readWidth: { value: rw }, readHeight: { value: rh }, readWhat: { value: 0 } },
    vertexShader: patchVertexShader(READ_VERTEX, smooth, path, method, slots),
    fragmentShader: READ_FRAGMENT,
  });
  const target = new THREE.WebGLRenderTarget(rw, rh, { type: THREE.FloatType, format: THREE.RGBAFormat, minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, depthBuffer: false });
  const scene = new THREE.Scene();
  const cloud = new THREE.Points(points, material);
  cloud.frustumCulled = false;
  scene.add(cloud);
  const camera = new THREE.Camera();
  const out = { positions: new Float32Array(3 * V), normals: new Float32Array(3 * V) };
  const pixels = new Float32Array(4 * rw * rh);
  for (const what of [0, 1]) {
    material.uniforms.readWhat.value = what;
    renderer.setRenderTarget(target);
    renderer.setClearColor(0x000000, 0);
    renderer.clear();
    renderer.render(scene, camera);
    renderer.readRenderTargetPixels(target, 0, 0, rw, rh, pixels);
    const dst = what === 0 ? out.positions : out.normals;
    for (let v = 0; v < V; v++) for (let c = 0; c < 3; c++) dst[3 * v + c] = pixels[4 * v + c];
  }
  renderer.setRenderTarget(null);
  target.dispose();
  material.dispose();
  return out;
}

/** The uniforms a GPU-backend mesh's patched material reads in its vertex stage. */
function vertexUniforms(mesh: THREE.Mesh): Record<string, THREE.IUniform | undefined> {
  const material = (Array.isArray(mesh.material) ? mesh.material[0] : mesh.material) as THREE.Material;
  return material.userData.gcsUniforms as Record<string, THREE.IUniform | undefined>;
}

export interface CheckResult {
  skins: number;
  backends: string[];
  /** each skin's GPU path */
  paths: string[];
  notes: string[];
  height: number;
  /** worst |GPU − CPU| position distance over every vertex and frame, divided by the height */
  positionError: number;
  /** worst distance between the GPU normal and the CPU normal (both unit) */
  normalError: number;
  /** worst distance between the GPU normal and the CPU normal as the CPU wrote it (its smooth-mode length fix included) */
  normalErrorRaw: number;
  /** the same comparison against the bind pose: how far the frames moved the skin (not vacuous) */
  motion: number;
  vertices: number;
  frames: number;
  /** share of pixels differing (any channel > 16/255) between the GPU and CPU backends' pictures, per frame */
  pixelDiff: number[];
  /** share of pixels covered by the character */
  coverage: number;
  /** share of pixels differing between the GPU backend's first frame and each later one: the picture moves */
  pixelMotion: number;
  extColorBufferFloat: boolean;
  /** the largest ratio of the longest to the shortest column of a skin matrix's 3×3 (1: no non-uniform scale) */
  anisotropy: number;
  /** each skin's joints per section in the joint-level table (4, or 8 on a rig that blends more) */
  tableSlots: number[];
  /** how far (of the height) the CPU result moves when each skin is cut to its first 4 influences: what the second set contributes */
  secondSet: number;
  /** per frame and skin, the joint poses' format uploaded: 'compact', 'full', or 'full only' (LBS, the section-level path) */
  formats: string[];
}

/** The format of the joint poses `sections` uploaded at its last update(). */
function poseFormat(sections: GpuSections): string {
  if (!sections.compactTexture) return 'full only';
  return sections.uniforms.gcsCompactPoses!.value === 1 ? 'compact' : 'full';
}

/** The scene drawn on black, read back as RGBA bytes. */
function picture(scene: THREE.Scene, camera: THREE.Camera): Uint8Array {
  renderer.setClearColor(0x000000, 1);
  renderer.render(scene, camera);
  const out = new Uint8Array(4 * W * H), gl = renderer.getContext();
  gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, out);
  return out;
}

/** Share of pixels of which a channel differs by more than 16 (of 255). */
function differing(a: Uint8Array, b: Uint8Array): number {
  let n = 0;
  for (let o = 0; o < a.length; o += 4)
    if (Math.abs(a[o] - b[o]) > 16 || Math.abs(a[o + 1] - b[o + 1]) > 16 || Math.abs(a[o + 2] - b[o + 2]) > 16) n++;
  return n / (a.length / 4);
}

/**
 * Loads a character, deforms it on both backends on the same frames and compares. `boneScale`: the
 * first bone's scale multiplied by it on every frame (a non-uniform scale puts a different scale
 * part K_j in every skin matrix below it).
 */
async function check(model: string, options: GcsOptions & { method?: GpuMethod }, times: number[], clipName?: string, gpuPath: GpuPath | 'auto' = 'auto',
  boneScale?: [number, number, number]): Promise<CheckResult> {
  const { method = 'gcs', ...gcsOptions } = options;
  const gcs = await gcsReady;
  const { root, clips } = await load(model);
  const { scene, camera } = stage(root, W, H); // framed from the bind pose
  const mixer = new THREE.AnimationMixer(root);
  const clip = clips.find((c) => c.name === clipName) ?? clips[0];
  mixer.clipAction(clip).play();
  const character = new GcsCharacter(gcs, root, { method, gcs: gcsOptions, backend: 'gpu', gpuPath });
  const result: CheckResult = { skins: character.skins.length, backends: character.skins.map((s) => s.backend), paths: character.skins.map((s) => s.gpuPath ?? 'none'), notes: character.skins.map((s) => s.backendNote),
    height: 0, positionError: 0, normalError: 0, normalErrorRaw: 0, motion: 0, vertices: 0, frames: times.length, pixelDiff: [], coverage: 0, pixelMotion: 0,
    extColorBufferFloat: renderer.extensions.has('EXT_color_buffer_float'), anisotropy: 1,
    tableSlots: character.skins.map((s) => s.gpuSections?.tableSlots ?? 0), secondSet: 0, formats: [] };
  // The same skins cut to their first 4 influences (on the CPU), for secondSet.
  const cut = character.skins.map((s) => {
    const rig = gcs.createRig(firstFour(rigInputFromSkinnedMesh(s.source)));
    return { rig, deformer: rig.buildGcs(gcsOptions) };
  });
  const pixels = (backend: Backend): Uint8Array => {
    if (character.backend !== backend) character.rebuild(undefined, { backend });
    character.update();
    return picture(scene, camera);
  };
  let first: Uint8Array | null = null;
  let scaled: THREE.Object3D | undefined;
  root.traverse((o) => { if (!scaled && (o as THREE.Bone).isBone) scaled = o; });
  const baseScale = scaled!.scale.clone();
  for (const t of times) {
    scaled!.scale.copy(baseScale);
    mixer.setTime(t);
    if (boneScale) scaled!.scale.multiply(new THREE.Vector3(...boneScale));
    if (character.backend !== 'gpu') character.rebuild(undefined, { backend: 'gpu' });
    character.update();
    renderer.render(scene, camera); // the joint-level path's node pass runs before the first draw
    character.skins.forEach((skin, k) => {
      const mesh = skin.mesh as THREE.Mesh;
      const sections = skin.gpuSections!;
      result.formats.push(poseFormat(sections));
      const gpuOut = readBack(mesh, vertexUniforms(mesh), sections.smooth, sections.path, sections.method, sections.tableSlots);
      const d = skin.deformer as GcsDeformer;
      const S = (skin as unknown as { skin: Float32Array }).skin;
      d.deform(S); // the same frame on the CPU
      for (let j = 0; j < S.length / 16; j++) {
        const l = [0, 1, 2].map((c) => Math.hypot(S[16 * j + 4 * c], S[16 * j + 4 * c + 1], S[16 * j + 4 * c + 2]));
        result.anisotropy = Math.max(result.anisotropy, Math.max(...l) / Math.min(...l));
      }
      const cpuP = d.positions, cpuN = d.normals;
      const rest = mesh.geometry.getAttribute('position').array as Float32Array;
      const height = skin.rig.height;
      result.height = Math.max(result.height, height);
      result.vertices += t === times[0] ? d.vertexCount : 0;
      for (let v = 0; v < d.vertexCount; v++) {
        const dp = Math.hypot(gpuOut.positions[3 * v] - cpuP[3 * v], gpuOut.positions[3 * v + 1] - cpuP[3 * v + 1], gpuOut.positions[3 * v + 2] - cpuP[3 * v + 2]) / height;
        const moved = Math.hypot(rest[3 * v] - cpuP[3 * v], rest[3 * v + 1] - cpuP[3 * v + 1], rest[3 * v + 2] - cpuP[3 * v + 2]) / height;
        const l = Math.hypot(cpuN[3 * v], cpuN[3 * v + 1], cpuN[3 * v + 2]) || 1;
        const dn = Math.hypot(gpuOut.normals[3 * v] - cpuN[3 * v] / l, gpuOut.normals[3 * v + 1] - cpuN[3 * v + 1] / l, gpuOut.normals[3 * v + 2] - cpuN[3 * v + 2] / l);
        if (!(dp <= result.positionError)) result.positionError = Number.isNaN(dp) ? Infinity : dp;
        if (!(dn <= result.normalError)) result.normalError = Number.isNaN(dn) ? Infinity : dn;
        const raw = Math.hypot(gpuOut.normals[3 * v] - cpuN[3 * v], gpuOut.normals[3 * v + 1] - cpuN[3 * v + 1], gpuOut.normals[3 * v + 2] - cpuN[3 * v + 2]);
        if (!(raw <= result.normalErrorRaw)) result.normalErrorRaw = Number.isNaN(raw) ? Infinity : raw;
        if (moved > result.motion) result.motion = moved;
      }
      cut[k].deformer.deform(S);
      const src = d.sourceVertex!, cutSrc = cut[k].deformer.sourceVertex!, cutP = cut[k].deformer.positions;
      const outputOf = new Uint32Array(src.length);
      for (let o = 0; o < cutSrc.length; o++) outputOf[cutSrc[o]] = o;
      for (let v = 0; v < d.vertexCount; v++) {
        const o = outputOf[src[v]];
        result.secondSet = Math.max(result.secondSet, Math.hypot(cutP[3 * o] - cpuP[3 * v], cutP[3 * o + 1] - cpuP[3 * v + 1], cutP[3 * o + 2] - cpuP[3 * v + 2]) / height);
      }
    });
    const a = pixels('gpu'), b = pixels('cpu');
    first ??= a;
    let covered = 0;
    for (let i = 0; i < W * H; i++) if (a[4 * i] + a[4 * i + 1] + a[4 * i + 2] > 0) covered++;
    result.pixelDiff.push(differing(a, b));
    result.pixelMotion = Math.max(result.pixelMotion, differing(a, first));
    result.coverage = Math.max(result.coverage, covered / (W * H));
  }
  for (const c of cut) { c.deformer.dispose(); c.rig.dispose(); }
  character.dispose();
  return result;
}

export interface CrowdResult {
  path: string; tableSlots: number; instances: number;
  /** the joint poses' format uploaded (poseFormat) */
  format: string;
  /** rows and width of the texture the frame uploaded */
  rows: number;
  width: number;
  /** worst |GPU − CPU| over every instance's vertices (each instance at its own clip time), of the height */
  positionError: number;
  /** share of pixels differing between the crowd's instance 0 (one instanced draw) and the CPU backend's character at the same pose */
  pixelDiff: number;
  coverage: number;
}

/**
 * GcsCrowd: instance i posed at `times[i]`. What the shader computes for each instance (its texels
 * at gcsBase + i · gcsStride, read back as in check) against the CPU deformer on that instance's
 * skin matrices; then the crowd drawn (instance 0 placed where the source stands, the source turned
 * and scaled unevenly first) against the CPU backend's picture of the character at times[0].
 */
async function crowd(model: string, times: number[], clipName?: string, gpuPath: GpuPath | 'auto' = 'auto'): Promise<CrowdResult> {
  const gcs = await gcsReady;
  const { root, clips } = await load(model);
  const { scene, camera } = stage(root, W, H);
  let source: THREE.SkinnedMesh | undefined;
  root.traverse((o) => { if (!source && (o as THREE.SkinnedMesh).isSkinnedMesh) source = o as THREE.SkinnedMesh; });
  const mixer = new THREE.AnimationMixer(root);
  mixer.clipAction(clips.find((c) => c.name === clipName) ?? clips[0]).play();
  const c = new GcsCrowd(gcs, source!, times.length, { gpuPath });
  const tmp = new THREE.Matrix4();
  times.forEach((t, i) => {
    mixer.setTime(t);
    root.updateMatrixWorld(true);
    writeSkinMatrices(source!, c.skins, c.offsetOf(i), tmp);
  });
  c.update();
  const drawn = new THREE.Scene(); // one draw runs the node pass (joint-level path) for every instance
  drawn.add(c.mesh);
  renderer.render(drawn, camera);
  drawn.remove(c.mesh);
  const sections = c.sections, height = c.rig.height;
  const result: CrowdResult = { path: sections.path, tableSlots: sections.tableSlots, instances: times.length, format: poseFormat(sections), positionError: 0, pixelDiff: 1, coverage: 0,
    ...(({ height: rows, width }) => ({ rows, width }))((poseFormat(sections) === 'compact' ? sections.compactTexture! : sections.texture).image as { width: number; height: number }) };
  const uniforms = vertexUniforms(c.mesh);
  const base = uniforms.gcsBase!.value as number, stride = uniforms.gcsStride!.value as number;
  times.forEach((_, i) => {
    const gpuOut = readBack(c.mesh, { ...uniforms, gcsBase: { value: base + i * stride } }, sections.smooth, sections.path);
    c.deformer.deform(c.skins.subarray(c.offsetOf(i), c.offsetOf(i) + 16 * c.jointCount));
    const cpu = c.deformer.positions;
    for (let v = 0; v < c.deformer.vertexCount; v++) {
      const dp = Math.hypot(gpuOut.positions[3 * v] - cpu[3 * v], gpuOut.positions[3 * v + 1] - cpu[3 * v + 1], gpuOut.positions[3 * v + 2] - cpu[3 * v + 2]) / height;
      if (!(dp <= result.positionError)) result.positionError = Number.isNaN(dp) ? Infinity : dp;
    }
  });
  // The picture: the character on the CPU backend at times[0], then the crowd's instance 0 in its place,
  // turned and scaled unevenly (the joint-level path folds the placement into the node pass).
  root.rotation.y += 0.6;
  root.scale.multiply(new THREE.Vector3(1.2, 0.85, 1.1));
  mixer.setTime(times[0]);
  const character = new GcsCharacter(gcs, root, { backend: 'cpu' });
  character.update();
  const read = (): Uint8Array => picture(scene, camera);
  const cpu = read();
  for (const m of character.meshes) m.visible = false;
  c.mesh.count = 1;
  c.mesh.setMatrixAt(0, source!.matrixWorld);
  c.mesh.instanceMatrix.needsUpdate = true;
  scene.add(c.mesh);
  const gpu = read();
  let covered = 0;
  for (let i = 0; i < W * H; i++) if (gpu[4 * i] + gpu[4 * i + 1] + gpu[4 * i + 2] > 0) covered++;
  result.coverage = covered / (W * H);
  result.pixelDiff = differing(gpu, cpu);
  character.dispose();
  c.dispose();
  return result;
}

export interface MaterialResult {
  type: string; backend: string; path: string; note: string;
  /** share of pixels differing between the GPU and CPU backends' pictures (character, its shadows on the ground) */
  pixelDiff: number;
  /** share of pixels the character covers, and that its shadows darken on the ground (GPU picture) */
  coverage: number; shadow: number;
  /** share of pixels differing from the character drawn in its bind pose on the GPU backend: the pose reaches the picture */
  posed: number;
}

const MATERIALS = {
  MeshBasicMaterial: () => new THREE.MeshBasicMaterial({ color: 0xd08050 }),
  MeshLambertMaterial: () => new THREE.MeshLambertMaterial({ color: 0xd08050 }),
  MeshPhongMaterial: () => new THREE.MeshPhongMaterial({ color: 0xd08050, shininess: 60 }),
  MeshStandardMaterial: () => new THREE.MeshStandardMaterial({ color: 0xd08050, roughness: 0.5 }),
  MeshPhysicalMaterial: () => new THREE.MeshPhysicalMaterial({ color: 0xd08050, roughness: 0.4, clearcoat: 0.5 }),
  MeshToonMaterial: () => new THREE.MeshToonMaterial({ color: 0xd08050 }),
  MeshMatcapMaterial: () => new THREE.MeshMatcapMaterial({ color: 0xd08050, matcap: matcapTexture() }),
  MeshNormalMaterial: () => new THREE.MeshNormalMaterial(),
} as const;

/** A matcap whose colour follows the normal's direction, so that normals show in the picture. */
function matcapTexture(): THREE.DataTexture {
  const n = 64, data = new Uint8Array(4 * n * n);
  for (let y = 0; y < n; y++) for (let x = 0; x < n; x++) data.set([255 * x / n, 255 * y / n, 128, 255], 4 * (y * n + x));
  const t = new THREE.DataTexture(data, n, n);
  t.needsUpdate = true;
  return t;
}

/**
 * Every built-in material on the GPU backend (GLSL kit, WebGLRenderer) against the CPU backend:
 * the character wears it, casts shadows from a directional light (MeshDepthMaterial) and a point
 * light (MeshDistanceMaterial) onto a ground that receives them, posed at `time`.
 * `broken`: the material's own onBeforeCompile declares a uniform the GCS patch declares too, so
 * only the patched shader fails to compile.
 */
async function materials(model: string, time: number, types: string[], clipName?: string, broken = false): Promise<MaterialResult[]> {
  const gcs = await gcsReady;
  const { root, clips } = await load(model);
  const { scene, camera } = stage(root, W, H);
  const box = new THREE.Box3().setFromObject(root), size = box.getSize(new THREE.Vector3()).length();
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(size * 4, size * 4), new THREE.MeshLambertMaterial({ color: 0x808080 }));
  ground.rotation.x = -Math.PI / 2;
  ground.position.y = box.min.y;
  ground.receiveShadow = true;
  scene.add(ground);
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.copy(box.getCenter(new THREE.Vector3())).add(new THREE.Vector3(size, size * 2, size * 0.5));
  sun.target.position.copy(box.getCenter(new THREE.Vector3()));
  sun.castShadow = true;
  Object.assign(sun.shadow.camera, { left: -size, right: size, top: size, bottom: -size, near: size / 100, far: size * 6 });
  sun.shadow.mapSize.set(1024, 1024);
  const lamp = new THREE.PointLight(0xffffff, 3, 0, 0);
  lamp.position.copy(box.getCenter(new THREE.Vector3())).add(new THREE.Vector3(-size * 0.6, size * 0.5, size * 0.3));
  lamp.castShadow = true;
  scene.add(sun, sun.target, lamp);
  renderer.shadowMap.enabled = true;
  const sources: THREE.SkinnedMesh[] = [];
  root.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) sources.push(o as THREE.SkinnedMesh); });
  const mixer = new THREE.AnimationMixer(root);
  mixer.clipAction(clips.find((c) => c.name === clipName) ?? clips[0]).play();
  const read = (): Uint8Array => picture(scene, camera);
  const results: MaterialResult[] = [];
  for (const type of types) {
    for (const s of sources) {
      s.castShadow = true;
      s.material = MATERIALS[type as keyof typeof MATERIALS]();
      if (broken) s.material.onBeforeCompile = (shader) => { shader.vertexShader = `uniform float gcsBase;\n${shader.vertexShader}`; };
    }
    mixer.setTime(0);
    mixer.stopAllAction();
    root.updateMatrixWorld(true);
    const character = new GcsCharacter(gcs, root, { backend: 'gpu' });
    character.update();
    const bind = read();
    mixer.clipAction(clips.find((c) => c.name === clipName) ?? clips[0]).play();
    mixer.setTime(time);
    character.update();
    const gpu = read();
    const backend = character.backend, path = character.skins[0].gpuPath ?? 'none';
    const note = character.skins.map((k) => k.backendNote).filter(Boolean).join('; ');
    const again = read(); // after a failed compile this is the CPU backend's frame
    character.rebuild(undefined, { backend: 'cpu' });
    character.update();
    const cpu = read();
    let covered = 0, shadow = 0;
    ground.visible = false;
    const alone = read();
    ground.visible = true;
    for (const s of sources) s.visible = false; // the ground with no character: where the shadows fall
    for (const m of character.meshes) m.visible = false;
    const empty = read();
    for (const m of character.meshes) m.visible = true;
    for (const s of sources) s.visible = true;
    for (let i = 0; i < W * H; i++) {
      if (alone[4 * i] + alone[4 * i + 1] + alone[4 * i + 2] > 0) covered++;
      else if (empty[4 * i] - gpu[4 * i] > 24) shadow++;
    }
    results.push({ type, backend, path, note, pixelDiff: differing(broken ? again : gpu, cpu), coverage: covered / (W * H), shadow: shadow / (W * H), posed: differing(gpu, bind) });
    character.dispose();
  }
  renderer.shadowMap.enabled = false;
  return results;
}

export interface PassResult {
  /** renderer.render calls (three.js's info.render.frame: the node pass is one) for: the first frame, the same frame drawn again, the next frame */
  renders: number[];
  /** with float render targets stubbed away: the skin's path and note after its first draw, and its picture against the CPU backend's */
  fallbackPath: string; fallbackNote: string; fallbackDiff: number;
  /** the crowd's next update() after a draw without float render targets */
  crowdError: string;
}

/**
 * The node pass runs once per frame (at the skin's first draw after update(), shadows on), and a
 * renderer without float render targets (EXT_color_buffer_float stubbed away) moves a skin to the
 * section-level path with a note, and stops a crowd with a GcsError.
 */
async function nodePass(model: string, time: number): Promise<PassResult> {
  const gcs = await gcsReady;
  const { root, clips } = await load(model);
  const { scene, camera } = stage(root, W, H);
  const mixer = new THREE.AnimationMixer(root);
  mixer.clipAction(clips[0]).play();
  mixer.setTime(time);
  renderer.shadowMap.enabled = true;
  scene.traverse((o) => { if ((o as THREE.DirectionalLight).isDirectionalLight) (o as THREE.DirectionalLight).castShadow = true; });
  let source: THREE.SkinnedMesh | undefined;
  root.traverse((o) => { if (!source && (o as THREE.SkinnedMesh).isSkinnedMesh) source = o as THREE.SkinnedMesh; });
  source!.castShadow = true;
  const character = new GcsCharacter(gcs, root, { backend: 'gpu' });
  const info = renderer.info.render;
  const count = (draw: () => void): number => { const before = info.frame; draw(); return info.frame - before; };
  const renders = [
    count(() => { character.update(); picture(scene, camera); }),
    count(() => picture(scene, camera)),
    count(() => { mixer.setTime(time + 0.1); character.update(); picture(scene, camera); }),
  ];
  character.dispose();
  const has = renderer.extensions.has.bind(renderer.extensions);
  renderer.extensions.has = (name: string) => name !== 'EXT_color_buffer_float' && has(name);
  const stubbed = new GcsCharacter(gcs, root, { backend: 'gpu' });
  stubbed.update();
  picture(scene, camera); // the first draw finds no float targets
  const skin = stubbed.skins[0];
  const fallbackPath = skin.gpuPath ?? 'none', fallbackNote = skin.backendNote;
  stubbed.update();
  const gpu = picture(scene, camera);
  stubbed.rebuild(undefined, { backend: 'cpu' });
  stubbed.update();
  const fallbackDiff = differing(gpu, picture(scene, camera));
  stubbed.dispose();
  const c = new GcsCrowd(gcs, source!, 2);
  c.update();
  const alone = new THREE.Scene();
  alone.add(c.mesh);
  picture(alone, camera);
  let crowdError = '';
  try { c.update(); } catch (e) { crowdError = `${(e as { code?: string }).code}: ${(e as Error).message}`; }
  c.dispose();
  renderer.extensions.has = has;
  renderer.shadowMap.enabled = false;
  return { renders, fallbackPath, fallbackNote, fallbackDiff, crowdError };
}

export interface SharedPassResult {
  /** render() calls for a frame of three characters, that frame drawn again, and a frame after a dispose and two new characters (each after the characters' first) */
  renders: number[];
  /** per character, the first row of its node pass (−1 for DQS) and of its joint pass, after the first frame and after the changes */
  rows: { first: number[][]; after: number[][] };
  /** the heights of the node page and the joint page after the changes */
  heights: number[];
  /** whether the node passes share one target and the joint passes another, before and after */
  shared: boolean[];
  /** share of pixels differing from the CPU backend's picture, after the first frame and after the changes */
  vsCpu: number[];
  /** the share of pixels that differ from the unanimated characters (the poses are applied) */
  vsRest: number;
}

/**
 * Every node pass of a renderer in one page: three characters (GCS, GPU DQS, GCS) posed at
 * different times are computed by one render(), each reading its own rows; then the DQS one is
 * disposed and two GCS ones are added (the first takes the freed row, the second grows the page,
 * which recomputes all): the pictures equal the CPU backend's each time.
 */
async function sharedPass(model: string): Promise<SharedPassResult> {
  const gcs = await gcsReady;
  // The GPU characters and their CPU twins (same models, places, methods and clip times), each set in its own scene.
  const sets = await Promise.all([0, 1].map(async () => {
    const scene = new THREE.Scene();
    scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2));
    const loads = await Promise.all([0, 1, 2, 3, 4].map(() => load(model)));
    const size = new THREE.Box3().setFromObject(loads[0].root).getSize(new THREE.Vector3());
    loads.forEach((l, i) => { l.root.position.x = (i - 2) * size.x * 1.2; scene.add(l.root); l.root.visible = i < 3; });
    const mixers = loads.map((l) => { const m = new THREE.AnimationMixer(l.root); m.clipAction(l.clips[0]).play(); return m; });
    return { scene, loads, mixers, characters: [] as (GcsCharacter | null)[] };
  }));
  const [gpu, cpu] = sets;
  gpu.scene.updateMatrixWorld(true);
  const all = new THREE.Box3().setFromObject(gpu.scene), centre = all.getCenter(new THREE.Vector3()), extent = all.getSize(new THREE.Vector3()).length();
  const camera = new THREE.PerspectiveCamera(40, W / H, extent / 100, extent * 10);
  camera.position.copy(centre).add(new THREE.Vector3(0, 0.2, 1).normalize().multiplyScalar(extent * 1.1));
  camera.lookAt(centre);
  const rest = picture(gpu.scene, camera);
  const methods = ['gcs', 'dqs', 'gcs', 'gcs', 'gcs'] as const;
  const make = (i: number) => {
    for (const set of sets) {
      set.loads[i].root.visible = true;
      set.characters[i] = new GcsCharacter(gcs, set.loads[i].root, { backend: set === gpu ? 'gpu' : 'cpu', method: methods[i] });
    }
  };
  [0, 1, 2].forEach(make);
  const info = renderer.info.render;
  // Both sets posed and updated; the GPU set drawn (counting render() calls), then the CPU set.
  const frame = (t = 0.2): { renders: number; vsCpu: number } => {
    for (const set of sets) set.characters.forEach((c, i) => { if (c) { set.mixers[i].setTime(t + 0.37 * i); c.update(); } });
    const before = info.frame;
    const image = picture(gpu.scene, camera);
    const renders = info.frame - before;
    return { renders, vsCpu: differing(image, picture(cpu.scene, camera)) };
  };
  // Per character: its node pass (null for DQS) and its joint pass.
  const passes = () => gpu.characters.filter((c): c is GcsCharacter => !!c).flatMap((c) => c.skins.map((s) => {
    const m = s.mesh.material as THREE.Material | THREE.Material[];
    const pass = (Array.isArray(m) ? m[0] : m).userData.gcsNodePass as NodePass;
    return pass.jointPass ? { nodes: pass, joints: pass.jointPass } : { nodes: null, joints: pass };
  }));
  const rowsOf = () => passes().map((p) => [p.nodes ? p.nodes.firstRow : -1, p.joints.firstRow]);
  const shared = () => new Set(passes().flatMap((p) => (p.nodes ? [p.nodes.target] : []))).size === 1 && new Set(passes().map((p) => p.joints.target)).size === 1;
  frame(0.1); // a skin joins its renderer's page at its first draw, and runs it then
  const first = frame();
  const before = info.frame;
  picture(gpu.scene, camera); // the same poses drawn again: no pass
  const renders = [first.renders, info.frame - before];
  const firstRows = rowsOf(), firstShared = shared();
  for (const set of sets) {
    set.characters[1]!.dispose();
    set.characters[1] = null;
    set.loads[1].root.visible = false;
  }
  make(3);
  make(4);
  frame(0.1);
  const after = frame();
  renders.push(after.renders);
  const result: SharedPassResult = {
    renders, rows: { first: firstRows, after: rowsOf() }, heights: [passes()[0].nodes!.target!.height, passes()[0].joints.target!.height],
    shared: [firstShared, shared()], vsCpu: [first.vsCpu, after.vsCpu],
    vsRest: differing(picture(gpu.scene, camera), rest),
  };
  for (const set of sets) for (const c of set.characters) c?.dispose();
  return result;
}

declare global {
  interface Window { __gpu: { check: typeof check; crowd: typeof crowd; materials: typeof materials; nodePass: typeof nodePass; sharedPass: typeof sharedPass } }
}
window.__gpu = { check, crowd, materials, nodePass, sharedPass };
