// A glTF document's own materials and textures for the displayed mesh.
//
// The worker loads the file with the core (welded mesh for the algorithms) and sends the RAW
// layout for display: each glTF primitive's vertices in accessor order, concatenated in scene
// traversal order (load info `primitives`: {mesh, primitive, firstVertex, numVertices,
// firstFace, numFaces}). The raw layout keeps every vertex the document has, so UV seams (a
// vertex split because its two sides use different texture coordinates) are still there;
// only the welded mesh merges them, and the page maps welded results back through
// toWelded (an edited or transferred position lands on every raw copy of the vertex).
//
// So the display material is put onto the worker's raw-layout geometry: three.js's GLTFLoader
// parses the same bytes on this thread (materials, samplers, textures, KHR_texture_transform
// …), and for every primitive the loader's mesh with the same (mesh, primitive) association
// gives its material and its TEXCOORD_0 / TEXCOORD_1, copied into [firstVertex, firstVertex +
// numVertices) of a uv attribute; a geometry group per primitive selects its material. Vertex
// correspondence is checked (the loader's vertex count of each primitive must equal the raw
// range); when it does not hold the textured display is refused (reason given) and the plain
// analysis material stays.
//
// Not carried over: vertex colours (COLOR_0; the analysis colours use the colour attribute),
// morph targets and skinning (the shown pose is the raw bind pose the core edits).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const lastSegment = (uri) => decodeURIComponent(uri.split('?')[0].replace(/^.*[\\/]/, ''));
// A 1×1 white PNG for images the user did not provide (the core needs only the geometry).
const whitePixel = 'data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8/5+hHgAHggJ/PchI7wAAAABJRU5ErkJggg==';

export const isGltfName = (name) => /\.(gltf|glb)$/i.test(name);

// The JSON of a .gltf (text) or of a .glb's JSON chunk; null when the bytes are neither.
function documentJson(bytes) {
  if (bytes.length >= 20 && String.fromCharCode(...bytes.subarray(0, 4)) === 'glTF') {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const length = view.getUint32(12, true);
    if (view.getUint32(16, true) !== 0x4e4f534a || 20 + length > bytes.length) return null;
    return { json: JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + length))), binary: true };
  }
  return { json: JSON.parse(new TextDecoder().decode(bytes)), binary: false };
}

// files: [{name, bytes}] (the mesh file first, its siblings after it: what the load op got);
// primitives: the load op's info.primitives; rawVertices: the raw vertex count.
// → {materials: Material[], groups: [{start, count, materialIndex}], uv, uv1 (Float32Array
//    #R·2 or null), textured (a material has a map), names} or {error: reason}.
export async function documentMaterials(files, primitives, rawVertices) {
  const [main] = files;
  if (!main || !isGltfName(main.name)) return { error: 'not a glTF file' };
  let parsed;
  try {
    parsed = documentJson(main.bytes);
  } catch (e) {
    return { error: `unreadable glTF JSON (${e.message})` };
  }
  if (!parsed) return { error: 'unreadable GLB' };
  const { json } = parsed;
  const required = json.extensionsRequired || [];
  const unsupported = required.filter((x) => /basisu|draco|meshopt/i.test(x));
  if (unsupported.length) return { error: `needs ${unsupported.join(', ')}` };

  // Siblings by file name, as blob: URLs (same origin: fine under COEP). Images the user did
  // not give are replaced by a white pixel, so the loader neither fetches nor complains.
  const siblings = new Map();
  const urls = [];
  for (const f of files.slice(1)) {
    const url = URL.createObjectURL(new Blob([f.bytes]));
    urls.push(url);
    siblings.set(f.name, url);
  }
  const missing = [];
  for (const image of json.images || []) {
    if (image.uri && !image.uri.startsWith('data:') && !siblings.has(lastSegment(image.uri))) {
      missing.push(image.uri);
      image.uri = whitePixel;
    }
  }
  for (const buffer of json.buffers || []) {
    if (buffer.uri && !buffer.uri.startsWith('data:') && !siblings.has(lastSegment(buffer.uri))) {
      return { error: `the buffer ${buffer.uri} was not given` };
    }
  }

  const manager = new THREE.LoadingManager();
  manager.setURLModifier((url) => (url.startsWith('data:') || url.startsWith('blob:') ? url : siblings.get(lastSegment(url)) ?? url));
  const loader = new GLTFLoader(manager);
  let gltf;
  try {
    let data;
    if (parsed.binary) {
      // The JSON chunk may have changed (missing images): rebuild only when it did.
      data = missing.length ? rebuildGlb(main.bytes, json) : main.bytes.slice().buffer;
    } else {
      data = JSON.stringify(json);
    }
    gltf = await loader.parseAsync(data, '');
  } catch (e) {
    return { error: `three.js could not read the document (${e?.message || e})` };
  } finally {
    for (const url of urls) URL.revokeObjectURL(url);
  }

  const byPrimitive = new Map();
  gltf.scene.traverse((object) => {
    if (!object.isMesh) return;
    const a = gltf.parser.associations.get(object);
    if (a?.meshes !== undefined && a.primitives !== undefined) byPrimitive.set(`${a.meshes}/${a.primitives}`, object);
  });

  const uv = new Float32Array(rawVertices * 2);
  let uv1 = null;
  const materials = [];
  const groups = [];
  const materialIndex = new Map();
  for (const p of primitives) {
    const object = byPrimitive.get(`${p.mesh}/${p.primitive}`);
    if (!object) return { error: `primitive ${p.name} is not in the three.js scene` };
    const geometry = object.geometry;
    const count = geometry.getAttribute('position')?.count;
    if (count !== p.numVertices) return { error: `primitive ${p.name}: ${count} vertices in three.js, ${p.numVertices} from the core` };
    copyAttribute(geometry.getAttribute('uv'), uv, p.firstVertex);
    const second = geometry.getAttribute('uv1');
    if (second) copyAttribute(second, (uv1 ??= new Float32Array(rawVertices * 2)), p.firstVertex);
    const material = Array.isArray(object.material) ? object.material[0] : object.material;
    if (!materialIndex.has(material)) {
      // Ours: no vertex colours (see above); a polygon offset keeps the wireframe on top.
      material.vertexColors = false;
      material.polygonOffset = true;
      material.polygonOffsetFactor = 1;
      material.polygonOffsetUnits = 1;
      materialIndex.set(material, materials.length);
      materials.push(material);
    }
    groups.push({ start: 3 * p.firstFace, count: 3 * p.numFaces, materialIndex: materialIndex.get(material) });
  }
  return {
    materials, groups, uv, uv1,
    textured: materials.some((m) => Boolean(m.map)),
    missing,
    names: materials.map((m) => m.name || '(unnamed)'),
  };
}

// Releases what documentMaterials made (materials and their textures).
export function disposeDocumentMaterials(display) {
  for (const material of display?.materials || []) {
    for (const value of Object.values(material)) if (value?.isTexture) value.dispose();
    material.dispose();
  }
}

function copyAttribute(attribute, out, firstVertex) {
  if (!attribute) return; // no texture coordinates: zeros (an untextured material ignores them)
  for (let v = 0; v < attribute.count; ++v) {
    out[2 * (firstVertex + v)] = attribute.getX(v);
    out[2 * (firstVertex + v) + 1] = attribute.getY(v);
  }
}

// A GLB with a new JSON chunk (same BIN chunk).
function rebuildGlb(bytes, json) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const jsonLength = view.getUint32(12, true);
  const rest = bytes.subarray(20 + jsonLength);
  let text = new TextEncoder().encode(JSON.stringify(json));
  const padded = (text.length + 3) & ~3;
  const chunk = new Uint8Array(padded).fill(0x20);
  chunk.set(text);
  text = chunk;
  const out = new Uint8Array(12 + 8 + text.length + rest.length);
  const o = new DataView(out.buffer);
  out.set(bytes.subarray(0, 12));
  o.setUint32(8, out.length, true);
  o.setUint32(12, text.length, true);
  o.setUint32(16, 0x4e4f534a, true);
  out.set(text, 20);
  out.set(rest, 20 + text.length);
  return out.buffer;
}
