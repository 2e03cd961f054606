// The controls: lil-gui's folders (Character, GCS model, Classic model, Animation, View), the
// keys (space pauses, "." steps), and the GUI's lines that follow the character on screen (the
// character and clip menus, the attribution, the cost of the GCS settings, the note on the
// paper's criteria). Loading is not done here: the Character folder calls the actions it is given.
import Stats from 'three/addons/libs/stats.module.js';
import GUI from 'three/addons/libs/lil-gui.module.min.js';
import { CLASSIC_LIMITS, MAX_SECTIONS, MIN_SECTIONS } from '../lib/index.js';
import { playClip, stepFrame } from './animate.js';
import { applyMaterials } from './colours.js';
import { CRITERION_MENU, PAPER_CRITERIA_NOTE } from './criteria.js';
import { SECTION_STOPS, stopIndex } from './section-stops.js';
import { textOptions, escapeHtml as esc } from './gui-text.js';
import { updateLabels } from './labels.js';
import { onCostChange, setBulge } from './models.js';
import { clearMessage } from './page.js';
import { addRendererSwitch, rendererKind } from './renderer.js';
import { dom, params, state } from './state.js';
import { relayout } from './views.js';

/** What the Character folder asks of the loader. */
export interface CharacterActions {
  /** The menu's value: 'human' or a shipped character's key. */
  choose(key: string): void;
}

/** A character in the menu: label → value ('human', a shipped key; 'file' for a loaded file). */
export interface MenuEntry { label: string; key: string }

// lil-gui's generic controller types do not assign to each other: keep what we call on them.
interface Ctl { domElement: HTMLElement; name(n: string): this; onChange(f: () => void): this; disable(d?: boolean): this; updateDisplay(): this }
interface OptionsCtl extends Ctl { options(values: string[] | Record<string, string>): OptionsCtl }
interface ValueCtl<T> extends Ctl { setValue(v: T): this }

let modelController: OptionsCtl;
let clipController: OptionsCtl;
let sectionsController: ValueCtl<number>;
let sectionsTrack: HTMLInputElement;

let pausedController: ValueCtl<boolean>;
/** The controls that only apply to the paper's criteria (y, axial). */
let paperOnlyControllers: Ctl[] = [];
let criterionNote: HTMLElement;
let menuEntries: MenuEntry[] = [];
let actions: CharacterActions;

/** The GUI, the keys and the message's close button. `menu`: the characters the menu offers. */
export function initControls(menu: MenuEntry[], characterActions: CharacterActions): void {
  menuEntries = menu;
  actions = characterActions;
  const gui = new GUI({ title: 'gcs-skin', width: 270 });
  const buttons = { loadFile: () => dom.fileInput.click(), stepFrame: () => pauseAndStep() };

  const m = gui.addFolder('Character');
  // Labels from files and URLs reach lil-gui (innerHTML) escaped: textOptions.
  modelController = m.add(params, 'model', textOptions(modelMenu(null))) as unknown as OptionsCtl;
  modelController.name('character').onChange(onModelMenu);
  m.add(buttons, 'loadFile').name('load file… (.glb / .gltf)');
  // The attribution line of the character on screen, under the menu; then how to load your own
  // (here, not at the GUI's end: the GUI is taller than a 720 px window).
  childrenOf(m).appendChild(dom.credit);
  childrenOf(m).appendChild(dom.hint);

  const g = gui.addFolder('GCS model (left)');
  const criterion = g.add(params, 'criterion', CRITERION_MENU).onChange(() => { state.pendingGcs = true; updatePaperOnlyControls(); }) as unknown as Ctl;
  criterion.domElement.style.setProperty('--name-width', '22%'); // room for "axial (paper's rule, bone axis)"
  // Under the paper's criteria, why the picture looks broken: text, beside the menu.
  criterionNote = document.createElement('div');
  criterionNote.className = 'criterion-note';
  criterionNote.textContent = PAPER_CRITERIA_NOTE;
  criterion.domElement.after(criterionNote);
  // The number box takes any count 3–256; the track under it is stepped (SECTION_STOPS), so that
  // every count of the useful range sits a finger's width apart (a linear 3–256 track gave them 3 px).
  sectionsController = g.add(params, 'sections').min(MIN_SECTIONS).step(1).name('sections')
    .onChange(onSectionsBox) as unknown as ValueCtl<number>;
  sectionsTrack = addSectionsTrack(sectionsController);
  g.add(params, 'smooth').name('smooth (no steps)').onChange(() => { state.pendingGcs = true; });
  const costShown = { text: 'measuring…' };
  const cost = g.add(costShown, 'text').name('cost / frame').disable();
  cost.domElement.title = 'ms per frame of the model as set, and of the stepped one (smooth off) at the same sections, measured in this page';
  onCostChange((text) => { costShown.text = text; cost.updateDisplay(); });
  paperOnlyControllers = [
    g.add(params, 'influenceWidth', 0.05, 1, 0.05).name('influence width').onChange(() => { state.pendingGcs = true; }),
    g.add(params, 'twistSpread').name('twist spread').onChange(() => { state.pendingGcs = true; }),
  ] as unknown as Ctl[];
  updatePaperOnlyControls();

  const c = gui.addFolder('Classic model (right)');
  c.add(params, 'contours', CLASSIC_LIMITS.minContours, 64, 1).onChange(() => { state.pendingClassic = true; });
  c.add(params, 'rays', CLASSIC_LIMITS.minRays, 64, 1).onChange(() => { state.pendingClassic = true; });
  c.add(params, 'bulge', 0, CLASSIC_LIMITS.maxBulge, 0.05).name('muscle bulge').onChange(setBulge);

  const a = gui.addFolder('Animation');
  clipController = a.add(params, 'clip', textOptions([params.clip])) as unknown as OptionsCtl;
  a.add(params, 'speed', 0, 2, 0.05);
  pausedController = a.add(params, 'paused').name('pause') as unknown as ValueCtl<boolean>;
  a.add(buttons, 'stepFrame').name('step one frame');

  const v = gui.addFolder('View');
  v.add(params, 'wireframe').onChange(onMaterials);
  v.add(params, 'colourBySection').name('colour by section').onChange(onMaterials);
  v.add(params, 'showSkeleton').name('show skeleton').onChange(() => { if (state.current) state.current.skeletonHelper.visible = params.showSkeleton; });
  v.add(params, 'lbsView').name('three.js LBS view').onChange(relayout);
  // The joint close-up (joint-mode.ts) of the character on screen (a dropped file: drop it there again).
  v.add({ open: () => { location.search = `?joint&model=${state.current?.key === 'file' ? 'human' : state.current?.key ?? 'human'}`; } }, 'open')
    .name('joint close-up (knees, elbows) ↗');
  addRendererSwitch(v, rendererKind());

  // FPS at the top of the GUI (the GUI is tall: at its end it fell below a 720 px window; fixed beside it, under it).
  state.stats = new Stats();
  state.stats.dom.id = 'stats';
  state.stats.dom.style.cssText = 'position:relative;margin:6px 8px;opacity:0.85;cursor:pointer';
  childrenOf(gui).prepend(state.stats.dom);

  window.addEventListener('keydown', (e) => {
    if ((e.target as HTMLElement).tagName === 'INPUT') return;
    if (e.code === 'Space') { e.preventDefault(); setPaused(!params.paused); }
    if (e.key === '.') pauseAndStep();
  });
  dom.messageClose.addEventListener('click', clearMessage);
}

/** The element lil-gui puts a folder's (or the GUI's) controllers in. */
const childrenOf = (folder: GUI) => (folder as unknown as { $children: HTMLElement }).$children;

function onMaterials(): void {
  applyMaterials();
  updateLabels();
}

/** Through the GUI's checkbox, so it shows the state. */
export function setPaused(paused: boolean): void {
  pausedController.setValue(paused);
}

export function setSections(n: number): void {
  sectionsController.setValue(n);
}

/** The number box: whole counts within MIN_SECTIONS–MAX_SECTIONS (lil-gui clamps the minimum only: a maximum would add its linear slider). */
function onSectionsBox(): void {
  const n = Math.round(Math.min(MAX_SECTIONS, Math.max(MIN_SECTIONS, params.sections)));
  if (n !== params.sections) {
    sectionsController.setValue(n);
    return;
  }
  sectionsTrack.value = String(stopIndex(n));
  state.pendingGcs = true;
}

/** A full-width stepped range input under the number box; moving it sets the box. */
function addSectionsTrack(box: ValueCtl<number>): HTMLInputElement {
  const track = document.createElement('input');
  track.type = 'range';
  track.className = 'sections-track';
  track.min = '0';
  track.max = String(SECTION_STOPS.length - 1);
  track.step = '1';
  track.value = String(stopIndex(params.sections));
  track.title = 'sections: 3 to 16 one by one, then 20, 24, 32, 48, 64, 96, 128, 192, 256 (type any count 3–256 in the box)';
  track.setAttribute('aria-label', 'sections');
  track.addEventListener('input', () => box.setValue(SECTION_STOPS[Number(track.value)]));
  box.domElement.after(track);
  return track;
}

function pauseAndStep(): void {
  if (!params.paused) setPaused(true);
  stepFrame();
}

/** The character menu: label → value; a loaded file is listed under its name while it is shown. */
function modelMenu(fileName: string | null): Record<string, string> {
  const menu: Record<string, string> = {};
  for (const m of menuEntries) menu[m.label] = m.key;
  if (fileName) menu[fileName] = 'file';
  return menu;
}

function onModelMenu(): void {
  const choice = params.model;
  if (choice === 'file' || choice === state.current?.key) return;
  actions.choose(choice);
}

/** The menu shows the character on screen (also after a failed load, which keeps the old one). */
export function syncModelMenu(): void {
  const ch = state.current;
  params.model = ch?.key ?? 'human';
  const fileName = ch?.key === 'file' ? ch.name : null;
  const select = modelController.domElement.querySelector('select');
  const labels = Object.keys(modelMenu(fileName));
  if (select && Array.from(select.options).map((o) => o.text).join('\n') === labels.join('\n')) {
    modelController.updateDisplay();
    return;
  }
  // lil-gui's options() re-adds the controller at the end of its folder: put it back first.
  modelController = modelController.options(textOptions(modelMenu(fileName))).name('character').onChange(onModelMenu);
  modelController.domElement.parentElement?.prepend(modelController.domElement);
}

/** The clip menu lists the character's clips. */
export function setClipOptions(names: string[]): void {
  // lil-gui's options() re-adds the controller at the end of its folder: put it back first.
  clipController = clipController.options(textOptions(names.length ? names : ['(none)'])).name('clip').onChange(playClip);
  clipController.domElement.parentElement?.prepend(clipController.domElement);
}

/** The attribution line of the character on screen, linking public/LICENSES.md. */
export function updateCredit(): void {
  const ch = state.current;
  const el = dom.credit;
  if (!ch) { el.hidden = true; return; }
  el.hidden = false;
  if (ch.credit) {
    el.innerHTML = `${esc(ch.credit)} · <a href="LICENSES.md" target="_blank" rel="noopener">LICENSES.md</a>`;
  } else {
    el.textContent = `${ch.name}: your own file`;
  }
}

/** Influence width and twist spread apply to the paper's criteria only: disabled (greyed) under weights; the note shown under the paper's. */
function updatePaperOnlyControls(): void {
  const off = params.criterion === 'weights';
  for (const c of paperOnlyControllers) {
    c.disable(off);
    c.domElement.title = off ? 'only for the Y and axial criteria' : '';
  }
  criterionNote.hidden = off;
}
