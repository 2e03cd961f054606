// The demo's joint close-up (?joint): one knee or elbow of a character bent alone from the bind
// pose (everything else at rest), drawn by GCS, DQS and LBS side by side from one camera, each with
// the joint's figures under it (gcs-skin/measure: volume change of the joint region, bulge and
// collapse — distance to the nearest bone over the same at bind — and new self-intersecting
// triangle pairs). The knees and elbows are found from the skeleton's layout (joint-pose.ts), so
// any dropped character with two legs and two arms works, named bones or not.
//
// URL: ?joint[=left knee|right elbow|…] &model=human|fox|cesiumman|robot|URL &bend=DEG (0 … 150)
//      &centres=1 (the GCS view with centres of rotation per node)
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import GUI from 'three/addons/libs/lil-gui.module.min.js';
import { initGcsSkin, type GcsSkin } from '../lib/index.js';
import { SkinDeformer } from '../lib/three.js';
import { jointCentres, type Hinge, type JointFigures } from '../lib/measure.js';
import { humanFromData } from '../lib/human/index.js';
import { humanDataInWorker } from './human-data.js';
import { escapeHtml as esc, textOptions } from './gui-text.js';
import { applySidebar } from './layout.js';
import { basename, GltfError, loadDroppedGltf, loadGltfUrl } from './load-gltf.js';
import { disposeObject, normaliseSize, SHIPPED } from './loading.js';
import { describeError, hideStatus, showMessage, shownMessage, showStatus, clearMessage, yieldToPage } from './page.js';
import { findJointRig, jointFigures, poseBend, type JointRig } from './joint-pose.js';
import { noJointMessage } from './joint-text.js';

/** The three views, left to right, and the camera layer of each one's meshes. */
const VIEWS = [
  { kind: 'gcs', method: 'gcs', layer: 1, title: 'GCS', sub: 'gcs-skin: generalized cross-sections, weights criterion' },
  { kind: 'dqs', method: 'dqs', layer: 2, title: 'DQS', sub: 'dual-quaternion skinning (Blender\'s "preserve volume")' },
  { kind: 'lbs', method: 'lbs', layer: 3, title: 'LBS', sub: 'linear blend skinning (three.js, Babylon)' },
] as const;
type ViewKind = (typeof VIEWS)[number]['kind'];
export const MAX_BEND = 150;

const query = new URLSearchParams(location.search);

/** True when the page was opened with ?joint. */
export function jointRequested(): boolean {
  return query.has('joint');
}

interface Shown {
  name: string;
  holder: THREE.Group;
  rig: JointRig;
  /** Per view, one SkinDeformer per skinned mesh of the character; [0] is the one of rig.mesh. */
  skins: Record<ViewKind, SkinDeformer[]>;
  /** Every view's skins in one list (the frame loop updates them). */
  all: SkinDeformer[];
}

const params = {
  model: 'human',
  joint: '',
  bend: Math.min(MAX_BEND, Math.max(0, Number(query.get('bend') ?? 90) || 0)),
  /** The GCS view with centres of rotation per node (GcsOptions.centres; off: the default). */
  centres: query.has('centres') && query.get('centres') !== '0',
};
let gcs: GcsSkin;
let renderer: THREE.WebGLRenderer;
let scene: THREE.Scene;
let camera: THREE.PerspectiveCamera;
let controls: OrbitControls;
let shown: Shown | null = null;
let figures: Record<ViewKind, JointFigures | null> = { gcs: null, dqs: null, lbs: null };
let frameCount = 0;
let jointController: { options(o: Record<string, string>): typeof jointController; name(n: string): typeof jointController;
  onChange(f: () => void): typeof jointController; updateDisplay(): void; domElement: HTMLElement };
let gui: GUI;

/** Sets up the page, loads the first character, and the hook tests drive it by. */
export async function startJointMode(): Promise<void> {
  renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
  document.body.prepend(renderer.domElement);
  scene = new THREE.Scene();
  scene.background = new THREE.Color(0x242a35);
  camera = new THREE.PerspectiveCamera(30, 1, 0.01, 100);
  controls = new OrbitControls(camera, renderer.domElement);
  controls.enableDamping = true;
  scene.add(new THREE.HemisphereLight(0xe8eeff, 0x30343d, 1.7));
  const key = new THREE.DirectionalLight(0xfff4e8, 2.2);
  key.position.set(2.2, 4.2, 3.0);
  const rim = new THREE.DirectionalLight(0xa8c8ff, 1.1);
  rim.position.set(-3, 2.6, -3.2);
  scene.add(key, rim);
  initGui();
  window.addEventListener('resize', layout);
  layout();
  renderer.setAnimationLoop(draw);
  showStatus('building… loading the WebAssembly core');
  gcs = await initGcsSkin();
  const model = query.get('model') ?? 'human';
  await load(model);
  const wanted = query.get('joint');
  if (wanted && shown?.rig.hinges.some((h) => h.label.startsWith(wanted))) selectJoint(shown.rig.hinges.find((h) => h.label.startsWith(wanted))!.label);
  await settled();
}

function initGui(): void {
  gui = new GUI({ title: 'gcs-skin · joint close-up', width: 270 });
  const menu: Record<string, string> = { 'default human': 'human' };
  for (const s of SHIPPED) menu[s.label] = s.key;
  gui.add(params, 'model', textOptions(menu)).name('character').onChange((key: string) => { void load(key); });
  const file = document.getElementById('file') as HTMLInputElement;
  gui.add({ load: () => file.click() }, 'load').name('load file… (.glb / .gltf)');
  file.addEventListener('change', () => {
    const files = Array.from(file.files ?? []);
    file.value = '';
    if (files.length) void loadFiles(files);
  });
  window.addEventListener('dragover', (e) => e.preventDefault());
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    const files = Array.from(e.dataTransfer?.files ?? []);
    if (files.length) void loadFiles(files);
  });
  jointController = gui.add(params, 'joint', ['(none)']).name('joint') as unknown as typeof jointController;
  jointController.onChange(() => selectJoint(params.joint));
  gui.add(params, 'bend', 0, MAX_BEND, 1).name('bend (degrees)').onChange(() => bend(params.bend));
  gui.add(params, 'centres').name('GCS: centres of rotation').onChange(() => setCentres(params.centres));
  gui.add({ back: () => { location.search = '' ; } }, 'back').name('← the comparison page');
}

// ----------------------------------------------------------------------------------- characters

async function load(key: string): Promise<void> {
  const shipped = SHIPPED.find((s) => s.key === key);
  try {
    if (key === 'human') {
      showStatus('building… generating the human character');
      const human = humanFromData(await humanDataInWorker({}));
      install('default human', human.mesh, false);
    } else {
      const name = shipped?.label ?? basename(key);
      showStatus(`building… loading ${name}`);
      const gltf = await loadGltfUrl(shipped?.file ?? key, name);
      install(name, gltf.scene, true);
    }
    params.model = shipped?.key ?? key;
  } catch (e) {
    showMessage(describeError(e));
  } finally {
    hideStatus();
    gui.controllersRecursive().forEach((c) => c.updateDisplay());
  }
}

async function loadFiles(files: File[]): Promise<void> {
  const main = files.find((f) => /\.(glb|gltf)$/i.test(f.name));
  try {
    if (!main) throw new GltfError('NOT_GLTF', files[0].name, '', `${files[0].name} is not a glTF file: drop a skinned .glb or .gltf`);
    showStatus(`building… reading ${main.name}`);
    await yieldToPage();
    install(main.name, (await loadDroppedGltf(main, files.filter((f) => f !== main))).scene, true);
  } catch (e) {
    showMessage(describeError(e));
  } finally {
    hideStatus();
  }
}

/** Builds the three views' skins of a character, finds its joints, swaps it in. */
function install(name: string, object: THREE.Object3D, normalise: boolean): void {
  const holder = new THREE.Group();
  holder.add(object);
  holder.updateMatrixWorld(true);
  const sources: THREE.SkinnedMesh[] = [];
  object.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) sources.push(o as THREE.SkinnedMesh); });
  if (!sources.length) throw new GltfError('NO_SKINNED_MESH', name, '', `${name} has no skinned mesh: drop a rigged character`);
  if (normalise) normaliseSize(name, object, holder);
  const rig = findJointRig(sources);
  const ordered = [rig.mesh, ...sources.filter((s) => s !== rig.mesh)];
  const skins = {} as Record<ViewKind, SkinDeformer[]>;
  try {
    for (const v of VIEWS) {
      skins[v.kind] = [];
      for (const src of ordered) {
        const s = new SkinDeformer(gcs, src, { method: v.method, backend: 'cpu', material: src.material, gcs: { centres: params.centres } });
        s.mesh.layers.set(v.layer);
        skins[v.kind].push(s);
      }
    }
  } catch (e) {
    for (const list of Object.values(skins)) for (const s of list) s.dispose();
    throw e;
  }
  for (const src of sources) src.layers.disableAll(); // drawn by the three views' meshes only
  const old = shown;
  shown = { name, holder, rig, skins, all: VIEWS.flatMap((v) => skins[v.kind]) };
  scene.add(holder);
  for (const s of shown.all) scene.add(s.mesh);
  if (old) {
    scene.remove(old.holder);
    for (const s of old.all) { s.mesh.removeFromParent(); s.dispose(); }
    disposeObject(old.holder);
  }
  clearMessage();
  const labels = rig.hinges.map((h) => h.label);
  jointController = jointController.options(textOptions(labels.length ? labels : ['(none found)'])).name('joint');
  jointController.onChange(() => selectJoint(params.joint));
  if (!rig.hinges.length) showMessage(noJointMessage(name, rig.notes));
  selectJoint(labels.find((l) => l.startsWith('left elbow')) ?? labels[0] ?? '');
}

// ----------------------------------------------------------------------------------- pose and figures

function currentHinge(): Hinge | null {
  return shown?.rig.hinges.find((h) => h.label === params.joint) ?? null;
}

function selectJoint(label: string): void {
  params.joint = label;
  jointController.updateDisplay();
  frameJoint();
  bend(params.bend);
}

/** Rebuilds the GCS view with or without centres of rotation, and measures it again. */
function setCentres(on: boolean): void {
  params.centres = on;
  if (!shown) return;
  try {
    for (const s of shown.skins.gcs) s.rebuild('gcs', { gcs: { centres: on } });
  } catch (e) {
    showMessage(`GCS: ${describeError(e)}`);
  }
  bend(params.bend);
}

/** Bends the chosen joint to `degrees` and measures it in every view. */
function bend(degrees: number): void {
  params.bend = degrees;
  gui.controllersRecursive().forEach((c) => c.updateDisplay());
  if (!shown) return;
  const hinge = currentHinge();
  poseBend(shown.rig, hinge, degrees);
  for (const v of VIEWS) {
    try {
      figures[v.kind] = hinge ? jointFigures(shown.rig, hinge, shown.skins[v.kind][0].deformer, degrees) : null;
    } catch (e) {
      figures[v.kind] = null;
      showMessage(`${v.title}: ${describeError(e)}`);
    }
  }
  updateText();
}

/**
 * The camera on the limb, from the outer side (along the hinge axis), a little from the front:
 * centred on the joint and far enough back for both of its bones (the thigh and shin, the upper arm
 * and forearm) at any bend, so the limb fills the view, not whatever lies beside the joint (hair).
 */
function frameJoint(): void {
  const hinge = currentHinge();
  if (!shown) return;
  const m = shown.rig.mesh.matrixWorld;
  if (!hinge || !shown.rig.frame) {
    const box = new THREE.Box3().setFromObject(shown.holder);
    controls.target.copy(box.getCenter(new THREE.Vector3()));
    camera.position.copy(controls.target).add(new THREE.Vector3(0, 0.3, 4));
    controls.update();
    return;
  }
  const toWorld = (v: readonly number[]) => new THREE.Vector3(v[0], v[1], v[2]).transformDirection(m);
  const centre = new THREE.Vector3(...hinge.centre).applyMatrix4(m);
  const end = new THREE.Vector3(...hinge.end).applyMatrix4(m);
  const side = toWorld(shown.rig.frame.left).multiplyScalar(hinge.side === 'left' ? 1 : -1);
  const axis = toWorld(hinge.axis);
  if (axis.dot(side) < 0) axis.negate();
  const direction = axis.addScaledVector(toWorld(shown.rig.frame.forward), 0.35).addScaledVector(toWorld(shown.rig.frame.up), 0.15).normalize();
  const parent = new THREE.Vector3(...jointCentres(shown.rig.input)[hinge.parent]).applyMatrix4(m);
  const reach = 1.1 * Math.max(centre.distanceTo(end), centre.distanceTo(parent)); // both bones whole, at any bend
  const aspect = Math.min(1, viewWidth() / window.innerHeight);
  const distance = reach / Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) / aspect;
  controls.target.copy(centre);
  camera.position.copy(centre).addScaledVector(direction, distance);
  camera.near = distance / 50;
  camera.updateProjectionMatrix();
  controls.update();
}

// ----------------------------------------------------------------------------------- drawing and text

let rects: { kind: ViewKind; x: number; width: number }[] = [];

/** Each view's column of the canvas, left to right (px); recomputed on resize only (draw() reads it every frame). */
export function jointViewRects(): readonly { kind: ViewKind; x: number; width: number }[] {
  return rects;
}

function viewWidth(): number {
  return rects[0]?.width ?? window.innerWidth / VIEWS.length;
}

function layout(): void {
  const width = applySidebar();
  renderer.setSize(width, window.innerHeight);
  const w = Math.floor(width / VIEWS.length);
  rects = VIEWS.map((v, i) => ({ kind: v.kind, x: i * w, width: w }));
  updateText();
}

function draw(): void {
  controls.update();
  if (shown) for (const s of shown.all) s.update();
  const h = window.innerHeight;
  renderer.setScissorTest(true);
  for (let i = 0; i < rects.length; i++) {
    const r = rects[i];
    renderer.setViewport(r.x, 0, r.width, h);
    renderer.setScissor(r.x, 0, r.width, h);
    camera.aspect = r.width / h;
    camera.updateProjectionMatrix();
    camera.layers.set(0);
    camera.layers.enable(VIEWS[i].layer);
    renderer.render(scene, camera);
  }
  frameCount++;
}

function updateText(): void {
  const labels = document.getElementById('labels')!, readouts = document.getElementById('readouts')!;
  const hinge = currentHinge();
  let top = '', bottom = '';
  const f2 = (x: number) => (Number.isFinite(x) ? x.toFixed(2) : '—');
  jointViewRects().forEach((r, i) => {
    const v = VIEWS[i];
    const title = v.kind === 'gcs' ? `GCS (${params.centres ? 'centres of rotation' : 'default'})` : v.title;
    top += `<div class="label" data-view="${v.kind}" style="left:${r.x + 10}px;max-width:${r.width - 20}px"><h2>${esc(title)}</h2>` +
      `<div class="sub">${esc(v.sub)}</div><div class="sub">${esc(shown?.name ?? '')}${hinge ? ` · ${esc(hinge.label)} bent ${params.bend}°` : ''}</div></div>`;
    if (i > 0) top += `<div class="divider" style="left:${r.x - 1}px"></div>`;
    const f = figures[v.kind];
    if (f) {
      bottom += `<div class="readout" data-view="${v.kind}" style="left:${r.x + 10}px;max-width:${r.width - 20}px">` +
        `<div class="row">volume <b>${f.volumeChange >= 0 ? '+' : ''}${f.volumeChange.toFixed(1)} %</b> · bulge p95 <b>${f2(f.bulgeP95)}</b> · max <b>${f2(f.bulgeMax)}</b></div>` +
        `<div class="row">collapse p5 <b>${f2(f.collapseP5)}</b> · min ${f2(f.collapseMin)} · creases ${f.creases} · new self-intersections <b>${f.newIntersections}</b></div></div>`;
    }
  });
  labels.innerHTML = top;
  readouts.innerHTML = bottom;
}

/** Resolves once the page has drawn two more frames. */
function settled(): Promise<void> {
  const f = frameCount;
  return new Promise((resolve) => { const wait = () => (frameCount > f + 1 ? resolve() : setTimeout(wait, 16)); wait(); });
}

/** What browser tests drive and read (window.__demo.joint). */
export const jointHook = {
  /** The joints found on the character on screen (their labels). */
  joints: () => shown?.rig.hinges.map((h) => h.label) ?? [],
  joint: () => params.joint,
  character: () => shown?.name ?? '',
  choose: async (label: string) => { selectJoint(label); await settled(); },
  bend: async (degrees: number) => { bend(Math.min(MAX_BEND, Math.max(0, degrees))); await settled(); },
  /** The GCS view with (true) or without centres of rotation. */
  centres: async (on: boolean) => { setCentres(on); await settled(); },
  load: async (key: string) => { await load(key); await settled(); },
  /** The figures under each view (null: none measured). */
  readouts: () => ({ ...figures }),
  views: () => [...rects],
  frame: () => frameCount,
  error: shownMessage,
};
