// The per-frame paths make no typed arrays and no views (a subarray or slice is an allocation too),
// counted while they run: a CPU-backend skin with tangents and velocity (previous positions), a
// GPU-backend skin whose previous-frame texture advances each frame, a crowd posed from a baked clip.
// The attributes and textures keep pointing at the same wasm views throughout.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three/webgpu';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { bakeClip, GcsCharacter, GcsCrowd } from '../../web/lib/webgpu.js';
import { createHuman, type Human } from '../../web/lib/human/index.js';
import { drawWith, humanWithTangents, webgpuRenderer } from '../helpers/velocity-pass.js';

const FRAMES = 60;
const TYPED_ARRAYS = ['Float32Array', 'Float64Array', 'Int8Array', 'Int16Array', 'Int32Array', 'Uint8Array', 'Uint8ClampedArray', 'Uint16Array', 'Uint32Array'];

/** Runs `frames`, counting the typed arrays constructed and the slice / subarray calls made meanwhile. */
function countTypedArrays(frames: () => void): { constructed: number; views: number } {
  const global = globalThis as unknown as Record<string, new (...args: unknown[]) => object>;
  const constructors = TYPED_ARRAYS.map((name) => global[name]);
  const prototype = Object.getPrototypeOf(Int8Array.prototype) as { slice(...a: unknown[]): unknown; subarray(...a: unknown[]): unknown };
  const { slice, subarray } = prototype;
  let constructed = 0, views = 0;
  TYPED_ARRAYS.forEach((name, i) => {
    global[name] = new Proxy(constructors[i], {
      construct(target, args, newTarget) {
        constructed++;
        return Reflect.construct(target, args, newTarget);
      },
    });
  });
  prototype.slice = function (this: unknown, ...a: unknown[]) { views++; return slice.apply(this, a); };
  prototype.subarray = function (this: unknown, ...a: unknown[]) { views++; return subarray.apply(this, a); };
  try {
    frames();
  } finally {
    TYPED_ARRAYS.forEach((name, i) => { global[name] = constructors[i]; });
    prototype.slice = slice;
    prototype.subarray = subarray;
  }
  return { constructed, views };
}

let gcs: GcsSkin;
let human: Human;
beforeAll(async () => {
  gcs = await initGcsSkin();
  human = createHuman({ vertices: 3000 });
});

/** A pose for frame f: a few bones turned by an angle that changes every frame. */
function pose(mesh: THREE.SkinnedMesh, f: number): void {
  const bones = mesh.skeleton.bones;
  for (let b = 1; b < bones.length; b += 3) bones[b].rotation.x = 0.3 * Math.sin(0.1 * f + b);
}

describe('no typed array or view made per frame', () => {
  test('the counter counts (else the tests below would pass on nothing)', () => {
    const counted = countTypedArrays(() => {
      const a = new Float32Array(8);
      a.subarray(2);
      a.slice(1);
    });
    expect(counted).toEqual({ constructed: 1, views: 2 });
  });

  test('CPU backend with tangents and velocity: positions, normals, tangents and previous positions stay the wasm views', () => {
    const { mesh, group } = humanWithTangents(human);
    const character = new GcsCharacter(gcs, group);
    try {
      const skin = character.skins[0];
      const g = skin.mesh.geometry;
      drawWith(skin.mesh, webgpuRenderer(true)); // a velocity pass: previous positions from the next update
      for (let f = 0; f < 3; f++) { pose(mesh, f); character.update(); }
      const attribute = (name: string) => g.getAttribute(name) as THREE.BufferAttribute;
      const normals = attribute('normal').array, tangents = attribute('tangent').array;
      const positions = new Set([attribute('position').array, attribute('gcsPreviousPosition').array]);
      expect(positions.size).toBe(2);
      expect(tangents).toBe(skin.deformer.tangents);
      const arrays = { same: true };
      const counted = countTypedArrays(() => {
        for (let f = 3; f < 3 + FRAMES; f++) {
          pose(mesh, f);
          character.update();
          const p = attribute('position').array, q = attribute('gcsPreviousPosition').array;
          if (!positions.has(p) || !positions.has(q) || p === q || attribute('normal').array !== normals || attribute('tangent').array !== tangents) arrays.same = false;
        }
      });
      expect(counted).toEqual({ constructed: 0, views: 0 });
      expect(arrays.same, 'the attributes keep the two position views, the normal and tangent views').toBe(true);
    } finally {
      character.dispose();
    }
  });

  test('GPU backend with velocity: the per-frame texture views the wasm texels, the previous one swaps two arrays', () => {
    const mesh = human.mesh.clone() as THREE.SkinnedMesh;
    const group = new THREE.Group();
    group.add(mesh);
    const character = new GcsCharacter(gcs, group, { backend: 'gpu' });
    try {
      const sections = character.skins[0].gpuSections!;
      const previous = sections.previousTexture(); // as a velocity pass's shader asks for it
      const data = (t: THREE.DataTexture) => (t.image as { data: Float32Array }).data;
      for (let f = 0; f < 3; f++) { pose(mesh, f); character.update(); sections.advanceFrame(f); }
      const texels = data(sections.texture);
      const kept = new Set([data(previous)]);
      const arrays = { same: true };
      const counted = countTypedArrays(() => {
        for (let f = 3; f < 3 + FRAMES; f++) {
          pose(mesh, f);
          character.update();
          sections.advanceFrame(f);
          sections.advanceFrame(f); // a second draw in the same frame changes nothing
          kept.add(data(previous));
          if (data(sections.texture) !== texels || data(sections.texture) !== sections.transforms.texels) arrays.same = false;
        }
      });
      expect(counted).toEqual({ constructed: 0, views: 0 });
      expect(arrays.same, 'the texture keeps viewing the wasm texels').toBe(true);
      expect(kept.size, 'the previous texture alternates between two arrays').toBe(2);
    } finally {
      character.dispose();
    }
  });

  test('a crowd posed from a baked clip, then updated', () => {
    const crowd = new GcsCrowd(gcs, human.mesh, 16);
    try {
      const walk = bakeClip(human.mesh, human.clips.find((c) => c.name === 'walk')!, 30);
      const texels = (crowd.sections.texture.image as { data: Float32Array }).data;
      const counted = countTypedArrays(() => {
        for (let f = 0; f < FRAMES; f++) {
          for (let i = 0; i < crowd.count; i++) crowd.setBakedPose(i, walk, f / 60 + 0.1 * i);
          crowd.update();
        }
      });
      expect(counted).toEqual({ constructed: 0, views: 0 });
      expect((crowd.sections.texture.image as { data: Float32Array }).data).toBe(texels);
    } finally {
      crowd.dispose();
    }
  });
});
