#!/usr/bin/env python3
"""Copies the sample meshes from ../shared/data into data/, converting OBJ/OFF to compact
binary little-endian PLY (float32 x,y,z; uchar-count int32 triangle lists). glTF files are
copied byte for byte. Run once by a developer; the result is committed (see data/MANIFEST.md)."""
import os, shutil, struct, sys

SRC = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..', 'shared', 'data')
DST = os.path.join(os.path.dirname(__file__), '..', 'data')

CONVERT = [  # (source, destination)
    ('pose/sumner/cat-reference.obj', 'pose/cat-reference.ply'),
    ('pose/sumner/cat-01.obj', 'pose/cat-01.ply'),
    ('pose/sumner/cat-05.obj', 'pose/cat-05.ply'),
    ('pose/sumner/cat-07.obj', 'pose/cat-07.ply'),
    ('pose/sumner/lion-reference.obj', 'pose/lion-reference.ply'),
    ('pose/sumner/lion-01.obj', 'pose/lion-01.ply'),
    ('pose/sumner/lion-05.obj', 'pose/lion-05.ply'),
    ('pose/sumner/lion-07.obj', 'pose/lion-07.ply'),
    ('pose/sumner/camel_ref.obj', 'pose/camel_ref.ply'),
    ('pose/tosca/horse0.off', 'pose/horse0.ply'),
    ('pose/tosca/horse15.off', 'pose/horse15.ply'),
    ('edit/armadillo.obj', 'edit/armadillo.ply'),
    ('edit/bar.off', 'edit/bar.ply'),
    ('edit/cylinder_coarse.off', 'edit/cylinder_coarse.ply'),
    ('edit/hand_lowres.obj', 'edit/hand_lowres.ply'),
    ('edit/decimated-knight.off', 'edit/decimated-knight.ply'),
    ('edit/skull_low_resolution.obj', 'edit/skull.ply'),
    ('edit/camelhead.off', 'edit/camelhead.ply'),
    ('edit/mannequin.off', 'edit/mannequin.ply'),
    ('anim/targets/human_woman.obj', 'anim/human_woman.ply'),
    ('anim/targets/wolf0.off', 'anim/wolf0.ply'),
]
COPY = [
    'anim/CesiumMan/CesiumMan.glb', 'anim/Fox/glTF-Binary/Fox.glb', 'anim/Fox/glTF/Fox.gltf',
    'anim/Fox/glTF/Fox.bin', 'anim/Fox/glTF/Texture.png', 'anim/KayKit/Knight.glb',
    'anim/KayKit/Barbarian.glb', 'anim/RobotExpressive/RobotExpressive.glb',
]


def read_obj(path):
    V, F = [], []
    for line in open(path, errors='replace'):
        t = line.split()
        if not t:
            continue
        if t[0] == 'v':
            V.append(tuple(float(x) for x in t[1:4]))
        elif t[0] == 'f':
            idx = [int(s.split('/')[0]) for s in t[1:]]
            idx = [i - 1 if i > 0 else len(V) + i for i in idx]
            for k in range(1, len(idx) - 1):  # fan triangulation
                F.append((idx[0], idx[k], idx[k + 1]))
    return V, F


def read_off(path):
    tok = []
    for line in open(path):
        line = line.split('#')[0]
        tok.extend(line.split())
    assert tok[0] == 'OFF'
    nv, nf = int(tok[1]), int(tok[2])
    p = 4
    V = [tuple(float(x) for x in tok[p + 3 * i:p + 3 * i + 3]) for i in range(nv)]
    p += 3 * nv
    F = []
    for _ in range(nf):
        k = int(tok[p]); idx = [int(x) for x in tok[p + 1:p + 1 + k]]; p += 1 + k
        for j in range(1, k - 1):
            F.append((idx[0], idx[j], idx[j + 1]))
    return V, F


def write_ply(path, V, F, comment):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'wb') as f:
        f.write(('ply\nformat binary_little_endian 1.0\ncomment %s\nelement vertex %d\n'
                 'property float x\nproperty float y\nproperty float z\nelement face %d\n'
                 'property list uchar int vertex_indices\nend_header\n' % (comment, len(V), len(F))).encode())
        f.write(b''.join(struct.pack('<3f', *v) for v in V))
        f.write(b''.join(struct.pack('<B3i', 3, *t) for t in F))


for src, dst in CONVERT:
    s = os.path.join(SRC, src)
    V, F = read_obj(s) if s.endswith('.obj') else read_off(s)
    write_ply(os.path.join(DST, dst), V, F, 'converted from shared/data/' + src)
    print('%-40s %6d v %6d f' % (dst, len(V), len(F)))
for src in COPY:
    d = os.path.join(DST, 'anim', os.path.relpath(src, 'anim'))
    os.makedirs(os.path.dirname(d), exist_ok=True)
    shutil.copyfile(os.path.join(SRC, src), d)
os.makedirs(os.path.join(DST, 'licenses'), exist_ok=True)
for name in os.listdir(os.path.join(SRC, 'licenses')):
    shutil.copyfile(os.path.join(SRC, 'licenses', name), os.path.join(DST, 'licenses', name))
