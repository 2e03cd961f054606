// Part of `npm run bench`: what a user waits for around the frame.
//   first picture  what the demo builds before it shows a character (web/demo/loading.ts): per
//                  skinned mesh a SkinDeformer of the default GCS, then one of the classic model
//                  (each its own rig, geometry and all). Its third view, LBS, is the source
//                  SkinnedMesh itself (three.js skins it): nothing to build.
//   slider         what the demo's section slider runs per change (web/demo/models.ts):
//                  SkinDeformer.rebuild('gcs', { gcs: { sections } }) with the count moving over
//                  3–8, as a drag does; beside it the core build alone (Rig.buildGcs). Medians
//                  after one untimed sweep; the page's first change (compiling the path) apart.
// Medians of several builds, and the best of them: the targets are set for a quiet host, and on a
// shared one the best build is the figure other work on the host cannot inflate (bench.mjs judges
// the build targets by it and prints the median beside it).
import { SkinDeformer } from '../../dist/three.js';
import { median } from '../../dist/measure.js';

function timed(fn) {
  const t0 = performance.now();
  const out = fn();
  return { ms: performance.now() - t0, out };
}

/** ms for the demo's first picture of `meshes`: GCS, classic, total (medians of `reps`). */
export function firstPicture(gcs, meshes, reps) {
  const gcsMs = [], classicMs = [], total = [];
  let classicError = null;
  for (let r = 0; r < reps; r++) {
    const a = timed(() => meshes.map((m) => new SkinDeformer(gcs, m, { method: 'gcs' })));
    let b;
    try {
      b = timed(() => meshes.map((m) => new SkinDeformer(gcs, m, { method: 'classic' })));
    } catch (e) {
      classicError = e;
      b = { ms: NaN, out: [] };
    }
    gcsMs.push(a.ms);
    classicMs.push(b.ms);
    total.push(a.ms + b.ms);
    for (const s of [...a.out, ...b.out]) s.dispose();
  }
  return { gcsMs: median(gcsMs), classicMs: median(classicMs), totalMs: median(total), totalBestMs: Math.min(...total),
    classicError: classicError?.message ?? null };
}

/**
 * ms per section-slider change: the adapter's rebuild and the core build alone. A drag rebuilds
 * on every change, so the medians are the steady cost, taken after one untimed sweep of the counts
 * (the page's first change also compiles the rebuild path: `firstMs`, reported apart).
 */
export function sliderRebuild(gcs, mesh, reps) {
  const skin = new SkinDeformer(gcs, mesh, { method: 'gcs' });
  const count = (i) => 3 + (i % 6);
  const adapter = [], core = [];
  try {
    const firstMs = timed(() => skin.rebuild('gcs', { gcs: { sections: 4 } })).ms;
    for (let i = 0; i < 6; i++) skin.rebuild('gcs', { gcs: { sections: count(i) } });
    for (let i = 0; i < reps; i++) adapter.push(timed(() => skin.rebuild('gcs', { gcs: { sections: count(i) } })).ms);
    for (let i = 0; i < reps; i++) {
      const b = timed(() => skin.rig.buildGcs({ sections: count(i) }));
      core.push(b.ms);
      b.out.dispose();
    }
    return { adapterMs: median(adapter), adapterBestMs: Math.min(...adapter), coreMs: median(core), firstMs };
  } finally {
    skin.dispose();
  }
}
