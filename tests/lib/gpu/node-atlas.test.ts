// The node passes' shared targets (web/lib/gpu/node-atlas.ts), in node with stand-in passes and a
// stand-in renderer: rows first-fit, freed rows reused, a growth that re-places and recomputes
// every member, one render() per run for the stale members only, the page freed with its last
// member, and a pass larger than a page refused (the skin then takes the section-level path).
import { describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { NodeAtlas, NodePage, PAGE_ROWS, PAGE_WIDTH, type PageMember } from '../../../web/lib/gpu/node-atlas.js';

class Member implements PageMember {
  readonly quad = new THREE.Mesh();
  page: NodePage | null = null;
  row = -1;
  version = 0;
  drawnVersion = -1;
  constructor(readonly rows: number, readonly columns = PAGE_WIDTH) {}
  stale(): boolean { return this.drawnVersion !== this.version; }
  drawn(): void { this.drawnVersion = this.version; }
  lost(): void { this.drawnVersion = -1; }
  place(page: NodePage, row: number): void { this.page = page; this.row = row; }
}

/** Counts render() calls and records which quads each drew. */
function standInRenderer() {
  const drawn: THREE.Object3D[][] = [];
  const renderer = {
    autoClear: true,
    getRenderTarget: () => null, getActiveCubeFace: () => 0, getActiveMipmapLevel: () => 0, setRenderTarget: () => {},
    render(scene: THREE.Scene) { drawn.push(scene.children.filter((c) => c.visible)); },
  };
  return { renderer: renderer as unknown as THREE.WebGLRenderer, drawn };
}

describe('NodeAtlas', () => {
  test('rows are taken first-fit, freed rows reused, and a growth re-places and recomputes every member', () => {
    const { renderer, drawn } = standInRenderer();
    const atlas = NodeAtlas.of(renderer, 'nodes');
    expect(NodeAtlas.of(renderer, 'nodes')).toBe(atlas);
    const [a, b, c] = [new Member(2), new Member(1), new Member(3)];
    const page = atlas.add(a)!;
    expect(atlas.add(b)).toBe(page);
    expect(atlas.add(c)).toBe(page);
    expect([a.row, b.row, c.row]).toEqual([0, 2, 3]);
    expect(page.target.height).toBe(6);
    expect(page.target.width).toBe(PAGE_WIDTH);
    const textures = page.target.textures.slice();

    page.run(renderer);
    expect(drawn).toEqual([[a.quad, b.quad, c.quad]]);
    page.run(renderer); // nothing stale: no render
    expect(drawn.length).toBe(1);
    b.version++;
    page.run(renderer); // only b
    expect(drawn[1]).toEqual([b.quad]);

    atlas.remove(b, page);
    const d = new Member(1);
    expect(atlas.add(d)).toBe(page);
    expect(d.row).toBe(2); // the gap b left
    expect(page.target.height).toBe(6);
    expect(a.stale() || c.stale()).toBe(false); // no growth: the others keep their texels

    const e = new Member(2);
    atlas.add(e);
    expect(e.row).toBe(6);
    expect(page.target.height).toBe(8);
    expect(page.target.textures).toEqual(textures); // the same texture objects: materials keep reading them
    expect([a, c, d, e].every((m) => m.stale())).toBe(true); // grown: every member recomputed
    page.run(renderer);
    expect(new Set(drawn[2])).toEqual(new Set([a.quad, c.quad, d.quad, e.quad]));
  });

  test('the page is freed with its last member; a pass larger than a page is refused', () => {
    const { renderer } = standInRenderer();
    const atlas = NodeAtlas.of(renderer, 'nodes');
    const a = new Member(1);
    const page = atlas.add(a)!;
    let freed = 0;
    page.target.addEventListener('dispose', () => freed++);
    atlas.remove(a, page);
    expect(freed).toBe(1);
    expect(atlas.add(new Member(PAGE_ROWS + 1))).toBeNull();
    expect(atlas.add(new Member(1, PAGE_WIDTH + 1))).toBeNull();
    // A full page: the next member opens another.
    const big = new Member(PAGE_ROWS), next = new Member(1);
    const first = atlas.add(big)!;
    expect(atlas.add(next)).not.toBe(first);
  });
});
