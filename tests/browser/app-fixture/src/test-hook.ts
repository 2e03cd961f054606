// Drives the README's example for tests/browser/app.test.ts, which writes src/main.ts from
// README.md itself: `import { installTestHook } from './test-hook';`, the README's block as it
// stands, then `installTestHook({ renderer, scene, camera, gltf, mixer, character });`.
// (src/reference.ts is the same block without its gcs-skin lines: three.js's own skinning;
// src/webgpu.ts the README's WebGPURenderer block between the same two lines.)
// The test serves its characters as the README's 'character.glb' and compares pictures, so:
// - at import, before the README's code runs, requestAnimationFrame is wrapped to count frames and
//   to hold the loop after a frame (screenshots do not compete with rendering on software WebGL),
//   and THREE.Timer's delta is 0: the pose is the one the hook sets, at a fixed clip time;
// - installTestHook makes a known scene (camera framed on the character, a directional light
//   casting shadows on a ground, a plain background), applies ?method= and ?clip=, and exposes
//   window.__app (clip change, rebuild, dispose, show/hide, WebGL errors).
import * as THREE from 'three';
import type { GLTF } from 'three/addons/loaders/GLTFLoader.js';
import type { DeformerKind } from 'gcs-skin';
import type { GcsCharacter } from 'gcs-skin/three';

const params = new URLSearchParams(location.search);
const TIME = Number(params.get('t') ?? '0.5');

let frames = 0;
let budget = Infinity; // frames the loop may still draw before it is held
let held: FrameRequestCallback | null = null;
const requestFrame = window.requestAnimationFrame.bind(window);
window.requestAnimationFrame = (callback) => requestFrame((time) => {
  if (budget <= 0) {
    held = callback;
    return;
  }
  budget--;
  callback(time);
  frames++;
});
THREE.Timer.prototype.getDelta = () => 0;

export interface Example {
  /** WebGLRenderer, or WebGPURenderer (three/webgpu: its context is WebGL2's on the WebGL2 backend) */
  renderer: { getContext(): unknown };
  scene: THREE.Scene;
  camera: THREE.PerspectiveCamera;
  gltf: GLTF;
  mixer: THREE.AnimationMixer;
  character: GcsCharacter | null;
}

export function installTestHook({ renderer, scene, camera, gltf, mixer, character }: Example): void {
  scene.background = new THREE.Color(0x3355aa); // told apart from the character
  const ground = frameScene(scene, camera, gltf.scene);

  const method = params.get('method');
  if (character && method && method !== character.method) character.rebuild(method as DeformerKind);
  const play = (name: string | null) => {
    const clip = name ? THREE.AnimationClip.findByName(gltf.animations, name) : gltf.animations[0];
    if (name && !clip) throw new Error(`no clip ${name}`);
    mixer.stopAllAction();
    if (clip) mixer.clipAction(clip).play();
    mixer.setTime(TIME);
  };
  play(params.get('clip'));

  const context = renderer.getContext();
  const gl = context instanceof WebGL2RenderingContext || context instanceof WebGLRenderingContext ? context : null;
  const skinned = () => {
    const found: THREE.SkinnedMesh[] = [];
    gltf.scene.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) found.push(o as THREE.SkinnedMesh); });
    return found;
  };
  const live = () => (character && !character.disposed ? character : null);
  const hook = {
    frames: () => frames,
    clips: () => gltf.animations.map((c) => c.name),
    skinnedMeshes: () => skinned().length,
    deformedMeshes: () => live()?.meshes.length ?? 0,
    method: () => live()?.method ?? 'three',
    backend: () => live()?.backend ?? 'three',
    textured: () => skinned().some((m) => !!(m.material as THREE.MeshStandardMaterial).map),
    play: (name: string) => play(name),
    rebuild: (m: DeformerKind) => character?.rebuild(m),
    dispose() {
      if (!character) return;
      character.dispose();
      character.update = () => {}; // the README's loop keeps calling it; an app would drop the character
    },
    show(what: { ground?: boolean; character?: boolean }) {
      if (what.ground !== undefined) ground.visible = what.ground;
      if (what.character !== undefined) gltf.scene.visible = what.character;
    },
    /** Draws one more frame, then holds the loop (true) or lets it run (false). */
    still(stop: boolean) {
      budget = stop ? 1 : Infinity;
      const callback = held;
      held = null;
      if (callback) window.requestAnimationFrame(callback);
    },
    /** gl.getError() since the last call (errors stay flagged until read); 0 on real WebGPU. */
    glError: () => gl?.getError() ?? 0,
  };
  (window as unknown as { __app: typeof hook }).__app = hook;
  document.title = 'ready';
}

/**
 * Frames the character's bind pose (any size, Y up; the source SkinnedMeshes only, the same with
 * and without gcs-skin), lights it with a shadow-casting sun and puts a ground under it.
 */
function frameScene(scene: THREE.Scene, camera: THREE.PerspectiveCamera, root: THREE.Object3D): THREE.Mesh {
  root.traverse((o) => { if ((o as THREE.Mesh).isMesh) o.castShadow = true; });
  root.updateMatrixWorld(true);
  const box = new THREE.Box3();
  root.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) box.expandByObject(o); });
  const size = box.getSize(new THREE.Vector3());
  const centre = box.getCenter(new THREE.Vector3());
  const h = Math.max(size.x, size.y, size.z);
  camera.near = h / 100;
  camera.far = h * 20;
  camera.position.set(centre.x + 0.3 * h, centre.y + 0.2 * h, centre.z + 1.6 * h);
  camera.lookAt(centre.x + 0.3 * h, centre.y - 0.04 * h, centre.z);
  camera.updateProjectionMatrix();
  const sun = new THREE.DirectionalLight(0xffffff, 2.5);
  sun.position.set(centre.x - 1.5 * h, centre.y + 2 * h, centre.z + 0.5 * h);
  sun.target.position.copy(centre);
  sun.castShadow = true;
  sun.shadow.mapSize.set(1024, 1024);
  const s = sun.shadow.camera;
  s.left = s.bottom = -1.6 * h;
  s.right = s.top = 1.6 * h;
  s.near = 0.1 * h;
  s.far = 6 * h;
  sun.shadow.bias = -0.0005;
  scene.add(sun, sun.target);
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(12 * h, 12 * h), new THREE.MeshStandardMaterial({ color: 0xd8d0c0 }));
  ground.rotation.x = -Math.PI / 2;
  ground.position.set(centre.x, box.min.y, centre.z);
  ground.receiveShadow = true;
  scene.add(ground);
  return ground;
}
