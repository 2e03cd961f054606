// "colour by section": one colour per GCS section or classic contour, on white materials; off,
// every deformed mesh wears its source's own material and vertex colours. Wireframe for all.
import * as THREE from 'three';
import type { ClassicDeformer, GcsDeformer } from '../lib/index.js';
import type { SkinDeformer } from '../lib/three.js';
import { params, state } from './state.js';

const gcsMaterial = new THREE.MeshStandardMaterial({ color: 0xffffff, vertexColors: true, roughness: 0.62, metalness: 0 });
const classicMaterial = new THREE.MeshStandardMaterial({ color: 0xffffff, vertexColors: true, roughness: 0.62, metalness: 0 });
const SKIN = new THREE.Color(0xd9a58a);
const tmpColour = new THREE.Color();

/** Vertices in rigid cores (weights criterion) of each GCS deformer, counted when it is coloured. */
export const rigidVertices = new WeakMap<SkinDeformer, number>();

/** A hue per part (joint index), spread around the wheel. */
const hueOf = (part: number) => (0.22 + ((part * 0.618034) % 1) * 0.8) % 1;

/**
 * One colour per generalized section: a hue per part, alternating light/dark bands along it; shared
 * sections (SGS) yellow. Weights criterion: bands run from one joint to the next (sections of one
 * joint pair sorted by the second joint's weight), rigid cores are a pale grey tinted by the part.
 */
export function gcsColours(skin: SkinDeformer): void {
  const d = skin.deformer as GcsDeformer;
  const sections = d.sections();
  const ofVertex = d.sectionOfVertex();
  const rank = new Array<number>(sections.length).fill(0);
  const groups = new Map<string, number[]>();
  const byWeights = state.builtCriterion === 'weights';
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
    if (s.shared) return tmpColour.setHSL(0.15, 1, 0.55).clone();
    if (s.rigid) return tmpColour.setHSL(hueOf(s.part), 0.2, 0.72).clone();
    return tmpColour.setHSL(hueOf(s.part), 0.6, rank[i] % 2 ? 0.36 : 0.56).clone();
  });
  const colours = new Float32Array(d.vertexCount * 3);
  for (let v = 0; v < d.vertexCount; v++) {
    const c = palette[ofVertex[v]] ?? SKIN;
    colours[3 * v] = c.r; colours[3 * v + 1] = c.g; colours[3 * v + 2] = c.b;
  }
  setSectionColours(skin, colours);
}

/**
 * The classic model, coloured like the GCS view: one colour per contour (a hue per part, light and
 * dark bands alternating along it; a shared joint contour takes the distal part's hue), the carried
 * skin a pale grey tinted by its part (the untinted grey: skin of a resampled part kept by carried
 * triangles, e.g. a band's border).
 */
export function classicColours(skin: SkinDeformer): void {
  const d = skin.deformer as ClassicDeformer;
  const contourOf = d.contourOfVertex;
  const contourHue = new Float32Array(d.sectionCount);
  const colours = new Float32Array(d.vertexCount * 3);
  const grey = new THREE.Color().setHSL(0, 0, 0.72);
  for (let v = 0; v < d.vertexCount; v++) grey.toArray(colours, 3 * v);
  for (const p of d.parts) {
    const end = Math.min(d.vertexCount, p.firstVertex + p.vertexCount);
    if (p.resampled) for (let v = Math.max(0, p.firstVertex); v < end; v++) contourHue[contourOf[v]] = hueOf(p.joint);
    else {
      tmpColour.setHSL(hueOf(p.joint), 0.2, 0.72);
      for (let v = Math.max(0, p.firstVertex); v < end; v++) tmpColour.toArray(colours, 3 * v);
    }
  }
  for (let v = 0; v < d.vertexCount; v++) {
    const c = contourOf[v];
    if (c >= 0) tmpColour.setHSL(contourHue[c], 0.6, c % 2 ? 0.36 : 0.56).toArray(colours, 3 * v);
  }
  setSectionColours(skin, colours);
}

/** Per output geometry: the section colours, and the source's own vertex colours they stand in for. */
const colourSets = new WeakMap<THREE.BufferGeometry, { section: THREE.BufferAttribute; own: THREE.BufferAttribute | null }>();

function setSectionColours(skin: SkinDeformer, colours: Float32Array): void {
  const geometry = skin.mesh.geometry;
  const known = colourSets.get(geometry);
  const own = known ? known.own : (geometry.getAttribute('color') as THREE.BufferAttribute | undefined) ?? null;
  colourSets.set(geometry, { section: new THREE.BufferAttribute(colours, 3), own });
  applyColourMode(skin);
}

/** "colour by section": the section colours on white; otherwise the source's own material and vertex colours. */
function applyColourMode(skin: SkinDeformer): void {
  const geometry = skin.mesh.geometry;
  const set = colourSets.get(geometry);
  const classic = skin.currentMethod === 'classic';
  if (params.colourBySection && set) {
    geometry.setAttribute('color', set.section);
    skin.mesh.material = classic ? classicMaterial : gcsMaterial;
  } else {
    if (set?.own) geometry.setAttribute('color', set.own);
    else if (set) geometry.deleteAttribute('color');
    skin.mesh.material = skin.source.material;
  }
}

/** Colour mode and wireframe on every mesh of the character on screen. */
export function applyMaterials(): void {
  for (const m of [gcsMaterial, classicMaterial]) {
    m.wireframe = params.wireframe;
    m.needsUpdate = true;
  }
  const ch = state.current;
  for (const s of [...ch?.gcs ?? [], ...ch?.classic ?? []]) applyColourMode(s);
  ch?.holder.traverse((o) => {
    const mesh = o as THREE.Mesh;
    if (!mesh.isMesh) return;
    for (const m of Array.isArray(mesh.material) ? mesh.material : [mesh.material]) {
      if ('wireframe' in m) { (m as THREE.MeshStandardMaterial).wireframe = params.wireframe; m.needsUpdate = true; }
    }
  });
}
