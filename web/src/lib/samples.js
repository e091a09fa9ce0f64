// The sample gallery: meshes bundled from the repository's data/ folder. vite.config.js copies
// exactly these files (and data/licenses/) into the build under samples/; the page fetches
// them relative to its own URL. `files` are siblings a .gltf refers to (buffers, images).
export const samples = [
  { id: 'skull', label: 'Skull (PLY)', path: 'edit/skull.ply', credit: 'YahooJAPAN via Thingiverse, remeshed by O. Stein', license: 'odedstein-skull-README.md' },
  { id: 'armadillo', label: 'Armadillo (PLY)', path: 'edit/armadillo.ply', credit: 'Stanford 3D Scanning Repository, remeshed by O. Stein', license: 'odedstein-armadillo-README.md' },
  { id: 'cesiumman', label: 'CesiumMan (GLB)', path: 'anim/CesiumMan/CesiumMan.glb', credit: 'Cesium, CC BY 4.0 (glTF sample models)' },
  { id: 'fox', label: 'Fox (glTF + .bin)', path: 'anim/Fox/glTF/Fox.gltf', files: ['Fox.bin', 'Texture.png'], credit: 'PixelMannen (CC0), rigged by tomkranis (CC BY 4.0)' },
  { id: 'robot', label: 'RobotExpressive (GLB)', path: 'anim/RobotExpressive/RobotExpressive.glb', credit: 'Tomás Laulhé (Quaternius), CC0', license: 'RobotExpressive-README.md' },
  { id: 'woman', label: 'Human woman (PLY)', path: 'anim/human_woman.ply', credit: 'Max Planck Society via SMPL, adapted by O. Stein', license: 'odedstein-human-README.md' },
  { id: 'cat', label: 'Cat, reference pose (PLY)', path: 'pose/cat-reference.ply', credit: 'R. Sumner and J. Popović, Deformation Transfer (2004)', license: 'sumner-deftransfer-README.txt' },
  { id: 'cat-01', label: 'Cat, pose 01 (PLY)', path: 'pose/cat-01.ply', credit: 'R. Sumner and J. Popović, Deformation Transfer (2004)', license: 'sumner-deftransfer-README.txt' },
  { id: 'cat-07', label: 'Cat, pose 07 (PLY)', path: 'pose/cat-07.ply', credit: 'R. Sumner and J. Popović, Deformation Transfer (2004)', license: 'sumner-deftransfer-README.txt' },
  { id: 'lion', label: 'Lion, reference pose (PLY)', path: 'pose/lion-reference.ply', credit: 'R. Sumner and J. Popović, Deformation Transfer (2004)', license: 'sumner-deftransfer-README.txt' },
  { id: 'hand', label: 'Hand, low resolution (PLY)', path: 'edit/hand_lowres.ply', credit: 'Max Planck Society via SMPL, adapted by O. Stein', license: 'odedstein-hand-README.md' },
  { id: 'horse', label: 'Horse (PLY, closed)', path: 'pose/horse0.ply', credit: 'TOSCA, Bronstein et al. (2008)' },
  { id: 'camelhead', label: 'Camel head, open neck (PLY)', path: 'edit/camelhead.ply', credit: 'Camel head (data/MANIFEST.md)' },
];

export const defaultSampleId = 'skull';

// Every data/ path the gallery needs (main files and siblings), relative to data/.
export function sampleFiles() {
  const out = [];
  for (const s of samples) {
    out.push(s.path);
    const dir = s.path.includes('/') ? s.path.slice(0, s.path.lastIndexOf('/') + 1) : '';
    for (const f of s.files || []) out.push(dir + f);
  }
  return out;
}
