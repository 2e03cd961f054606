// Checks of a glTF's meshes (primitives, attributes, Draco references, morph targets) and of the
// materials, textures and images they refer to (loaded then dropped, but a bad index would crash the loader).
import { n, plural } from './error.js';
import type { GltfJson } from './json.js';
import { LIMITS } from './limits.js';
import { isIndex, isObject, type Fail, type Ref, type ValidationContext } from './validation-context.js';

/** Meshes: primitives, attributes of one count, Draco references, morph targets. */
export function checkMeshes(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { accessors, bufferViews, meshes, materials, named } = ctx;
  meshes.forEach((m, mi) => {
    const mesh = named('mesh', mi, m);
    if (!Array.isArray(m.primitives) || !m.primitives.length) fail('BAD_STRUCTURE', `/meshes/${mi}/primitives`, `${mesh} has no primitives`);
    if (m.primitives.length > LIMITS.items)
      fail('TOO_LARGE', `/meshes/${mi}/primitives`, `${mesh} has ${n(m.primitives.length)} primitives, more than the ${n(LIMITS.items)} this loader reads`);
    m.primitives.forEach((p: GltfJson, pi: number) => {
      const where = `/meshes/${mi}/primitives/${pi}`;
      const prim = `${mesh} primitive ${pi}`;
      if (!isObject(p) || !isObject(p.attributes)) fail('BAD_STRUCTURE', where, `${prim} has no attributes`);
      let first: [string, number] | undefined;
      for (const [k, a] of Object.entries(p.attributes)) {
        ref(a, accessors, 'accessor', `${where}/attributes/${k}`, `${prim}'s ${k}`, true);
        const count = accessors[a as number].count;
        if (!first) {
          first = [k, count];
          if (count > LIMITS.vertices)
            fail('TOO_LARGE', `${where}/attributes/${k}`, `${prim} has ${plural(count, 'vertex', 'vertices')}, more than the ${n(LIMITS.vertices)} gcs-skin takes`);
        }
        else if (count !== first[1])
          fail('BAD_STRUCTURE', `${where}/attributes/${k}`,
            `${prim}'s ${k} (accessor ${a}) has ${plural(count, 'element')} but its ${first[0]} has ${n(first[1])}: every attribute has one per vertex`);
      }
      ref(p.indices, accessors, 'accessor', `${where}/indices`, `${prim}'s indices`);
      const draco = p.extensions?.KHR_draco_mesh_compression;
      if (draco !== undefined) {
        const dw = `${where}/extensions/KHR_draco_mesh_compression`;
        if (!isObject(draco) || !isObject(draco.attributes)) fail('BAD_STRUCTURE', dw, `the KHR_draco_mesh_compression of ${prim} has no attributes`);
        ref(draco.bufferView, bufferViews, 'buffer view', `${dw}/bufferView`, `the Draco data of ${prim}`, true);
        for (const [k, id] of Object.entries(draco.attributes)) {
          if (!isIndex(id)) fail('BAD_STRUCTURE', `${dw}/attributes/${k}`, `the Draco attribute id of ${prim}'s ${k} is ${JSON.stringify(id)}, not a whole number`);
          if (p.attributes[k] === undefined)
            fail('BAD_STRUCTURE', `${dw}/attributes/${k}`, `${prim} has Draco data for ${k} but no ${k} attribute`);
        }
      }
      ref(p.material, materials, 'material', `${where}/material`, prim);
      if (p.targets !== undefined) {
        if (!Array.isArray(p.targets)) fail('BAD_STRUCTURE', `${where}/targets`, `${prim}'s morph targets are not an array`);
        p.targets.forEach((t: GltfJson, ti: number) => {
          if (!isObject(t)) fail('BAD_STRUCTURE', `${where}/targets/${ti}`, `${prim}'s morph target ${ti} is not an object`);
          for (const [k, a] of Object.entries(t)) ref(a, accessors, 'accessor', `${where}/targets/${ti}/${k}`, `${prim}'s morph target ${ti} ${k}`, true);
        });
      }
    });
  });
}

/** Textures, images, materials. */
export function checkMaterials(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { bufferViews, materials, textures, images, samplers, named } = ctx;
  // textures, images, materials (loaded then dropped, but a bad index would crash the loader)
  images.forEach((im, i) => ref(im.bufferView, bufferViews, 'buffer view', `/images/${i}/bufferView`, `image ${i}`));
  textures.forEach((t, i) => {
    ref(t.source, images, 'image', `/textures/${i}/source`, `texture ${i}`);
    ref(t.sampler, samplers, 'sampler', `/textures/${i}/sampler`, `texture ${i}`);
  });
  materials.forEach((m, i) => {
    const infos: [string, unknown][] = [
      ['normalTexture', m.normalTexture], ['occlusionTexture', m.occlusionTexture], ['emissiveTexture', m.emissiveTexture],
      ['pbrMetallicRoughness/baseColorTexture', m.pbrMetallicRoughness?.baseColorTexture],
      ['pbrMetallicRoughness/metallicRoughnessTexture', m.pbrMetallicRoughness?.metallicRoughnessTexture],
    ];
    for (const [key, info] of infos)
      if (info !== undefined) {
        if (!isObject(info)) fail('BAD_STRUCTURE', `/materials/${i}/${key}`, `the ${key} of ${named('material', i, m)} is not an object`);
        ref(info.index, textures, 'texture', `/materials/${i}/${key}/index`, `the ${key} of ${named('material', i, m)}`, true);
      }
  });
}
