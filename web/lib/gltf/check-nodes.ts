// Checks of a glTF's nodes, their graph, scenes and skins.
import { n, plural } from './error.js';
import type { GltfJson } from './json.js';
import { LIMITS } from './limits.js';
import { COMPONENT, isIndex, type Fail, type Ref, type ValidationContext } from './validation-context.js';

/** Nodes: references and transforms. */
export function checkNodes(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { meshes, nodes, skins, cameras, named } = ctx;
  // nodes: references and transforms
  const numbers = (x: unknown, length: number) => Array.isArray(x) && x.length === length && x.every((v) => typeof v === 'number' && Number.isFinite(v));
  nodes.forEach((d, i) => {
    const where = `/nodes/${i}`;
    const node = named('node', i, d);
    ref(d.mesh, meshes, 'mesh', `${where}/mesh`, node);
    ref(d.skin, skins, 'skin', `${where}/skin`, node);
    ref(d.camera, cameras, 'camera', `${where}/camera`, node);
    if (d.children !== undefined) {
      if (!Array.isArray(d.children)) fail('BAD_STRUCTURE', `${where}/children`, `the children of ${node} are not an array`);
      d.children.forEach((c: unknown, k: number) => ref(c, nodes, 'node', `${where}/children/${k}`, `child ${k} of ${node}`, true));
    }
    for (const [key, length] of [['matrix', 16], ['translation', 3], ['rotation', 4], ['scale', 3]] as const)
      if (d[key] !== undefined && !numbers(d[key], length))
        fail('BAD_STRUCTURE', `${where}/${key}`, `the ${key} of ${node} is not ${length} finite numbers`);
  });
}

/** The vertices the nodes instance. */
export function checkInstancing(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const { accessors, meshes, nodes } = ctx;
  // Instances: every node using a mesh repeats its work in the loaders (an object per node and
  // primitive) and, skinned, in whatever builds deformers on it (the report, the demo).
  const meshVertices = meshes.map((m) => (m.primitives as GltfJson[]).reduce((sum, p) => {
    const first = Object.values(p.attributes)[0];
    return sum + (first === undefined ? 0 : accessors[first as number].count);
  }, 0));
  const used = new Set<number>(), skinnedUsed = new Set<number>();
  let instanced = 0, skinnedInstanced = 0;
  for (const d of nodes) {
    if (d.mesh === undefined) continue;
    used.add(d.mesh);
    instanced += meshVertices[d.mesh];
    if (d.skin !== undefined) { skinnedUsed.add(d.mesh); skinnedInstanced += meshVertices[d.mesh]; }
  }
  const distinct = (set: Set<number>) => [...set].reduce((sum, m) => sum + meshVertices[m], 0);
  if (skinnedInstanced > LIMITS.instancing * distinct(skinnedUsed))
    fail('TOO_LARGE', '/nodes',
      `its skinned nodes instance ${n(skinnedInstanced)} vertices from meshes of ${n(distinct(skinnedUsed))}: more than ${LIMITS.instancing} uses per skinned mesh vertex`);
  if (instanced > Math.max(LIMITS.instancing * distinct(used), LIMITS.instancedFloor))
    fail('TOO_LARGE', '/nodes',
      `its nodes instance ${n(instanced)} vertices from meshes of ${n(distinct(used))}: more than ${LIMITS.instancing} uses per vertex (or ${n(LIMITS.instancedFloor)} in all)`);
}

/** The node graph: no cycle, one parent at most, bounded depth. */
export function checkNodeGraph(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const { nodes, skins, nodeName, named } = ctx;
  const children = nodes.map((d) => (d.children ?? []) as number[]);
  children.forEach((cs, i) => {
    const seen = new Set<number>();
    cs.forEach((c, k) => {
      if (c === i) fail('NODE_CYCLE', `/nodes/${i}/children/${k}`, `${nodeName(i)} is its own child (a cycle in the node hierarchy)`);
      if (seen.has(c)) fail('NODE_HIERARCHY', `/nodes/${i}/children`, `${nodeName(i)} lists ${nodeName(c)} twice among its children`);
      seen.add(c);
    });
  });
  const jointOf = new Map<number, number[]>();
  skins.forEach((s, si) => {
    if (Array.isArray(s.joints)) for (const j of s.joints) if (isIndex(j)) jointOf.set(j, [...(jointOf.get(j) ?? []), si]);
  });
  const cycle = findCycle(children);
  if (cycle) {
    const shown = cycle.length > 9 ? [...cycle.slice(0, 4), -1, ...cycle.slice(-4)] : cycle;
    const path = [...shown, cycle[0]].map((i) => (i < 0 ? '…' : nodeName(i))).join(' → ');
    const skinsIn = [...new Set(cycle.flatMap((i) => jointOf.get(i) ?? []))];
    const joints = skinsIn.length ? ` (joints of ${skinsIn.map((si) => named('skin', si, skins[si])).join(', ')})` : '';
    fail('NODE_CYCLE', `/nodes/${cycle[0]}/children`, `the node hierarchy has a cycle: ${path}${joints}`);
  }
  const parent = new Array<number>(nodes.length).fill(-1);
  children.forEach((cs, i) => cs.forEach((c) => {
    if (parent[c] >= 0)
      fail('NODE_HIERARCHY', `/nodes/${i}/children`,
        `${nodeName(c)} has two parents, ${nodeName(parent[c])} and ${nodeName(i)}: a glTF node has at most one`);
    parent[c] = i;
  }));
  ctx.parent = parent;

  // Depth of the hierarchy (acyclic by now): each node's is its parent's + 1, walked from each root down.
  const depth = new Int32Array(nodes.length);
  for (let r = 0; r < nodes.length; r++) {
    if (parent[r] >= 0) continue;
    const stack = [r];
    depth[r] = 1;
    while (stack.length) {
      const v = stack.pop()!;
      if (depth[v] > LIMITS.nodeDepth)
        fail('TOO_LARGE', `/nodes/${v}`, `the node hierarchy is more than ${n(LIMITS.nodeDepth)} levels deep (at ${nodeName(v)}), past what the loaders walk`);
      for (const c of children[v]) { depth[c] = depth[v] + 1; stack.push(c); }
    }
  }
}

/** Scenes: roots are roots. */
export function checkScenes(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { json, nodes, scenes, nodeName, named, parent } = ctx;
  ref(json.scene, scenes, 'scene', '/scene', 'the file');
  scenes.forEach((s, si) => {
    const where = `/scenes/${si}/nodes`;
    if (s.nodes === undefined) return;
    if (!Array.isArray(s.nodes)) fail('BAD_STRUCTURE', where, `the nodes of ${named('scene', si, s)} are not an array`);
    s.nodes.forEach((r: unknown, k: number) => {
      ref(r, nodes, 'node', `${where}/${k}`, named('scene', si, s), true);
      if (parent[r as number] >= 0)
        fail('NODE_HIERARCHY', `${where}/${k}`,
          `${named('scene', si, s)} lists ${nodeName(r as number)} as a root, but it is a child of ${nodeName(parent[r as number])}`);
    });
  });
}

/** Skins and skinned nodes. */
export function checkSkins(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { accessors, meshes, nodes, skins, nodeName, named } = ctx;
  skins.forEach((s, si) => {
    const where = `/skins/${si}`;
    const skin = named('skin', si, s);
    if (!Array.isArray(s.joints) || !s.joints.length) fail('BAD_SKIN', `${where}/joints`, `${skin} has no joints`);
    const seen = new Set<number>();
    s.joints.forEach((j: unknown, k: number) => {
      ref(j, nodes, 'node', `${where}/joints/${k}`, `joint ${k} of ${skin}`, true);
      if (seen.has(j as number)) fail('BAD_SKIN', `${where}/joints/${k}`, `${skin} lists ${nodeName(j as number)} twice among its joints (joints ${s.joints.indexOf(j)} and ${k})`);
      seen.add(j as number);
    });
    ref(s.skeleton, nodes, 'node', `${where}/skeleton`, `the skeleton of ${skin}`);
    if (s.inverseBindMatrices !== undefined) {
      ref(s.inverseBindMatrices, accessors, 'accessor', `${where}/inverseBindMatrices`, `the inverse bind matrices of ${skin}`);
      const a = accessors[s.inverseBindMatrices];
      if (a.type !== 'MAT4' || a.componentType !== 5126)
        fail('BAD_SKIN', `${where}/inverseBindMatrices`,
          `the inverse bind matrices of ${skin} (accessor ${s.inverseBindMatrices}) are ${a.type} of ${COMPONENT[a.componentType].name}, not MAT4 of FLOAT`);
      if (a.count < s.joints.length)
        fail('BAD_SKIN', `${where}/inverseBindMatrices`,
          `${skin} has ${plural(s.joints.length, 'joint')} but ${plural(a.count, 'inverse bind matrix', 'inverse bind matrices')} (accessor ${s.inverseBindMatrices})`);
    }
  });
  nodes.forEach((d, i) => {
    if (d.skin === undefined) return;
    const skin = named('skin', d.skin, skins[d.skin]);
    if (d.mesh === undefined) fail('BAD_SKIN', `/nodes/${i}/skin`, `${nodeName(i)} has ${skin} but no mesh to skin`);
    const m = meshes[d.mesh];
    m.primitives.forEach((p: GltfJson, pi: number) => {
      const missing = ['JOINTS_0', 'WEIGHTS_0'].filter((k) => p.attributes[k] === undefined);
      if (missing.length)
        fail('BAD_SKIN', `/meshes/${d.mesh}/primitives/${pi}/attributes`,
          `${nodeName(i)} has ${skin} but its ${named('mesh', d.mesh, m)} primitive ${pi} has no ${missing.join(' or ')} attribute: no vertex says which joints move it`);
    });
  });
}

/** A cycle of the directed graph `children` (as a list of nodes, each the parent of the next), or null. Iterative. */
export function findCycle(children: readonly (readonly number[])[]): number[] | null {
  const state = new Uint8Array(children.length); // 0 unseen, 1 on the current path, 2 done
  for (let root = 0; root < children.length; root++) {
    if (state[root]) continue;
    const path = [root], next = [0];
    state[root] = 1;
    while (path.length) {
      const v = path[path.length - 1];
      const k = next[next.length - 1]++;
      if (k >= children[v].length) {
        state[v] = 2;
        path.pop();
        next.pop();
        continue;
      }
      const c = children[v][k];
      if (state[c] === 1) return path.slice(path.indexOf(c));
      if (state[c] === 0) {
        state[c] = 1;
        path.push(c);
        next.push(0);
      }
    }
  }
  return null;
}
