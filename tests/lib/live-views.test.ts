// Live views: growing wasm memory (another rig's build) detaches every typed array on the old
// buffer. Whatever a user reads between that growth and the next update() — raycasts, bounds, the
// attribute arrays, the deformer's outputs, the GPU texture's data — must see live memory. Here the
// memory grows before every single read, and every read must give what it gave before any growth.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three/webgpu';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { GcsCharacter } from '../../web/lib/webgpu.js';
import { createHuman, type Human } from '../../web/lib/human/index.js';
import { drawWith, humanWithTangents, webgpuRenderer } from '../helpers/velocity-pass.js';

let gcs: GcsSkin;
let human: Human;
beforeAll(async () => {
  gcs = await initGcsSkin();
  human = createHuman({ vertices: 3000 });
});

/** Grows wasm memory (by 1 MB, as another rig's allocation would) and checks that it detached the old buffer. */
function grow(): void {
  const before = gcs.memory.buffer;
  gcs.memory.grow(16);
  expect(before.byteLength, 'the old buffer is detached').toBe(0);
}

/** Every public read of a character's memory, as plain numbers (a copy). */
function reads(character: GcsCharacter): Record<string, () => number[]> {
  const skin = character.skins[0];
  const mesh = skin.mesh;
  const attribute = (name: string) => () => Array.from((mesh.geometry.getAttribute(name) as THREE.BufferAttribute | undefined)?.array ?? []);
  const raycaster = new THREE.Raycaster(new THREE.Vector3(0, 1, 5), new THREE.Vector3(0, 0, -1));
  return {
    raycast: () => raycaster.intersectObject(character.root, true).flatMap((hit) => [hit.distance, hit.point.x, hit.point.y, hit.point.z]),
    bounds: () => {
      const box = new THREE.Box3().setFromObject(mesh, true); // precise: reads every position
      return [...box.min.toArray(), ...box.max.toArray()];
    },
    'attribute position': attribute('position'),
    'attribute normal': attribute('normal'),
    'attribute tangent': attribute('tangent'),
    'attribute previous position': attribute('gcsPreviousPosition'),
    'deformer positions': () => Array.from(skin.deformer.positions),
    'deformer normals': () => Array.from(skin.deformer.normals),
    'deformer tangents': () => Array.from(skin.deformer.tangents ?? []),
    'deformer previous positions': () => Array.from(skin.deformer.previousPositions ?? []),
    'GPU texture data': () => Array.from((skin.gpuSections?.texture.image as { data: Float32Array } | undefined)?.data ?? []),
    'GPU skins': () => Array.from(skin.gpuSections?.skins ?? []),
  };
}

/** Poses two frames, reads everything once, then reads everything again with a growth before each read. */
function expectLiveAfterGrowth(character: GcsCharacter, mesh: THREE.SkinnedMesh, expected: string[]): void {
  for (let f = 0; f < 2; f++) {
    for (const [b, bone] of mesh.skeleton.bones.entries()) bone.rotation.x = 0.2 * Math.sin(f + b);
    character.update();
  }
  const all = reads(character);
  const before = Object.fromEntries(Object.entries(all).map(([name, read]) => [name, read()]));
  for (const name of expected) expect(before[name].length, `${name} has something to read`).toBeGreaterThan(0);
  expect(before.raycast.every(Number.isFinite)).toBe(true);
  for (const [name, read] of Object.entries(all)) {
    grow();
    const after = read();
    expect(after.length, name).toBe(before[name].length);
    expect(after.every((x, i) => Object.is(x, before[name][i])), `${name} reads the same after memory growth`).toBe(true);
  }
}

describe('every public read sees live memory after growth, before the next update()', () => {
  test('CPU backend with tangents and velocity', () => {
    const { mesh, group } = humanWithTangents(human);
    const character = new GcsCharacter(gcs, group);
    try {
      drawWith(character.skins[0].mesh, webgpuRenderer(true)); // previous positions from the next update
      expectLiveAfterGrowth(character, mesh, ['raycast', 'bounds', 'attribute position', 'attribute normal', 'attribute tangent',
        'attribute previous position', 'deformer positions', 'deformer normals', 'deformer tangents', 'deformer previous positions']);
    } finally {
      character.dispose();
    }
  });

  test('GPU backend: the texture, its skins and the raycast geometry', () => {
    const { mesh, group } = humanWithTangents(human);
    const character = new GcsCharacter(gcs, group, { backend: 'gpu' });
    try {
      expect(character.backend).toBe('gpu');
      expectLiveAfterGrowth(character, mesh, ['raycast', 'bounds', 'deformer positions', 'GPU texture data', 'GPU skins']);
    } finally {
      character.dispose();
    }
  });

  test('classic and LBS builds, and after a rebuild', () => {
    const { mesh, group } = humanWithTangents(human);
    const character = new GcsCharacter(gcs, group, { method: 'classic' });
    try {
      expectLiveAfterGrowth(character, mesh, ['raycast', 'bounds', 'attribute position', 'attribute normal']);
      character.rebuild('lbs');
      expectLiveAfterGrowth(character, mesh, ['raycast', 'bounds', 'attribute position', 'attribute normal', 'attribute tangent']);
    } finally {
      character.dispose();
    }
  });
});
