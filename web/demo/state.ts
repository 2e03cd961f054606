// The demo's one state object: the settings the GUI edits (seeded from the URL), what init() makes
// (renderer, scene, camera), the character on screen and the flags the frame loop reads. Every
// other module reads and writes it here; none keeps page state of its own.
import * as THREE from 'three';
import type { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type Stats from 'three/addons/libs/stats.module.js';
import { CLASSIC_DEFAULTS, CRITERIA, GCS_DEFAULTS, MAX_SECTIONS, MIN_SECTIONS, type ClassicReason, type Criterion, type GcsSkin } from '../lib/index.js';
import { SkinDeformer } from '../lib/three.js';
import type { DemoRenderer } from './renderer.js';
import { FrameCost } from './cost.js';
import type { InfluenceCount } from './influences.js';

export type ViewKind = 'gcs' | 'classic' | 'lbs';

/**
 * Camera layers: 0 holds what every view draws (ground, lights, the character's parts that are
 * not skinned); each view adds its own layer (the source SkinnedMeshes are the LBS view's).
 */
export const LAYER: Record<ViewKind, number> = { lbs: 1, gcs: 2, classic: 3 };

export interface Character {
  name: string;
  /** The character menu's value: 'human', a shipped key, or 'file' (dropped, loaded or ?model=URL). */
  key: string;
  /** The attribution line, or null for the user's own file. */
  credit: string | null;
  /** Holds the source object, scaled so the character is ~1.8 units tall, feet on y = 0. */
  holder: THREE.Group;
  sources: THREE.SkinnedMesh[];
  gcs: SkinDeformer[];
  classic: SkinDeformer[];
  classicError: string | null;
  /** Bones whose parts the classic model carries rigidly (not resampled), and why. */
  rigidParts: { name: string; reason: ClassicReason }[];
  /** Branching trunk parts resampled along the spine (their branch region carried). */
  trunkParts: string[];
  mixer: THREE.AnimationMixer;
  clips: THREE.AnimationClip[];
  action: THREE.AnimationAction | null;
  skeletonHelper: THREE.SkeletonHelper;
  sourceVertices: number;
  sourceTriangles: number;
  /** Influences per vertex of the source skins (the LBS view, three's skinning, takes four). */
  influences: InfluenceCount;
  /** Meshes under the character that are not skinned: drawn in every view, moved by three.js. */
  rigidMeshes: number;
}

export const query = new URLSearchParams(location.search);
export const queryNumber = (key: string, fallback: number) => {
  const v = Number(query.get(key));
  return query.has(key) && Number.isFinite(v) ? v : fallback;
};
const queryBool = (key: string, fallback: boolean) => (query.has(key) ? query.get(key) !== '0' && query.get(key) !== 'false' : fallback);

/** ?criterion=weights|y|axial (default weights, the library's default; any other value too). */
function parseCriterion(value: string | null): Criterion {
  const v = (value ?? '').toLowerCase();
  return CRITERIA.find((c) => c === v) ?? GCS_DEFAULTS.criterion;
}

/** What the GUI edits (lil-gui binds to these properties). */
export const params = {
  // GCS model (left)
  sections: Math.round(Math.min(MAX_SECTIONS, Math.max(MIN_SECTIONS, queryNumber('sections', GCS_DEFAULTS.sections)))), // the slider's range
  criterion: parseCriterion(query.get('criterion')),
  influenceWidth: GCS_DEFAULTS.influenceWidth,
  smooth: queryBool('smooth', GCS_DEFAULTS.smooth(GCS_DEFAULTS.criterion)), // the default: no steps (false: the stepped, faster level of detail)
  twistSpread: queryBool('twist', GCS_DEFAULTS.twistSpread),
  // classic model (right)
  contours: CLASSIC_DEFAULTS.contours,
  rays: CLASSIC_DEFAULTS.rays,
  bulge: CLASSIC_DEFAULTS.bulge,
  // animation
  clip: query.get('clip') ?? 'walk',
  speed: 1,
  paused: queryBool('paused', false),
  // view
  wireframe: queryBool('wireframe', false),
  colourBySection: queryBool('colour', false),
  showSkeleton: queryBool('skeleton', false),
  lbsView: queryBool('lbs', false),
  model: 'human',
};

export interface DemoState {
  gcs: GcsSkin;
  renderer: DemoRenderer;
  /** gcs-skin/three's SkinDeformer, or gcs-skin/webgpu's with ?renderer=webgpu. */
  Skin: typeof SkinDeformer;
  scene: THREE.Scene;
  camera: THREE.PerspectiveCamera;
  controls: OrbitControls;
  stats: Stats;
  /** The key light (its shadow camera follows the character's size). */
  key: THREE.DirectionalLight;
  /** Parents of the deformed meshes (their layers pick the view). */
  gcsGroup: THREE.Group;
  classicGroup: THREE.Group;
  current: Character | null;
  /** A GUI change asks for a rebuild; the frame loop does it (at most one per frame). */
  pendingGcs: boolean;
  pendingClassic: boolean;
  frameCount: number;
  /** Loads queued or running. */
  busy: number;
  /** Builds and rebuilds of the GCS model so far. */
  gcsBuilds: number;
  /** Builds of the classic model so far (a bulge change must not add one). */
  classicBuilds: number;
  /** The criterion the current GCS model was built with. */
  builtCriterion: Criterion;
  /** Pixels the picture is moved down in every view so that the character's centre sits between labels and readouts. */
  viewShift: number;
  /** ms per frame of each model, measured after each build as the bench measures it (cost.ts). */
  frameCost: FrameCost;
}

// Set by init() before anything reads them (the renderer, scene, camera and core come first).
export const state: DemoState = {
  gcs: undefined as unknown as GcsSkin,
  renderer: undefined as unknown as DemoRenderer,
  Skin: SkinDeformer,
  scene: undefined as unknown as THREE.Scene,
  camera: undefined as unknown as THREE.PerspectiveCamera,
  controls: undefined as unknown as OrbitControls,
  stats: undefined as unknown as Stats,
  key: undefined as unknown as THREE.DirectionalLight,
  gcsGroup: new THREE.Group(),
  classicGroup: new THREE.Group(),
  current: null,
  pendingGcs: false,
  pendingClassic: false,
  frameCount: 0,
  busy: 0,
  gcsBuilds: 0,
  classicBuilds: 0,
  builtCriterion: params.criterion,
  viewShift: 0,
  frameCost: new FrameCost(),
};

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
/** The page's own elements (index.html). */
export const dom = {
  fileInput: $<HTMLInputElement>('file'),
  message: $('message'),
  messageText: $('message-text'),
  messageClose: $('message-close'),
  status: $('status'),
  readouts: $('readouts'),
  labels: $('labels'),
  drop: $('drop'),
  credit: $('credit'),
  hint: $('hint'),
  sidebar: $('sidebar'),
};
