// The crowd page's stage: sky colour and fog, lights (a shadow-casting sun), the ground, the camera
// left of the control column and its orbit controls.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { sidebarWidth } from './layout.js';
import type { DemoRenderer } from './renderer.js';

export interface CrowdStage {
  scene: THREE.Scene;
  sun: THREE.DirectionalLight;
  camera: THREE.PerspectiveCamera;
  controls: OrbitControls;
}

export function createStage(renderer: DemoRenderer): CrowdStage {
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
  return { scene, sun, camera, controls };
}

/** Fits the sun's shadow camera to a crowd `halfSide` world units across from its centre. */
export function fitShadow(sun: THREE.DirectionalLight, halfSide: number): void {
  sun.shadow.camera.left = sun.shadow.camera.bottom = -halfSide;
  sun.shadow.camera.right = sun.shadow.camera.top = halfSide;
  sun.shadow.camera.updateProjectionMatrix();
}
