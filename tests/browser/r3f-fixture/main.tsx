// Renders docs/react-three-fiber.md's component (the test writes its block to tests/.tmp/r3f/GcsModel.tsx)
// inside <StrictMode>, as create-vite's React template does, with the character served as
// /character.glb; window.__r3f lets tests/browser/r3f.test.ts read the skins' state and unmount it.
// ?variant=memo draws the same with the character in useMemo (disposed by an effect's cleanup),
// the pattern the docs page warns against: StrictMode's extra cleanup disposes it.
import { StrictMode, Suspense, use, useEffect, useMemo, useState } from 'react';
import { createRoot } from 'react-dom/client';
import { Canvas, useFrame, useLoader } from '@react-three/fiber';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { initGcsSkin } from 'gcs-skin';
import { GcsCharacter } from 'gcs-skin/three';
import { GcsModel } from '../../.tmp/r3f/GcsModel';

const gcsReady = initGcsSkin();
function MemoModel({ url }: { url: string }) {
  const gcs = use(gcsReady);
  const gltf = useLoader(GLTFLoader, url);
  const character = useMemo(() => new GcsCharacter(gcs, gltf.scene), [gcs, gltf.scene]);
  useEffect(() => () => character.dispose(), [character]);
  useFrame(() => { if (!character.disposed) character.update(); });
  return <primitive object={gltf.scene} />;
}

const query = new URLSearchParams(location.search);
const memo = query.get('variant') === 'memo';
const clip = query.get('clip') ?? undefined; // ?clip=: the docs component's clip prop
const skins = new Set<THREE.SkinnedMesh>();
let frames = 0;
let setShown: (shown: boolean) => void = () => {};

function App() {
  const [shown, show] = useState(true);
  setShown = show;
  return (
    <Canvas camera={{ position: [0, 0.9, 3.2], fov: 45 }} gl={{ preserveDrawingBuffer: true }}
      onCreated={({ scene }) => {
        scene.onAfterRender = () => { frames++; scene.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) skins.add(o as THREE.SkinnedMesh); }); };
      }}>
      <color attach="background" args={[0x3355aa]} />
      <hemisphereLight args={[0xffffff, 0x444444, 2]} />
      <directionalLight position={[1, 2, 3]} intensity={2} />
      <Suspense fallback={null}>{shown && (memo ? <MemoModel url="/character.glb" /> : <GcsModel url="/character.glb" clip={clip} />)}</Suspense>
    </Canvas>
  );
}

createRoot(document.getElementById('root')!).render(<StrictMode><App /></StrictMode>);

declare global { interface Window { __r3f: { frames(): number; layerMasks(): number[]; unmount(): void } } }
window.__r3f = {
  frames: () => frames,
  /** Each skinned mesh's layers: 0 while GcsCharacter draws it (the source hidden), 1 when three's skinning does. */
  layerMasks: () => [...skins].map((m) => m.layers.mask),
  unmount: () => setShown(false),
};
