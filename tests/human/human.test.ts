import { beforeAll, describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { GcsError } from '../../web/lib/errors.js';
import { createHuman, createHumanData, Human, HumanData, humanToGlb, JOINT_NAMES, JOINT_PARENTS } from '../../web/lib/human/index.js';

const PAPER_V = 17023;
const PAPER_T = 31235;

/** Edge check on the welded mesh: every undirected edge in exactly two triangles, once per direction. */
function edgeReport(index: ArrayLike<number>, weld?: ArrayLike<number>) {
  const w = (i: number) => (weld ? weld[i] : i);
  const dir = new Map<number, number>();
  const M = 1 << 21;
  for (let t = 0; t < index.length; t += 3) {
    for (let e = 0; e < 3; e++) {
      const a = w(index[t + e]), b = w(index[t + ((e + 1) % 3)]);
      const key = a * M + b;
      dir.set(key, (dir.get(key) ?? 0) + 1);
    }
  }
  let bad = 0, undirected = 0;
  for (const [key, n] of dir) {
    const a = Math.floor(key / M), b = key % M;
    const back = dir.get(b * M + a) ?? 0;
    if (n !== 1 || back !== 1) bad++;
    if (a < b) undirected++;
  }
  return { bad, edges: undirected };
}

function triangleAreas(pos: Float32Array, idx: Uint32Array): Float64Array {
  const out = new Float64Array(idx.length / 3);
  for (let t = 0; t < idx.length; t += 3) {
    const a = 3 * idx[t], b = 3 * idx[t + 1], c = 3 * idx[t + 2];
    const ux = pos[b] - pos[a], uy = pos[b + 1] - pos[a + 1], uz = pos[b + 2] - pos[a + 2];
    const vx = pos[c] - pos[a], vy = pos[c + 1] - pos[a + 1], vz = pos[c + 2] - pos[a + 2];
    out[t / 3] = 0.5 * Math.hypot(uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx);
  }
  return out;
}

function volume(pos: Float32Array, idx: Uint32Array): number {
  let v = 0;
  for (let t = 0; t < idx.length; t += 3) {
    const a = 3 * idx[t], b = 3 * idx[t + 1], c = 3 * idx[t + 2];
    v += pos[a] * (pos[b + 1] * pos[c + 2] - pos[b + 2] * pos[c + 1])
      - pos[a + 1] * (pos[b] * pos[c + 2] - pos[b + 2] * pos[c])
      + pos[a + 2] * (pos[b] * pos[c + 1] - pos[b + 1] * pos[c]);
  }
  return v / 6;
}

function checkWeights(d: HumanData) {
  const n = d.positions.length / 3;
  let worst = 0;
  let bad = 0;
  for (let v = 0; v < n; v++) {
    let s = 0;
    for (let k = 0; k < 4; k++) {
      const w = d.weights[4 * v + k];
      if (!(w >= 0 && w <= 1) || d.joints[4 * v + k] >= JOINT_NAMES.length) bad++;
      s += w;
    }
    worst = Math.max(worst, Math.abs(s - 1));
  }
  expect(bad).toBe(0);
  expect(d.joints.length).toBe(4 * n); // at most 4 influences
  expect(worst).toBeLessThan(1e-6);
}

function checkSurface(d: HumanData) {
  // closed, consistently oriented: on the welded mesh, and seam copies share position and weights
  const er = edgeReport(d.indices, d.weld);
  expect(er.bad).toBe(0);
  const first = new Int32Array(d.weldedCount).fill(-1);
  for (let v = 0; v < d.weld.length; v++) {
    const w = d.weld[v];
    if (first[w] < 0) { first[w] = v; continue; }
    for (let k = 0; k < 3; k++) if (d.positions[3 * v + k] !== d.positions[3 * first[w] + k]) throw new Error(`seam copy ${v} moved`);
    for (let k = 0; k < 4; k++) if (d.weights[4 * v + k] !== d.weights[4 * first[w] + k]) throw new Error(`seam copy ${v} weights differ`);
  }
  expect(first.every((f) => f >= 0)).toBe(true);
  // genus 0, one piece: V − E + F = 2
  expect(d.weldedCount - er.edges + d.indices.length / 3).toBe(2);
  const areas = triangleAreas(d.positions, d.indices);
  let min = Infinity;
  for (const a of areas) min = Math.min(min, a);
  expect(min).toBeGreaterThan(1e-10);
  const vol = volume(d.positions, d.indices);
  expect(vol).toBeGreaterThan(0.05); // m³: an adult is ~0.06–0.08
  expect(vol).toBeLessThan(0.1);
  expect(d.positions.every(Number.isFinite) && d.normals.every(Number.isFinite)).toBe(true);
  return { minArea: min, volume: vol };
}

/** Knee/forearm angles from a clip's quaternion track. */
function trackAngles(clip: THREE.AnimationClip, bone: string, axis?: THREE.Vector3): number[] {
  const tr = clip.tracks.find((t) => t.name === `${bone}.quaternion`)!;
  const out: number[] = [];
  for (let i = 0; i < tr.times.length; i++) {
    const q = new THREE.Quaternion().fromArray(tr.values as unknown as number[], 4 * i);
    if (!axis) out.push((2 * Math.acos(Math.min(1, Math.abs(q.w))) * 180) / Math.PI);
    else {
      // twist about axis (swing–twist decomposition)
      const p = axis.clone().multiplyScalar(q.x * axis.x + q.y * axis.y + q.z * axis.z);
      const tw = new THREE.Quaternion(p.x, p.y, p.z, q.w).normalize();
      out.push((2 * Math.acos(Math.min(1, Math.abs(tw.w))) * 180) / Math.PI);
    }
  }
  return out;
}

describe('human: options', () => {
  it('rejects out-of-range vertex counts and unknown poses with a GcsError OUT_OF_RANGE', () => {
    expect(() => createHumanData({ vertices: 100 })).toThrow(GcsError);
    expect(() => createHumanData({ vertices: 3e6 })).toThrow(/2000 to 2000000/);
    expect(() => createHumanData({ vertices: NaN })).toThrow(GcsError);
    expect(() => createHumanData({ pose: 'sit' as never })).toThrow(/'stand' or 'tpose'/);
  });
});

describe('human: default body', () => {
  let human: Human;
  let ms = 0;
  beforeAll(() => {
    const t0 = performance.now();
    human = createHuman();
    ms = performance.now() - t0;
  });

  it('matches the paper model size (17,023 vertices / 31,235 triangles, within 1 %)', () => {
    const d = human.data;
    const V = d.positions.length / 3, T = d.indices.length / 3;
    console.log(`default human: ${V} vertices (${d.weldedCount} distinct positions, ${d.stats.charts} UV charts), ${T} triangles, built in ${ms.toFixed(0)} ms`);
    expect(Math.abs(V / PAPER_V - 1)).toBeLessThan(0.01);
    expect(Math.abs(T / PAPER_T - 1)).toBeLessThan(0.01);
  });

  it('is one closed, oriented, genus-0 surface without degenerate triangles', () => {
    const r = checkSurface(human.data);
    console.log(`default human: volume ${(r.volume * 1000).toFixed(1)} L, smallest triangle ${r.minArea.toExponential(2)} m²`);
  });

  it('has smooth weights: ≤ 4 influences summing to 1, every joint with a child dominates some vertices', () => {
    const d = human.data;
    checkWeights(d);
    const owned = new Array(JOINT_NAMES.length).fill(0);
    for (let v = 0; v < d.positions.length / 3; v++) owned[d.joints[4 * v]]++; // slot 0 holds the largest weight
    const hasChild = JOINT_PARENTS.map((_, j) => JOINT_PARENTS.includes(j));
    JOINT_NAMES.forEach((n, j) => { if (hasChild[j]) expect(owned[j], n).toBeGreaterThan(50); });
    // blending across joints: some vertices near the knee are shared by thigh and shank
    const up = JOINT_NAMES.indexOf('LeftUpLeg'), lo = JOINT_NAMES.indexOf('LeftLeg');
    let shared = 0;
    for (let v = 0; v < d.positions.length / 3; v++) {
      const js = Array.from(d.joints.subarray(4 * v, 4 * v + 4)), ws = d.weights.subarray(4 * v, 4 * v + 4);
      if (js.includes(up) && js.includes(lo) && ws[js.indexOf(up)] > 0.2 && ws[js.indexOf(lo)] > 0.2) shared++;
    }
    expect(shared).toBeGreaterThan(20);
  });

  it('is a 1.75 m person standing on y = 0, facing +Z, joints in anatomical places', () => {
    const d = human.data;
    const box = new THREE.Box3().setFromArray(d.positions);
    expect(box.min.y).toBeCloseTo(0, 6);
    expect(box.max.y).toBeCloseTo(1.75, 3);
    expect(human.height).toBeCloseTo(1.75, 3);
    const J = (n: string) => new THREE.Vector3().fromArray(d.jointPositions, 3 * JOINT_NAMES.indexOf(n as never));
    expect(J('LeftArm').x).toBeGreaterThan(0.12); // left on +X
    expect(J('LeftArm').y).toBeGreaterThan(1.3); // shoulder joint at the top of the arm
    expect(J('LeftUpLeg').y).toBeGreaterThan(0.8);
    expect(J('LeftLeg').y).toBeGreaterThan(0.4);
    expect(J('LeftLeg').y).toBeLessThan(0.55);
    expect(J('LeftHand').y).toBeLessThan(J('LeftForeArm').y);
    // toes in front of the ankle (+Z)
    let maxZ = -Infinity;
    for (let v = 0; v < d.positions.length / 3; v++) if (d.positions[3 * v + 1] < 0.05) maxZ = Math.max(maxZ, d.positions[3 * v + 2]);
    expect(maxZ).toBeGreaterThan(J('LeftFoot').z + 0.1);
  });

  it('is denser around the knee than along the thigh', () => {
    const d = human.data;
    const knee = JOINT_NAMES.indexOf('LeftLeg'), hip = JOINT_NAMES.indexOf('LeftUpLeg');
    const ky = d.jointPositions[3 * knee + 1], hy = d.jointPositions[3 * hip + 1];
    const midY = (ky + hy) / 2;
    const len = (y0: number) => {
      let s = 0, n = 0;
      for (let t = 0; t < d.indices.length; t += 3) {
        const a = 3 * d.indices[t], b = 3 * d.indices[t + 1];
        if (d.positions[a] < 0.03 || Math.abs(d.positions[a + 1] - y0) > 0.03) continue;
        s += Math.hypot(d.positions[b] - d.positions[a], d.positions[b + 1] - d.positions[a + 1], d.positions[b + 2] - d.positions[a + 2]);
        n++;
      }
      return s / n;
    };
    const atKnee = len(ky), atThigh = len(midY);
    console.log(`mean edge length: knee ${(atKnee * 1000).toFixed(1)} mm, mid-thigh ${(atThigh * 1000).toFixed(1)} mm`);
    expect(atKnee).toBeLessThan(0.85 * atThigh);
  });

  it('has idle, walk and run clips that loop, stay finite and sample through AnimationMixer', () => {
    expect(human.clips.map((c) => c.name)).toEqual(['idle', 'walk', 'run']);
    const { mesh } = human;
    const mixer = new THREE.AnimationMixer(mesh);
    for (const clip of human.clips) {
      expect(clip.validate()).toBe(true);
      for (const tr of clip.tracks) {
        for (const v of tr.values) expect(Number.isFinite(v)).toBe(true);
        const sz = tr.getValueSize(), n = tr.times.length;
        for (let k = 0; k < sz; k++) expect(tr.values[(n - 1) * sz + k]).toBe(tr.values[k]); // seamless
        expect(tr.times[n - 1]).toBeCloseTo(clip.duration, 6);
      }
      const names = new Set(clip.tracks.map((t) => t.name.split('.')[0]));
      for (const j of JOINT_NAMES) expect(names.has(j)).toBe(true);
      mixer.stopAllAction();
      mixer.clipAction(clip).reset().play();
      const frames = clip.tracks[0].times.length;
      for (let f = 0; f < frames; f++) {
        mixer.setTime((f / (frames - 1)) * clip.duration * 0.9999);
        mesh.updateMatrixWorld(true);
        mesh.skeleton.update();
        for (const m of mesh.skeleton.boneMatrices!) expect(Number.isFinite(m)).toBe(true);
      }
    }
  });

  it('deforms finitely with three.js CPU skinning at every 10th frame of every clip', () => {
    const { mesh } = human;
    const mixer = new THREE.AnimationMixer(mesh);
    const pos = mesh.geometry.getAttribute('position');
    const v = new THREE.Vector3();
    const box = new THREE.Box3();
    for (const clip of human.clips) {
      mixer.stopAllAction();
      mixer.clipAction(clip).reset().play();
      const frames = clip.tracks[0].times.length;
      for (let f = 0; f < frames; f += 10) {
        mixer.setTime(clip.tracks[0].times[f]);
        mesh.updateMatrixWorld(true);
        mesh.skeleton.update();
        box.makeEmpty();
        for (let i = 0; i < pos.count; i++) {
          v.fromBufferAttribute(pos, i);
          mesh.applyBoneTransform(i, v);
          if (!Number.isFinite(v.x) || !Number.isFinite(v.y) || !Number.isFinite(v.z)) throw new Error(`${clip.name} frame ${f} vertex ${i}`);
          box.expandByPoint(v);
        }
        // still a person-sized thing near the origin
        expect(box.max.y).toBeGreaterThan(1.55);
        expect(box.max.y).toBeLessThan(1.85);
        expect(box.min.y).toBeGreaterThan(-0.15);
      }
    }
  });

  it('reaches plausible knee flexion, forearm twist and hip swing', () => {
    const clip = (n: string) => human.clips.find((c) => c.name === n)!;
    const maxOf = (a: number[]) => Math.max(...a);
    const walkKnee = maxOf(trackAngles(clip('walk'), 'LeftLeg'));
    const runKnee = maxOf(trackAngles(clip('run'), 'LeftLeg'));
    const axis = new THREE.Vector3().fromArray(human.data.jointPositions, 3 * JOINT_NAMES.indexOf('LeftHand'))
      .sub(new THREE.Vector3().fromArray(human.data.jointPositions, 3 * JOINT_NAMES.indexOf('LeftForeArm'))).normalize();
    const twist = maxOf(trackAngles(clip('walk'), 'LeftForeArm', axis));
    const hipRange = trackAngles(clip('walk'), 'LeftUpLeg');
    console.log(`knee flexion max: walk ${walkKnee.toFixed(1)}°, run ${runKnee.toFixed(1)}°; forearm twist max (walk) ${twist.toFixed(1)}°`);
    expect(walkKnee).toBeGreaterThan(50);
    expect(walkKnee).toBeLessThan(75);
    expect(runKnee).toBeGreaterThan(95);
    expect(runKnee).toBeLessThan(125);
    expect(twist).toBeGreaterThan(25);
    expect(twist).toBeLessThan(50);
    expect(maxOf(hipRange)).toBeGreaterThan(15);
  });

  it('round-trips through GLB and three.js GLTFLoader', async () => {
    const glb = await humanToGlb(human);
    const buf = glb.buffer.slice(glb.byteOffset, glb.byteOffset + glb.byteLength) as ArrayBuffer;
    const gltf = await new Promise<any>((res, rej) => new GLTFLoader().parse(buf, '', res, rej));
    let sk: THREE.SkinnedMesh | undefined;
    gltf.scene.traverse((o: THREE.Object3D) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) sk = o as THREE.SkinnedMesh; });
    expect(sk).toBeDefined();
    expect(sk!.geometry.getAttribute('position').count).toBe(human.data.positions.length / 3);
    expect(sk!.geometry.index!.count).toBe(human.data.indices.length);
    expect(sk!.skeleton.bones.map((b) => b.name)).toEqual(JOINT_NAMES);
    expect(gltf.animations.map((a: THREE.AnimationClip) => a.name)).toEqual(['idle', 'walk', 'run']);
    for (const a of gltf.animations as THREE.AnimationClip[]) {
      expect(a.duration).toBeCloseTo(human.clips.find((c) => c.name === a.name)!.duration, 5);
    }
    // the loaded clip drives the loaded skeleton
    const mixer = new THREE.AnimationMixer(gltf.scene);
    mixer.clipAction(gltf.animations[1]).play();
    mixer.setTime(0.3);
    gltf.scene.updateMatrixWorld(true);
    sk!.skeleton.update();
    for (const m of sk!.skeleton.boneMatrices!) expect(Number.isFinite(m)).toBe(true);
  });
});

describe('human: sizes and variants', () => {
  for (const n of [5000, 100000]) {
    it(`generates ${n} vertices within 1 %`, () => {
      const t0 = performance.now();
      const d = createHumanData({ vertices: n });
      const V = d.positions.length / 3;
      console.log(`human ${n}: ${V} vertices, ${d.indices.length / 3} triangles, ${(performance.now() - t0).toFixed(0)} ms`);
      expect(Math.abs(V / n - 1)).toBeLessThan(0.01);
      checkSurface(d);
      checkWeights(d);
    });
  }

  it('without seams is index-watertight (T = 2V − 4)', () => {
    const d = createHumanData({ vertices: 8000, seams: false });
    const V = d.positions.length / 3;
    expect(Math.abs(V / 8000 - 1)).toBeLessThan(0.01);
    expect(d.indices.length / 3).toBe(2 * V - 4);
    expect(edgeReport(d.indices).bad).toBe(0);
  });

  it('has a T-pose variant with horizontal arms whose clips give the same motion', () => {
    const t = createHuman({ pose: 'tpose', vertices: 6000 });
    checkSurface(t.data);
    checkWeights(t.data);
    const J = (h: Human, n: string) => new THREE.Vector3().fromArray(h.data.jointPositions, 3 * JOINT_NAMES.indexOf(n as never));
    expect(J(t, 'LeftHand').x).toBeGreaterThan(0.6);
    expect(Math.abs(J(t, 'LeftHand').y - J(t, 'LeftArm').y)).toBeLessThan(0.01);
    // same animated joint positions as the stand-pose character
    const s = createHuman({ vertices: 6000 });
    const world = (h: Human, clipName: string, time: number) => {
      const mixer = new THREE.AnimationMixer(h.mesh);
      mixer.clipAction(h.clips.find((c) => c.name === clipName)!).play();
      mixer.setTime(time);
      h.mesh.updateMatrixWorld(true);
      return h.mesh.skeleton.bones.map((b) => b.getWorldPosition(new THREE.Vector3()));
    };
    const a = world(t, 'walk', 0.37), b = world(s, 'walk', 0.37);
    a.forEach((p, i) => expect(p.distanceTo(b[i])).toBeLessThan(3e-3)); // the two meshes are scaled to 1.75 m separately
  });

  it.skipIf(process.env.GCS_BIG !== '1')('generates a 1 M vertex body (GCS_BIG=1)', () => {
    const t0 = performance.now();
    const d = createHumanData({ vertices: 1000000 });
    const ms = performance.now() - t0;
    const V = d.positions.length / 3;
    console.log(`human 1M: ${V} vertices, ${d.indices.length / 3} triangles, built in ${(ms / 1000).toFixed(1)} s`);
    expect(Math.abs(V / 1e6 - 1)).toBeLessThan(0.01);
    expect(edgeReport(d.indices, d.weld).bad).toBe(0);
  });
});
