// The Retarget job's bundled characters (web/src/ui/panels/retarget.js): the clip library's
// sources (skinned, animated glTF) and the bundled targets, with the joints files the targets
// need. vite.config.js copies exactly these files (with the gallery's, lib/samples.js) into the
// build under samples/. Paths are relative to data/.
//
// A joint file places the target's joints under the source skeleton's joint names, so the
// file to use depends on the source's skeleton `family` (KayKit's names differ from
// CesiumMan's): `joints` maps a family to its file.

export const librarySources = [
  { id: 'knight', label: 'KayKit Knight', path: 'anim/KayKit/Knight.glb', family: 'kaykit', credit: 'Kay Lousberg (KayKit), CC0' },
  { id: 'barbarian', label: 'KayKit Barbarian', path: 'anim/KayKit/Barbarian.glb', family: 'kaykit', credit: 'Kay Lousberg (KayKit), CC0' },
  { id: 'robot', label: 'RobotExpressive', path: 'anim/RobotExpressive/RobotExpressive.glb', family: 'robot', credit: 'Tomás Laulhé (Quaternius), CC0' },
  { id: 'cesiumman', label: 'CesiumMan', path: 'anim/CesiumMan/CesiumMan.glb', family: 'cesium', credit: 'Cesium, CC BY 4.0' },
  { id: 'fox', label: 'Fox', path: 'anim/Fox/glTF-Binary/Fox.glb', family: 'fox', credit: 'PixelMannen (CC0), rigged by tomkranis (CC BY 4.0)' },
];

// Bundled targets: rigged glTF characters (joints from their skin) and plain meshes with
// hand-placed joints (one file per source family they fit).
export const libraryTargets = [
  { id: 'barbarian', label: 'KayKit Barbarian (rigged)', path: 'anim/KayKit/Barbarian.glb', skinned: true },
  { id: 'knight', label: 'KayKit Knight (rigged)', path: 'anim/KayKit/Knight.glb', skinned: true },
  { id: 'woman', label: 'Human woman (PLY, placed joints)', path: 'anim/human_woman.ply', skinned: false,
    joints: { cesium: 'joints/human_woman_joints.json', kaykit: 'joints/human_woman_kaykit_joints.json' } },
  { id: 'wolf', label: 'Wolf (PLY, placed joints)', path: 'anim/wolf0.ply', skinned: false, joints: { fox: 'joints/wolf0_joints.json' } },
];

// Every data/ path the library needs.
export function libraryFiles() {
  const out = new Set();
  for (const s of librarySources) out.add(s.path);
  for (const t of libraryTargets) {
    out.add(t.path);
    for (const f of Object.values(t.joints || {})) out.add(f);
  }
  return [...out];
}

// The joints file of a bundled target for a source family: its path, or null when the target
// has none for that family (then its skin, or the person's own file, gives the joints).
export function jointsFileFor(target, family) {
  return target?.joints?.[family] ?? null;
}

// The families a bundled plain-mesh target has joints for, as labels for a message.
export function familiesOf(target) {
  return Object.keys(target?.joints || {});
}

// A clip's label in the library: glTF clips may be unnamed (CesiumMan's is "").
export function clipLabel(name, index) {
  return name ? name : `(unnamed clip ${index + 1})`;
}

// Clips of a character matching a filter text (case-insensitive, every word must occur):
// [{index, name, label, duration}] in the file's order.
export function filterClips(clips, query = '') {
  const words = query.toLowerCase().split(/\s+/).filter(Boolean);
  return clips
    .map((c, index) => ({ index, name: c.name, label: clipLabel(c.name, index), duration: c.duration }))
    .filter((c) => words.every((w) => c.label.toLowerCase().includes(w)));
}

// The `clip` option the job takes for a clip of the list: its name; an unnamed clip can only
// be the first one ("" = the first clip).
export function clipOption(clips, index) {
  const name = clips[index]?.name ?? '';
  if (name) return name;
  if (index === 0) return '';
  return null;
}
