/** @module @gcs-skin/cli/gltf */
// `@gcs-skin/cli/gltf`: a glTF/GLB character in node, as rigs and skin matrices, with no three.js in
// sight. `loadCharacter(file)` reads the file (validated, compressed geometry decoded: see
// gltf-node.ts), and gives per skinned mesh the RigInput for `gcs.createRig`, the character's
// height in that mesh's units, and its clips, each sampled at any time into the J×16 skin matrices
// `deformer.deform()` takes. three's GLTFLoader and AnimationMixer do the work inside; nothing of
// three appears in the types. Documented in docs/node.md.
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { asGiven, GcsError, type RigInput } from 'gcs-skin';
import { GltfError } from 'gcs-skin/gltf';
import { morphData, rigInputFromSkinnedMesh, writeSkinMatrices } from 'gcs-skin/three';
import { characterHeight, loadGltfFile, rootOf } from './gltf-node.js';

export { GltfError, type GltfErrorCode } from 'gcs-skin/gltf';
export type { RigInput } from 'gcs-skin';

/** One animation clip of the file, as seen by one skinned mesh. */
export interface CharacterClip {
  readonly name: string;
  /** Seconds. */
  readonly duration: number;
  /**
   * The mesh's skin matrices at time `t` seconds: jointCount × 16 floats, column-major,
   * `S_j = posed_j · inverseBind_j` in mesh space, what `deformer.deform()` takes. `t` outside
   * [0, duration] wraps around (a looping clip). Written into `out` when given (reused across calls
   * saves an allocation), else into a new array.
   */
  sample(t: number, out?: Float32Array): Float32Array;
  /**
   * The mesh's morph target influences at time `t` (`morphTargets.positions.length` floats, what
   * `deformer.setMorphInfluences()` takes); empty when the mesh has no morph targets.
   */
  morphInfluences(t: number, out?: Float32Array): Float32Array;
}

/** One skinned mesh of the character. */
export interface CharacterMesh {
  /** The mesh's node name ('' if none). */
  readonly name: string;
  /** Its skinned geometry and skeleton, ready for `gcs.createRig(rigInput)` (glTF conventions, mesh space). */
  readonly rigInput: RigInput;
  readonly jointCount: number;
  /** The joints' node names, in the order of the skin matrices. */
  readonly jointNames: readonly string[];
  /**
   * The character's height (largest extent of the bind-pose bounding box of all its skinned
   * meshes) in this mesh's units: the units of the deformers' output positions. Divide a distance
   * by it for "% of the character's height", as `gcs-skin report` does.
   */
  readonly height: number;
  /** The mesh's world matrix (16 floats, column-major): places the deformers' output in the scene. */
  readonly worldMatrix: Float32Array;
  /** Morph targets as relative position (and normal) deltas, one array of vertexCount × 3 per target, for `deformer.setMorphTargets`; null without. */
  readonly morphTargets: { positions: Float32Array[]; normals: Float32Array[] | null } | null;
  /** The skin matrices of the file's rest pose (the nodes' own transforms, no clip). */
  restPose(out?: Float32Array): Float32Array;
  /** Every clip of the file, in file order. */
  readonly clips: readonly CharacterClip[];
  /** The clip with this name, or undefined. */
  clip(name: string): CharacterClip | undefined;
}

export interface Character {
  /** The file as given (or the name given for bytes). */
  readonly file: string;
  /** Largest extent of the bind-pose bounding box of every skinned mesh, in world units. */
  readonly height: number;
  /** One entry per skinned mesh, in scene order. */
  readonly meshes: readonly CharacterMesh[];
  /** The clips' names, in file order. */
  readonly clipNames: readonly string[];
  /** What the loaders warned about (unused extensions, 8 influences per vertex reduced to 4, …); [] if nothing. */
  readonly warnings: readonly string[];
}

export interface LoadCharacterOptions {
  /** Names the file in messages when `source` is bytes. Default 'the glTF bytes'. */
  name?: string;
}

/**
 * Reads a .glb or .gltf (a path, a file: URL, or the bytes of a .glb or self-contained .gltf) into
 * its skinned meshes' rigs and clips. Geometry compressed with KHR_mesh_quantization,
 * EXT_meshopt_compression or KHR_draco_mesh_compression is decoded; textures are not read.
 * Throws a GltfError (`code`, `file`, `where`, one-sentence message) for a bad or unsupported
 * file, and a GltfError with code 'NO_SKINNED_MESH' when the file has no skinned mesh.
 */
export async function loadCharacter(source: string | URL | Uint8Array | ArrayBuffer, options: LoadCharacterOptions = {}): Promise<Character> {
  const path = characterSource(source);
  const file = typeof path === 'string' ? path : (typeof options?.name === 'string' ? options.name : 'the glTF bytes');
  const model = typeof path === 'string' ? await loadGltfFile(path)
    : await loadGltfFile(path instanceof Uint8Array ? path : new Uint8Array(path), file);
  if (!model.skinnedMeshes.length)
    throw new GltfError('NO_SKINNED_MESH', file, '', `${file} has no skinned mesh (no skin, joints and weights): nothing to deform`);
  const poser = new Poser(model.scene, model.clips);
  const height = characterHeight(model.skinnedMeshes);
  const meshes = model.skinnedMeshes.map((mesh, i) => characterMesh(mesh, height.meshUnits[i], poser));
  return { file, height: height.world, meshes, clipNames: model.clips.map((c) => c.name), warnings: model.warnings };
}

/** loadCharacter's source by type: a path, a file: URL, or bytes; anything else is a GltfError naming what was given. */
function characterSource(source: unknown): string | Uint8Array | ArrayBuffer {
  if (typeof source === 'string' || source instanceof Uint8Array || source instanceof ArrayBuffer) return source;
  const given = source instanceof URL ? source.href : typeof source === 'object' && source !== null ? 'an object' : String(typeof source === 'symbol' ? 'a symbol' : source);
  if (source instanceof URL && source.protocol === 'file:') {
    try {
      return fileURLToPath(source);
    } catch {
      throw new GltfError('BAD_URI', given, '', `${given} does not name a local file (a file: URL with a host, or an encoded '/')`);
    }
  }
  if (source instanceof URL)
    throw new GltfError('UNREADABLE', given, '', `${given} is not a file: URL: loadCharacter reads files (a path or a file: URL) or bytes; fetch the file first and pass its bytes`);
  throw new GltfError('UNREADABLE', given, '', `loadCharacter reads a path, a file: URL, a Uint8Array or an ArrayBuffer; got ${given}`);
}

/**
 * Poses the scene at (clip, time). One AnimationMixer per clip on the scene's root, one action
 * playing at a time: switching clip stops the previous action, restores every node's rest
 * transform and morph weights, and starts the next one (which then records that rest state as its
 * original: three's mixer only writes values it sees change), so a clip never inherits a bone the
 * previous one moved and it does not.
 */
class Poser {
  private readonly rest: { o: THREE.Object3D; p: THREE.Vector3; q: THREE.Quaternion; s: THREE.Vector3; w: number[] | null }[] = [];
  private readonly actions: THREE.AnimationAction[];
  private current = -1; // -1: the rest pose
  private time = NaN;

  constructor(private readonly root: THREE.Object3D, readonly clips: THREE.AnimationClip[]) {
    root.traverse((o) => {
      const w = (o as THREE.Mesh).morphTargetInfluences;
      this.rest.push({ o, p: o.position.clone(), q: o.quaternion.clone(), s: o.scale.clone(), w: w ? [...w] : null });
    });
    this.actions = clips.map((clip) => new THREE.AnimationMixer(root).clipAction(clip));
  }

  /** Poses the scene at time t of clip c (-1: the rest pose) and updates its world matrices. */
  pose(c: number, t: number): void {
    if (c === this.current && (t === this.time || c < 0)) return;
    if (c !== this.current) {
      if (this.current >= 0) this.actions[this.current].stop();
      for (const r of this.rest) {
        r.o.position.copy(r.p);
        r.o.quaternion.copy(r.q);
        r.o.scale.copy(r.s);
        if (r.w) (r.o as THREE.Mesh).morphTargetInfluences!.splice(0, r.w.length, ...r.w);
      }
      if (c >= 0) this.actions[c].play();
    }
    if (c >= 0) {
      const action = this.actions[c];
      const d = this.clips[c].duration;
      // Exactly t inside the clip (its end included), wrapped outside; a zero mixer step evaluates there.
      action.time = d > 0 ? (t >= 0 && t <= d ? t : ((t % d) + d) % d) : 0;
      action.getMixer().update(0);
    }
    this.current = c;
    this.time = t;
    this.root.updateMatrixWorld(true);
  }
}

function characterMesh(mesh: THREE.SkinnedMesh, height: number, poser: Poser): CharacterMesh {
  const rigInput = rigInputFromSkinnedMesh(mesh);
  const J = mesh.skeleton.bones.length;
  const tmp = new THREE.Matrix4();
  const skin = (out?: Float32Array) => {
    const o = out ?? new Float32Array(16 * J);
    if (!(o instanceof Float32Array) || o.length < 16 * J) throw new GcsError('LENGTH_MISMATCH', `sample(): out must be a Float32Array of ${16 * J} floats (16 per joint)`);
    writeSkinMatrices(mesh, o, 0, tmp);
    return o;
  };
  const morph = morphData(mesh.geometry);
  const morphs = morph && { positions: morph.positions, normals: morph.normals };
  const T = morphs?.positions.length ?? 0;
  const influences = (out?: Float32Array) => {
    const o = out ?? new Float32Array(T);
    const w = mesh.morphTargetInfluences ?? [];
    for (let k = 0; k < T; k++) o[k] = w[k] ?? 0;
    return o;
  };
  const clips: CharacterClip[] = poser.clips.map((clip, c) => ({
    name: clip.name,
    duration: clip.duration,
    sample(t: number, out?: Float32Array) {
      if (typeof t !== 'number' || !Number.isFinite(t)) throw new GcsError('OUT_OF_RANGE', `sample(${asGiven(t)}): the time must be a finite number of seconds`);
      poser.pose(c, t);
      return skin(out);
    },
    morphInfluences(t: number, out?: Float32Array) {
      if (typeof t !== 'number' || !Number.isFinite(t)) throw new GcsError('OUT_OF_RANGE', `morphInfluences(${asGiven(t)}): the time must be a finite number of seconds`);
      poser.pose(c, t);
      return influences(out);
    },
  }));
  rootOf(mesh).updateMatrixWorld(true);
  return {
    name: mesh.name,
    rigInput,
    jointCount: J,
    jointNames: mesh.skeleton.bones.map((b) => b.name),
    height,
    worldMatrix: Float32Array.from(mesh.matrixWorld.elements),
    morphTargets: morphs,
    restPose(out?: Float32Array) {
      poser.pose(-1, 0);
      return skin(out);
    },
    clips,
    clip: (name: string) => clips.find((c) => c.name === name),
  };
}
