// What a glTF file may declare and require, checked before any loader allocates.

/** The required extensions the loaders read (geometry decoded by the node reader, packages/cli/src/gltf-node.ts, and the demo; KTX2 textures by the demo, dropped in node); any other is UNSUPPORTED. */
export const READ_EXTENSIONS: readonly string[] = ['KHR_mesh_quantization', 'EXT_meshopt_compression', 'KHR_draco_mesh_compression', 'KHR_texture_basisu'];

/**
 * What a file may declare, checked on the JSON before a loader allocates or loops over anything:
 * work and memory then grow with the bytes a file has, not with the counts its header claims.
 */
export const LIMITS = {
  /**
   * Bytes of a file and its external buffers together, checked on their sizes before they are
   * read (the loaders then hold several copies: past ~512 MiB a load would pass 1.5 GB).
   */
  fileBytes: 512 * 2 ** 20,
  /** Vertices of one primitive: the core's GCS_MAX_VERTICES (wasm/include/gcs_skin.h). */
  vertices: 16_777_216,
  /** Nodes: three makes an Object3D of each (skinned characters have hundreds). */
  nodes: 8_192,
  /** Entries of any other top-level array (accessors, meshes, animations, …) and of a mesh's primitives or an animation's channels. */
  items: 262_144,
  /** Depth of the node hierarchy: the loaders walk it recursively. */
  nodeDepth: 1_024,
  /** Nesting of the JSON (extras included): deeper would overflow the loaders' recursive copies. */
  jsonDepth: 128,
  /**
   * Bytes the loaders allocate for accessors and meshopt-decoded views: at most this floor plus
   * `expansion` × the bytes of buffer data the file has (accessors sharing a view, zero-filled
   * and sparse accessors, decompression: real files stay well under 4×).
   */
  expandedFloor: 32 * 2 ** 20,
  /** The multiple of the file's buffer bytes the loaders may allocate beyond `expandedFloor`. */
  expansion: 16,
  /**
   * Vertices the nodes instance (a mesh used by several nodes counts once per node): at most this
   * many uses per vertex of the meshes used (skinned meshes), or `instancedFloor` in all (others:
   * a prop repeated many times).
   */
  instancing: 4,
  /** Vertices instanced in all that are always allowed, whatever `instancing` says. */
  instancedFloor: 1_048_576,
} as const;
