// Where the crowd stands and how the camera frames it: a staggered grid facing the camera, centred
// on the origin; the camera backs off until every character fits the picture (left of the controls).
import * as THREE from 'three';
import type { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { distanceToFit } from './fit-box.js';
import type { DemoRenderer } from './renderer.js';

const SPACING = 1.1;
/** A walking human's reach around its feet and its height (world units): what framing keeps in the picture. */
const CHARACTER_RADIUS = 0.5;
const CHARACTER_HEIGHT = 1.85;
/** From the crowd's centre, where the camera looks from. */
const VIEW_DIRECTION = new THREE.Vector3(0.55, 0.45, 0.95).normalize();

export class CrowdLayout {
  /** Characters placed. */
  count = 0;

  constructor(private readonly camera: THREE.PerspectiveCamera, private readonly controls: OrbitControls) {}

  /** Half the grid's side (world units): what the sun's shadow camera must cover. */
  get halfSide(): number {
    return Math.ceil(Math.sqrt(this.count)) * SPACING;
  }

  /** Where character i of the crowd stands. */
  positionOf(i: number, out: THREE.Vector3): THREE.Vector3 {
    const n = this.count, side = Math.ceil(Math.sqrt(n));
    const row = Math.floor(i / side), col = i % side;
    return out.set((col - (side - 1) / 2) * SPACING + (row % 2) * SPACING * 0.35, 0, (row - (Math.ceil(n / side) - 1) / 2) * SPACING);
  }

  /** Every character's box (its ground square, its height), world units. */
  private boxes(each: (box: THREE.Box3) => void): void {
    const p = new THREE.Vector3(), box = new THREE.Box3();
    for (let i = 0; i < this.count; i++) {
      this.positionOf(i, p);
      box.min.set(p.x - CHARACTER_RADIUS, 0, p.z - CHARACTER_RADIUS);
      box.max.set(p.x + CHARACTER_RADIUS, CHARACTER_HEIGHT, p.z + CHARACTER_RADIUS);
      each(box);
    }
  }

  /** Points the camera at the crowd and backs off until every character fits the picture. */
  frame(): void {
    const all = new THREE.Box3();
    this.boxes((b) => all.union(b));
    const centre = all.getCenter(new THREE.Vector3());
    const tanV = Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 0.9;
    const distance = distanceToFit(all, VIEW_DIRECTION, tanV * this.camera.aspect * 0.95, tanV);
    this.camera.position.copy(centre).addScaledVector(VIEW_DIRECTION, distance);
    this.controls.target.copy(centre);
    this.controls.update();
  }

  /** The characters' extent on the page (px), their boxes projected by the camera onto the canvas. */
  screenBounds(renderer: DemoRenderer): { left: number; right: number; top: number; bottom: number } {
    this.camera.updateMatrixWorld();
    const canvas = renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector3();
    let left = Infinity, right = -Infinity, top = Infinity, bottom = -Infinity;
    this.boxes((b) => {
      for (let i = 0; i < 8; i++) {
        p.set(i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z).project(this.camera);
        const px = canvas.left + (p.x + 1) / 2 * canvas.width, py = canvas.top + (1 - p.y) / 2 * canvas.height;
        left = Math.min(left, px); right = Math.max(right, px); top = Math.min(top, py); bottom = Math.max(bottom, py);
      }
    });
    return { left, right, top, bottom };
  }
}
