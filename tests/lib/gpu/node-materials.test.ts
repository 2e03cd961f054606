// gcs-skin/webgpu's material side, in node (what the TSL computes is checked in headless Chromium,
// tests/browser/webgpu.test.ts): built-in materials become their node equivalents with every map,
// colour and flag kept; node materials are cloned; GCS is the positionNode and the shadow position;
// what cannot take GCS is named; a GPU-backend character builds its node materials and its
// per-frame texture as the WebGL one does.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three/webgpu';
import { initGcsSkin, type GcsSkin } from '../../../web/lib/index.js';
import { nodeMaterialSupport, toNodeMaterial } from '../../../web/lib/gpu/node-materials.js';
import { GcsCharacter, GcsCrowd } from '../../../web/lib/webgpu.js';
import { GcsCharacter as WebGLCharacter } from '../../../web/lib/three.js';
import { createHuman, type Human } from '../../../web/lib/human/index.js';
import { drawWith, humanWithTangents, webgpuRenderer } from '../../helpers/velocity-pass.js';

let gcs: GcsSkin;
let human: Human;
beforeAll(async () => {
  gcs = await initGcsSkin();
  human = createHuman({ vertices: 3000 });
});

describe('toNodeMaterial', () => {
  test('a MeshStandardMaterial becomes a MeshStandardNodeMaterial with every map, colour and flag', () => {
    const map = new THREE.Texture(), normalMap = new THREE.Texture(), roughnessMap = new THREE.Texture(), emissiveMap = new THREE.Texture();
    const source = new THREE.MeshStandardMaterial({
      name: 'skin', color: 0x886644, map, normalMap, normalScale: new THREE.Vector2(0.5, -0.5), roughness: 0.3, metalness: 0.2, roughnessMap,
      emissive: 0x112233, emissiveMap, emissiveIntensity: 2, transparent: true, opacity: 0.7, alphaTest: 0.25, side: THREE.DoubleSide,
      vertexColors: true, flatShading: true, envMapIntensity: 0.4, depthWrite: false,
    });
    const node = toNodeMaterial(source) as THREE.MeshStandardNodeMaterial;
    expect(node.isNodeMaterial).toBe(true);
    expect(node.type).toBe('MeshStandardNodeMaterial');
    expect(node.uuid).not.toBe(source.uuid);
    for (const key of ['name', 'map', 'normalMap', 'roughness', 'metalness', 'roughnessMap', 'emissiveMap', 'emissiveIntensity', 'transparent',
      'opacity', 'alphaTest', 'side', 'vertexColors', 'flatShading', 'envMapIntensity', 'depthWrite'] as const)
      expect(node[key], key).toBe(source[key]);
    expect(node.color.getHex()).toBe(0x886644);
    expect(node.emissive.getHex()).toBe(0x112233);
    expect(node.normalScale.toArray()).toEqual([0.5, -0.5]);
  });

  test('each built-in mesh material has its node equivalent; node materials are cloned', () => {
    const pairs: [THREE.Material, string][] = [
      [new THREE.MeshBasicMaterial(), 'MeshBasicNodeMaterial'], [new THREE.MeshLambertMaterial(), 'MeshLambertNodeMaterial'],
      [new THREE.MeshPhongMaterial(), 'MeshPhongNodeMaterial'], [new THREE.MeshPhysicalMaterial(), 'MeshPhysicalNodeMaterial'],
      [new THREE.MeshToonMaterial(), 'MeshToonNodeMaterial'], [new THREE.MeshNormalMaterial(), 'MeshNormalNodeMaterial'],
      [new THREE.MeshMatcapMaterial(), 'MeshMatcapNodeMaterial'],
    ];
    for (const [m, type] of pairs) {
      expect(nodeMaterialSupport(m)).toBeNull();
      expect(toNodeMaterial(m).type).toBe(type);
    }
    const node = new THREE.MeshStandardNodeMaterial({ color: 0x123456 });
    const clone = toNodeMaterial(node) as THREE.MeshStandardNodeMaterial;
    expect(clone).not.toBe(node);
    expect(clone.color.getHex()).toBe(0x123456);
  });

  test('what cannot take GCS is named: custom shaders, a node material with its own position, a type with no node equivalent', () => {
    expect(nodeMaterialSupport(new THREE.ShaderMaterial())).toMatch(/custom shader/);
    const own = new THREE.MeshStandardNodeMaterial();
    own.positionNode = THREE.TSL.positionLocal;
    expect(nodeMaterialSupport(own)).toMatch(/its own positionNode/);
    expect(nodeMaterialSupport(new THREE.MeshDepthMaterial())).toMatch(/no node material equivalent/);
  });
});

describe('GcsCharacter and GcsCrowd of gcs-skin/webgpu', () => {
  test("backend 'gpu': node materials with GCS as position and shadow position, the same texture and upload as gcs-skin/three", () => {
    const group = new THREE.Group();
    group.add(human.mesh);
    const character = new GcsCharacter(gcs, group, { backend: 'gpu' });
    const webgl = new WebGLCharacter(gcs, group, { backend: 'gpu' });
    try {
      const skin = character.skins[0], other = webgl.skins[0];
      expect(skin.backend).toBe('gpu');
      expect(skin.gpuPath).toBe('joints');
      const material = skin.mesh.material as THREE.MeshStandardNodeMaterial;
      expect(material.isNodeMaterial).toBe(true);
      expect(material.positionNode).not.toBeNull();
      expect(material.castShadowPositionNode).toBe(material.positionNode);
      expect(skin.mesh.customDepthMaterial).toBeUndefined(); // node materials cast their shadow through castShadowPositionNode
      expect(skin.bytesPerFrame).toBe(other.bytesPerFrame);
      expect(skin.mesh.geometry.getAttribute('gcsBlend').count).toBe(other.mesh.geometry.getAttribute('gcsBlend').count);
    } finally {
      webgl.dispose();
      character.dispose();
      group.remove(human.mesh);
    }
  });

  test('a ShaderMaterial skin runs on the CPU backend with a note', () => {
    const mesh = human.mesh.clone() as THREE.SkinnedMesh;
    mesh.material = new THREE.ShaderMaterial();
    const warn = console.warn;
    const warnings: string[] = [];
    console.warn = (m: string) => warnings.push(m);
    try {
      const character = new GcsCharacter(gcs, mesh, { backend: 'gpu' });
      expect(character.backend).toBe('cpu');
      expect(character.skins[0].backendNote).toMatch(/custom shader/);
      expect(warnings.filter((w) => w.startsWith('gcs-skin:'))).toHaveLength(1);
      character.dispose();
    } finally {
      console.warn = warn;
    }
  });

  test('a crowd: node materials placing each instance after GCS, one texture for every instance', () => {
    const crowd = new GcsCrowd(gcs, human.mesh, 5);
    try {
      const material = crowd.mesh.material as THREE.NodeMaterial;
      expect(material.isNodeMaterial).toBe(true);
      expect(material.positionNode).not.toBeNull();
      expect(crowd.mesh.count).toBe(5);
      expect(crowd.bytesPerFrame).toBeGreaterThanOrEqual(5 * crowd.jointCount * 24); // the compact joint poses (bind pose: rigid)
    } finally {
      crowd.dispose();
    }
  });
});

describe('the CPU backend of gcs-skin/webgpu: tangents and velocity from the core pass', () => {
  test('tangents are the deformer\'s own output (no copy); a velocity pass gives the mesh previous positions, swapped each update', () => {
    const { mesh, group } = humanWithTangents(human);
    const character = new GcsCharacter(gcs, group);
    try {
      const skin = character.skins[0];
      const g = () => skin.mesh.geometry;
      expect(skin.deformsTangents).toBe(true);
      expect((g().getAttribute('tangent') as THREE.BufferAttribute).array).toBe(skin.deformer.tangents);
      // Drawn without velocity: nothing changes.
      drawWith(skin.mesh, webgpuRenderer(false));
      character.update();
      expect(skin.mesh.material).toBe(mesh.material);
      expect(g().getAttribute('gcsPreviousPosition')).toBeUndefined();
      const bytes = skin.bytesPerFrame;
      // Drawn in a velocity pass: from the next update, previous positions and a node material that reads them.
      drawWith(skin.mesh, webgpuRenderer(true));
      const before = skin.deformer.positions.slice();
      mesh.skeleton.bones[3].rotation.x += 0.5; // the human's own skeleton: turned back below
      character.update();
      const material = skin.mesh.material as THREE.NodeMaterial;
      expect(material.isNodeMaterial).toBe(true);
      expect(material.positionNode).not.toBeNull();
      const previous = g().getAttribute('gcsPreviousPosition') as THREE.BufferAttribute;
      expect(previous.array).toBe(skin.deformer.previousPositions);
      expect(Array.from(previous.array)).toEqual(Array.from(before));
      expect((g().getAttribute('position') as THREE.BufferAttribute).array).toBe(skin.deformer.positions);
      expect(skin.bytesPerFrame).toBe(bytes + before.byteLength);
      const current = skin.deformer.positions;
      character.update(); // the same pose: previous = current, the arrays swapped, not copied
      expect(previous.array).toBe(current);
      expect(Array.from(previous.array)).toEqual(Array.from(skin.deformer.positions));
      // A rebuild keeps velocity on.
      character.rebuild('lbs');
      character.update();
      expect((skin.mesh.material as THREE.NodeMaterial).isNodeMaterial).toBe(true);
      expect((g().getAttribute('gcsPreviousPosition') as THREE.BufferAttribute).array).toBe(skin.deformer.previousPositions);
    } finally {
      mesh.skeleton.bones[3].rotation.x -= 0.5;
      character.dispose();
    }
  });
});
