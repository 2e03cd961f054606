// Procedural idle, walk and run cycles (in place), as three.js AnimationClips with a
// quaternion track per bone and a Hips position track. Every track's last key equals its
// first, so the clips loop seamlessly.
//
// Rotations are authored for the 'stand' bind pose (all bind rotations identity, bone frames
// aligned with the world: X = left→ lateral axis, Y up, Z forward): flexion of hips, knees,
// ankles, shoulders and elbows is a rotation about X. For the T-pose bind the arm rotations
// are conjugated so the animated pose is the same.
import * as THREE from 'three';
import { JOINT_NAMES, Pose, STAND_ARM_ANGLE } from './model.js';

const DEG = Math.PI / 180;
type PoseFn = (phi: number) => { rot: Map<string, THREE.Quaternion>; hips: [number, number, number] };

const qAxis = (x: number, y: number, z: number, deg: number) =>
  new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(x, y, z).normalize(), deg * DEG);
const qX = (deg: number) => qAxis(1, 0, 0, deg);
const qY = (deg: number) => qAxis(0, 1, 0, deg);
const qZ = (deg: number) => qAxis(0, 0, 1, deg);
const mul = (...qs: THREE.Quaternion[]) => qs.reduce((a, b) => a.clone().multiply(b), new THREE.Quaternion());
/** mirror a left-side rotation to the right side (reflection x → −x) */
const mirror = (q: THREE.Quaternion) => new THREE.Quaternion(q.x, -q.y, -q.z, q.w);
/** raised-cosine bump, 1 at x = 0 (mod 2π), sharper with larger p */
const bump = (x: number, p: number) => Math.pow((1 + Math.cos(x)) / 2, p);

/** forearm axis of the left arm in the stand bind pose */
const FOREARM_AXIS: [number, number, number] = [Math.sin(STAND_ARM_ANGLE), -Math.cos(STAND_ARM_ANGLE), 0];

interface LimbParams {
  hip: number; knee: number; ankle: number; legRoll?: number;
  shoulder: number; elbow: number; twist: number; armRoll?: number;
}

function limbs(rot: Map<string, THREE.Quaternion>, side: 'Left' | 'Right', p: LimbParams): void {
  const m = side === 'Left' ? (q: THREE.Quaternion) => q : mirror;
  rot.set(`${side}UpLeg`, m(mul(qZ(p.legRoll ?? 0), qX(-p.hip))));
  rot.set(`${side}Leg`, m(qX(p.knee)));
  rot.set(`${side}Foot`, m(qX(p.ankle)));
  rot.set(`${side}Shoulder`, new THREE.Quaternion());
  rot.set(`${side}Arm`, m(mul(qZ(p.armRoll ?? 0), qX(-p.shoulder))));
  rot.set(`${side}ForeArm`, m(mul(qX(-p.elbow), qAxis(...FOREARM_AXIS, -p.twist))));
  rot.set(`${side}Hand`, m(qX(-0.15 * p.elbow)));
}

const walk: PoseFn = (phi) => {
  const rot = new Map<string, THREE.Quaternion>();
  const leg = (f: number) => ({
    hip: 4 + 21 * Math.sin(f),
    knee: 4 + 58 * bump(f + 0.25, 2.5) + 12 * bump(f - (Math.PI / 2 + 0.5), 6),
    ankle: 4 + 11 * Math.sin(f - Math.PI),
  });
  const arm = (f: number) => ({
    shoulder: 3 - 15 * Math.sin(f),
    elbow: 14 + 8 * (1 - Math.sin(f)),
    twist: 22 - 13 * Math.sin(f),
  });
  limbs(rot, 'Left', { ...leg(phi), ...arm(phi) });
  limbs(rot, 'Right', { ...leg(phi + Math.PI), ...arm(phi + Math.PI) });
  rot.set('Hips', mul(qY(-6 * Math.sin(phi)), qZ(2 * Math.sin(phi))));
  rot.set('Spine', mul(qX(3), qY(3 * Math.sin(phi))));
  rot.set('Chest', qY(7 * Math.sin(phi)));
  rot.set('Neck', qY(-2.5 * Math.sin(phi)));
  rot.set('Head', mul(qX(-3), qY(-1.5 * Math.sin(phi))));
  return { rot, hips: [-0.015 * Math.cos(phi), -0.008 + 0.014 * Math.cos(2 * phi), 0] };
};

const run: PoseFn = (phi) => {
  const rot = new Map<string, THREE.Quaternion>();
  const leg = (f: number) => ({
    hip: 18 + 32 * Math.sin(f),
    knee: 12 + 100 * bump(f + 0.35, 2) + 28 * bump(f - (Math.PI / 2 + 0.6), 5),
    ankle: 5 + 16 * Math.sin(f - Math.PI),
  });
  const arm = (f: number) => ({
    shoulder: 6 - 32 * Math.sin(f),
    elbow: 85 - 12 * Math.sin(f),
    twist: 30 - 12 * Math.sin(f),
    armRoll: -4,
  });
  limbs(rot, 'Left', { ...leg(phi), ...arm(phi) });
  limbs(rot, 'Right', { ...leg(phi + Math.PI), ...arm(phi + Math.PI) });
  rot.set('Hips', mul(qX(6), qY(-9 * Math.sin(phi))));
  rot.set('Spine', mul(qX(4), qY(4 * Math.sin(phi))));
  rot.set('Chest', mul(qX(2), qY(14 * Math.sin(phi))));
  rot.set('Neck', mul(qX(-5), qY(-5 * Math.sin(phi))));
  rot.set('Head', mul(qX(-6), qY(-3 * Math.sin(phi))));
  return { rot, hips: [-0.01 * Math.cos(phi), -0.045 - 0.025 * Math.cos(2 * phi), 0.0] };
};

const idle: PoseFn = (phi) => {
  const rot = new Map<string, THREE.Quaternion>();
  const sway = Math.sin(phi);
  const common = (f: number, s: number) => ({
    hip: 1 + s, knee: 3 + 2 * (1 + s), ankle: 1 + s, legRoll: 0,
    shoulder: 2 + 3 * Math.sin(f + 0.5), elbow: 9 + 3 * Math.sin(2 * f), twist: 15 + 8 * Math.sin(f), armRoll: -2,
  });
  limbs(rot, 'Left', { ...common(phi, sway), legRoll: -1.5 * sway });
  limbs(rot, 'Right', { ...common(phi + Math.PI / 3, -sway), legRoll: 1.5 * sway });
  rot.set('Hips', qZ(1.5 * sway));
  rot.set('Spine', mul(qX(0.8 * Math.sin(phi)), qZ(-0.8 * sway)));
  rot.set('Chest', mul(qX(1.2 * Math.sin(2 * phi)), qZ(-0.7 * sway)));
  rot.set('Neck', qY(6 * Math.sin(phi)));
  rot.set('Head', mul(qX(3 * Math.sin(2 * phi + 1)), qY(4 * Math.sin(phi + 0.7))));
  return { rot, hips: [0.012 * sway, -0.006 + 0.003 * Math.sin(2 * phi), 0] };
};

export const CLIP_SPECS: { name: string; duration: number; fn: PoseFn }[] = [
  { name: 'idle', duration: 4, fn: idle },
  { name: 'walk', duration: 1.1, fn: walk },
  { name: 'run', duration: 0.7, fn: run },
];

/**
 * Build the clips for a bind pose. `hipsBind` is the Hips bone's bind (local) position:
 * the position track adds the bob to it.
 */
export function makeClips(pose: Pose, hipsBind: [number, number, number], fps = 30): THREE.AnimationClip[] {
  const arm = Math.PI / 2 - STAND_ARM_ANGLE;
  const C: Record<string, THREE.Quaternion> = { Left: qZ(arm / DEG), Right: qZ(-arm / DEG) };
  return CLIP_SPECS.map(({ name, duration, fn }) => {
    const n = Math.round(duration * fps);
    const times = new Float32Array(n + 1);
    const quat = new Map<string, Float32Array>(JOINT_NAMES.map((j) => [j, new Float32Array(4 * (n + 1))]));
    const hp = new Float32Array(3 * (n + 1));
    for (let f = 0; f <= n; f++) {
      const src = f === n ? 0 : f; // last key = first key
      times[f] = f === n ? duration : (f * duration) / n;
      const { rot, hips } = fn((2 * Math.PI * src) / n);
      for (const j of JOINT_NAMES) {
        let q = rot.get(j) ?? new THREE.Quaternion();
        if (pose === 'tpose') {
          const side = j.startsWith('Left') ? 'Left' : j.startsWith('Right') ? 'Right' : '';
          const part = j.replace(/^(Left|Right)/, '');
          if (side && part === 'Arm') q = mul(q, C[side].clone().invert());
          else if (side && (part === 'ForeArm' || part === 'Hand')) q = mul(C[side], q, C[side].clone().invert());
        }
        const arr = quat.get(j)!;
        if (f === n) { arr.copyWithin(4 * n, 0, 4); continue; }
        // keep consecutive keys in the same hemisphere
        if (f > 0 && arr[4 * f - 4] * q.x + arr[4 * f - 3] * q.y + arr[4 * f - 2] * q.z + arr[4 * f - 1] * q.w < 0) {
          q = new THREE.Quaternion(-q.x, -q.y, -q.z, -q.w);
        }
        arr.set([q.x, q.y, q.z, q.w], 4 * f);
      }
      hp.set([hipsBind[0] + hips[0], hipsBind[1] + hips[1], hipsBind[2] + hips[2]], 3 * f);
    }
    const tracks: THREE.KeyframeTrack[] = [new THREE.VectorKeyframeTrack('Hips.position', Array.from(times), Array.from(hp))];
    for (const j of JOINT_NAMES) tracks.push(new THREE.QuaternionKeyframeTrack(`${j}.quaternion`, Array.from(times), Array.from(quat.get(j)!)));
    return new THREE.AnimationClip(name, duration, tracks);
  });
}
