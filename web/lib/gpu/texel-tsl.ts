/**
 * Texel reads for the TSL passes and vertex stage without three.js's per-load row flip.
 *
 * WebGPURenderer's WebGL2 backend stores render targets upside down, so three.js's TextureNode
 * flips the row of every load (NodeBuilder.isFlipY): a `textureSize` query and a select per load,
 * behind a uniform that is false for data textures. The vertex stage loads 12 texels per vertex
 * and the node pass 3–6 per joint of a node, always at a few coordinates: here the row is flipped
 * once per coordinate (`storedRow`, only on a backend that flips, only for render targets), and the
 * loads take it as it is (`texelView`). Real WebGPU flips nothing (docs/gpu.md).
 */
import { Node, TextureNode } from 'three/webgpu';
import type { NodeBuilder, Texture } from 'three/webgpu';

type Int = Node<'int'>;

/** A TextureNode whose loads use their coordinate as given (no flip added by three.js). */
class TexelViewNode extends (TextureNode as unknown as new (value?: Texture) => TextureNode) {
  static get type(): string {
    return 'TexelViewNode';
  }

  setupUV(_builder: NodeBuilder, uvNode: Node): Node {
    return uvNode;
  }
}

/**
 * A texture read with `.load(ivec2)` at the coordinate given. A render target's rows must go
 * through `storedRow`; a data texture's need nothing (three.js flips those on no backend).
 */
export const texelView = (value: Texture): TextureNode => new TexelViewNode(value);

/** Row `row` of a render target `rows` high as the backend stores it: rows − 1 − row where the backend renders upside down. */
class StoredRowNode extends Node {
  static get type(): string {
    return 'StoredRowNode';
  }

  constructor(private readonly row: Int, private readonly rows: Int) {
    super('int');
  }

  setup(builder: NodeBuilder): Node {
    return (builder as NodeBuilder & { isFlipY(): boolean }).isFlipY() ? this.rows.sub(1).sub(this.row) : this.row;
  }
}

/** Where row `row` of a render target `rows` high is read on this backend (see the file's comment). */
export const storedRow = (row: Int, rows: Int): Int => new StoredRowNode(row, rows) as unknown as Int;
