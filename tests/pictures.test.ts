// The demo's pictures in README and docs/ tell what the current build does: each picture that
// scripts/screenshot-demo.mjs took has its readouts beside it (docs/NAME.readouts.json), and those
// must agree with the build (the section and vertex counts our human has now, exactly) and with
// docs/figures.json (the per-frame cost the bench measured, within the noise between a browser page
// and the bench on a shared host: a factor of 2; absolute times moved 1.6× between runs minutes
// apart). A picture whose readouts are missing or stale fails: regenerate it with
// `node scripts/screenshot-demo.mjs`.
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { beforeAll, describe, expect, test } from 'vitest';
import { initGcsSkin, type GcsSkin } from '../web/lib/index.js';
import { createHuman } from '../web/lib/human/index.js';
import { rigInputFromSkinnedMesh } from '../web/lib/three/rig-input.js';

const ROOT = resolve(__dirname, '..');
const DOCS = join(ROOT, 'docs');
/** How far a picture's per-frame figure may be from the bench's, as a factor either way. */
const NOISE = 2;

interface Shown {
  picture: string;
  query: string;
  taken: string;
  host: string;
  readouts?: { gcs: { ms: number; sections: number; vertices: number; criterion: string } | null; classic: { ms: number } | null };
  text?: string;
}

const figures = JSON.parse(readFileSync(join(DOCS, 'figures.json'), 'utf8'));
const shots: Shown[] = readdirSync(DOCS).filter((f) => f.endsWith('.readouts.json')).map((f) => JSON.parse(readFileSync(join(DOCS, f), 'utf8')));
/** Pictures of our human at the default settings (no other character, no other section count or criterion). */
const defaultHuman = (s: Shown) => !/model=|sections=|criterion=|smooth=|crowd=|vertices=/.test(s.query);

test('the README\'s picture has its readouts beside it', () => {
  const readme = readFileSync(join(ROOT, 'README.md'), 'utf8');
  const [, picture] = /!\[[^\]]*\]\(docs\/([\w-]+\.png)\)/.exec(readme) ?? [];
  expect(picture, 'the README shows a picture of the demo').toBeDefined();
  expect(existsSync(join(DOCS, picture)), picture).toBe(true);
  expect(shots.map((s) => s.picture), `docs/${picture.replace(/\.png$/, '.readouts.json')}`).toContain(picture);
});

describe('each picture\'s readouts', () => {
  let gcs: GcsSkin;
  let defaultSections: number;
  let defaultVertices: number;
  beforeAll(async () => {
    gcs = await initGcsSkin();
    const human = createHuman();
    const rig = gcs.createRig(rigInputFromSkinnedMesh(human.mesh));
    const d = rig.buildGcs();
    defaultSections = d.sectionCount;
    defaultVertices = d.vertexCount;
    d.dispose();
    rig.dispose();
  }, 60000);

  test.each(shots.filter(defaultHuman).map((s) => [s.picture, s] as const))('%s: the current build\'s human and the bench\'s cost', (_, shot) => {
    expect(existsSync(join(DOCS, shot.picture)), shot.picture).toBe(true);
    const g = shot.readouts?.gcs;
    expect(g, 'the GCS view\'s readouts').toBeTruthy();
    // What the build makes of our human today, exactly (a stale picture shows an old section count).
    expect({ sections: g!.sections, vertices: g!.vertices, criterion: g!.criterion })
      .toEqual({ sections: defaultSections, vertices: defaultVertices, criterion: 'weights' });
    expect(g!.vertices).toBe(figures.human.vertices);
    // The per-frame cost as the bench measured it, within the noise (a factor of 2 either way).
    const ratio = g!.ms / figures.defaultMsPerFrame;
    console.log(`${shot.picture} (${shot.taken}, ${shot.host}): GCS ${g!.ms.toFixed(3)} ms/frame, the bench ${figures.defaultMsPerFrame.toFixed(3)} ms (${figures.measured}): ${ratio.toFixed(2)}×`);
    expect(ratio).toBeGreaterThan(1 / NOISE);
    expect(ratio).toBeLessThan(NOISE);
    // The picture's text says the same figures (no "0.00", the sections as counted).
    expect(shot.text).toContain(`${defaultSections.toLocaleString('en')} sections`);
    expect(shot.text).not.toMatch(/(^|[^\d.])0\.00(?!\d)/m);
  });
});
