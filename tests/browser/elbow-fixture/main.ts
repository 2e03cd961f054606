// The page of tests/browser/elbow.test.ts: our human's right elbow, close up, at a fixed frame of
// the run clip, drawn by the CPU backend as the default GCS, as DQS and as the stepped plain GCS,
// with one camera and light. The test compares the pictures (steps show as shading bands).
import * as THREE from 'three';
import { initGcsSkin, type DeformerKind, type GcsOptions } from '../../../web/lib/index.js';
import { GcsCharacter } from '../../../web/lib/three.js';
import { createHuman } from '../../../web/lib/human/index.js';

const W = 384, H = 384;
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setSize(W, H);
renderer.setPixelRatio(1);
document.body.append(renderer.domElement);

/** Renders one method at the run clip's time t; returns the canvas as a PNG data URL. */
async function shot(method: DeformerKind, gcs: GcsOptions, t: number, bone: string, offset: readonly number[]): Promise<string> {
  const core = await ready;
  const human = createHuman();
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x202428);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x303030, 1.2));
  const sun = new THREE.DirectionalLight(0xffffff, 2.5);
  sun.position.set(-1, 2, 3);
  scene.add(sun);
  const group = new THREE.Group();
  group.add(human.mesh);
  scene.add(group);
  (human.mesh.material as THREE.MeshStandardMaterial).flatShading = false;
  const character = new GcsCharacter(core, group, { method, gcs });
  const mixer = new THREE.AnimationMixer(group);
  mixer.clipAction(human.clips.find((c) => c.name === 'run')!).play();
  mixer.setTime(t);
  group.updateMatrixWorld(true);
  character.update();
  // The camera looks at the joint (by default the inside of the right elbow, from the front and a
  // little to the side).
  const joint = human.mesh.skeleton.bones.find((b) => b.name === bone)!;
  const at = joint.getWorldPosition(new THREE.Vector3());
  const camera = new THREE.PerspectiveCamera(30, W / H, 0.01, 10);
  camera.position.copy(at).add(new THREE.Vector3(offset[0], offset[1], offset[2]));
  camera.lookAt(at);
  renderer.render(scene, camera);
  const url = renderer.domElement.toDataURL('image/png');
  character.dispose();
  human.mesh.geometry.dispose();
  return url;
}

/** Pixels of a PNG data URL. */
async function pixels(url: string): Promise<Uint8ClampedArray> {
  const bitmap = await createImageBitmap(await (await fetch(url)).blob());
  const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
  const ctx = canvas.getContext('2d')!;
  ctx.drawImage(bitmap, 0, 0);
  return ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
}

/**
 * The default GCS, DQS and plain GCS at time t: the share of the character's pixels (not
 * background in either picture) that differ from DQS's by more than 8/255 in a channel.
 */
async function compare(t: number, bone = 'RightForeArm', offset: readonly number[] = [-0.3, 0, 0.25]): Promise<{ coverage: number; defaultVsDqs: number; plainVsDqs: number; shots: Record<string, string> }> {
  const shots = {
    gcs: await shot('gcs', {}, t, bone, offset), dqs: await shot('dqs', {}, t, bone, offset),
    plain: await shot('gcs', { smooth: false }, t, bone, offset),
  };
  const [a, d, p] = await Promise.all([pixels(shots.gcs), pixels(shots.dqs), pixels(shots.plain)]);
  const bg = (x: Uint8ClampedArray, i: number) => x[i] === 0x20 && x[i + 1] === 0x24 && x[i + 2] === 0x28;
  const differs = (x: Uint8ClampedArray, y: Uint8ClampedArray, i: number) =>
    Math.abs(x[i] - y[i]) > 8 || Math.abs(x[i + 1] - y[i + 1]) > 8 || Math.abs(x[i + 2] - y[i + 2]) > 8;
  let body = 0, da = 0, dp = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (bg(d, i) && bg(a, i) && bg(p, i)) continue;
    body++;
    if (differs(a, d, i)) da++;
    if (differs(p, d, i)) dp++;
  }
  return { coverage: body / (W * H), defaultVsDqs: da / body, plainVsDqs: dp / body, shots };
}

const ready = initGcsSkin();
(window as unknown as { __elbow: unknown }).__elbow = { compare };
