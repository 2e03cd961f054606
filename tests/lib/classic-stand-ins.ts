// Stand-ins for rigs the shared characters do not cover, built in code (nothing to license).
//
// rigidShellFigure: a figure of separate closed shells, one per bone, each bound 100 % to it, with
// gaps at the joints, like Mixamo's X Bot (whose body is 48 closed shells, the joints covered by
// balls in another mesh). The shank's shell is slanted at the knee (its front reaches above the
// knee's centre, its back stops below), so a contour at its upper end finds skin on one side
// only; and the thigh's shell ends just above, inside the window where a contour near the knee
// reads influences. strideFrames bends its hip and knee as a run does.
import type { RigInput } from '../../web/lib/index.js';

type Vec3 = [number, number, number];

/** A closed shell from a to b (radius r, ends domed by dome · r), its near end slanted by slant · r. */
function shell(pos: number[], idx: number[], owner: number[], a: Vec3, b: Vec3, r: number, joint: number, dome: number, slant = 0): void {
  const rings = 24, around = 20, cap = 0.15;
  const axis = b.map((x, i) => x - a[i]);
  const length = Math.hypot(...axis);
  const n = axis.map((x) => x / length);
  const g = Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
  const dot = g[0] * n[0] + g[1] * n[1] + g[2] * n[2];
  let e1 = g.map((x, i) => x - dot * n[i]);
  const l1 = Math.hypot(...e1);
  e1 = e1.map((x) => x / l1);
  const e2 = [n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]];
  const profile: [number, number][] = [];
  for (let i = 0; i <= rings; i++) {
    const s = i / rings;
    if (s < cap) profile.push([-dome * r * Math.cos((s / cap) * Math.PI / 2), r * Math.sin((s / cap) * Math.PI / 2)]);
    else if (s > 1 - cap) profile.push([length + dome * r * Math.cos(((1 - s) / cap) * Math.PI / 2), r * Math.sin(((1 - s) / cap) * Math.PI / 2)]);
    else profile.push([((s - cap) / (1 - 2 * cap)) * length, r]);
  }
  const pole0 = pos.length / 3;
  pos.push(...a.map((x, i) => x + profile[0][0] * n[i]));
  owner.push(joint);
  for (let i = 1; i < rings; i++)
    for (let k = 0; k < around; k++) {
      const t = (2 * Math.PI * k) / around;
      const [along, radius] = profile[i];
      const tilt = i < rings / 2 ? slant * r * Math.sin(t) * (1 - (2 * i) / rings) : 0;
      pos.push(...a.map((x, c) => x + (along - tilt) * n[c] + radius * (Math.cos(t) * e1[c] + Math.sin(t) * e2[c])));
      owner.push(joint);
    }
  const pole1 = pos.length / 3;
  pos.push(...a.map((x, i) => x + profile[rings][0] * n[i]));
  owner.push(joint);
  const V = (i: number, k: number) => pole0 + 1 + (i - 1) * around + (k % around);
  for (let k = 0; k < around; k++) idx.push(pole0, V(1, k + 1), V(1, k));
  for (let i = 1; i < rings - 1; i++)
    for (let k = 0; k < around; k++) idx.push(V(i, k), V(i, k + 1), V(i + 1, k + 1), V(i, k), V(i + 1, k + 1), V(i + 1, k));
  for (let k = 0; k < around; k++) idx.push(pole1, V(rings - 1, k), V(rings - 1, k + 1));
}

export interface ShellFigure {
  input: RigInput;
  centres: Vec3[];
  parents: number[];
}

/**
 * Joints: 0 hips, 1 spine, 2 head, 3 thigh, 4 shank, 5 foot; 1.8 units tall. The thigh ends
 * `thighGap` above the knee's centre; the shank starts `shankStart` below it (negative: above).
 */
export function rigidShellFigure(thighGap = 0.01, shankStart = -0.03, dome = 0.2, slant = 0.4): ShellFigure {
  const centres: Vec3[] = [[0, 1.0, 0], [0, 1.15, 0], [0, 1.6, 0], [0.1, 0.95, 0], [0.1, 0.52, 0], [0.1, 0.08, 0]];
  const parents = [-1, 0, 1, 0, 3, 4];
  const pos: number[] = [], idx: number[] = [], owner: number[] = [];
  const towards = (p: Vec3, q: Vec3, s: number): Vec3 => {
    const d = q.map((x, i) => x - p[i]);
    const l = Math.hypot(...d);
    return p.map((x, i) => x + (s * d[i]) / l) as Vec3;
  };
  const [, , , hip, knee, ankle] = centres;
  shell(pos, idx, owner, [0, 0.93, 0], [0, 1.08, 0], 0.14, 0, 0.3);   // pelvis
  shell(pos, idx, owner, [0, 1.2, 0], [0, 1.55, 0], 0.15, 1, 0.3);    // trunk
  shell(pos, idx, owner, [0, 1.66, 0], [0, 1.72, 0], 0.09, 2, 0.9);   // head
  shell(pos, idx, owner, towards(hip, knee, -0.01), towards(knee, hip, thighGap + dome * 0.07), 0.07, 3, dome);  // thigh
  shell(pos, idx, owner, towards(knee, ankle, shankStart + dome * 0.06), ankle, 0.06, 4, dome, slant);          // shank
  shell(pos, idx, owner, [0.1, 0.04, -0.03], [0.1, 0.04, 0.14], 0.04, 5, 0.5);  // foot
  const count = pos.length / 3, J = centres.length;
  const joints = new Uint32Array(4 * count), weights = new Float32Array(4 * count);
  for (let v = 0; v < count; v++) joints[4 * v] = owner[v], weights[4 * v] = 1;
  const inverseBindMatrices = new Float32Array(16 * J);
  centres.forEach((c, j) => inverseBindMatrices.set([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -c[0], -c[1], -c[2], 1], 16 * j));
  return {
    input: { positions: new Float32Array(pos), indices: new Uint32Array(idx), joints, weights, parents: Int32Array.from(parents), inverseBindMatrices },
    centres,
    parents,
  };
}

/** Skin matrices of a stride: the hip flexes forward and back, the knee bends up to `kneeDegrees`. */
export function strideFrames(figure: ShellFigure, count: number, kneeDegrees = 130): Float32Array[] {
  const { centres, parents } = figure;
  const J = centres.length;
  const mul = (A: number[], B: number[]) => {
    const C = new Array<number>(16).fill(0);
    for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) for (let k = 0; k < 4; k++) C[j * 4 + i] += A[k * 4 + i] * B[j * 4 + k];
    return C;
  };
  const translate = (x: number[]) => [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x[0], x[1], x[2], 1];
  const turnX = (a: number) => [1, 0, 0, 0, 0, Math.cos(a), Math.sin(a), 0, 0, -Math.sin(a), Math.cos(a), 0, 0, 0, 0, 1];
  const frames: Float32Array[] = [];
  for (let f = 0; f < count; f++) {
    const s = f / Math.max(1, count - 1);
    const angle = [0, 0, 0, -0.6 * Math.sin(Math.PI * s), ((kneeDegrees * Math.PI) / 180) * s, -0.3 * s];
    const world: number[][] = [];
    for (let j = 0; j < J; j++) {
      const p = parents[j];
      const offset = p < 0 ? centres[j] : centres[j].map((x, i) => x - centres[p][i]);
      world.push(mul(p < 0 ? translate([0, 0, 0]) : world[p], mul(translate(offset), turnX(angle[j]))));
    }
    const skin = new Float32Array(16 * J);
    for (let j = 0; j < J; j++) skin.set(mul(world[j], translate(centres[j].map((x) => -x))), 16 * j);
    frames.push(skin);
  }
  return frames;
}
