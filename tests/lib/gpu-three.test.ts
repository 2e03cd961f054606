// The GPU backend of the three.js adapter, in node (no WebGL here: what the shader computes is
// checked in headless Chromium, tests/browser/gpu.test.ts): the geometry is the bind pose plus the
// static section data, uploaded once; update() computes only the per-frame texture (the joint
// poses on the default 'joints' path, the section transforms on the 'sections' path); materials are
// patched clones (shadows too); unsupported methods and materials fall back to the CPU and say
// why; raycasts hit the deformed skin; rebuilds switch backends; dispose frees.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import * as SkeletonUtils from 'three/addons/utils/SkeletonUtils.js';
import { GcsError, initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { GcsCharacter, SkinDeformer } from '../../web/lib/three.js';
import { gpuMaterialSupport, patchVertexShader } from '../../web/lib/gpu.js';
import { createHuman, type Human } from '../../web/lib/human/index.js';
import { bakeClip, GcsCrowd } from '../../web/lib/crowd.js';
import { JointPoses, SectionTransforms } from '../../web/lib/index.js';

let gcs: GcsSkin;
let human: Human;
beforeAll(async () => {
  gcs = await initGcsSkin();
  human = createHuman();
});

/** The human in a group, walking at time t. */
function walking(t: number) {
  const mesh = SkeletonUtils.clone(human.mesh) as THREE.SkinnedMesh; // its own bones
  const group = new THREE.Group();
  group.add(mesh);
  const mixer = new THREE.AnimationMixer(group);
  mixer.clipAction(human.clips.find((c) => c.name === 'walk')!).play();
  mixer.setTime(t);
  group.updateMatrixWorld(true);
  return { group, mesh, mixer };
}

describe('GPU backend (three.js adapter)', () => {
  test('patches three.js built-in shaders, and refuses a shader without skinning chunks', () => {
    for (const name of ['standard', 'physical', 'lambert', 'phong', 'basic', 'toon', 'matcap', 'normal', 'depth', 'distance'] as const) {
      const src = THREE.ShaderLib[name].vertexShader;
      for (const smooth of [false, true]) {
        for (const path of ['sections', 'joints'] as const) {
          const out = patchVertexShader(src, smooth, path);
          expect(out).not.toContain('#include <skinning_vertex>');
          expect(out).not.toContain('#include <skinbase_vertex>');
          // The joint-level vertex stage reads node transforms (the node pass blends them once per frame).
          expect(out).toContain(path === 'joints' ? 'gcsNode(' : 'gcsRows');
          expect(out).not.toContain(path === 'joints' ? 'gcsRows' : 'gcsNode(');
          expect(out).not.toContain('gcsSectionBlend');
          // Where skinbase_vertex is compiled out (MeshBasicMaterial without an env map), skinning_vertex reads the transform.
          expect(out).toMatch(/#ifndef GCS_BASE[\s\S]*#endif[\s\S]*transformed = /);
          expect(out.startsWith('#define GCS_SMOOTH')).toBe(smooth);
        }
      }
    }
    expect(() => patchVertexShader('void main() { gl_Position = vec4(0.0); }', false)).toThrow(GcsError);
    expect(() => patchVertexShader(THREE.ShaderLib.standard.vertexShader, false, 'vertices' as 'joints')).toThrow(GcsError);
    expect(gpuMaterialSupport(new THREE.MeshStandardMaterial())).toBeNull();
    expect(gpuMaterialSupport(new THREE.ShaderMaterial())).toMatch(/custom shader/);
  });

  test('the bind pose and section data are uploaded once; a frame moves only the joint poses (default path)', () => {
    const { mesh, group, mixer } = walking(0.3);
    const character = new GcsCharacter(gcs, group, { backend: 'gpu' });
    expect(character.backend).toBe('gpu');
    const skin = character.skins[0];
    expect(skin.gpuPath).toBe('joints');
    expect(skin.backendNote).toBe('');
    const g = skin.mesh.geometry;
    const position = g.getAttribute('position') as THREE.BufferAttribute;
    expect(position.usage).toBe(THREE.StaticDrawUsage);
    expect(position.array.buffer).not.toBe(gcs.memory.buffer);
    expect(g.getAttribute('gcsBlend')).toBeDefined(); // the default blends two sections per vertex
    // Bind-pose positions: the rig's own, in output order.
    const src = skin.deformer.sourceVertex!;
    const rest = mesh.geometry.getAttribute('position');
    for (let o = 0; o < src.length; o += 997) expect(position.getY(o)).toBe(rest.getY(src[o]));
    // The material is a patched clone of the source's; shadows have patched depth materials.
    expect(skin.mesh.material).not.toBe(mesh.material);
    expect((skin.mesh.material as THREE.Material).type).toBe((mesh.material as THREE.Material).type);
    for (const m of [skin.mesh.material as THREE.Material, skin.mesh.customDepthMaterial!, skin.mesh.customDistanceMaterial!])
      expect(m.customProgramCacheKey()).toContain('gcs-smooth-joints');
    const sections = skin.gpuSections!;
    const J = skin.deformer.jointCount;
    expect(sections.path).toBe('joints');
    // A walk is rigid with unit scale: the compact joint poses, 24 bytes per joint in one row (19 joints: 29 texels, 464 bytes), whatever the section count.
    expect(sections.uniforms.gcsCompactPoses!.value).toBe(1);
    expect(skin.bytesPerFrame).toBe(Math.ceil(J * 1.5) * 16);
    expect(sections.uniforms.gcsCompactJoints!.value).toBe(sections.compactTexture);
    expect(sections.uniforms.gcsJoints!.value).toBe(sections.texture);
    expect(sections.uniforms.gcsTable!.value).toBe(sections.table);
    const table = sections.table!.image.data as Float32Array;
    // Per section: its joints, its weights (gcs_gcs_section_influences), its centre of rotation (gcs_gcs_section_centres).
    const gcsDeformer = skin.deformer as import('../../web/lib/index.js').GcsDeformer;
    const influences = gcsDeformer.sectionInfluences()!, centres = gcsDeformer.sectionCentres()!;
    for (let s = 0; s < gcsDeformer.sectionCount; s++) {
      expect(Array.from(table.subarray(12 * s, 12 * s + 8))).toEqual(Array.from(influences.subarray(8 * s, 8 * s + 8)));
      expect(Array.from(table.subarray(12 * s + 8, 12 * s + 12))).toEqual(Array.from(centres.subarray(4 * s, 4 * s + 4)));
    }
    const positionVersion = position.version, textureVersion = sections.texture.version, tableVersion = sections.table!.version;
    const compactVersion = sections.compactTexture!.version;
    mixer.setTime(0.6);
    character.update();
    expect(position.version).toBe(positionVersion);
    expect(sections.compactTexture!.version).toBe(compactVersion + 1); // this frame's (compact) joint poses go up
    expect(sections.texture.version).toBe(textureVersion); // the full format's texture is not read this frame: not uploaded
    expect(sections.table!.version).toBe(tableVersion); // static
    // The texture views wasm memory (no copy) and holds this frame's joint poses: per joint 3 quaternion components, then t_j (S_j's translation).
    const data = sections.compactTexture!.image.data as Float32Array;
    expect(data.buffer).toBe(gcs.memory.buffer);
    const S = (skin as unknown as { skin: Float32Array }).skin; // this frame's S_j
    for (let j = 0; j < J; j++) for (let r = 0; r < 3; r++) expect(data[6 * j + 3 + r]).toBe(S[16 * j + 12 + r]);
    character.dispose();
  });

  test('the section-level path on request and for the paper criteria: a frame moves only the section texture', () => {
    const { group, mixer } = walking(0.3);
    const character = new GcsCharacter(gcs, group, { backend: 'gpu', gpuPath: 'sections' });
    const skin = character.skins[0];
    expect(skin.gpuPath).toBe('sections');
    expect((skin.mesh.material as THREE.Material).customProgramCacheKey()).toContain('gcs-smooth-sections');
    const sections = skin.gpuSections!;
    expect(sections.table).toBeNull();
    const S = skin.deformer.sectionCount;
    expect(skin.bytesPerFrame).toBe(sections.transforms.width * sections.transforms.height * 16);
    expect(skin.bytesPerFrame).toBeGreaterThanOrEqual(S * 48);
    expect(skin.bytesPerFrame).toBeLessThan(S * 48 + 2048 * 16);
    const textureVersion = sections.texture.version;
    mixer.setTime(0.6);
    character.update();
    expect(sections.texture.version).toBe(textureVersion + 1);
    const data = sections.texture.image.data as Float32Array;
    expect(data.buffer).toBe(gcs.memory.buffer);
    skin.deformer.deform((skin as unknown as { skin: Float32Array }).skin); // this frame's S_j, on the CPU
    const m = (skin.deformer as import('../../web/lib/index.js').GcsDeformer).sectionMatrices();
    for (let s = 0; s < S; s += 7) for (let r = 0; r < 3; r++) for (let c = 0; c < 4; c++) expect(data[12 * s + 4 * r + c]).toBe(m[16 * s + 4 * c + r]);
    // Back to 'auto': the joint-level path; the paper's criteria have only the section-level one.
    character.rebuild('gcs', { gpuPath: 'auto' });
    expect(skin.gpuPath).toBe('joints');
    character.rebuild('gcs', { gcs: { criterion: 'y' } });
    expect(skin.gpuPath).toBe('sections');
    expect(() => character.rebuild('gcs', { gpuPath: 'joints' })).toThrow(GcsError); // 'y' has no joint-level path
    expect(skin.gpuPath).toBe('sections'); // unchanged
    expect(() => character.rebuild('gcs', { gpuPath: 'vertices' as 'joints' })).toThrow(GcsError);
    character.dispose();
  });

  test('raycasts hit the deformed skin as on the CPU backend', () => {
    const hits: Record<string, THREE.Vector3> = {};
    for (const backend of ['cpu', 'gpu'] as const) {
      const { group } = walking(0.45);
      const character = new GcsCharacter(gcs, group, { backend, gcs: { smooth: true } });
      expect(character.backend).toBe(backend);
      const ray = new THREE.Raycaster(new THREE.Vector3(3, 1.0, 0.02), new THREE.Vector3(-1, 0, 0));
      const hit = ray.intersectObject(group, true)[0];
      expect(hit).toBeDefined();
      hits[backend] = hit.point;
      character.dispose();
    }
    expect(hits.gpu.distanceTo(hits.cpu)).toBeLessThan(1e-5);
  });

  test('falls back to the CPU with a reason, and rebuilds switch backends', () => {
    const { group, mesh } = walking(0.2);
    // LBS and DQS run on the GPU too (each vertex blends its own joints); the classic model resamples the mesh: CPU only.
    const character = new GcsCharacter(gcs, group, { backend: 'gpu', method: 'classic' });
    const skin = character.skins[0];
    expect(skin.backend).toBe('cpu');
    expect(skin.backendNote).toMatch(/'classic' runs on the CPU/);
    for (const method of ['lbs', 'dqs'] as const) {
      character.rebuild(method, { backend: 'gpu' });
      expect(skin.backend).toBe('gpu');
      expect(skin.backendNote).toBe('');
      expect(skin.mesh.geometry.getAttribute('gcsInfluences0')).toBeDefined();
      expect(skin.mesh.geometry.getAttribute('gcsBlend')).toBeUndefined();
      expect((skin.mesh.material as THREE.Material).customProgramCacheKey()).toContain(`gcs-${method}-4`);
      // The joint poses only: LBS's in the full format (64 bytes per joint), DQS's compact (24) on this rigid frame.
      expect(skin.bytesPerFrame).toBe(method === 'lbs' ? skin.deformer.jointCount * 64 : Math.ceil(skin.deformer.jointCount * 1.5) * 16);
    }
    character.rebuild('gcs', { gcs: { smooth: true } });
    expect(skin.backend).toBe('gpu');
    expect(skin.mesh.geometry.getAttribute('gcsBlend')).toBeDefined();
    expect((skin.mesh.material as THREE.Material).customProgramCacheKey()).toContain('gcs-smooth');
    character.rebuild('gcs', { backend: 'cpu' });
    expect(skin.backend).toBe('cpu');
    expect(skin.mesh.material).toBe(mesh.material);
    expect((skin.mesh.geometry.getAttribute('position') as THREE.BufferAttribute).array.buffer).toBe(gcs.memory.buffer);
    expect(() => character.rebuild('gcs', { backend: 'webgpu' as 'gpu' })).toThrow(GcsError);
    expect(skin.backend).toBe('cpu');
    character.dispose();
    const custom = walking(0.2);
    custom.mesh.material = new THREE.ShaderMaterial();
    const alone = new SkinDeformer(gcs, custom.mesh, { backend: 'gpu' });
    expect(alone.backend).toBe('cpu');
    expect(alone.backendNote).toMatch(/custom shader/);
    alone.dispose();
  });

  test('morph targets stay on the mesh for three.js to apply in the shader', () => {
    const { mesh, group } = walking(0.1);
    const g = mesh.geometry.clone();
    const n = g.getAttribute('position').count;
    const delta = new Float32Array(3 * n);
    for (let i = 0; i < n; i++) delta[3 * i + 1] = 0.01;
    g.morphAttributes.position = [new THREE.BufferAttribute(delta, 3)];
    g.morphTargetsRelative = true;
    mesh.geometry = g;
    mesh.updateMorphTargets();
    mesh.morphTargetInfluences![0] = 0.5;
    const character = new GcsCharacter(gcs, group, { backend: 'gpu' });
    const skin = character.skins[0];
    expect(skin.backend).toBe('gpu');
    const morph = skin.mesh.geometry.morphAttributes.position![0];
    const src = skin.deformer.sourceVertex!;
    expect(morph.count).toBe(src.length);
    expect(skin.mesh.morphTargetInfluences).toBe(mesh.morphTargetInfluences);
    character.dispose();
  });

  for (const gpuPath of ['joints', 'sections'] as const) {
    test(`a crowd (${gpuPath} path): one instanced mesh, every instance its own pose, one wasm call and one texture per frame`, () => {
      const { mesh } = walking(0);
      const N = 5;
      const crowd = new GcsCrowd(gcs, mesh, N, { gcs: { smooth: true }, gpuPath: gpuPath === 'joints' ? undefined : gpuPath });
      expect(crowd.sections.path).toBe(gpuPath);
      expect(crowd.mesh).toBeInstanceOf(THREE.InstancedMesh);
      expect(crowd.mesh.count).toBe(N);
      expect((crowd.mesh.material as THREE.Material).customProgramCacheKey()).toContain(`gcs-smooth-${gpuPath}`);
      const S = crowd.deformer.sectionCount, J = crowd.jointCount;
      const perInstance = gpuPath === 'joints' ? J * 16 : S * 12; // floats
      expect(crowd.sections.transforms.texelsPerInstance * 4).toBe(perInstance);
      // The joints path uploads the compact joint poses (a rigid frame: 6 floats per joint), the sections path its section texture.
      const image = (gpuPath === 'joints' ? crowd.sections.compactTexture! : crowd.sections.texture).image as { width: number; height: number };
      expect(crowd.bytesPerFrame).toBe(image.width * image.height * 16);
      expect(crowd.bytesPerFrame).toBeLessThan(N * (gpuPath === 'joints' ? J * 6 : perInstance) * 4 + 2048 * 16);
      const walk = bakeClip(mesh, human.clips.find((c) => c.name === 'walk')!, 30);
      expect(walk.frames).toBe(Math.round(walk.duration * 30));
      const times = [0, 0.21, 0.5, -0.3, 7.9];
      times.forEach((t, i) => crowd.setBakedPose(i, walk, t));
      const uploaded = gpuPath === 'joints' ? crowd.sections.compactTexture! : crowd.sections.texture, version = uploaded.version;
      crowd.update();
      expect(uploaded.version).toBe(version + 1);
      // Instance i's texels are those of its own pose (the baked frame at its time); the joints path's are compact (6 floats per joint).
      const one = gpuPath === 'joints' ? new JointPoses(crowd.deformer, 1, 2048, true) : new SectionTransforms(crowd.deformer, 1);
      const all = crowd.sections.transforms.texels, floats = gpuPath === 'joints' ? J * 6 : perInstance;
      times.forEach((t, i) => {
        let f = Math.floor(t * walk.fps) % walk.frames;
        if (f < 0) f += walk.frames;
        one.skins.set(walk.data.subarray(f * J * 16, (f + 1) * J * 16));
        one.compute();
        expect(Array.from(all.subarray(i * floats, (i + 1) * floats))).toEqual(Array.from(one.texels.subarray(0, floats)));
      });
      expect(Array.from(all.subarray(0, floats))).not.toEqual(Array.from(all.subarray(floats, 2 * floats)));
      one.dispose();
      expect(() => crowd.offsetOf(N)).toThrow(GcsError);
      expect(() => new GcsCrowd(gcs, mesh, 0)).toThrow(GcsError);
      crowd.dispose();
      expect(() => crowd.update()).toThrow(GcsError);
    });
  }

  test('a crowd of a paper criterion runs the section-level path; asking it for joints is a GcsError', () => {
    const { mesh } = walking(0);
    const crowd = new GcsCrowd(gcs, mesh, 2, { gcs: { criterion: 'axial' } });
    expect(crowd.sections.path).toBe('sections');
    crowd.dispose();
    expect(() => new GcsCrowd(gcs, mesh, 2, { gcs: { criterion: 'y' }, gpuPath: 'joints' })).toThrow(GcsError);
  });
});
