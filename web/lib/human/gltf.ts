// GLB export of a skinned character and its clips, written with @gltf-transform/core: an optional
// peer dependency of gcs-skin (installed with @gcs-skin/cli), loaded on the first call.
import type * as THREE from 'three';
import { GcsError } from '../errors.js';

// A specifier in a variable: bundlers leave it alone, so an app that imports gcs-skin/human
// builds without @gltf-transform/core installed.
const GLTF_TRANSFORM = '@gltf-transform/core';

async function gltfTransform(): Promise<typeof import('@gltf-transform/core')> {
  try {
    return await import(/* @vite-ignore */ GLTF_TRANSFORM);
  } catch (e) {
    throw new GcsError('MISSING_PACKAGE', `humanToGlb needs the package ${GLTF_TRANSFORM} (npm install ${GLTF_TRANSFORM}, or use @gcs-skin/cli): ${(e as Error).message}`);
  }
}

interface HumanLike {
  mesh: THREE.SkinnedMesh;
  clips: THREE.AnimationClip[];
}

/** Write the character (mesh, skin, skeleton, clips) as a binary glTF. */
export async function humanToGlb(human: HumanLike): Promise<Uint8Array> {
  const mesh = (human as HumanLike | null)?.mesh, clips = (human as HumanLike | null)?.clips;
  const skinned = mesh?.isSkinnedMesh && mesh.skeleton && mesh.geometry?.isBufferGeometry
    && ['position', 'normal', 'skinIndex', 'skinWeight'].every((name) => (mesh.geometry.getAttribute(name) as { isBufferAttribute?: boolean } | undefined)?.isBufferAttribute);
  if (!skinned || !Array.isArray(clips) || !clips.every((c) => Array.isArray((c as THREE.AnimationClip | null)?.tracks)))
    throw new GcsError('INVALID_ARGUMENT', 'humanToGlb takes { mesh, clips }: a SkinnedMesh with position, normal, skinIndex and skinWeight, and an array of AnimationClips (what createHuman returns)');
  const { Document, WebIO } = await gltfTransform();
  const doc = new Document();
  doc.createScene('Scene');
  const buffer = doc.createBuffer();
  const geo = mesh.geometry;
  const attr = (name: string) => geo.getAttribute(name) as THREE.BufferAttribute;
  const acc = (type: 'SCALAR' | 'VEC2' | 'VEC3' | 'VEC4' | 'MAT4', array: Float32Array<ArrayBuffer> | Uint16Array<ArrayBuffer> | Uint32Array<ArrayBuffer>) =>
    doc.createAccessor().setType(type).setArray(array).setBuffer(buffer);

  const prim = doc.createPrimitive()
    .setAttribute('POSITION', acc('VEC3', Float32Array.from(attr('position').array as ArrayLike<number>)))
    .setAttribute('NORMAL', acc('VEC3', Float32Array.from(attr('normal').array as ArrayLike<number>)))
    .setAttribute('JOINTS_0', acc('VEC4', Uint16Array.from(attr('skinIndex').array as ArrayLike<number>)))
    .setAttribute('WEIGHTS_0', acc('VEC4', Float32Array.from(attr('skinWeight').array as ArrayLike<number>)));
  if (geo.getAttribute('uv')) prim.setAttribute('TEXCOORD_0', acc('VEC2', Float32Array.from(attr('uv').array as ArrayLike<number>)));
  const index = geo.getIndex()!;
  const nv = attr('position').count;
  prim.setIndices(acc('SCALAR', nv > 65535 ? Uint32Array.from(index.array) : Uint16Array.from(index.array)));
  const m = mesh.material as THREE.MeshStandardMaterial;
  const c = m.color ?? { r: 0.8, g: 0.6, b: 0.5 };
  const srgb = (v: number) => v; // three's Color is linear; glTF baseColorFactor is linear too
  prim.setMaterial(doc.createMaterial('Skin').setBaseColorFactor([srgb(c.r), srgb(c.g), srgb(c.b), 1]).setRoughnessFactor(m.roughness ?? 0.65).setMetallicFactor(0));
  const gmesh = doc.createMesh(mesh.name || 'Human').addPrimitive(prim);

  const bones = mesh.skeleton.bones;
  const nodes = new Map<THREE.Object3D, ReturnType<typeof doc.createNode>>();
  for (const b of bones) {
    nodes.set(b, doc.createNode(b.name)
      .setTranslation([b.position.x, b.position.y, b.position.z])
      .setRotation([b.quaternion.x, b.quaternion.y, b.quaternion.z, b.quaternion.w])
      .setScale([b.scale.x, b.scale.y, b.scale.z]));
  }
  const root = doc.createNode('HumanRoot');
  for (const b of bones) {
    const parent = b.parent && nodes.get(b.parent);
    if (parent) parent.addChild(nodes.get(b)!);
    else root.addChild(nodes.get(b)!);
  }
  const ibm = new Float32Array(16 * bones.length);
  mesh.skeleton.boneInverses.forEach((mat, i) => ibm.set(mat.elements, 16 * i));
  const skin = doc.createSkin('Skin')
    .setInverseBindMatrices(acc('MAT4', ibm))
    .setSkeleton(nodes.get(bones[0])!);
  for (const b of bones) skin.addJoint(nodes.get(b)!);
  const meshNode = doc.createNode(mesh.name || 'Human').setMesh(gmesh).setSkin(skin);
  root.addChild(meshNode);
  doc.getRoot().listScenes()[0].addChild(root);

  const byName = new Map(bones.map((b) => [b.name, nodes.get(b)!]));
  for (const clip of clips) {
    const anim = doc.createAnimation(clip.name);
    for (const track of clip.tracks) {
      const dot = track.name.lastIndexOf('.');
      const target = byName.get(track.name.slice(0, dot));
      const prop = track.name.slice(dot + 1);
      const path = prop === 'quaternion' ? 'rotation' : prop === 'position' ? 'translation' : prop === 'scale' ? 'scale' : null;
      if (!target || !path) continue;
      const sampler = doc.createAnimationSampler()
        .setInput(acc('SCALAR', Float32Array.from(track.times)))
        .setOutput(acc(path === 'rotation' ? 'VEC4' : 'VEC3', Float32Array.from(track.values)))
        .setInterpolation('LINEAR');
      anim.addSampler(sampler).addChannel(doc.createAnimationChannel().setTargetNode(target).setTargetPath(path).setSampler(sampler));
    }
  }
  return new WebIO().writeBinary(doc);
}
