// Checks of a glTF's meshes (primitives, attributes, Draco references, morph targets) and of the
// materials, textures and images they refer to (loaded then dropped, but a bad index would crash the loader).
import { n, plural } from './error.js';
import type { GltfJson } from './json.js';
import { LIMITS } from './limits.js';
import { COMPONENT, isIndex, isObject, type Fail, type Ref, type ValidationContext } from './validation-context.js';
import { shownName, shownValue } from './shown-name.js';

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
        ref(a, accessors, 'accessor', `${where}/attributes/${k}`, `${prim}'s ${shownName(k)}`, true);
        const count = accessors[a as number].count;
        checkInfluenceType(ctx, k, a as number, `${where}/attributes/${k}`);
        if (!first) {
          first = [k, count];
          if (count > LIMITS.vertices)
            fail('TOO_LARGE', `${where}/attributes/${k}`, `${prim} has ${plural(count, 'vertex', 'vertices')}, more than the ${n(LIMITS.vertices)} gcs-skin takes`);
        }
        else if (count !== first[1])
          fail('BAD_STRUCTURE', `${where}/attributes/${k}`,
            `${prim}'s ${shownName(k)} (accessor ${a}) has ${plural(count, 'element')} but its ${shownName(first[0])} has ${n(first[1])}: every attribute has one per vertex`);
      }
      ref(p.indices, accessors, 'accessor', `${where}/indices`, `${prim}'s indices`);
      const draco = p.extensions?.KHR_draco_mesh_compression;
      if (draco !== undefined) {
        const dw = `${where}/extensions/KHR_draco_mesh_compression`;
        if (!isObject(draco) || !isObject(draco.attributes)) fail('BAD_STRUCTURE', dw, `the KHR_draco_mesh_compression of ${prim} has no attributes`);
        ref(draco.bufferView, bufferViews, 'buffer view', `${dw}/bufferView`, `the Draco data of ${prim}`, true);
        for (const [k, id] of Object.entries(draco.attributes)) {
          if (!isIndex(id)) fail('BAD_STRUCTURE', `${dw}/attributes/${k}`, `the Draco attribute id of ${prim}'s ${shownName(k)} is ${shownValue(id)}, not a whole number`);
          if (p.attributes[k] === undefined)
            fail('BAD_STRUCTURE', `${dw}/attributes/${k}`, `${prim} has Draco data for ${shownName(k)} but no ${shownName(k)} attribute`);
        }
        // An attribute with no buffer view has its data only in the Draco stream: it needs its id there.
        for (const [k, a] of Object.entries(p.attributes))
          if (accessors[a as number].bufferView === undefined && draco.attributes[k] === undefined)
            fail('BAD_STRUCTURE', `${dw}/attributes`, `${prim}'s ${shownName(k)} has neither a buffer view nor a Draco attribute id: its data is nowhere`);
      }
      ref(p.material, materials, 'material', `${where}/material`, prim);
      if (p.targets !== undefined) {
        if (!Array.isArray(p.targets)) fail('BAD_STRUCTURE', `${where}/targets`, `${prim}'s morph targets are not an array`);
        p.targets.forEach((t: GltfJson, ti: number) => {
          if (!isObject(t)) fail('BAD_STRUCTURE', `${where}/targets/${ti}`, `${prim}'s morph target ${ti} is not an object`);
          for (const [k, a] of Object.entries(t)) ref(a, accessors, 'accessor', `${where}/targets/${ti}/${k}`, `${prim}'s morph target ${ti} ${shownName(k)}`, true);
        });
      }
    });
  });
}

/**
 * JOINTS_n and WEIGHTS_n of glTF's types (JOINTS: VEC4 of UNSIGNED_BYTE or UNSIGNED_SHORT;
 * WEIGHTS: VEC4 of FLOAT, or normalized UNSIGNED_BYTE or UNSIGNED_SHORT): read as anything else,
 * their values would be blamed on a joint ("joint 30608") instead of on the accessor.
 */
function checkInfluenceType(ctx: ValidationContext, semantic: string, index: number, where: string): void {
  const joints = /^JOINTS_\d+$/.test(semantic);
  if (!joints && !/^WEIGHTS_\d+$/.test(semantic)) return;
  const a = ctx.accessors[index];
  const integer = a.componentType === 5121 || a.componentType === 5123;
  const ok = a.type === 'VEC4' && (joints ? integer : a.componentType === 5126 || (integer && a.normalized === true));
  if (!ok)
    ctx.fail('BAD_STRUCTURE', where, `${ctx.accessorName(index)} is ${a.type} ${COMPONENT[a.componentType].name}${integer && !joints && !a.normalized ? ' not normalized' : ''}, ` +
      (joints ? 'not VEC4 UNSIGNED_BYTE/SHORT' : 'not VEC4 FLOAT or normalized UNSIGNED_BYTE/SHORT'));
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
