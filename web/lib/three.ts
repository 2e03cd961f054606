/**
 * three.js adapter: THREE.Meshes whose position and normal attributes ARE the deformers'
 * wasm-memory views, driven by SkinnedMeshes' skeletons (and so by an AnimationMixer).
 *
 * A whole character (a glTF scene or any Object3D), in place:
 *
 *   const character = new GcsCharacter(gcs, gltf.scene);      // every SkinnedMesh under it
 *   scene.add(gltf.scene);
 *   const mixer = new THREE.AnimationMixer(gltf.scene);
 *   // each frame: mixer.update(dt); character.update(); renderer.render(scene, camera);
 *   // at the end: character.dispose();                        // the SkinnedMeshes come back
 *
 * One SkinnedMesh, its deformed mesh placed by hand (carries the source's world transform):
 *
 *   const skin = new SkinDeformer(gcs, skinnedMesh, { method: 'gcs', gcs: { sections: 8 } });
 *   scene.add(skin.mesh);
 *   // each frame: mixer.update(dt); skin.update(); renderer.render(scene, camera);
 *
 * @module gcs-skin/three
 */
export type { Backend, GcsCharacterOptions, RebuildOptions, SkinDeformerOptions } from './three/options.js';
export { writeSkinMatrices } from './three/skin-matrices.js';
export { rigInputFromSkinnedMesh } from './three/rig-input.js';
export { morphData, type MorphData } from './three/morph-data.js';
export { SkinDeformer } from './three/skin-deformer.js';
export { GcsCharacter } from './three/character.js';
