// The views: one scene and one camera, drawn once per view into its column of the canvas with the
// view's camera layer; the camera framed on the character between the labels and the readouts.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { distanceToFit } from './fit-box.js';
import { updateLabels } from './labels.js';
import { applySidebar, viewRects } from './layout.js';
import { updateReadouts } from './readouts.js';
import { createRenderer, rendererKind } from './renderer.js';
import { dom, LAYER, state, type Character } from './state.js';

/** The renderer, scene, camera, orbit controls, lights and ground. */
export async function initViews(): Promise<void> {
  const kind = rendererKind();
  const renderer = (state.renderer = await createRenderer(kind));
  if (kind === 'webgpu') state.Skin = (await import('../lib/webgpu.js')).SkinDeformer;
  renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFShadowMap;
  document.body.prepend(renderer.domElement);

  const scene = (state.scene = new THREE.Scene());
  scene.background = new THREE.Color(0x242a35);
  scene.fog = new THREE.Fog(0x242a35, 7, 16);

  const camera = (state.camera = new THREE.PerspectiveCamera(30, 1, 0.05, 100));
  camera.position.set(1.9, 1.5, 4.9);
  const controls = (state.controls = new OrbitControls(camera, renderer.domElement));
  controls.target.set(0, 0.95, 0);
  controls.enableDamping = true;
  controls.minDistance = 0.5;
  controls.maxDistance = 20;
  controls.update();

  scene.add(new THREE.HemisphereLight(0xe8eeff, 0x30343d, 1.7));
  const key = (state.key = new THREE.DirectionalLight(0xfff4e8, 2.4));
  key.position.set(2.2, 4.2, 3.0);
  key.castShadow = true;
  key.shadow.mapSize.set(1024, 1024);
  const sc = key.shadow.camera;
  sc.left = -1.6; sc.right = 1.6; sc.top = 2.4; sc.bottom = -0.6; sc.near = 0.5; sc.far = 12;
  key.shadow.bias = -0.0005;
  key.shadow.normalBias = 0.02;
  key.target.position.set(0, 0.9, 0);
  scene.add(key, key.target);
  const rim = new THREE.DirectionalLight(0xa8c8ff, 1.3);
  rim.position.set(-3, 2.6, -3.2);
  scene.add(rim);

  const ground = new THREE.Mesh(new THREE.CircleGeometry(8, 64), new THREE.MeshStandardMaterial({ color: 0x3a4250, roughness: 0.95 }));
  ground.rotation.x = -Math.PI / 2;
  ground.receiveShadow = true;
  scene.add(ground);
  const grid = new THREE.GridHelper(16, 32, 0x56607a, 0x46505f);
  (grid.material as THREE.Material).transparent = true;
  (grid.material as THREE.Material).opacity = 0.55;
  grid.position.y = 0.001;
  scene.add(grid);

  scene.add(state.gcsGroup, state.classicGroup);
}

export function onWindowResize(): void {
  state.renderer.setSize(applySidebar(), window.innerHeight);
  updateLabels();
  updateReadouts();
}

/** The views changed (the LBS view, the window's size): lay them out and frame the character again. */
export function relayout(): void {
  onWindowResize();
  if (state.current) frameCharacter(state.current);
}

export function render(): void {
  const { renderer, camera, scene } = state;
  const h = window.innerHeight;
  renderer.setScissorTest(true);
  for (const r of viewRects()) {
    renderer.setViewport(r.x, 0, r.width, h);
    renderer.setScissor(r.x, 0, r.width, h);
    camera.aspect = r.width / h;
    // The picture moved down by viewShift px (its centre in the band between labels and readouts).
    camera.setViewOffset(r.width, h, 0, -state.viewShift, r.width, h);
    camera.layers.set(0);
    camera.layers.enable(LAYER[r.kind]);
    renderer.render(scene, camera);
  }
}

/** From the target, where the camera looks from (as the first view opened for the human). */
const VIEW_DIRECTION = new THREE.Vector3(1.9, 0.55, 4.9).normalize();
/** The key light's place relative to the character's centre. */
const KEY_OFFSET = new THREE.Vector3(2.2, 3.3, 3.0);

/**
 * Rows of the window free for the character: below every view's label (title, settings, the
 * classic model's carried parts) and above every readout, measured on the page (px from the top).
 */
function freeBand(): { top: number; bottom: number } {
  const h = window.innerHeight;
  let top = 0, bottom = h;
  for (const el of dom.labels.querySelectorAll('.label')) top = Math.max(top, el.getBoundingClientRect().bottom);
  for (const el of dom.readouts.querySelectorAll('.readout')) bottom = Math.min(bottom, el.getBoundingClientRect().top);
  // Keep at least half the height for the character, whatever the text (a tiny window).
  if (bottom - top < 0.5 * h) {
    const lack = 0.5 * h - (bottom - top);
    top = Math.max(0, top - lack / 2);
    bottom = Math.min(h, top + 0.5 * h);
  }
  return { top: top + 6, bottom: bottom - 6 };
}

/**
 * Points the shared camera at the character and backs off until its bounding box fits every view
 * between the labels and the readouts (freeBand), the picture moved so that it is centred in that
 * band; the key light's shadow camera is fitted to it too. Sizes differ a lot (glTF files are
 * scaled to 1.8 units, but a fox is long and low, a human tall and thin). Called again when the
 * views change (LBS view, window size, the labels' text).
 */
export function frameCharacter(ch: Character): void {
  const { camera, controls, key } = state;
  updateLabels();
  updateReadouts();
  ch.holder.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(ch.holder);
  if (box.isEmpty() || !Number.isFinite(box.min.x + box.max.x)) return;
  const centre = box.getCenter(new THREE.Vector3());
  const h = window.innerHeight;
  const band = freeBand();
  const width = Math.min(...viewRects().map((r) => r.width));
  const tanHalf = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2));
  const tanV = tanHalf * 0.94 * (band.bottom - band.top) / h;
  const tanH = tanHalf * (width / h) * 0.88;
  state.viewShift = (band.top + band.bottom) / 2 - h / 2;
  const distance = distanceToFit(box, VIEW_DIRECTION, tanH, tanV);
  camera.position.copy(centre).addScaledVector(VIEW_DIRECTION, distance);
  controls.target.copy(centre);
  controls.update();

  const radius = box.getSize(new THREE.Vector3()).length() / 2;
  key.target.position.copy(centre);
  key.position.copy(centre).add(KEY_OFFSET);
  const sc = key.shadow.camera;
  sc.left = sc.bottom = -1.3 * radius;
  sc.right = sc.top = 1.3 * radius;
  sc.far = KEY_OFFSET.length() + 4 * radius;
  sc.updateProjectionMatrix();
}
