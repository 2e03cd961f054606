// The README's WebGPURenderer example ("### With WebGPURenderer"), line for line: the consumer app
// test (tests/browser/app.test.ts) type-checks it with `tsc --noEmit --strict` against the packed
// package, as it does the WebGLRenderer example in main.ts.
import * as THREE from 'three/webgpu';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { initGcsSkin } from 'gcs-skin';
import { GcsCharacter } from 'gcs-skin/webgpu';

const renderer = new THREE.WebGPURenderer({ antialias: true }); // WebGPU, else its WebGL2 backend
await renderer.init();
renderer.setSize(innerWidth, innerHeight);
renderer.shadowMap.enabled = true;
document.body.append(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(45, innerWidth / innerHeight, 0.1, 100);
camera.position.set(0, 1.2, 4);
scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 2));

const gcs = await initGcsSkin();
const gltf = await new GLTFLoader().loadAsync('character.glb');
const character = new GcsCharacter(gcs, gltf.scene, { backend: 'gpu' }); // GCS in the vertex stage (TSL)
scene.add(gltf.scene);
if (character.backend !== 'gpu') console.warn(character.skins.map((s) => s.backendNote).join('; '));

const mixer = new THREE.AnimationMixer(gltf.scene);
const clip = gltf.animations[0];
if (clip) mixer.clipAction(clip).play();

const timer = new THREE.Timer();
timer.connect(document);
renderer.setAnimationLoop((time: number) => {
  timer.update(time);
  mixer.update(timer.getDelta());
  character.update();
  renderer.render(scene, camera);
});
