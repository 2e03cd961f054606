// gcs-skin demo: the generalized cross-section model (left) and the classic cross-section model
// (right) deforming the same character in the same pose, with one shared camera; optionally
// three.js's own skinning (LBS) as a third, reference view.
//
// Structure as in the three.js examples: init() · GUI · onWindowResize() · animate() driven by
// renderer.setAnimationLoop. A small hook on window.__demo lets browser tests drive the page.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader, type GLTF } from 'three/addons/loaders/GLTFLoader.js';
import Stats from 'three/addons/libs/stats.module.js';
import GUI from 'three/addons/libs/lil-gui.module.min.js';
import {
  CLASSIC_LIMITS, GcsError, initGcsSkin,
  type ClassicDeformer, type ClassicOptions, type Criterion, type GcsDeformer, type GcsOptions, type GcsSkin,
} from '../lib/index.js';
import { SkinDeformer } from '../lib/three.js';
import { createHumanData, humanFromData, type HumanData } from '../lib/human/index.js';

// ---------------------------------------------------------------------------------------------
// State

type ViewKind = 'gcs' | 'classic' | 'lbs';

interface Character {
  name: string;
  /** Holds the source object, scaled so the character is ~1.8 units tall, feet on y = 0. */
  holder: THREE.Group;
  sources: THREE.SkinnedMesh[];
  gcs: SkinDeformer[];
  classic: SkinDeformer[];
  classicError: string | null;
  /** Bones whose parts the classic model carries rigidly (not resampled). */
  rigidParts: string[];
  mixer: THREE.AnimationMixer;
  clips: THREE.AnimationClip[];
  action: THREE.AnimationAction | null;
  skeletonHelper: THREE.SkeletonHelper;
  sourceVertices: number;
  sourceTriangles: number;
}

/** An error whose message is meant for the page as it is. */
class DemoError extends Error {}

const query = new URLSearchParams(location.search);
const qNumber = (key: string, fallback: number) => {
  const v = Number(query.get(key));
  return query.has(key) && Number.isFinite(v) ? v : fallback;
};
const qBool = (key: string, fallback: boolean) => (query.has(key) ? query.get(key) !== '0' && query.get(key) !== 'false' : fallback);

/** ?criterion=weights|y|axial (default weights, the library's default). */
function parseCriterion(value: string | null): Criterion {
  const v = (value ?? '').toLowerCase();
  return v === 'y' || v === 'axial' ? v : 'weights';
}

/** The criterion menu: label → value. */
const CRITERION_MENU: Record<string, Criterion> = {
  'weights (default)': 'weights',
  'Y (paper)': 'y',
  "axial (paper's rule, bone axis)": 'axial',
};
/** What the GCS view says about each criterion: a short name and one line on why the default differs from the paper. */
const CRITERION_TEXT: Record<Criterion, { name: string; why: string }> = {
  weights: { name: 'weights', why: 'vertices bound 100 % to a bone move exactly with it; the paper\'s Y rule bends them' },
  y: { name: 'Y (paper)', why: 'bins of bind-pose height; skin bound 100 % to one bone bends too (weights keeps it rigid)' },
  axial: { name: 'axial (paper\'s rule)', why: 'bins along each bone; skin bound 100 % to one bone bends too (weights keeps it rigid)' },
};

const params = {
  // GCS model (left)
  sections: Math.round(Math.min(48, Math.max(3, qNumber('sections', 6)))),
  criterion: parseCriterion(query.get('criterion')),
  influenceWidth: 1,
  smooth: qBool('smooth', false),
  twistSpread: qBool('twist', false),
  // classic model (right)
  contours: 25,
  rays: 20,
  bulge: 0.3,
  // animation
  clip: query.get('clip') ?? 'walk',
  speed: 1,
  paused: qBool('paused', false),
  stepFrame: () => stepFrame(),
  // view
  wireframe: qBool('wireframe', false),
  colourBySection: qBool('colour', false),
  showSkeleton: qBool('skeleton', false),
  lbsView: qBool('lbs', false),
  loadFile: () => fileInput.click(),
  loadHuman: () => void enqueue(() => loadHuman()),
};

let gcs: GcsSkin;
let renderer: THREE.WebGLRenderer;
let scene: THREE.Scene;
let camera: THREE.PerspectiveCamera;
let controls: OrbitControls;
let stats: Stats;
let gui: GUI;
// lil-gui's generic controller types do not assign to each other: keep what we call on them.
interface OptionsCtl { options(values: string[]): OptionsCtl; name(n: string): OptionsCtl; onChange(f: () => void): OptionsCtl }
let clipController: OptionsCtl;
let sectionsController: { setValue(v: number): unknown };
/** The controls that only apply to the paper's criteria (y, axial). */
let paperOnlyControllers: { disable(d?: boolean): unknown; domElement: HTMLElement }[] = [];
let pausedController: { setValue(v: boolean): unknown };
let current: Character | null = null;
const gcsGroup = new THREE.Group();
const classicGroup = new THREE.Group();
const gcsMaterial = new THREE.MeshStandardMaterial({ color: 0xd9a58a, roughness: 0.62, metalness: 0 });
const classicMaterial = new THREE.MeshStandardMaterial({ color: 0xd9a58a, roughness: 0.62, metalness: 0 });
const SKIN = new THREE.Color(0xd9a58a);

let pendingGcs = false;
let pendingClassic = false;
let frameCount = 0;
let lastTime = performance.now();
let lastReadout = 0;
const timing = { gcs: NaN, classic: NaN };
let busy = 0;
/** Builds of the classic model so far (a bulge change must not add one). */
let classicBuilds = 0;
/** Builds and rebuilds of the GCS model so far. */
let gcsBuilds = 0;
/** The criterion the current GCS model was built with. */
let builtCriterion: Criterion = params.criterion;

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const fileInput = $<HTMLInputElement>('file');
const messageEl = $('message');
const messageText = $('message-text');
const statusEl = $('status');
const readoutsEl = $('readouts');
const labelsEl = $('labels');
const dropEl = $('drop');

// ---------------------------------------------------------------------------------------------
// Page messages

function showMessage(text: string): void {
  messageText.textContent = text;
  messageEl.hidden = false;
  console.warn('[gcs-skin demo]', text);
}
function clearMessage(): void {
  messageEl.hidden = true;
  messageText.textContent = '';
}
function showStatus(text: string): void {
  statusEl.textContent = text;
  statusEl.hidden = false;
}
function describeError(e: unknown): string {
  if (e instanceof GcsError) return `${e.message} (${e.code})`;
  if (e instanceof Error) return e.message;
  return String(e);
}

/** Lets the browser paint (the "building…" status) before the next synchronous step. */
function yieldToPage(): Promise<void> {
  return new Promise((resolve) => {
    let done = false;
    const finish = () => { if (!done) { done = true; resolve(); } };
    requestAnimationFrame(() => setTimeout(finish, 0));
    setTimeout(finish, 60); // rAF stalls in hidden tabs
  });
}

// Loads run one at a time, in order.
let queue: Promise<unknown> = Promise.resolve();
function enqueue(task: () => Promise<void>): Promise<void> {
  const run = queue.then(async () => {
    busy++;
    try {
      await task();
    } catch (e) {
      showMessage(describeError(e));
    } finally {
      busy--;
      if (!busy) statusEl.hidden = true;
    }
  });
  queue = run;
  return run;
}

// ---------------------------------------------------------------------------------------------
// init

async function init(): Promise<void> {
  renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFShadowMap;
  document.body.prepend(renderer.domElement);

  scene = new THREE.Scene();
  scene.background = new THREE.Color(0x242a35);
  scene.fog = new THREE.Fog(0x242a35, 7, 16);

  camera = new THREE.PerspectiveCamera(30, 1, 0.05, 100);
  camera.position.set(1.9, 1.5, 4.9);
  controls = new OrbitControls(camera, renderer.domElement);
  controls.target.set(0, 0.95, 0);
  controls.enableDamping = true;
  controls.minDistance = 0.5;
  controls.maxDistance = 20;
  controls.update();

  const hemi = new THREE.HemisphereLight(0xe8eeff, 0x30343d, 1.7);
  scene.add(hemi);
  const key = new THREE.DirectionalLight(0xfff4e8, 2.4);
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

  scene.add(gcsGroup, classicGroup);

  stats = new Stats();
  stats.dom.style.cssText = 'position:fixed;right:10px;bottom:96px;z-index:10;opacity:0.85;cursor:pointer';
  document.body.appendChild(stats.dom);

  initGui();
  initDrop();
  window.addEventListener('resize', onWindowResize);
  window.addEventListener('keydown', (e) => {
    if ((e.target as HTMLElement).tagName === 'INPUT') return;
    if (e.code === 'Space') { e.preventDefault(); pausedController.setValue(!params.paused); }
    if (e.key === '.') stepFrame();
  });
  $('message-close').addEventListener('click', clearMessage);
  onWindowResize();
  renderer.setAnimationLoop(animate);

  showStatus('building… loading the WebAssembly core');
  gcs = await initGcsSkin();
  const model = query.get('model');
  if (model) {
    await enqueue(() => loadUrl(model));
    if (!current) {
      const reason = messageText.textContent;
      await enqueue(() => loadHuman());
      showMessage(`${reason} Showing the default human instead.`);
    }
  } else {
    await enqueue(() => loadHuman());
  }
}

// ---------------------------------------------------------------------------------------------
// GUI

function initGui(): void {
  gui = new GUI({ title: 'gcs-skin', width: 270 });

  const g = gui.addFolder('GCS model (left)');
  const criterionCtl = g.add(params, 'criterion', CRITERION_MENU).onChange(() => { pendingGcs = true; updatePaperOnlyControls(); });
  criterionCtl.domElement.style.setProperty('--name-width', '22%'); // room for "axial (paper's rule, bone axis)"
  sectionsController = g.add(params, 'sections', 3, 48, 1).name('sections').onChange(() => { pendingGcs = true; });
  g.add(params, 'smooth').name('smooth mode').onChange(() => { pendingGcs = true; });
  paperOnlyControllers = [
    g.add(params, 'influenceWidth', 0.05, 1, 0.05).name('influence width').onChange(() => { pendingGcs = true; }),
    g.add(params, 'twistSpread').name('twist spread').onChange(() => { pendingGcs = true; }),
  ];
  updatePaperOnlyControls();

  const c = gui.addFolder('Classic model (right)');
  c.add(params, 'contours', CLASSIC_LIMITS.minContours, 64, 1).onChange(() => { pendingClassic = true; });
  c.add(params, 'rays', CLASSIC_LIMITS.minRays, 64, 1).onChange(() => { pendingClassic = true; });
  c.add(params, 'bulge', 0, CLASSIC_LIMITS.maxBulge, 0.05).name('muscle bulge').onChange(setBulge);

  const a = gui.addFolder('Animation');
  clipController = a.add(params, 'clip', [params.clip]) as unknown as OptionsCtl;
  a.add(params, 'speed', 0, 2, 0.05);
  pausedController = a.add(params, 'paused').name('pause');
  a.add(params, 'stepFrame').name('step one frame');

  const v = gui.addFolder('View');
  v.add(params, 'wireframe').onChange(applyMaterials);
  v.add(params, 'colourBySection').name('colour by section').onChange(applyMaterials);
  v.add(params, 'showSkeleton').name('show skeleton').onChange(() => { if (current) current.skeletonHelper.visible = params.showSkeleton; });
  v.add(params, 'lbsView').name('three.js LBS view').onChange(onWindowResize);
  v.add(params, 'loadFile').name('load file… (.glb / .gltf)');
  v.add(params, 'loadHuman').name('load the default human');
}

/** Influence width and twist spread apply to the paper's criteria only: disabled (greyed) under weights. */
function updatePaperOnlyControls(): void {
  const off = params.criterion === 'weights';
  for (const c of paperOnlyControllers) {
    c.disable(off);
    c.domElement.title = off ? 'only for the Y and axial criteria' : '';
  }
}

function setClipOptions(names: string[]): void {
  // lil-gui's options() re-adds the controller at the end of its folder: put it back first.
  clipController = clipController.options(names.length ? names : ['(none)']).name('clip').onChange(playClip);
  const el = (clipController as unknown as { domElement: HTMLElement }).domElement;
  el.parentElement?.prepend(el);
}

function gcsOptions(): GcsOptions {
  const options: GcsOptions = { sections: params.sections, criterion: params.criterion, smooth: params.smooth };
  if (params.criterion !== 'weights') Object.assign(options, { influenceWidth: params.influenceWidth, twistSpread: params.twistSpread });
  return options;
}
function classicOptions(): ClassicOptions {
  return { contours: params.contours, rays: params.rays, bulge: params.bulge };
}

function setBulge(): void {
  if (!current) return;
  try {
    for (const s of current.classic) (s.deformer as ClassicDeformer).setBulge(params.bulge);
  } catch (e) {
    showMessage(describeError(e));
  }
}

function playClip(): void {
  const ch = current;
  if (!ch) return;
  const clip = ch.clips.find((c) => c.name === params.clip);
  ch.mixer.stopAllAction();
  ch.action = clip ? ch.mixer.clipAction(clip).play() : null;
}

function stepFrame(): void {
  if (!params.paused) pausedController.setValue(true);
  current?.mixer.update(1 / 30);
}

// ---------------------------------------------------------------------------------------------
// Colours and materials

const tmpColour = new THREE.Color();
/** Vertices in rigid cores (weights criterion) of each GCS deformer, counted when it is coloured. */
const rigidVertices = new WeakMap<SkinDeformer, number>();

/**
 * One colour per generalized section: a hue per part, alternating light/dark bands along it; shared
 * sections (SGS) yellow. Weights criterion: bands run from one joint to the next (sections of one
 * joint pair sorted by the second joint's weight), rigid cores are a pale grey tinted by the part.
 */
function gcsColours(skin: SkinDeformer): void {
  const d = skin.deformer as GcsDeformer;
  const sections = d.sections();
  const ofVertex = d.sectionOfVertex();
  const rank = new Array<number>(sections.length).fill(0);
  const groups = new Map<string, number[]>();
  const byWeights = builtCriterion === 'weights';
  sections.forEach((s, i) => {
    const key = byWeights ? `${s.part}:${s.distal}` : `${s.part}`;
    if (!groups.has(key)) groups.set(key, []);
    groups.get(key)!.push(i);
  });
  for (const list of groups.values()) {
    list.sort((a, b) => sections[a].t - sections[b].t);
    list.forEach((i, r) => { rank[i] = r; });
  }
  rigidVertices.set(skin, sections.reduce((n, s) => n + (s.rigid ? s.count : 0), 0));
  const palette = sections.map((s, i) => {
    const hue = (0.22 + ((s.part * 0.618034) % 1) * 0.8) % 1;
    if (s.shared) return tmpColour.setHSL(0.15, 1, 0.55).clone();
    if (s.rigid) return tmpColour.setHSL(hue, 0.2, 0.72).clone();
    return tmpColour.setHSL(hue, 0.6, rank[i] % 2 ? 0.36 : 0.56).clone();
  });
  const colours = new Float32Array(d.vertexCount * 3);
  for (let v = 0; v < d.vertexCount; v++) {
    const c = palette[ofVertex[v]] ?? SKIN;
    colours[3 * v] = c.r; colours[3 * v + 1] = c.g; colours[3 * v + 2] = c.b;
  }
  skin.mesh.geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
}

/** The classic model: a colour per resampled part, grey for the parts it carries rigidly. */
function classicColours(skin: SkinDeformer): void {
  const d = skin.deformer as ClassicDeformer;
  const colours = new Float32Array(d.vertexCount * 3);
  const grey = new THREE.Color().setHSL(0, 0, 0.5);
  for (let v = 0; v < d.vertexCount; v++) grey.toArray(colours, 3 * v);
  for (const p of d.parts) {
    const c = p.resampled ? new THREE.Color().setHSL((0.22 + ((p.joint * 0.618034) % 1) * 0.8) % 1, 0.6, 0.5) : grey;
    const end = Math.min(d.vertexCount, p.firstVertex + p.vertexCount);
    for (let v = Math.max(0, p.firstVertex); v < end; v++) c.toArray(colours, 3 * v);
  }
  skin.mesh.geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
}

function applyMaterials(): void {
  for (const m of [gcsMaterial, classicMaterial]) {
    m.vertexColors = params.colourBySection;
    m.color.copy(params.colourBySection ? new THREE.Color(0xffffff) : SKIN);
    m.wireframe = params.wireframe;
    m.needsUpdate = true;
  }
  current?.holder.traverse((o) => {
    const mesh = o as THREE.Mesh;
    if (!mesh.isMesh) return;
    for (const m of Array.isArray(mesh.material) ? mesh.material : [mesh.material]) {
      if ('wireframe' in m) { (m as THREE.MeshStandardMaterial).wireframe = params.wireframe; m.needsUpdate = true; }
    }
  });
  updateLabels();
}

// ---------------------------------------------------------------------------------------------
// Characters: build completely, then swap; the old one stays when anything fails.

async function loadHuman(): Promise<void> {
  const vertices = query.has('vertices') ? qNumber('vertices', 17023) : undefined;
  showStatus('building… generating the human character');
  const data = await humanDataInWorker({ vertices });
  const human = humanFromData(data);
  await install(`Human (procedural)`, human.mesh, human.clips, { normalise: false });
}

/** createHumanData in a module worker; on the main thread if workers are unavailable. */
function humanDataInWorker(options: { vertices?: number }): Promise<HumanData> {
  return new Promise((resolve, reject) => {
    let worker: Worker;
    const fallback = async () => {
      await yieldToPage();
      try { resolve(createHumanData(options)); } catch (e) { reject(e); }
    };
    try {
      worker = new Worker(new URL('./human-worker.ts', import.meta.url), { type: 'module' });
    } catch {
      void fallback();
      return;
    }
    worker.onmessage = (e: MessageEvent<{ data?: HumanData; error?: string }>) => {
      worker.terminate();
      if (e.data.data) resolve(e.data.data);
      else reject(new DemoError(`could not generate the human: ${e.data.error}`));
    };
    worker.onerror = (e) => {
      e.preventDefault();
      worker.terminate();
      void fallback();
    };
    worker.postMessage(options);
  });
}

const basename = (path: string) => decodeURIComponent(path.split(/[\\/]/).pop() ?? path);

async function loadFiles(files: File[]): Promise<void> {
  const main = files.find((f) => /\.glb$/i.test(f.name)) ?? files.find((f) => /\.gltf$/i.test(f.name));
  if (!main) throw new DemoError(`${files.map((f) => f.name).join(', ') || 'That'} is not a glTF file: drop a skinned .glb or .gltf.`);
  showStatus(`building… reading ${main.name}`);
  await yieldToPage();
  const manager = new THREE.LoadingManager();
  const loader = new GLTFLoader(manager);
  const objectUrls: string[] = [];
  let gltf: GLTF;
  try {
    if (/\.glb$/i.test(main.name)) {
      gltf = await loader.parseAsync(await main.arrayBuffer(), '');
    } else {
      const text = await main.text();
      let json: { buffers?: { uri?: string }[] };
      try {
        json = JSON.parse(text);
      } catch (e) {
        throw new DemoError(`Could not read ${main.name}: it is not valid glTF JSON (${(e as Error).message}).`);
      }
      const byName = new Map(files.map((f) => [f.name, f]));
      const external = (json.buffers ?? []).map((b) => b.uri).filter((u): u is string => !!u && !u.startsWith('data:'));
      const missing = external.filter((u) => !byName.has(basename(u)));
      if (missing.length) {
        throw new DemoError(`${main.name} keeps its data in external files (${missing.join(', ')}), which a dropped .gltf cannot reach. ` +
          'Drop the .gltf together with those files (select them all), or use a .glb or a .gltf with embedded buffers.');
      }
      manager.setURLModifier((url) => {
        const file = byName.get(basename(url));
        if (!file) return url;
        const objectUrl = URL.createObjectURL(file);
        objectUrls.push(objectUrl);
        return objectUrl;
      });
      gltf = await loader.parseAsync(text, '');
    }
  } catch (e) {
    if (e instanceof DemoError) throw e;
    throw new DemoError(`Could not read ${main.name}: ${describeError(e)}`);
  } finally {
    setTimeout(() => objectUrls.forEach((u) => URL.revokeObjectURL(u)), 10000);
  }
  await install(main.name, gltf.scene, gltf.animations, { normalise: true });
}

async function loadUrl(url: string): Promise<void> {
  showStatus(`building… loading ${basename(url)}`);
  let gltf: GLTF;
  try {
    gltf = await new GLTFLoader().loadAsync(url);
  } catch (e) {
    throw new DemoError(`Could not load ${url}: ${describeError(e)}`);
  }
  await install(basename(url), gltf.scene, gltf.animations, { normalise: true });
}

function disposeObject(root: THREE.Object3D): void {
  root.traverse((o) => {
    const mesh = o as THREE.Mesh;
    if (!mesh.isMesh) return;
    mesh.geometry?.dispose();
    for (const m of Array.isArray(mesh.material) ? mesh.material : [mesh.material]) {
      if (!m) continue;
      for (const value of Object.values(m)) if ((value as THREE.Texture)?.isTexture) (value as THREE.Texture).dispose();
      m.dispose();
    }
  });
}

async function install(name: string, object: THREE.Object3D, clips: THREE.AnimationClip[], { normalise }: { normalise: boolean }): Promise<void> {
  const holder = new THREE.Group();
  holder.name = name;
  holder.add(object);
  holder.updateMatrixWorld(true);
  const sources: THREE.SkinnedMesh[] = [];
  object.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) sources.push(o as THREE.SkinnedMesh); });
  const built: SkinDeformer[] = [];
  try {
    if (!sources.length) throw new DemoError(`${name} has no skinned mesh (no skeleton and skin weights), so there is nothing to deform. Drop a rigged character.`);

    if (normalise) {
      const box = new THREE.Box3().setFromObject(object);
      const size = box.getSize(new THREE.Vector3());
      const extent = Math.max(size.x, size.y, size.z);
      if (!(extent > 0) || !Number.isFinite(extent)) throw new DemoError(`${name}: the skinned mesh has no extent (empty or non-finite positions).`);
      const s = 1.8 / extent;
      const centre = box.getCenter(new THREE.Vector3());
      holder.scale.setScalar(s);
      holder.position.set(-centre.x * s, -box.min.y * s, -centre.z * s);
      holder.updateMatrixWorld(true);
    }
    for (const src of sources) {
      src.castShadow = true;
      src.frustumCulled = false;
    }

    let vertices = 0;
    let triangles = 0;
    for (const [i, src] of sources.entries()) {
      showStatus(`building… GCS model${sources.length > 1 ? ` ${i + 1}/${sources.length}` : ''} (${src.geometry.getAttribute('position').count.toLocaleString('en')} vertices)`);
      await yieldToPage();
      const skin = new SkinDeformer(gcs, src, { method: 'gcs', gcs: gcsOptions(), material: gcsMaterial });
      built.push(skin);
      builtCriterion = params.criterion;
      vertices += src.geometry.getAttribute('position').count;
      triangles += src.geometry.index ? src.geometry.index.count / 3 : src.geometry.getAttribute('position').count / 3;
    }
    const gcsSkins = built.slice();
    gcsBuilds++;

    showStatus('building… classic cross-section model');
    await yieldToPage();
    const { skins: classicSkins, error: classicError } = buildClassic(sources);
    built.push(...classicSkins);

    const mixer = new THREE.AnimationMixer(object);
    const skeletonHelper = new THREE.SkeletonHelper(holder);
    skeletonHelper.visible = params.showSkeleton;
    (skeletonHelper.material as THREE.LineBasicMaterial).linewidth = 2;

    const next: Character = {
      name, holder, sources, gcs: gcsSkins, classic: classicSkins, classicError, rigidParts: [],
      mixer, clips, action: null, skeletonHelper, sourceVertices: vertices, sourceTriangles: triangles,
    };
    next.rigidParts = rigidParts(next);
    for (const s of next.gcs) { s.mesh.castShadow = true; gcsColours(s); }
    for (const s of next.classic) { s.mesh.castShadow = true; classicColours(s); }

    // Swap: the new character is complete.
    const old = current;
    current = next;
    scene.add(holder, skeletonHelper);
    for (const s of next.gcs) gcsGroup.add(s.mesh);
    for (const s of next.classic) classicGroup.add(s.mesh);
    const names = clips.map((c) => c.name);
    if (!names.includes(params.clip)) params.clip = names.find((n) => /walk/i.test(n)) ?? names[0] ?? '(none)';
    setClipOptions(names);
    playClip();
    applyMaterials();
    if (old) disposeCharacter(old);
    clearMessage();
    updateLabels();
    updateReadouts();
  } catch (e) {
    for (const s of built) s.dispose();
    disposeObject(holder);
    throw e instanceof DemoError || e instanceof GcsError ? e : new DemoError(`${name}: ${describeError(e)}`);
  }
}

function buildClassic(sources: THREE.SkinnedMesh[]): { skins: SkinDeformer[]; error: string | null } {
  const skins: SkinDeformer[] = [];
  classicBuilds++;
  try {
    for (const src of sources) skins.push(new SkinDeformer(gcs, src, { method: 'classic', classic: classicOptions(), material: classicMaterial }));
    return { skins, error: null };
  } catch (e) {
    for (const s of skins) s.dispose();
    return { skins: [], error: describeError(e) };
  }
}

function rigidParts(ch: Character): string[] {
  const names: string[] = [];
  ch.classic.forEach((s, i) => {
    const bones = ch.sources[i].skeleton.bones;
    for (const p of (s.deformer as ClassicDeformer).parts)
      if (!p.resampled) names.push(bones[p.joint]?.name || `joint ${p.joint}`);
  });
  return [...new Set(names)];
}

function disposeCharacter(ch: Character): void {
  ch.mixer.stopAllAction();
  ch.mixer.uncacheRoot(ch.holder.children[0]);
  scene.remove(ch.holder, ch.skeletonHelper);
  for (const s of [...ch.gcs, ...ch.classic]) {
    s.mesh.removeFromParent();
    s.dispose();
  }
  ch.skeletonHelper.dispose();
  disposeObject(ch.holder);
}

// ---------------------------------------------------------------------------------------------
// Rebuilds from the GUI (coalesced: at most one per frame)

function rebuildGcs(ch: Character): void {
  pendingGcs = false;
  gcsBuilds++;
  try {
    for (const s of ch.gcs) {
      s.rebuild('gcs', { gcs: gcsOptions() });
      builtCriterion = params.criterion;
      gcsColours(s);
    }
  } catch (e) {
    showMessage(`GCS model: ${describeError(e)}`);
  }
  updateLabels();
  updateReadouts();
}

function rebuildClassic(ch: Character): void {
  pendingClassic = false;
  if (ch.classic.length) {
    classicBuilds++;
    try {
      for (const s of ch.classic) {
        s.rebuild('classic', { classic: classicOptions() });
        classicColours(s);
      }
      ch.classicError = null;
    } catch (e) {
      ch.classicError = describeError(e);
    }
  } else {
    const { skins, error } = buildClassic(ch.sources);
    ch.classic = skins;
    ch.classicError = error;
    for (const s of skins) { s.mesh.castShadow = true; classicColours(s); classicGroup.add(s.mesh); }
  }
  ch.rigidParts = rigidParts(ch);
  updateLabels();
  updateReadouts();
}

// ---------------------------------------------------------------------------------------------
// Layout, labels, readouts

function views(): ViewKind[] {
  return params.lbsView ? ['gcs', 'classic', 'lbs'] : ['gcs', 'classic'];
}
/** Width of the control column on the right (the GUI overlays the views on narrow windows). */
function sidebarWidth(): number {
  return window.innerWidth >= 900 ? 290 : 0;
}
function viewRects(): { kind: ViewKind; x: number; width: number }[] {
  const list = views();
  const w = window.innerWidth - sidebarWidth();
  return list.map((kind, i) => {
    const x = Math.round((i * w) / list.length);
    return { kind, x, width: Math.round(((i + 1) * w) / list.length) - x };
  });
}

function onWindowResize(): void {
  const side = sidebarWidth();
  document.documentElement.style.setProperty('--sidebar', `${side}px`);
  $('sidebar').hidden = side === 0;
  renderer.setSize(window.innerWidth - side, window.innerHeight);
  updateLabels();
  updateReadouts();
}

const esc = (s: string) => s.replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]!);

function updateLabels(): void {
  const rects = viewRects();
  const ch = current;
  let html = '';
  rects.forEach((r, i) => {
    const overlaid = i === rects.length - 1 && sidebarWidth() === 0; // the GUI covers its right part
    const maxWidth = Math.max(160, Math.min(440, r.width - (overlaid ? 300 : 20)));
    let body = '';
    if (r.kind === 'gcs') {
      const byWeights = builtCriterion === 'weights';
      const detail = byWeights
        ? `${params.sections} sections: weight step 1/${2 * (params.sections - 2)}`
        : `${params.sections} sections per part`;
      body = '<h2>GCS — generalized cross-sections</h2><div class="sub">Li, Wang, Mao · ' +
        `${esc(CRITERION_TEXT[builtCriterion].name)} criterion · ${detail}` +
        `${params.smooth ? ', smooth' : ''}${!byWeights && params.twistSpread ? ', twist spread' : ''}</div>`;
      if (params.colourBySection) {
        body += '<div class="sub">colour = section · <span style="color:#ffd83d">yellow = shared section (SGS)</span>' +
          (byWeights ? ' · <span style="color:#c4c8cc">pale grey = rigid core (moves exactly with its bone)</span>' : '') + '</div>';
      }
    } else if (r.kind === 'classic') {
      body = '<h2>Classic cross-sections</h2><div class="sub">Shen, Magnenat-Thalmann, Thalmann 1994 · ' +
        `${params.contours} contours × ${params.rays} rays per limb</div>`;
      if (ch?.classicError) body += `<div class="err">Not available: ${esc(ch.classicError)}</div>`;
      else if (ch?.rigidParts.length) body += `<div class="warn">Carried rigidly, not resampled: ${esc(summariseBones(ch.rigidParts))}</div>`;
      if (params.colourBySection && !ch?.classicError) body += '<div class="sub">colour = resampled part · grey = rigid part</div>';
    } else {
      body = '<h2>three.js skinning (LBS)</h2><div class="sub">the source SkinnedMesh itself, for reference</div>';
    }
    html += `<div class="label" data-view="${r.kind}" style="left:${r.x + 10}px;max-width:${maxWidth}px">${body}</div>`;
    if (i > 0) html += `<div class="divider" style="left:${r.x - 1}px"></div>`;
  });
  labelsEl.innerHTML = html;
}

/** A short list of bone names: no common prefix (e.g. "mixamorig"), fingers counted, at most 10. */
function summariseBones(names: string[]): string {
  let prefix = names.length > 1 ? names[0] : '';
  for (const n of names) while (prefix && !n.startsWith(prefix)) prefix = prefix.slice(0, -1);
  const short = names.map((n) => n.slice(prefix.length) || n);
  const fingers = short.filter((n) => /thumb|index|middle|ring|pinky|finger/i.test(n));
  const rest = short.filter((n) => !fingers.includes(n));
  if (fingers.length) rest.push(`${fingers.length} finger bones`);
  return rest.length > 10 ? `${rest.slice(0, 10).join(', ')} and ${rest.length - 10} more` : rest.join(', ');
}

interface Readouts {
  character: string;
  gcs: { ms: number; vertices: number; triangles: number; sections: number; adjustedShare: number; criterion: Criterion; rigidShare: number } | null;
  classic: { ms: number; vertices: number; triangles: number; contours: number; detailLoss: { rms: number; max: number } } | null;
  lbs: { vertices: number; triangles: number } | null;
}
let lastReadouts: Readouts = { character: '', gcs: null, classic: null, lbs: null };

function collectReadouts(): Readouts {
  const ch = current;
  if (!ch) return { character: '', gcs: null, classic: null, lbs: null };
  const tri = (s: SkinDeformer) => (s.mesh.geometry.index?.count ?? 0) / 3;
  let gcsInfo: Readouts['gcs'] = null;
  let classicInfo: Readouts['classic'] = null;
  try {
    let sections = 0, adjusted = 0, rigid = 0, vertices = 0;
    for (const s of ch.gcs) {
      const d = s.deformer as GcsDeformer;
      rigid += rigidVertices.get(s) ?? 0;
      vertices += d.vertexCount;
      sections += d.sectionCount;
      adjusted += d.adjustedShare * d.sectionCount;
    }
    gcsInfo = {
      ms: timing.gcs, sections, adjustedShare: sections ? adjusted / sections : 0, criterion: builtCriterion, rigidShare: vertices ? rigid / vertices : 0,
      vertices: ch.gcs.reduce((n, s) => n + s.deformer.vertexCount, 0), triangles: ch.gcs.reduce((n, s) => n + tri(s), 0),
    };
    if (ch.classic.length) {
      let rms2 = 0, max = 0, n = 0;
      for (const s of ch.classic) {
        const loss = (s.deformer as ClassicDeformer).detailLoss;
        const w = s.deformer.vertexCount;
        rms2 += loss.rms * loss.rms * w; n += w; max = Math.max(max, loss.max);
      }
      classicInfo = {
        ms: timing.classic, vertices: ch.classic.reduce((k, s) => k + s.deformer.vertexCount, 0),
        triangles: ch.classic.reduce((k, s) => k + tri(s), 0), contours: ch.classic.reduce((k, s) => k + s.deformer.sectionCount, 0),
        detailLoss: { rms: Math.sqrt(rms2 / Math.max(1, n)), max },
      };
    }
  } catch {
    /* a deformer mid-rebuild: keep the last numbers */
    return lastReadouts;
  }
  return { character: ch.name, gcs: gcsInfo, classic: classicInfo, lbs: { vertices: ch.sourceVertices, triangles: ch.sourceTriangles } };
}

function updateReadouts(): void {
  const r = (lastReadouts = collectReadouts());
  const n = (v: number) => Math.round(v).toLocaleString('en');
  const ms = (v: number) => (!Number.isFinite(v) ? '—' : v < 10 ? v.toFixed(2) : v.toFixed(1));
  const rows: Record<ViewKind, string[]> = { gcs: [], classic: [], lbs: [] };
  if (r.gcs) {
    rows.gcs.push(`deform <b>${ms(r.gcs.ms)} ms</b> / frame · ${n(r.gcs.vertices)} vertices · ${n(r.gcs.triangles)} triangles`);
    rows.gcs.push(`<b>${n(r.gcs.sections)}</b> sections` +
      (r.gcs.criterion === 'weights' ? ` · <b>${(r.gcs.rigidShare * 100).toFixed(0)} %</b> of vertices in rigid cores` : '') +
      ` · <b>${(r.gcs.adjustedShare * 100).toFixed(0)} %</b> adjusted this frame · rest pose exact`);
    const c = CRITERION_TEXT[r.gcs.criterion];
    rows.gcs.push(`<span class="criterion">criterion <b>${esc(c.name)}</b>: ${esc(c.why)}</span>`);
  }
  if (r.classic) {
    rows.classic.push(`deform <b>${ms(r.classic.ms)} ms</b> / frame · ${n(r.classic.vertices)} vertices · ${n(r.classic.triangles)} triangles`);
    rows.classic.push(`<b>${n(r.classic.contours)}</b> contours · resampling detail loss <b>${r.classic.detailLoss.rms.toFixed(2)} %</b> rms, ` +
      `<b>${r.classic.detailLoss.max.toFixed(2)} %</b> max (of height)`);
  }
  if (r.lbs) rows.lbs.push(`skinned on the GPU by three.js · ${n(r.lbs.vertices)} vertices · ${n(r.lbs.triangles)} triangles`);
  const clip = current?.action ? current.action.getClip().name : '';
  let html = '';
  viewRects().forEach((v, i) => {
    const lines = rows[v.kind].slice();
    if (i === 0 && r.character) lines.unshift(`<b>${esc(r.character)}</b>${clip ? ` · ${esc(clip)}` : ''}`);
    if (lines.length)
      html += `<div class="readout" data-view="${v.kind}" style="left:${v.x + 10}px;max-width:${v.width - 20}px">` +
        lines.map((l) => `<div class="row">${l}</div>`).join('') + '</div>';
  });
  readoutsEl.innerHTML = html;
}

// ---------------------------------------------------------------------------------------------
// Drag and drop, file input

function initDrop(): void {
  let depth = 0;
  window.addEventListener('dragenter', (e) => { e.preventDefault(); depth++; dropEl.hidden = false; });
  window.addEventListener('dragleave', () => { depth = Math.max(0, depth - 1); if (!depth) dropEl.hidden = true; });
  window.addEventListener('dragover', (e) => { e.preventDefault(); if (e.dataTransfer) e.dataTransfer.dropEffect = 'copy'; });
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    depth = 0;
    dropEl.hidden = true;
    const files = Array.from(e.dataTransfer?.files ?? []);
    if (files.length) void enqueue(() => loadFiles(files));
  });
  fileInput.addEventListener('change', () => {
    const files = Array.from(fileInput.files ?? []);
    fileInput.value = '';
    if (files.length) void enqueue(() => loadFiles(files));
  });
}

// ---------------------------------------------------------------------------------------------
// animate

const ema = (prev: number, value: number) => (Number.isFinite(prev) ? prev * 0.92 + value * 0.08 : value);

function animate(): void {
  const now = performance.now();
  const dt = Math.min((now - lastTime) / 1000, 0.1);
  lastTime = now;
  controls.update();

  const ch = current;
  if (ch) {
    if (pendingGcs) rebuildGcs(ch);
    if (pendingClassic) rebuildClassic(ch);
    ch.mixer.timeScale = params.speed;
    if (!params.paused) ch.mixer.update(dt);
    try {
      // One world-matrix pass for the shared skeletons, then every deformer skips its own.
      let root: THREE.Object3D | undefined = ch.gcs[0]?.source ?? ch.classic[0]?.source;
      while (root?.parent) root = root.parent;
      root?.updateMatrixWorld();
      const noWorldUpdate = { updateMatrixWorld: false };
      let t0 = performance.now();
      for (const s of ch.gcs) s.update(noWorldUpdate);
      timing.gcs = ema(timing.gcs, performance.now() - t0);
      if (ch.classic.length) {
        t0 = performance.now();
        for (const s of ch.classic) s.update(noWorldUpdate);
        timing.classic = ema(timing.classic, performance.now() - t0);
      }
    } catch (e) {
      showMessage(`deform: ${describeError(e)}`);
    }
  }
  render();
  stats.update();
  frameCount++;
  if (now - lastReadout > 250) {
    lastReadout = now;
    updateReadouts();
  }
}

function render(): void {
  const h = window.innerHeight;
  renderer.setScissorTest(true);
  for (const r of viewRects()) {
    renderer.setViewport(r.x, 0, r.width, h);
    renderer.setScissor(r.x, 0, r.width, h);
    camera.aspect = r.width / h;
    camera.updateProjectionMatrix();
    gcsGroup.visible = r.kind === 'gcs';
    classicGroup.visible = r.kind === 'classic';
    if (current) current.holder.visible = r.kind === 'lbs';
    renderer.render(scene, camera);
  }
}

// ---------------------------------------------------------------------------------------------
// Testing hook

const ready = init()
  .catch((e) => showMessage(`The demo could not start: ${describeError(e)}`))
  .then(() => new Promise<void>((resolve) => { const f = frameCount; const wait = () => (frameCount > f + 1 ? resolve() : setTimeout(wait, 16)); wait(); }));

Object.assign(window, {
  __demo: {
    ready,
    frame: () => frameCount,
    busy: () => busy > 0,
    error: () => (messageEl.hidden ? '' : messageText.textContent ?? ''),
    character: () => current?.name ?? '',
    sectionCount: () => current?.gcs.reduce((n, s) => n + s.deformer.sectionCount, 0) ?? 0,
    sectionsPerPart: () => params.sections,
    setSections: (n: number) => { sectionsController.setValue(n); },
    /** The criterion of the GCS model on screen. */
    criterion: () => builtCriterion,
    gcsBuilds: () => gcsBuilds,
    classicError: () => current?.classicError ?? null,
    rigidParts: () => current?.rigidParts ?? [],
    readouts: () => collectReadouts(),
    views: () => viewRects(),
    time: () => current?.mixer.time ?? 0,
    clip: () => current?.action?.getClip().name ?? '',
    classicBuilds: () => classicBuilds,
    /** Pauses (through the GUI's checkbox), optionally at clip time t seconds. */
    pause: (t?: number) => {
      pausedController.setValue(true);
      if (t !== undefined) current?.mixer.setTime(t);
    },
    /** Moves the shared camera (for close-ups): eye position and target, world units. */
    lookAt: (eye: [number, number, number], target: [number, number, number]) => {
      camera.position.set(...eye);
      controls.target.set(...target);
      controls.update();
    },
    /** Settles when every queued load has finished. */
    idle: () => queue.then(() => undefined),
  },
});
