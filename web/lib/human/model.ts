// The default human: skeleton (joint positions in the bind pose) and the implicit body
// (a smooth union of ellipsoids and round cones, each tagged with the bone that owns it).
// Units: metres, y-up, facing +Z, the character's left side on +X.

/** The bind pose: arms down (`'stand'`) or a T-pose (`'tpose'`). */
export type Pose = 'stand' | 'tpose';

/** The human's joint names, in joint order (Hips first). */
export const JOINT_NAMES = [
  'Hips', 'Spine', 'Chest', 'Neck', 'Head',
  'LeftShoulder', 'LeftArm', 'LeftForeArm', 'LeftHand',
  'RightShoulder', 'RightArm', 'RightForeArm', 'RightHand',
  'LeftUpLeg', 'LeftLeg', 'LeftFoot',
  'RightUpLeg', 'RightLeg', 'RightFoot',
] as const;
export type JointName = (typeof JOINT_NAMES)[number];

/** Parent of each joint of JOINT_NAMES, -1 for the root (Hips). */
export const JOINT_PARENTS: readonly number[] = [
  -1, 0, 1, 2, 3,
  2, 5, 6, 7,
  2, 9, 10, 11,
  0, 13, 14,
  0, 16, 17,
];

export const jointIndex = (name: JointName): number => JOINT_NAMES.indexOf(name);

/** Arm abduction of the 'stand' bind pose (arms down, slightly away from the body). */
export const STAND_ARM_ANGLE = (11 * Math.PI) / 180;

export type Vec3 = [number, number, number];

export const PRIM_ELLIPSOID = 0;
export const PRIM_ROUNDCONE = 1;

export interface Primitive {
  type: number;
  bone: number;
  group: number;
  /** ellipsoid: cx,cy,cz, ux,uy,uz, vx,vy,vz, wx,wy,wz, ra,rb,rc ; round cone: ax,ay,az, bx,by,bz, r1, r2 */
  p: number[];
}

// Blend groups: smooth union inside a group with the group's radius, then a tighter union
// between groups (so arms do not web onto the torso, legs not onto each other).
export const GROUP_K = [0.09, 0.02, 0.028, 0.028, 0.035, 0.035];
export const TOP_K = 0.022;
const G_TORSO = 0, G_HEAD = 1, G_ARM_L = 2, G_ARM_R = 3, G_LEG_L = 4, G_LEG_R = 5;

export interface BodyModel {
  pose: Pose;
  prims: Primitive[];
  /** bind-pose joint positions (world), before the final shift that puts the feet on y = 0 */
  joints: Vec3[];
  /** bone segment ends of the leaf joints (head top, finger tips, toes) */
  ends: Map<number, Vec3>;
  /** coordinates (per axis) where the mesh is made denser: joint locations */
  densify: { x: number[]; y: number[]; z: number[] };
  bboxMin: Vec3;
  bboxMax: Vec3;
}

const norm = (v: Vec3): Vec3 => {
  const l = Math.hypot(v[0], v[1], v[2]);
  return [v[0] / l, v[1] / l, v[2] / l];
};
const cross = (a: Vec3, b: Vec3): Vec3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const add = (a: Vec3, b: Vec3, s = 1): Vec3 => [a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s];

function ellipsoid(bone: number, group: number, c: Vec3, r: Vec3, axisV: Vec3 = [0, 1, 0], axisW: Vec3 = [0, 0, 1]): Primitive {
  // axes: u = v × w, v = main (second radius), w = third radius
  const v = norm(axisV);
  let w = norm(axisW);
  const u = norm(cross(v, w));
  w = norm(cross(u, v));
  return { type: PRIM_ELLIPSOID, bone, group, p: [...c, ...u, ...v, ...w, ...r] };
}
function cone(bone: number, group: number, a: Vec3, b: Vec3, r1: number, r2: number): Primitive {
  return { type: PRIM_ROUNDCONE, bone, group, p: [...a, ...b, r1, r2] };
}

/** Rotation about +Z by angle (radians) around a centre. */
function rotZ(p: Vec3, c: Vec3, ang: number): Vec3 {
  const s = Math.sin(ang), co = Math.cos(ang);
  const x = p[0] - c[0], y = p[1] - c[1];
  return [c[0] + co * x - s * y, c[1] + s * x + co * y, p[2]];
}
function rotDirZ(d: Vec3, ang: number): Vec3 {
  return rotZ(d, [0, 0, 0], ang);
}

function transformPrim(pr: Primitive, fp: (p: Vec3) => Vec3, fd: (d: Vec3) => Vec3): Primitive {
  const p = pr.p.slice();
  if (pr.type === PRIM_ELLIPSOID) {
    const c = fp([p[0], p[1], p[2]]);
    const u = fd([p[3], p[4], p[5]]), v = fd([p[6], p[7], p[8]]), w = fd([p[9], p[10], p[11]]);
    p.splice(0, 12, ...c, ...u, ...v, ...w);
  } else {
    const a = fp([p[0], p[1], p[2]]), b = fp([p[3], p[4], p[5]]);
    p.splice(0, 6, ...a, ...b);
  }
  return { ...pr, p };
}

/** The left arm's and leg's joints, ends and primitives (mirrored to the right by addMirrored). */
interface LeftLimbs {
  prims: Primitive[];
  joints: [JointName, Vec3][];
  ends: [JointName, Vec3][];
}

export function buildBodyModel(pose: Pose): BodyModel {
  const joints: Vec3[] = new Array(JOINT_NAMES.length);
  const ends = new Map<number, Vec3>();
  const prims: Primitive[] = [];
  addTorsoAndHead(joints, ends, prims);
  const left: LeftLimbs = { prims: [], joints: [], ends: [] };
  addLeftArm(left, pose);
  addLeftLeg(left);
  addMirrored(left, joints, ends, prims);
  const { mn, mx } = paddedBounds(prims);
  return { pose, prims, joints, ends, densify: densifyPlanes(pose, joints), bboxMin: mn, bboxMax: mx };
}

/** Torso, neck and head (symmetric). */
function addTorsoAndHead(joints: Vec3[], ends: Map<number, Vec3>, prims: Primitive[]): void {
  const J = (n: JointName) => jointIndex(n);
  joints[J('Hips')] = [0, 0.96, 0];
  joints[J('Spine')] = [0, 1.06, 0];
  joints[J('Chest')] = [0, 1.22, 0];
  joints[J('Neck')] = [0, 1.47, -0.01];
  joints[J('Head')] = [0, 1.585, 0.0];
  ends.set(J('Head'), [0, 1.77, 0.01]);

  const T = G_TORSO, H = G_HEAD;
  prims.push(ellipsoid(J('Hips'), T, [0, 0.95, -0.005], [0.155, 0.13, 0.102]));
  prims.push(ellipsoid(J('Hips'), T, [0, 0.9, -0.035], [0.15, 0.085, 0.095])); // buttocks / lower pelvis
  prims.push(ellipsoid(J('Spine'), T, [0, 1.1, 0.0], [0.14, 0.18, 0.095]));
  prims.push(ellipsoid(J('Chest'), T, [0, 1.28, 0.0], [0.152, 0.17, 0.105]));
  prims.push(ellipsoid(J('Chest'), T, [0, 1.38, -0.008], [0.168, 0.07, 0.095])); // upper chest / shoulder line
  prims.push(ellipsoid(J('Chest'), T, [0, 1.3, 0.045], [0.12, 0.075, 0.07])); // pectorals
  prims.push(cone(J('Neck'), T, [0, 1.42, -0.015], [0, 1.6, 0.0], 0.058, 0.05));
  prims.push(ellipsoid(J('Head'), H, [0, 1.665, 0.01], [0.076, 0.105, 0.095]));
  prims.push(ellipsoid(J('Head'), H, [0, 1.603, 0.035], [0.058, 0.05, 0.068])); // jaw
  prims.push(ellipsoid(J('Head'), H, [0, 1.645, 0.106], [0.013, 0.024, 0.018], [0, 1, 0.25])); // nose
  prims.push(ellipsoid(J('Head'), H, [0, 1.615, 0.093], [0.025, 0.012, 0.012])); // chin/lips
  for (const sx of [1, -1]) {
    prims.push(ellipsoid(J('Head'), H, [sx * 0.075, 1.655, 0.0], [0.012, 0.03, 0.018])); // ears
    prims.push(ellipsoid(J('Head'), H, [sx * 0.036, 1.685, 0.075], [0.024, 0.012, 0.022])); // brow
  }
}

/** The left arm (hanging, or raised to horizontal for the T-pose) and the clavicle. */
function addLeftArm(left: LeftLimbs, pose: Pose): void {
  const T = G_TORSO;
  const LA = G_ARM_L;
  const sh: Vec3 = [0.195, 1.43, -0.01];
  const d: Vec3 = [Math.sin(STAND_ARM_ANGLE), -Math.cos(STAND_ARM_ANGLE), 0];
  const side: Vec3 = [Math.cos(STAND_ARM_ANGLE), Math.sin(STAND_ARM_ANGLE), 0]; // lateral, ⟂ arm
  const fwd: Vec3 = [0, 0, 1];
  const at = (o: Vec3, t: number, s = 0, f = 0): Vec3 => add(add(add(o, d, t), side, s), fwd, f);
  const elbow = at(sh, 0.29);
  const wrist = at(elbow, 0.25);
  const tip = at(wrist, 0.185);
  const clav: Vec3 = [0.035, 1.445, 0.02];
  const armPrims: Primitive[] = [];
  const A = jointIndex('LeftArm'), F = jointIndex('LeftForeArm'), Hd = jointIndex('LeftHand');
  armPrims.push(ellipsoid(A, LA, at(sh, 0.045, 0.012), [0.052, 0.075, 0.056], d, fwd)); // deltoid
  armPrims.push(cone(A, LA, sh, elbow, 0.046, 0.036));
  armPrims.push(ellipsoid(A, LA, at(sh, 0.15, -0.002, 0.012), [0.04, 0.095, 0.043], d, fwd)); // biceps
  armPrims.push(ellipsoid(A, LA, at(sh, 0.15, 0.0, -0.014), [0.038, 0.1, 0.038], d, fwd)); // triceps
  armPrims.push(cone(F, LA, elbow, wrist, 0.036, 0.025));
  armPrims.push(ellipsoid(F, LA, at(elbow, 0.075, 0.003, 0.004), [0.04, 0.085, 0.036], d, fwd)); // forearm muscles
  // hand hanging with the palm towards the thigh: width along z, thickness along `side`
  armPrims.push(ellipsoid(Hd, LA, at(wrist, 0.07, 0.002, 0.003), [0.021, 0.068, 0.044], d, fwd)); // palm
  armPrims.push(ellipsoid(Hd, LA, at(wrist, 0.135, 0.0, 0.0), [0.017, 0.055, 0.038], d, fwd)); // fingers
  armPrims.push(cone(Hd, LA, at(wrist, 0.03, -0.008, 0.03), at(wrist, 0.1, -0.012, 0.05), 0.014, 0.01)); // thumb
  left.ends.push(['LeftHand', tip]);
  left.joints.push(['LeftShoulder', clav], ['LeftArm', sh], ['LeftForeArm', elbow], ['LeftHand', wrist]);
  // clavicle / trapezius (part of the torso blend group)
  left.prims.push(cone(jointIndex('LeftShoulder'), T, [0.04, 1.45, -0.02], [0.17, 1.44, -0.015], 0.05, 0.045));

  if (pose === 'tpose') {
    const ang = Math.PI / 2 - STAND_ARM_ANGLE; // rotate the arm up to horizontal (+X)
    const fp = (p: Vec3) => rotZ(p, sh, ang);
    const fd = (v: Vec3) => rotDirZ(v, ang);
    for (const p of armPrims) left.prims.push(transformPrim(p, fp, fd));
    for (const j of left.joints) if (j[0] !== 'LeftShoulder' && j[0] !== 'LeftArm') j[1] = fp(j[1]);
    left.ends[0][1] = fp(left.ends[0][1]);
  } else {
    left.prims.push(...armPrims);
  }
}

/** The left leg. */
function addLeftLeg(left: LeftLimbs): void {
  const LL = G_LEG_L;
  const hip: Vec3 = [0.09, 0.905, 0];
  const knee: Vec3 = [0.095, 0.495, 0.0];
  const ankle: Vec3 = [0.1, 0.085, -0.015];
  const toe: Vec3 = [0.105, 0.025, 0.165];
  const U = jointIndex('LeftUpLeg'), Lg = jointIndex('LeftLeg'), Ft = jointIndex('LeftFoot');
  left.joints.push(['LeftUpLeg', hip], ['LeftLeg', knee], ['LeftFoot', ankle]);
  left.ends.push(['LeftFoot', toe]);
  left.prims.push(cone(U, LL, [0.088, 0.92, -0.005], knee, 0.088, 0.052));
  left.prims.push(ellipsoid(U, LL, [0.098, 0.73, 0.012], [0.074, 0.17, 0.074], [0.01, 1, 0])); // quadriceps
  left.prims.push(ellipsoid(U, LL, [0.092, 0.75, -0.02], [0.07, 0.15, 0.065])); // hamstrings
  left.prims.push(cone(Lg, LL, knee, ankle, 0.05, 0.032));
  left.prims.push(ellipsoid(Lg, LL, [0.098, 0.36, -0.02], [0.05, 0.115, 0.05])); // calf
  left.prims.push(cone(Lg, LL, [0.095, 0.5, 0.022], [0.097, 0.45, 0.03], 0.032, 0.03)); // kneecap
  left.prims.push(ellipsoid(Ft, LL, [0.1, 0.055, 0.045], [0.044, 0.042, 0.1], [0, 1, 0], [0.03, -0.12, 1])); // foot body
  left.prims.push(cone(Ft, LL, [0.1, 0.045, -0.045], [0.1, 0.05, -0.01], 0.042, 0.04)); // heel
  left.prims.push(cone(Ft, LL, [0.1, 0.035, 0.07], [0.107, 0.027, 0.165], 0.036, 0.026)); // forefoot/toes
}

/** The left limbs and their mirror images (x → −x, Left → Right, the left groups → the right ones). */
function addMirrored(left: LeftLimbs, joints: Vec3[], ends: Map<number, Vec3>, prims: Primitive[]): void {
  const mir = (p: Vec3): Vec3 => [-p[0], p[1], p[2]];
  for (const [n, p] of left.joints) {
    joints[jointIndex(n)] = p;
    joints[jointIndex(n.replace('Left', 'Right') as JointName)] = mir(p);
  }
  for (const [n, p] of left.ends) {
    ends.set(jointIndex(n), p);
    ends.set(jointIndex(n.replace('Left', 'Right') as JointName), mir(p));
  }
  const rightOf = (b: number) => jointIndex(JOINT_NAMES[b].replace('Left', 'Right') as JointName);
  const rightGroup = (g: number) => (g === G_ARM_L ? G_ARM_R : g === G_LEG_L ? G_LEG_R : g);
  for (const p of left.prims) {
    prims.push(p);
    prims.push({ ...transformPrim(p, mir, mir), bone: rightOf(p.bone), group: rightGroup(p.group) });
  }
}

/** Where the mesh is densified around joints: along y for the vertical chains, along x for T-posed arms. */
function densifyPlanes(pose: Pose, joints: Vec3[]): { x: number[]; y: number[]; z: number[] } {
  const ys = ['LeftFoot', 'LeftLeg', 'LeftUpLeg', 'Neck', 'LeftArm'].map((n) => joints[jointIndex(n as JointName)][1]);
  const xs: number[] = [];
  if (pose === 'stand') {
    ys.push(joints[jointIndex('LeftForeArm')][1], joints[jointIndex('LeftHand')][1]);
  } else {
    for (const n of ['LeftArm', 'LeftForeArm', 'LeftHand']) {
      const x = joints[jointIndex(n as JointName)][0];
      xs.push(x, -x);
    }
  }
  return { x: xs, y: ys, z: [] };
}

/** The primitives' bounding box, 3 cm larger on every side. */
function paddedBounds(prims: Primitive[]): { mn: Vec3; mx: Vec3 } {
  let mn: Vec3 = [Infinity, Infinity, Infinity], mx: Vec3 = [-Infinity, -Infinity, -Infinity];
  for (const pr of prims) {
    const p = pr.p;
    let c: Vec3, r: number;
    if (pr.type === PRIM_ELLIPSOID) { c = [p[0], p[1], p[2]]; r = Math.max(p[12], p[13], p[14]); }
    else { c = [p[0], p[1], p[2]]; r = p[6]; }
    const ext = [c, pr.type === PRIM_ROUNDCONE ? ([p[3], p[4], p[5]] as Vec3) : c];
    const rr = [r, pr.type === PRIM_ROUNDCONE ? p[7] : r];
    for (let e = 0; e < 2; e++) for (let a = 0; a < 3; a++) {
      mn[a] = Math.min(mn[a], ext[e][a] - rr[e]);
      mx[a] = Math.max(mx[a], ext[e][a] + rr[e]);
    }
  }
  mn = add(mn, [-0.03, -0.03, -0.03]);
  mx = add(mx, [0.03, 0.03, 0.03]);
  return { mn, mx };
}
