/**
 * Where node passes draw (WebGLRenderer): every skin a renderer draws on the joint-level path (and
 * every GPU DQS skin) shares one set of float render targets, a *page*, each skin owning whole rows
 * of it, and one `render()` per frame computes the nodes of every skin that changed. A pass costs a
 * render-target switch whatever its size (about as much as a thousand nodes under SwiftShader), so
 * sixteen characters of two skins each drawing their own would spend more on switching than on the
 * nodes (docs/gpu.md, "The node pass").
 *
 * Rows are allocated first-fit and freed when a skin is disposed (a section slider rebuilds every
 * frame: its new pass takes the rows the old one left). A page grows when no gap fits (the
 * targets' textures keep their identity, so every material's uniforms stay valid) and every member
 * is recomputed after a growth (the old contents are gone); it never shrinks, and is freed with its
 * last member.
 */
import * as THREE from 'three';
import { DQS_TEXELS_PER_JOINT, GPU_NODE_TEXTURES, GPU_TEXELS_PER_JOINT } from './layout.js';
import type { GpuSections } from './sections.js';

/** The widest row of a shared page: WebGL2's guaranteed 2048. */
export const PAGE_WIDTH = 2048;

/** The most rows a page grows to: WebGL2's guaranteed texture size. */
export const PAGE_ROWS = 2048;

/** What a pass writes: one texel per node (of every instance), or two per joint, one row per instance (the joint pass). */
export type PassKind = 'nodes' | 'joints';

/** What a page needs of a pass drawn into it. */
export interface PageMember {
  /** Rows the member needs (its nodes, or its instances for a joint pass). */
  readonly rows: number;
  /** Texels per row the member writes (its quad's width; ≤ the page's width). */
  readonly columns: number;
  /** The mesh that draws the member's fragments: placed by `place`, shown only while stale. */
  readonly quad: THREE.Mesh;
  /** Whether the member's texels are older than its joint poses. */
  stale(): boolean;
  /** The member's texels now hold its current joint poses. */
  drawn(): void;
  /** The member's texels were lost (the page grew): recompute them at the next run. */
  lost(): void;
  /** Its rows in `page` start at `firstRow` (after an allocation or a growth). */
  place(page: NodePage, firstRow: number): void;
}

/** The options of a page's float targets: four RGBA32F textures (GPU_NODE_TEXTURES), read texel by texel. */
export const PAGE_TARGET_OPTIONS = {
  type: THREE.FloatType, format: THREE.RGBAFormat, minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
  depthBuffer: false, stencilBuffer: false, generateMipmaps: false, count: GPU_NODE_TEXTURES,
} as const;

/** A set of float render targets shared by node passes, each owning `rows` consecutive rows. */
export class NodePage<Target extends THREE.RenderTarget = THREE.WebGLRenderTarget> {
  /** The four RGBA32F targets (GPU_NODE_TEXTURES), `width` texels wide. */
  readonly target: Target;
  protected readonly scene = new THREE.Scene();
  protected readonly camera = new THREE.Camera();
  /** Members and their first rows, in row order. */
  protected readonly members: { member: PageMember; row: number }[] = [];

  /**
   * @param width Texels per row. @param rows Rows at first (grows as members join).
   * @param makeTarget The renderer's kind of target (WebGLRenderTarget; RenderTarget for WebGPURenderer).
   */
  constructor(readonly width: number, rows: number, makeTarget?: (width: number, height: number) => Target) {
    this.target = makeTarget ? makeTarget(width, Math.max(1, rows)) : new THREE.WebGLRenderTarget(width, Math.max(1, rows), PAGE_TARGET_OPTIONS) as unknown as Target;
    this.scene.matrixWorldAutoUpdate = false;
  }

  /** Members drawn into this page. */
  get size(): number {
    return this.members.length;
  }

  /** The first row of a gap of `rows` rows, or the row past the last member; null when the page cannot hold them. */
  private gap(rows: number): number | null {
    let end = 0;
    for (const m of this.members) {
      if (m.row - end >= rows) return end;
      end = m.row + m.member.rows;
    }
    return end + rows <= PAGE_ROWS ? end : null;
  }

  /** Takes `member` into the first gap that fits (growing the targets if needed); false when the page cannot hold it. */
  add(member: PageMember): boolean {
    if (member.columns > this.width) return false;
    const row = this.gap(member.rows);
    if (row === null) return false;
    const at = this.members.findIndex((m) => m.row > row);
    this.members.splice(at < 0 ? this.members.length : at, 0, { member, row });
    member.quad.frustumCulled = false;
    this.scene.add(member.quad);
    const height = row + member.rows;
    if (height > this.target.height) {
      // The textures keep their identity (materials keep reading them); their contents are gone.
      this.grow(height);
      for (const m of this.members) { m.member.place(this as unknown as NodePage, m.row); m.member.lost(); }
    } else {
      member.place(this as unknown as NodePage, row);
      member.lost();
    }
    return true;
  }

  /** The targets become `height` rows high (their contents are lost). */
  protected grow(height: number): void {
    this.target.setSize(this.width, height);
  }

  /** Frees `member`'s rows. */
  remove(member: PageMember): void {
    const i = this.members.findIndex((m) => m.member === member);
    if (i < 0) return;
    this.members.splice(i, 1);
    this.scene.remove(member.quad);
  }

  /**
   * One render of every stale member into the targets (the others hidden), restoring the renderer's
   * render target, cube face, mip level and autoClear.
   */
  run(renderer: object): void {
    let any = false;
    for (const { member } of this.members) {
      const stale = member.stale();
      member.quad.visible = stale;
      if (stale) { member.drawn(); any = true; }
    }
    if (any) this.draw(renderer);
  }

  /** One render of the page's visible quads into its targets, the renderer's state restored. */
  protected draw(into: object): void {
    const renderer = into as THREE.WebGLRenderer;
    const target = renderer.getRenderTarget(), face = renderer.getActiveCubeFace(), level = renderer.getActiveMipmapLevel();
    const autoClear = renderer.autoClear;
    renderer.autoClear = false; // each member writes every texel of its rows
    renderer.setRenderTarget(this.target as unknown as THREE.WebGLRenderTarget);
    renderer.render(this.scene, this.camera);
    renderer.setRenderTarget(target, face, level);
    renderer.autoClear = autoClear;
  }

  /** Frees the targets. */
  dispose(): void {
    this.target.dispose();
  }
}

/** The pages of one renderer (usually one). */
export class NodeAtlas<Page extends NodePage<THREE.RenderTarget> = NodePage> {
  private static readonly atlases = new WeakMap<object, Map<string, NodeAtlas<NodePage<THREE.RenderTarget>>>>();
  private readonly pages: Page[] = [];

  private constructor(private readonly makePage: (width: number, rows: number) => Page) {}

  /**
   * The atlas of `renderer` for passes of one kind ('nodes', or 'joints': the joint passes the
   * node passes read, drawn first), made at its first use (its pages made by `makePage`:
   * WebGLRenderer's by default).
   */
  static of<P extends NodePage<THREE.RenderTarget> = NodePage>(renderer: object, kind: PassKind, makePage?: (width: number, rows: number) => P): NodeAtlas<P> {
    let kinds = NodeAtlas.atlases.get(renderer);
    if (!kinds) NodeAtlas.atlases.set(renderer, kinds = new Map());
    let atlas = kinds.get(kind);
    if (!atlas) kinds.set(kind, atlas = new NodeAtlas(makePage ?? ((width, rows) => new NodePage(width, rows))));
    return atlas as unknown as NodeAtlas<P>;
  }

  /** Places `member` in the first page that holds it, or in a new one; returns its page, or null when no page can hold it. */
  add(member: PageMember): Page | null {
    if (member.rows > PAGE_ROWS || member.columns > PAGE_WIDTH) return null;
    for (const page of this.pages) if (page.add(member)) return page;
    const page = this.makePage(PAGE_WIDTH, member.rows);
    page.add(member);
    this.pages.push(page);
    return page;
  }

  /** Frees `member`'s rows, and its page when it was the last. */
  remove(member: PageMember, page: Page): void {
    page.remove(member);
    if (page.size > 0) return;
    const i = this.pages.indexOf(page);
    if (i >= 0) this.pages.splice(i, 1);
    page.dispose();
  }
}

/**
 * What the GLSL and TSL passes share: the rows and columns a pass writes, whether its texels are
 * current (GpuSections.version), and its rows in its renderer's atlas, taken at its first draw and
 * moved when another renderer draws it.
 */
export abstract class PagedPass<Page extends NodePage<THREE.RenderTarget>> implements PageMember {
  /** Rows of the page this pass writes: its nodes' (one per instance for the joint pass). */
  readonly rows: number;
  /** Texels per row this pass writes. */
  readonly columns: number;
  /** Per instance: its joints (the joint pass) or its sections (the node pass). */
  protected readonly perInstance: number;
  /** The mesh that draws this pass's fragments into its page. */
  abstract readonly quad: THREE.Mesh;
  /** The page the pass draws into (null before its first draw). */
  protected page: Page | null = null;
  /** The renderer whose atlas holds `page` (null: none yet, or a page of the pass's own). */
  private renderer: object | null = null;
  /** The GpuSections.version the texels hold (−1: none yet). */
  private drawnVersion = -1;

  /**
   * @param sections The GPU sections whose joint poses (and section table) the pass reads.
   * @param kind 'joints': two texels per joint, one row per instance (2 · GCS_MAX_JOINTS = PAGE_WIDTH,
   * read without a division per joint); 'nodes': one texel per section, rows of PAGE_WIDTH.
   */
  constructor(readonly sections: GpuSections, readonly kind: PassKind) {
    const joints = kind === 'joints';
    this.perInstance = joints ? sections.transforms.texelsPerInstance / GPU_TEXELS_PER_JOINT : sections.deformer.sectionCount;
    const nodes = sections.instanceCount * this.perInstance;
    this.columns = joints ? this.perInstance * DQS_TEXELS_PER_JOINT : Math.min(PAGE_WIDTH, nodes);
    this.rows = joints ? sections.instanceCount : Math.ceil(nodes / PAGE_WIDTH);
  }

  /** @internal Whether the texels are older than the joint poses. */
  stale(): boolean {
    return this.drawnVersion !== this.sections.version;
  }

  /** @internal The texels hold the current joint poses. */
  drawn(): void {
    this.drawnVersion = this.sections.version;
  }

  /** @internal The texels were lost (the page grew, or the pass is new to it). */
  lost(): void {
    this.drawnVersion = -1;
  }

  /** @internal This pass's rows start at `firstRow` of `page`. */
  abstract place(page: NodePage, firstRow: number): void;

  /**
   * Rows in `renderer`'s atlas (pages made by `makePage`), taken at the first draw and moved when
   * another renderer draws the pass; why it cannot have them (more rows than a page holds), or null.
   */
  protected seat(renderer: object, makePage?: (width: number, rows: number) => Page): string | null {
    if (this.renderer === renderer) return null;
    this.leave(makePage);
    this.page = NodeAtlas.of(renderer, this.kind, makePage).add(this);
    if (!this.page) return `the node pass needs ${this.rows} rows of ${this.columns} texels, more than one float target holds (${PAGE_ROWS} × ${PAGE_WIDTH})`;
    this.renderer = renderer;
    return null;
  }

  /** Frees the pass's rows in its renderer's atlas (the page with its last pass). */
  protected leave(makePage?: (width: number, rows: number) => Page): void {
    if (this.page && this.renderer) NodeAtlas.of(this.renderer, this.kind, makePage).remove(this, this.page);
    this.page = null;
    this.renderer = null;
  }
}
