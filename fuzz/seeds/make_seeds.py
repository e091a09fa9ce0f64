#!/usr/bin/env python3
"""Writes the hand-made fuzz seeds of fuzz/seeds/ (small files that reach the parts of each reader
that the repo's data does not: skins, animations, morph targets, sparse accessors, strips, PLY
variants, OBJ polygons with UVs and normals). Run once; the outputs are committed."""
import base64, json, os, struct

here = os.path.dirname(os.path.abspath(__file__))


def put(rel, data):
    path = os.path.join(here, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def f32(*xs): return struct.pack("<%df" % len(xs), *xs)
def u16(*xs): return struct.pack("<%dH" % len(xs), *xs)
def u8(*xs): return struct.pack("<%dB" % len(xs), *xs)


def pad4(b): return b + b"\0" * (-len(b) % 4)


def skinned_gltf():
    """A 5-vertex strip with two joints, skin weights, a morph target, a sparse accessor and an
    animation on translation, rotation, scale and weights."""
    pos = f32(0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0)
    idx = u16(0, 1, 2, 3, 4, 0)
    joints = u8(*([0, 1, 0, 0] * 5))
    weights = f32(*([0.5, 0.5, 0, 0] * 5))
    ibm = f32(*([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] * 2))
    times = f32(0, 0.5, 1)
    tr = f32(0, 0, 0, 0, 1, 0, 0, 0, 0)
    rot = f32(0, 0, 0, 1, 0, 0.7071, 0, 0.7071, 0, 0, 0, 1)
    wts = f32(0, 1, 0)
    morph = f32(*([0, 0, 0.1] * 5))
    sp_idx = u16(1, 3)
    sp_val = f32(0, 0, 1, 0, 0, 2)
    parts = [pos, idx, joints, weights, ibm, times, tr, rot, wts, morph, sp_idx, sp_val]
    buf, views = b"", []
    for p in parts:
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(p)})
        buf = pad4(buf + p)
    acc = [
        {"bufferView": 0, "componentType": 5126, "count": 5, "type": "VEC3", "min": [0, 0, 0], "max": [1, 2, 0]},
        {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        {"bufferView": 2, "componentType": 5121, "count": 5, "type": "VEC4"},
        {"bufferView": 3, "componentType": 5126, "count": 5, "type": "VEC4"},
        {"bufferView": 4, "componentType": 5126, "count": 2, "type": "MAT4"},
        {"bufferView": 5, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0], "max": [1]},
        {"bufferView": 6, "componentType": 5126, "count": 3, "type": "VEC3"},
        {"bufferView": 7, "componentType": 5126, "count": 3, "type": "VEC4"},
        {"bufferView": 8, "componentType": 5126, "count": 3, "type": "SCALAR"},
        {"bufferView": 9, "componentType": 5126, "count": 5, "type": "VEC3"},
        {"componentType": 5126, "count": 5, "type": "VEC3",
         "sparse": {"count": 2, "indices": {"bufferView": 10, "componentType": 5123},
                    "values": {"bufferView": 11}}},
    ]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"name": "root", "children": [1], "translation": [0, 0, 0]},
            {"name": "j0", "children": [2], "rotation": [0, 0, 0, 1]},
            {"name": "j1", "translation": [0, 1, 0], "scale": [1, 1, 1]},
            {"name": "body", "mesh": 0, "skin": 0},
            {"name": "prop", "mesh": 1, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 2, 0, 0, 1]},
        ],
        "meshes": [
            {"name": "strip", "weights": [0],
             "primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 2, "WEIGHTS_0": 3}, "indices": 1,
                             "mode": 5, "targets": [{"POSITION": 9}]}]},
            {"name": "sparse", "primitives": [{"attributes": {"POSITION": 10}, "mode": 6}]},
        ],
        "skins": [{"joints": [1, 2], "inverseBindMatrices": 4, "skeleton": 0}],
        "animations": [{"name": "wave",
                        "samplers": [{"input": 5, "output": 6}, {"input": 5, "output": 7, "interpolation": "STEP"},
                                     {"input": 5, "output": 8}],
                        "channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}},
                                     {"sampler": 1, "target": {"node": 1, "path": "rotation"}},
                                     {"sampler": 2, "target": {"node": 3, "path": "weights"}}]}],
        "buffers": [{"byteLength": len(buf)}],
        "bufferViews": views,
        "accessors": acc,
    }
    return doc, buf


def glb(doc, buf):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    buf = pad4(buf)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(buf), 0x004E4942) + buf
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


doc, buf = skinned_gltf()
put("glb/skinned.glb", glb(doc, buf))
d = json.loads(json.dumps(doc))
d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(buf).decode()
put("gltf/skinned.gltf", json.dumps(d, indent=1))
d = json.loads(json.dumps(doc))
d["buffers"] = [{"byteLength": 64, "uri": "buffer.bin"}]  # the harness's resolver serves it
d["bufferViews"] = [{"buffer": 0, "byteLength": 60}, {"buffer": 0, "byteOffset": 60, "byteLength": 4, "byteStride": 4}]
d["accessors"] = [{"bufferView": 0, "componentType": 5126, "count": 5, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5121, "count": 3, "type": "SCALAR"}]
d["meshes"] = [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}]
d["nodes"] = [{"mesh": 0}]
d["scenes"] = [{"nodes": [0]}]
for k in ("skins", "animations"):
    del d[k]
put("gltf/external_buffer.gltf", json.dumps(d))

put("obj/cube.obj", """# cube with UVs, normals, groups and a quad, negative indices
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1 0.5 0.5 0.5
v 1 1 1
v 0 1 1
vt 0 0
vt 1 0
vt 1 1
vn 0 0 -1
vn 0 0 1
g bottom
usemtl red
s 1
f 1/1/1 3/3/1 2/2/1
f 1//1 4//1 3//1
g top
f 5/1 6/2 7/3 8/1
f -4 -3 -2
f 1 2 6 5
l 1 2
""")
put("off/cube.off", """OFF
# a comment
8 7 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
3 0 1 5 255 0 0
3 0 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
""")
put("off/colors.coff", "COFF\n3 1 3\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n3 0 1 2\n")

ply_head = """ply
format {fmt} 1.0
comment seed
obj_info small
element vertex 4
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
property float nx
element face 2
property list uchar int vertex_indices
property int flags
element edge 1
property int vertex1
property int vertex2
end_header
"""
put("ply/quad_ascii.ply", ply_head.format(fmt="ascii") +
    "0 0 0 255 0 0 1\n1 0 0 0 255 0 1\n1 1 0 0 0 255 1\n0 1 0 9 9 9 1\n3 0 1 2 7\n4 0 2 3 1 8\n0 1\n")
for fmt, e in (("binary_little_endian", "<"), ("binary_big_endian", ">")):
    body = b""
    for x, y in ((0, 0), (1, 0), (1, 1), (0, 1)):
        body += struct.pack(e + "fffBBBf", x, y, 0, 1, 2, 3, 1)
    body += struct.pack(e + "BiiiI", 3, 0, 1, 2, 0) + struct.pack(e + "Biiiii", 4, 0, 2, 3, 1, 0)
    body += struct.pack(e + "ii", 0, 1)
    put("ply/quad_%s.ply" % fmt, ply_head.format(fmt=fmt).encode() + body)
put("ply/double_ushort.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n"
    b"property double y\nproperty double z\nelement face 1\nproperty list uint8 uint16 vertex_index\nend_header\n" +
    struct.pack("<9d", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<BHHH", 3, 0, 1, 2))

put("edit_spec/selectors.json", json.dumps({
    "roi": {"spheres": [{"center": [0, 0, 0], "radius_rel": 2}], "boxes": [{"min": [-1, -1, -1], "max": [20, 20, 20]}]},
    "fixed": {"rings": [{"vertex": 0, "k": 1}], "slabs": [{"axis": "x", "from": 0, "to": 0.1}]},
    "handles": [{"select": {"disks": [{"vertex": 35, "radius": 1.5}]}, "translate_rel": [0, 0, 0.1],
                 "rotate": {"axis": [0, 0, 1], "degrees": 30}, "pivot": "centroid", "scale": 1.1},
                {"select": {"slabs": [{"axis": "long", "from": 0.4, "to": 0.5}], "indices": [14]},
                 "translate": [1, 0, 0], "pivot": [0, 0, 0]}],
    "features": "scale",
    "options": {"method": "naive", "coherence_rings": 2, "handle_basis": True}}))
put("edit_spec/matrix.json", json.dumps({
    "handles": [{"select": [30, 31], "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1]},
                {"select": {"spheres": [{"vertex": 3, "radius_rel": 0.1}]}, "rotate": {"axis": [1, 0, 0], "radians": 0.5}}],
    "comment": "two handles"}))
put("edit_spec/transforms.json", json.dumps([{"translate": [0, 0, 1]}, {"matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1]}]))
put("joints/map.json", json.dumps({"Hips": "pelvis", "Spine": "spine_01", "Head": "head"}))
put("joints/joints.json", json.dumps({"Hips": [0, 1, 0], "Spine": [0, 1.2, 0.01], "Head": [0, 1.7, -1e-3]}))
put("landmarks/pairs.json", json.dumps({"comment": "x", "pairs": [[0, 1], [2147483647, 0], [5, 5]]}))
