// The files a load request carries, read from where the page gets them: gallery samples over
// HTTP (lib/samples.js, served under samples/) and File objects from the picker or a drop.
// Both give [{name, bytes: Uint8Array}] with the mesh file first, its siblings (a .gltf's
// buffers and images) after it.
import { MeshMorphError } from '../lib/errors.js';

export const meshExtensions = ['.glb', '.gltf', '.obj', '.off', '.ply'];

export function isMeshFile(name) {
  const lower = name.toLowerCase();
  return meshExtensions.some((ext) => lower.endsWith(ext));
}

async function fetchBytes(url) {
  const response = await fetch(url);
  if (!response.ok) throw new MeshMorphError('IoError', `could not fetch ${url}: HTTP ${response.status}`);
  return new Uint8Array(await response.arrayBuffer());
}

// A gallery sample's files, relative to the page's URL.
export async function sampleFiles(sample) {
  const dir = sample.path.slice(0, sample.path.lastIndexOf('/') + 1);
  const names = [sample.path, ...(sample.files || []).map((f) => dir + f)];
  const bytes = await Promise.all(names.map((n) => fetchBytes(new URL(`samples/${n}`, document.baseURI))));
  return names.map((n, i) => ({ name: n.slice(n.lastIndexOf('/') + 1), bytes: bytes[i] }));
}

// Files from the picker or a drop: the first mesh file is opened, the others are offered to
// it as siblings. Throws Unsupported when none of them is a mesh file.
export async function userFiles(fileList) {
  const list = [...fileList];
  const main = list.find((f) => isMeshFile(f.name));
  if (!main) {
    throw new MeshMorphError('Unsupported', `none of ${list.map((f) => f.name).join(', ')} is a mesh file (expected ${meshExtensions.join(', ')})`);
  }
  const ordered = [main, ...list.filter((f) => f !== main)];
  return Promise.all(ordered.map(async (f) => ({ name: f.name, bytes: new Uint8Array(await f.arrayBuffer()) })));
}
