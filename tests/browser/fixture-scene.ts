// Shared by the browser fixture pages (gpu-fixture, webgpu-fixture): load a character, and a lit
// scene with a camera framing it.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { createHuman } from '../../web/lib/human/index.js';

export interface Loaded { root: THREE.Object3D; clips: THREE.AnimationClip[] }

/** 'human' (the default human) or a glTF URL. */
export async function load(model: string): Promise<Loaded> {
  if (model === 'human') {
    const h = createHuman();
    const root = new THREE.Group();
    root.add(h.mesh);
    return { root, clips: h.clips };
  }
  const gltf = await new GLTFLoader().loadAsync(model);
  return { root: gltf.scene, clips: gltf.animations };
}

/** A scene lit by a hemisphere and a sun holding `root`, and a camera framing `root` as it stands now. */
export function stage(root: THREE.Object3D, width: number, height: number): { scene: THREE.Scene; camera: THREE.PerspectiveCamera } {
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2));
  const sun = new THREE.DirectionalLight(0xffffff, 2);
  sun.position.set(2, 4, 3);
  scene.add(sun);
  scene.add(root);
  root.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(root);
  const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
  const camera = new THREE.PerspectiveCamera(40, width / height, size / 100, size * 10);
  camera.position.copy(centre).add(new THREE.Vector3(0.6, 0.3, 1).normalize().multiplyScalar(size * 1.3));
  camera.lookAt(centre);
  return { scene, camera };
}
