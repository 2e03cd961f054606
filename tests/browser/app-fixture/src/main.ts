// The README's "Using it with three.js" example (GcsCharacter), as an app would write it, adapted
// only so that tests/browser/app.test.ts can compare pictures. Every change from the README is
// marked "test:":
// - a known scene: the camera framed on the character, a directional light casting shadows on a
//   ground plane, a plain background colour;
// - a fixed animation time instead of THREE.Timer (every frame draws the same pose);
// - query switches: ?model=FILE, ?method=gcs|lbs|dqs|classic|three (three: no GcsCharacter,
//   three.js's own SkinnedMesh), ?clip=NAME, ?t=SECONDS;
// - a small hook, window.__app, for the test (clip change, rebuild, dispose, WebGL errors); it can
//   stop the loop after a frame so that screenshots do not compete with rendering on software WebGL.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { initGcsSkin } from 'gcs-skin';
import { GcsCharacter } from 'gcs-skin/three';
import type { DeformerKind } from 'gcs-skin';                // test

// test: the switches.
const params = new URLSearchParams(location.search);
const model = params.get('model') ?? 'character.glb';
const methodParam = params.get('method') ?? 'gcs';
const METHODS: readonly DeformerKind[] = ['gcs', 'lbs', 'dqs', 'classic'];
const method = METHODS.find((m) => m === methodParam) ?? null; // null: three.js's own skinning
if (!method && methodParam !== 'three') throw new Error(`unknown method ${methodParam}`);
const TIME = Number(params.get('t') ?? '0.5');

const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setSize(innerWidth, innerHeight);
renderer.shadowMap.enabled = true;
document.body.append(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x3355aa); // test: a plain background, told apart from the character
const camera = new THREE.PerspectiveCamera(45, innerWidth / innerHeight, 0.1, 100);
camera.position.set(0, 1.2, 4);
scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 2));

const gcs = await initGcsSkin();                            // loads gcs-skin.wasm beside the module
const gltf = await new GLTFLoader().loadAsync(model);

// test: the known scene, framed on the character's bind pose (any size, Y up).
gltf.scene.traverse((o) => {
  if ((o as THREE.Mesh).isMesh) o.castShadow = true;        // GcsCharacter copies the flags when it builds
});
gltf.scene.updateMatrixWorld(true);
const box = new THREE.Box3().setFromObject(gltf.scene);
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

let character: GcsCharacter | null = method ? new GcsCharacter(gcs, gltf.scene, { method, gcs: { sections: 8 } }) : null;
scene.add(gltf.scene);                                      // that is all: the skins are replaced in place

const mixer = new THREE.AnimationMixer(gltf.scene);
const clip = THREE.AnimationClip.findByName(gltf.animations, params.get('clip') ?? '') ?? gltf.animations[0];
if (clip) mixer.clipAction(clip).play();

let frames = 0; // test
let still = false; // test: the hook stops the loop after a frame is drawn (screenshots on software WebGL)
const animate = () => {
  mixer.setTime(TIME);                                      // test: a fixed pose instead of THREE.Timer
  character?.update();                                      // then every skin, once per frame
  renderer.render(scene, camera);
  frames++;
  if (still) renderer.setAnimationLoop(null);               // test
};
renderer.setAnimationLoop(animate);

// test: the hook the acceptance test drives.
const gl = renderer.getContext();
const hook = {
  frames: () => frames,
  clips: () => gltf.animations.map((c) => c.name),
  skinnedMeshes: () => {
    let n = 0;
    gltf.scene.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) n++; });
    return n;
  },
  deformedMeshes: () => character?.meshes.length ?? 0,
  method: () => character?.method ?? 'three',
  textured: () => {
    let t = false;
    gltf.scene.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh && ((o as THREE.Mesh).material as THREE.MeshStandardMaterial).map) t = true; });
    return t;
  },
  play(name: string) {
    const next = THREE.AnimationClip.findByName(gltf.animations, name);
    if (!next) throw new Error(`no clip ${name}`);
    mixer.stopAllAction();
    mixer.clipAction(next).play();
  },
  rebuild(m: DeformerKind) {
    character?.rebuild(m);
  },
  dispose() {
    character?.dispose();
    character = null;
  },
  show(what: { ground?: boolean; character?: boolean }) {
    if (what.ground !== undefined) ground.visible = what.ground;
    if (what.character !== undefined) gltf.scene.visible = what.character;
  },
  /** Draws one more frame, then stops the loop (true) or keeps it running (false). */
  still(stop: boolean) {
    still = stop;
    renderer.setAnimationLoop(animate);
  },
  /** gl.getError() since the last call (errors stay flagged until read). */
  glError: () => gl.getError(),
};
(window as unknown as { __app: typeof hook }).__app = hook;
document.title = 'ready';
