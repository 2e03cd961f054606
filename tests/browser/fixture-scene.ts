// Shared by the browser fixture pages (gpu-fixture, webgpu-fixture): load a character, and a lit
// scene with a camera framing it.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { createHuman } from '../../web/lib/human/index.js';

export interface Loaded { root: THREE.Object3D; clips: THREE.AnimationClip[] }

/**
 * 'human' (the default human), 'human-morph' (the same with a morph target at influence 0.8 that
 * swells the body along its normals by up to 4 cm, varying along the body) or a glTF URL.
 */
export async function load(model: string): Promise<Loaded> {
  if (model === 'human' || model === 'human-morph') {
    const h = createHuman();
    if (model === 'human-morph') {
      const g = h.mesh.geometry, p = g.getAttribute('position'), n = g.getAttribute('normal');
      const delta = new Float32Array(3 * p.count);
      for (let i = 0; i < p.count; i++) for (let c = 0; c < 3; c++) delta[3 * i + c] = n.getComponent(i, c) * 0.04 * (0.5 + 0.5 * Math.sin(8 * p.getY(i)));
      g.morphAttributes.position = [new THREE.BufferAttribute(delta, 3)];
      g.morphTargetsRelative = true;
      h.mesh.updateMorphTargets();
      h.mesh.morphTargetInfluences![0] = 0.8;
    }
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
