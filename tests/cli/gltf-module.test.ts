// `gcs-skin/gltf` (packages/cli/src/gltf.ts): loadCharacter gives per skinned mesh a RigInput, the
// character's height and clips sampled into skin matrices — the same matrices as the report's
// sampling through three's AnimationMixer, wrapped outside the clip, independent of the clip
// sampled before; the rest pose; morph targets and their animated influences; bytes and URLs as
// well as paths; a GltfError for a file with no skin.
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { Document, NodeIO } from '@gltf-transform/core';
import { createHuman, humanToGlb } from '../../web/lib/human/index.js';
import { GltfError, loadCharacter, type Character } from '../../packages/cli/src/gltf.js';
import { loadGltfFile, sampleClip } from '../../packages/cli/src/gltf-node.js';
import { GcsError, initGcsSkin } from '../../web/lib/index.js';

let dir: string;
let file: string;
let character: Character;

beforeAll(async () => {
  dir = mkdtempSync(join(tmpdir(), 'gcs-gltf-module-'));
  file = join(dir, 'human.glb');
  writeFileSync(file, await humanToGlb(createHuman({ vertices: 2500 })));
  character = await loadCharacter(file);
});
afterAll(() => rmSync(dir, { recursive: true, force: true }));

const maxDiff = (a: ArrayLike<number>, b: ArrayLike<number>) => {
  expect(a.length).toBe(b.length);
  let m = 0;
  for (let i = 0; i < a.length; i++) m = Math.max(m, Math.abs(a[i] - b[i]));
  return m;
};

describe('loadCharacter', () => {
  it('gives the rig, the height and the clips of each skinned mesh', () => {
    expect(character.file).toBe(file);
    expect(character.meshes).toHaveLength(1);
    expect(character.clipNames).toEqual(['idle', 'walk', 'run']);
    expect(character.warnings).toEqual([]);
    expect(character.height).toBeGreaterThan(1.5);
    expect(character.height).toBeLessThan(2);
    const m = character.meshes[0];
    expect(m.name).toBe('Human');
    expect(m.jointCount).toBe(m.jointNames.length);
    expect(m.rigInput.parents.length).toBe(m.jointCount);
    expect(m.rigInput.inverseBindMatrices.length).toBe(16 * m.jointCount);
    expect(m.rigInput.positions.length).toBeGreaterThan(3 * 2400);
    expect(m.height).toBeCloseTo(character.height, 6); // world scale 1
    expect(Array.from(m.worldMatrix)).toEqual([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
    expect(m.morphTargets).toBeNull();
    expect(m.clips.map((c) => c.name)).toEqual(character.clipNames);
    expect(m.clip('walk')).toBe(m.clips[1]);
    expect(m.clip('nope')).toBeUndefined();
    for (const c of m.clips) expect(c.duration).toBeGreaterThan(0);
  });

  it("samples the same skin matrices as the report's sampling (three's AnimationMixer), wrapping outside the clip", async () => {
    const model = await loadGltfFile(file);
    const m = character.meshes[0];
    for (const [c, clip] of model.clips.entries()) {
      const frames = sampleClip(model.skinnedMeshes[0], clip, 7);
      frames.forEach((expected, f) => expect(maxDiff(m.clips[c].sample((clip.duration * f) / 7), expected)).toBeLessThan(1e-6));
    }
    const walk = m.clip('walk')!, run = m.clip('run')!;
    const t = 0.3 * walk.duration;
    const a = walk.sample(t);
    run.sample(0.7 * run.duration); // another clip in between: it leaves nothing behind
    expect(maxDiff(walk.sample(t), a)).toBe(0);
    expect(maxDiff(walk.sample(t + 2 * walk.duration), a)).toBeLessThan(1e-5);
    expect(maxDiff(walk.sample(t - walk.duration), a)).toBeLessThan(1e-5);
    const out = new Float32Array(16 * m.jointCount);
    expect(walk.sample(t, out)).toBe(out);
    expect(maxDiff(out, a)).toBe(0);
    expect(() => walk.sample(Number.NaN)).toThrow(GcsError);
    expect(() => walk.sample(0, new Float32Array(3))).toThrow(/16 per joint/);
    // Walking moves the legs: the matrices change along the clip.
    expect(maxDiff(walk.sample(0), walk.sample(0.5 * walk.duration))).toBeGreaterThan(0.01);
  });

  it('the rest pose of a file whose nodes sit in the bind pose is identity skin matrices; deforming gives the rig back', async () => {
    const m = character.meshes[0];
    m.clip('run')!.sample(0.4);
    const rest = m.restPose();
    const id = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
    for (let j = 0; j < m.jointCount; j++) expect(maxDiff(rest.subarray(16 * j, 16 * j + 16), id)).toBeLessThan(1e-5);
    const gcs = await initGcsSkin();
    const rig = gcs.createRig(m.rigInput);
    const d = rig.buildGcs({ sections: 6 });
    d.deform(rest);
    const src = d.sourceVertex!;
    let err = 0;
    for (let v = 0; v < d.vertexCount; v++)
      for (let k = 0; k < 3; k++) err = Math.max(err, Math.abs(d.positions[3 * v + k] - m.rigInput.positions[3 * src[v] + k]));
    expect(err).toBeLessThan(1e-5 * m.height);
    d.deform(m.clip('walk')!.sample(0.25));
    expect(d.positions.every(Number.isFinite)).toBe(true);
    expect(d.sectionCount).toBeGreaterThan(0);
    d.dispose();
    rig.dispose();
  });

  it('reads bytes and file: URLs as well as paths', async () => {
    const bytes = readFileSync(file);
    for (const source of [new Uint8Array(bytes), bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), pathToFileURL(file)]) {
      const c = await loadCharacter(source, { name: 'human' });
      expect(c.file).toBe(source instanceof URL ? file : 'human');
      expect(maxDiff(c.meshes[0].clips[2].sample(0.2), character.meshes[0].clips[2].sample(0.2))).toBe(0);
      expect(maxDiff(c.meshes[0].rigInput.positions, character.meshes[0].rigInput.positions)).toBe(0);
    }
  });

  it('morph targets and their animated influences', async () => {
    const io = new NodeIO();
    const doc: Document = await io.read(file);
    const node = doc.getRoot().listNodes().find((n) => n.getSkin())!;
    const prim = node.getMesh()!.listPrimitives()[0];
    const V = prim.getAttribute('POSITION')!.getCount();
    const delta = new Float32Array(3 * V);
    for (let v = 0; v < V; v++) delta[3 * v + 2] = 0.01 * (v % 3); // a bulge forward
    const buffer = doc.getRoot().listBuffers()[0];
    prim.addTarget(doc.createPrimitiveTarget('bulge').setAttribute('POSITION', doc.createAccessor().setType('VEC3').setArray(delta).setBuffer(buffer)));
    node.getMesh()!.setWeights([0.25]);
    const anim = doc.getRoot().listAnimations()[0];
    const sampler = doc.createAnimationSampler()
      .setInput(doc.createAccessor().setType('SCALAR').setArray(new Float32Array([0, 1])).setBuffer(buffer))
      .setOutput(doc.createAccessor().setType('SCALAR').setArray(new Float32Array([0, 1])).setBuffer(buffer))
      .setInterpolation('LINEAR');
    anim.addSampler(sampler).addChannel(doc.createAnimationChannel().setTargetNode(node).setTargetPath('weights').setSampler(sampler));
    const morphFile = join(dir, 'morph.glb');
    await io.write(morphFile, doc);

    const c = await loadCharacter(morphFile);
    const m = c.meshes[0];
    expect(m.morphTargets!.positions).toHaveLength(1);
    expect(maxDiff(m.morphTargets!.positions[0], delta)).toBe(0);
    const animated = m.clips[0]; // animation 0 drives the weight
    expect(Array.from(animated.morphInfluences(0.5))).toEqual([0.5]);
    // Another clip leaves the mesh's own default weight.
    expect(Array.from(m.clips[1].morphInfluences(0.5))).toEqual([0.25]);
    const gcs = await initGcsSkin();
    const rig = gcs.createRig(m.rigInput);
    const d = rig.buildLbs();
    d.setMorphTargets(m.morphTargets!.positions, m.morphTargets!.normals);
    d.setMorphInfluences(animated.morphInfluences(0.5));
    d.deform(m.restPose());
    const before = d.positions.slice();
    d.setMorphInfluences([0]);
    d.deform(m.restPose());
    let moved = 0;
    for (let v = 0; v < V; v++) moved = Math.max(moved, Math.abs(before[3 * v + 2] - d.positions[3 * v + 2] - 0.5 * delta[3 * v + 2]));
    expect(moved).toBeLessThan(1e-5);
    d.dispose();
    rig.dispose();
  });

  it('a file with no skinned mesh, and a bad file: a GltfError with its code', async () => {
    const doc = new Document();
    const buffer = doc.createBuffer();
    const prim = doc.createPrimitive().setAttribute('POSITION', doc.createAccessor().setType('VEC3').setArray(new Float32Array(9)).setBuffer(buffer));
    doc.createScene().addChild(doc.createNode('Box').setMesh(doc.createMesh('Box').addPrimitive(prim)));
    const plain = join(dir, 'plain.glb');
    writeFileSync(plain, await new NodeIO().writeBinary(doc));
    const e = await loadCharacter(plain).then(() => null, (x: unknown) => x);
    expect(e).toBeInstanceOf(GltfError);
    expect((e as GltfError).code).toBe('NO_SKINNED_MESH');
    expect((e as GltfError).message).toBe(`${plain} has no skinned mesh (no skin, joints and weights): nothing to deform`);
    const bad = await loadCharacter(new Uint8Array([1, 2, 3, 4, 5]), { name: 'junk.glb' }).then(() => null, (x: unknown) => x);
    expect((bad as GltfError).code).toBe('NOT_GLTF');
    expect((bad as GltfError).message).toMatch(/^junk\.glb is not a glTF file/);
  });
});
