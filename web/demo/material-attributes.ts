// Which geometry attributes a material reads (its textures' uv channels, vertex colours): what the
// page's test hooks check every deformed mesh carries (the classic model's resampled ones get them
// from the library: gcs-skin/three, surface-attributes.ts).
import * as THREE from 'three';

/** Attributes a material reads that a resampled mesh lacks: uv channels of its textures, vertex colours. */
export function attributesNeeded(material: THREE.Material | THREE.Material[]): string[] {
  const names = new Set<string>();
  for (const m of Array.isArray(material) ? material : [material]) {
    if (!m) continue;
    for (const value of Object.values(m)) {
      const t = value as THREE.Texture;
      if (t?.isTexture && !(t as THREE.CubeTexture).isCubeTexture) names.add(t.channel ? `uv${t.channel}` : 'uv');
    }
    if (m.vertexColors) names.add('color');
  }
  return [...names];
}
