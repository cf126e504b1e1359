#!/usr/bin/env python3
"""Generate the round-trip test assets in tests/data/roundtrip/.

Run from the repository root:

    .venv/bin/python scripts/assets/make_roundtrip_assets.py

(any virtual environment with scripts/assets/requirements.txt installed works).
The output is deterministic: no random state without a fixed seed, no time stamps,
so rerunning it rewrites byte-identical files.

What writes what:
  scene.glb                   trimesh.Scene.export (file_type="glb"), unmodified
  scene.gltf/.bin, checker.png   trimesh.Scene.export (file_type="glb") JSON, split into
                              .gltf + one external .bin + the external PNG by split_glb()
                              below (trimesh's own .gltf export keeps the image inside a .bin
                              and writes one .bin per accessor, so we re-pack it)
  morph.glb, skinned.glb      pygltflib (geometry from trimesh.creation)
  textured.obj/.mtl/.png      numpy quad-sphere + the small OBJ/MTL writer below
                              (no maintained Python package writes quads + materials + groups)
  colored.ply, colored_ascii.ply   plyfile
All textures are generated with numpy and encoded by Pillow.
"""

from __future__ import annotations

import io
import json
import os
import struct
import sys

import numpy as np
import trimesh
from PIL import Image
import pygltflib
from pygltflib import (
    GLTF2,
    Accessor,
    Animation,
    AnimationChannel,
    AnimationChannelTarget,
    AnimationSampler,
    Asset,
    Buffer,
    BufferView,
    Material,
    Mesh,
    Node,
    PbrMetallicRoughness,
    Primitive,
    Scene,
    Skin,
)
from plyfile import PlyData, PlyElement

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
OUT = os.path.join(ROOT, "tests", "data", "roundtrip")

GENERATOR = "fairmesh scripts/assets/make_roundtrip_assets.py"


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------
def write_bytes(name: str, data: bytes) -> None:
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(data)


def png_bytes(img: Image.Image) -> bytes:
    buf = io.BytesIO()
    img.save(buf, format="PNG")
    return buf.getvalue()


def checker_image(size=64, cells=8, a=(235, 235, 235), b=(40, 90, 200)) -> Image.Image:
    ij = np.indices((size, size)) // (size // cells)
    mask = ((ij[0] + ij[1]) % 2).astype(bool)
    img = np.empty((size, size, 3), dtype=np.uint8)
    img[mask] = a
    img[~mask] = b
    return Image.fromarray(img, "RGB")


def uv_sphere(radius=1.0, nlat=16, nlon=32):
    """Lat/long sphere with a UV seam (duplicated seam + pole vertices).

    Returns vertices, faces, uv (v up, OpenGL convention), smooth unit normals. Welding the
    vertices by position gives a closed 2-manifold.
    """
    theta = np.linspace(0.0, np.pi, nlat + 1)  # from +Y (north) to -Y
    phi = np.linspace(0.0, 2.0 * np.pi, nlon + 1)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.cos(th), -np.sin(th) * np.sin(ph)], axis=-1)
    # exact poles / seam so welding by position is exact
    n[0, :] = (0.0, 1.0, 0.0)
    n[-1, :] = (0.0, -1.0, 0.0)
    n[:, -1] = n[:, 0]
    u = np.broadcast_to(np.arange(nlon + 1) / nlon, (nlat + 1, nlon + 1)).copy()
    v = 1.0 - np.broadcast_to((np.arange(nlat + 1) / nlat)[:, None], (nlat + 1, nlon + 1))
    # pole vertices get the u of the middle of their triangle
    u[0, :-1] += 0.5 / nlon
    u[-1, :-1] += 0.5 / nlon
    idx = np.arange((nlat + 1) * (nlon + 1)).reshape(nlat + 1, nlon + 1)
    faces = []
    for i in range(nlat):
        for j in range(nlon):
            a, b, c, d = idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]
            if i != 0:
                faces.append((a, b, d))
            if i != nlat - 1:
                faces.append((d, b, c))
    faces = np.array(faces, dtype=np.int64)
    verts = n.reshape(-1, 3) * radius
    uv = np.stack([u.reshape(-1), v.reshape(-1)], axis=-1)
    normals = n.reshape(-1, 3)
    used = np.zeros(len(verts), dtype=bool)
    used[faces.reshape(-1)] = True
    remap = np.cumsum(used) - 1
    return verts[used], remap[faces], uv[used], normals[used]


def weld_check(vertices, faces) -> trimesh.Trimesh:
    m = trimesh.Trimesh(vertices=np.asarray(vertices, dtype=np.float64), faces=faces, process=True)
    m.merge_vertices(merge_tex=True, merge_norm=True)
    assert m.is_watertight, "mesh is not closed after welding"
    assert m.is_winding_consistent
    assert m.volume > 0, "faces point inwards"
    return m


def trs_matrix(translation, axis, angle_deg, scale):
    t = trimesh.transformations.translation_matrix(translation)
    r = trimesh.transformations.rotation_matrix(np.radians(angle_deg), axis)
    s = np.diag([scale, scale, scale, 1.0])
    return t @ r @ s


def quat_xyzw(axis, angle_deg):
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    h = np.radians(angle_deg) / 2.0
    return np.concatenate([axis * np.sin(h), [np.cos(h)]])


# --------------------------------------------------------------------------------------------
# a/b: scene.glb and scene.gltf (trimesh)
# --------------------------------------------------------------------------------------------
def build_trimesh_scene() -> trimesh.Scene:
    # (i) textured, smooth-shaded ball
    v, f, uv, nrm = uv_sphere(radius=0.5, nlat=16, nlon=32)
    weld_check(v, f)
    checker = checker_image()
    mat_checker = trimesh.visual.material.PBRMaterial(
        name="checker",
        baseColorTexture=checker,
        baseColorFactor=[255, 255, 255, 255],
        metallicFactor=0.0,
        roughnessFactor=0.8,
    )
    ball = trimesh.Trimesh(
        vertices=v,
        faces=f,
        vertex_normals=nrm,
        visual=trimesh.visual.TextureVisuals(uv=uv, material=mat_checker),
        process=False,
    )

    # (ii) hard-surface block: subdivided box, one vertex per face corner (flat normals),
    # per-vertex colours, second material
    box = trimesh.creation.box(extents=(1.2, 0.6, 0.6))
    box = box.subdivide().subdivide().subdivide()  # 12 -> 768 faces, interior vertices
    weld_check(box.vertices, box.faces)
    tri = box.vertices[box.faces]  # (F, 3, 3) unmerged: vertices split per face
    fv = tri.reshape(-1, 3)
    ff = np.arange(len(fv)).reshape(-1, 3)
    fn = np.repeat(box.face_normals, 3, axis=0)
    # colour depends on position only, so the copies of a welded vertex agree
    lo, hi = fv.min(axis=0), fv.max(axis=0)
    t = (fv - lo) / (hi - lo)
    col = np.empty((len(fv), 4), dtype=np.uint8)
    col[:, 0] = np.round(60 + 195 * t[:, 0])
    col[:, 1] = np.round(60 + 195 * t[:, 1])
    col[:, 2] = np.round(60 + 195 * t[:, 2])
    col[:, 3] = 255
    mat_paint = trimesh.visual.material.PBRMaterial(
        name="paint",
        baseColorFactor=[230, 80, 50, 255],
        metallicFactor=0.2,
        roughnessFactor=0.5,
    )
    vis = trimesh.visual.TextureVisuals(material=mat_paint)
    vis.vertex_attributes["color"] = col
    block = trimesh.Trimesh(vertices=fv, faces=ff, vertex_normals=fn, visual=vis, process=False)

    scene = trimesh.Scene()
    root_tf = trs_matrix((0.25, 0.5, -0.75), (0.0, 1.0, 0.0), 30.0, 1.5)
    scene.graph.update(frame_from=scene.graph.base_frame, frame_to="root", matrix=root_tf)
    scene.add_geometry(
        ball,
        geom_name="ball_mesh",
        node_name="ball",
        parent_node_name="root",
        transform=trimesh.transformations.translation_matrix((-0.8, 0.0, 0.0)),
    )
    scene.add_geometry(
        block,
        geom_name="block_mesh",
        node_name="block",
        parent_node_name="root",
        transform=trs_matrix((0.9, 0.1, 0.0), (0.0, 0.0, 1.0), 20.0, 1.0),
    )
    return scene


def split_glb(glb: bytes, bin_name: str, image_names: list[str]):
    """Turn a GLB into .gltf JSON + one external .bin + external image files.

    Image bufferViews are dropped from the .bin (their bytes become the image files); all other
    bufferViews are re-packed in order, 4-byte aligned, and renumbered.
    """
    magic, version, length = struct.unpack_from("<III", glb, 0)
    assert magic == 0x46546C67 and version == 2
    off = 12
    json_chunk = bin_chunk = None
    while off < length:
        clen, ctype = struct.unpack_from("<II", glb, off)
        data = glb[off + 8 : off + 8 + clen]
        if ctype == 0x4E4F534A:
            json_chunk = json.loads(data.decode("utf-8"))
        elif ctype == 0x004E4942:
            bin_chunk = data
        off += 8 + clen
    tree = json_chunk
    views = tree["bufferViews"]
    image_views = {img["bufferView"] for img in tree.get("images", []) if "bufferView" in img}
    files = {}
    new_index = {}
    new_views = []
    blob = bytearray()
    for i, view in enumerate(views):
        start = view.get("byteOffset", 0)
        data = bin_chunk[start : start + view["byteLength"]]
        if i in image_views:
            continue
        while len(blob) % 4:
            blob.append(0)
        nv = dict(view)
        nv["buffer"] = 0
        nv["byteOffset"] = len(blob)
        blob += data
        new_index[i] = len(new_views)
        new_views.append(nv)
    while len(blob) % 4:
        blob.append(0)
    for k, img in enumerate(tree.get("images", [])):
        if "bufferView" in img:
            view = views[img["bufferView"]]
            start = view.get("byteOffset", 0)
            files[image_names[k]] = bytes(bin_chunk[start : start + view["byteLength"]])
            del img["bufferView"]
            img["uri"] = image_names[k]
    for acc in tree.get("accessors", []):
        if "bufferView" in acc:
            acc["bufferView"] = new_index[acc["bufferView"]]
    tree["bufferViews"] = new_views
    tree["buffers"] = [{"uri": bin_name, "byteLength": len(blob)}]
    files[bin_name] = bytes(blob)
    return tree, files


def make_scene_files() -> None:
    scene = build_trimesh_scene()
    glb = scene.export(file_type="glb", include_normals=True)
    write_bytes("scene.glb", glb)
    tree, files = split_glb(glb, "scene.bin", ["checker.png"])
    for name, data in files.items():
        write_bytes(name, data)
    write_bytes("scene.gltf", (json.dumps(tree, indent=1, sort_keys=False) + "\n").encode("utf-8"))


# --------------------------------------------------------------------------------------------
# c: morph.glb and skinned.glb (pygltflib)
# --------------------------------------------------------------------------------------------
class GltfBuilder:
    def __init__(self):
        self.gltf = GLTF2(asset=Asset(version="2.0", generator=f"pygltflib {pygltflib.__version__} via {GENERATOR}"))
        self.blob = bytearray()

    def view(self, data: bytes, target=None) -> int:
        while len(self.blob) % 4:
            self.blob.append(0)
        bv = BufferView(buffer=0, byteOffset=len(self.blob), byteLength=len(data))
        if target is not None:
            bv.target = target
        self.blob += data
        self.gltf.bufferViews.append(bv)
        return len(self.gltf.bufferViews) - 1

    def accessor(self, arr: np.ndarray, type_: str, target=None, minmax=False, normalized=None) -> int:
        arr = np.ascontiguousarray(arr)
        ctype = {
            np.dtype("float32"): pygltflib.FLOAT,
            np.dtype("uint32"): pygltflib.UNSIGNED_INT,
            np.dtype("uint16"): pygltflib.UNSIGNED_SHORT,
            np.dtype("uint8"): pygltflib.UNSIGNED_BYTE,
        }[arr.dtype]
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}[type_]
        count = arr.size // ncomp
        bv = self.view(arr.astype(arr.dtype.newbyteorder("<")).tobytes(), target)
        acc = Accessor(bufferView=bv, byteOffset=0, componentType=ctype, count=count, type=type_)
        if normalized:
            acc.normalized = True
        if minmax:
            flat = arr.reshape(count, ncomp)
            if arr.dtype.kind == "f":
                acc.min = [float(x) for x in flat.min(axis=0)]
                acc.max = [float(x) for x in flat.max(axis=0)]
            else:
                acc.min = [int(x) for x in flat.min(axis=0)]
                acc.max = [int(x) for x in flat.max(axis=0)]
        self.gltf.accessors.append(acc)
        return len(self.gltf.accessors) - 1

    def finish(self, name: str) -> None:
        while len(self.blob) % 4:
            self.blob.append(0)
        self.gltf.buffers.append(Buffer(byteLength=len(self.blob)))
        self.gltf.set_binary_blob(bytes(self.blob))
        self.gltf.save_binary(os.path.join(OUT, name))


def smooth_normals(vertices, faces) -> np.ndarray:
    m = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    return np.asarray(m.vertex_normals, dtype=np.float64)


def make_morph() -> None:
    ico = trimesh.creation.icosphere(subdivisions=3, radius=0.6)  # 642 vertices, 1280 faces
    v = np.asarray(ico.vertices, dtype=np.float64)
    f = np.asarray(ico.faces, dtype=np.int64)
    weld_check(v, f)
    n0 = smooth_normals(v, f)
    # target 0 "bulge": a smooth bump around +Y along the normal
    ang = np.arccos(np.clip(v[:, 1] / np.linalg.norm(v, axis=1), -1, 1))
    bump = 0.35 * np.exp(-(ang**2) / 0.25)
    v_bulge = v + n0 * bump[:, None]
    # target 1 "squash": flatten along Y, widen in X/Z
    v_squash = v * np.array([1.25, 0.6, 1.25])
    targets = []
    for vt in (v_bulge, v_squash):
        nt = smooth_normals(vt, f)
        targets.append(((vt - v).astype(np.float32), (nt - n0).astype(np.float32)))

    b = GltfBuilder()
    g = b.gltf
    pos = b.accessor(v.astype(np.float32), "VEC3", pygltflib.ARRAY_BUFFER, minmax=True)
    nrm = b.accessor(n0.astype(np.float32), "VEC3", pygltflib.ARRAY_BUFFER)
    idx = b.accessor(f.astype(np.uint16).reshape(-1), "SCALAR", pygltflib.ELEMENT_ARRAY_BUFFER, minmax=True)
    prim_targets = []
    for dp, dn in targets:
        prim_targets.append(
            {
                "POSITION": b.accessor(dp, "VEC3", pygltflib.ARRAY_BUFFER, minmax=True),
                "NORMAL": b.accessor(dn, "VEC3", pygltflib.ARRAY_BUFFER),
            }
        )
    g.materials.append(
        Material(
            name="clay",
            pbrMetallicRoughness=PbrMetallicRoughness(
                baseColorFactor=[0.8, 0.55, 0.4, 1.0], metallicFactor=0.0, roughnessFactor=0.9
            ),
        )
    )
    prim = Primitive(
        attributes=pygltflib.Attributes(POSITION=pos, NORMAL=nrm),
        indices=idx,
        material=0,
        mode=pygltflib.TRIANGLES,
        targets=prim_targets,
    )
    g.meshes.append(
        Mesh(name="blob_mesh", primitives=[prim], weights=[0.0, 0.5], extras={"targetNames": ["bulge", "squash"]})
    )
    g.nodes.append(Node(name="morph_root", children=[1], translation=[0.0, 0.5, 0.0]))
    g.nodes.append(Node(name="blob", mesh=0, rotation=[float(x) for x in quat_xyzw((1, 0, 0), 15.0)]))
    g.scenes.append(Scene(name="morph_scene", nodes=[0]))
    g.scene = 0
    # animation of the morph weights: 5 keys, 2 weights per key
    times = np.array([0.0, 0.5, 1.0, 1.5, 2.0], dtype=np.float32)
    weights = np.array([[0.0, 0.5], [1.0, 0.5], [1.0, 0.0], [0.0, 1.0], [0.0, 0.5]], dtype=np.float32)
    t_acc = b.accessor(times, "SCALAR", minmax=True)
    w_acc = b.accessor(weights.reshape(-1), "SCALAR")
    g.animations.append(
        Animation(
            name="breathe",
            samplers=[AnimationSampler(input=t_acc, output=w_acc, interpolation="LINEAR")],
            channels=[AnimationChannel(sampler=0, target=AnimationChannelTarget(node=1, path="weights"))],
        )
    )
    b.finish("morph.glb")


def make_skinned() -> None:
    # a capsule standing on the XZ plane, along +Y, from y=0 to y=2.4
    cap = trimesh.creation.capsule(height=1.8, radius=0.3, count=[16, 16])
    v = np.asarray(cap.vertices, dtype=np.float64)
    f = np.asarray(cap.faces, dtype=np.int64)
    # capsule is along Z: rotate Z -> Y (x, y, z) -> (x, z, -y) keeps orientation
    v = np.stack([v[:, 0], v[:, 2], -v[:, 1]], axis=1)
    v[:, 1] -= v[:, 1].min()
    v = np.round(v, 6)
    weld_check(v, f)
    n = smooth_normals(v, f)
    height = v[:, 1].max()
    knee = 0.5 * height
    # weights: smooth blend over +-0.3 around the knee
    s = np.clip((v[:, 1] - (knee - 0.3)) / 0.6, 0.0, 1.0)
    w_upper = (s * s * (3 - 2 * s)).astype(np.float32)
    w_lower = (1.0 - w_upper).astype(np.float32)
    joints = np.zeros((len(v), 4), dtype=np.uint8)
    joints[:, 1] = np.where(w_upper > 0, 1, 0)  # joint index 0 wherever the weight is 0
    weights = np.zeros((len(v), 4), dtype=np.float32)
    weights[:, 0] = w_lower
    weights[:, 1] = w_upper
    # vertices entirely on one joint: put that joint first and zero the rest
    only_upper = w_lower == 0.0
    joints[only_upper, 0] = 1
    joints[only_upper, 1] = 0
    weights[only_upper, 0] = 1.0
    weights[only_upper, 1] = 0.0

    b = GltfBuilder()
    g = b.gltf
    pos = b.accessor(v.astype(np.float32), "VEC3", pygltflib.ARRAY_BUFFER, minmax=True)
    nrm = b.accessor(n.astype(np.float32), "VEC3", pygltflib.ARRAY_BUFFER)
    jnt = b.accessor(joints, "VEC4", pygltflib.ARRAY_BUFFER)
    wgt = b.accessor(weights, "VEC4", pygltflib.ARRAY_BUFFER)
    idx = b.accessor(f.astype(np.uint16).reshape(-1), "SCALAR", pygltflib.ELEMENT_ARRAY_BUFFER, minmax=True)
    g.materials.append(
        Material(
            name="rubber",
            pbrMetallicRoughness=PbrMetallicRoughness(
                baseColorFactor=[0.2, 0.6, 0.3, 1.0], metallicFactor=0.0, roughnessFactor=0.7
            ),
        )
    )
    g.meshes.append(
        Mesh(
            name="leg_mesh",
            primitives=[
                Primitive(
                    attributes=pygltflib.Attributes(POSITION=pos, NORMAL=nrm, JOINTS_0=jnt, WEIGHTS_0=wgt),
                    indices=idx,
                    material=0,
                    mode=pygltflib.TRIANGLES,
                )
            ],
        )
    )
    # nodes: 0 "leg" (skinned mesh, scene root, no transform), 1 "hip" (root joint),
    # 2 "knee" (child joint)
    hip_t = np.array([0.0, 0.1, 0.0])
    knee_t = np.array([0.0, round(knee - 0.1, 6), 0.0])
    g.nodes.append(Node(name="leg", mesh=0, skin=0))
    g.nodes.append(Node(name="hip", children=[2], translation=[float(x) for x in hip_t]))
    g.nodes.append(Node(name="knee", translation=[float(x) for x in knee_t]))
    # inverse bind matrices: inverse of each joint's world matrix (pure translations here),
    # column-major
    ibm = []
    for world_t in (hip_t, hip_t + knee_t):
        m = np.eye(4)
        m[:3, 3] = -world_t
        ibm.append(m.T.reshape(-1))
    ibm_acc = b.accessor(np.array(ibm, dtype=np.float32).reshape(-1), "MAT4")
    g.skins.append(Skin(name="leg_skin", inverseBindMatrices=ibm_acc, joints=[1, 2], skeleton=1))
    g.scenes.append(Scene(name="skinned_scene", nodes=[0, 1]))
    g.scene = 0
    # bend the knee
    times = np.array([0.0, 1.0, 2.0], dtype=np.float32)
    rots = np.array(
        [quat_xyzw((0, 0, 1), 0.0), quat_xyzw((0, 0, 1), 60.0), quat_xyzw((0, 0, 1), 0.0)], dtype=np.float32
    )
    t_acc = b.accessor(times, "SCALAR", minmax=True)
    r_acc = b.accessor(rots, "VEC4")
    g.animations.append(
        Animation(
            name="bend",
            samplers=[AnimationSampler(input=t_acc, output=r_acc, interpolation="LINEAR")],
            channels=[AnimationChannel(sampler=0, target=AnimationChannelTarget(node=2, path="rotation"))],
        )
    )
    b.finish("skinned.glb")


# --------------------------------------------------------------------------------------------
# d: textured.obj (+ .mtl + .png): quad-sphere, own writer
# --------------------------------------------------------------------------------------------
def make_obj(n=8) -> None:
    # six cube faces: (normal axis, u axis, v axis) with u x v = normal (CCW from outside)
    cube_faces = [
        ("px", (1, 0, 0), (0, 0, -1), (0, 1, 0)),
        ("nx", (-1, 0, 0), (0, 0, 1), (0, 1, 0)),
        ("py", (0, 1, 0), (1, 0, 0), (0, 0, -1)),
        ("ny", (0, -1, 0), (1, 0, 0), (0, 0, 1)),
        ("pz", (0, 0, 1), (1, 0, 0), (0, 1, 0)),
        ("nz", (0, 0, -1), (-1, 0, 0), (0, 1, 0)),
    ]
    key_to_vertex: dict[tuple[int, int, int], int] = {}
    positions: list[np.ndarray] = []
    texcoords: list[tuple[float, float]] = []
    groups = []  # (group name, material, list of quads [(v, vt, vn) * 4])
    for name, nn, uu, vv in cube_faces:
        nn, uu, vv = (np.array(x, dtype=np.int64) for x in (nn, uu, vv))
        assert (np.cross(uu, vv) == nn).all()
        vid = np.empty((n + 1, n + 1), dtype=np.int64)
        tid = np.empty((n + 1, n + 1), dtype=np.int64)
        for i in range(n + 1):
            for j in range(n + 1):
                lattice = n * nn + (2 * i - n) * uu + (2 * j - n) * vv  # integer cube lattice
                key = tuple(int(x) for x in lattice)
                if key not in key_to_vertex:
                    c = np.tan(np.pi / 4 * lattice / n)  # equal-angle cube -> sphere
                    key_to_vertex[key] = len(positions)
                    positions.append(c / np.linalg.norm(c))
                vid[i, j] = key_to_vertex[key]
                tid[i, j] = len(texcoords)
                texcoords.append((i / n, j / n))
        quads = []
        for i in range(n):
            for j in range(n):
                corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                quads.append([(vid[c], tid[c], vid[c]) for c in corners])
        material = "checker" if name in ("py", "ny") else "paint"
        groups.append((name, material, quads))
    pos = np.array(positions)
    # sanity: closed after triangulation
    tris = []
    for _, _, quads in groups:
        for q in quads:
            a, b, c, d = (x[0] for x in q)
            tris += [(a, b, c), (a, c, d)]
    weld_check(pos, np.array(tris))

    nquads = sum(len(q) for _, _, q in groups)
    lines = [
        "# textured.obj: quad-sphere (equal-angle cube sphere), radius 1",
        f"# written by {GENERATOR} (numpy geometry, own OBJ writer)",
        f"# {len(pos)} vertices, {len(texcoords)} texcoords, {len(pos)} normals, {nquads} quads",
        "# licence: MIT OR Apache-2.0 (generated data, no third-party content)",
        "mtllib textured.mtl",
        "o quadsphere",
    ]
    lines += ["v {:.6f} {:.6f} {:.6f}".format(*p) for p in pos]
    lines += ["vt {:.6f} {:.6f}".format(*t) for t in texcoords]
    lines += ["vn {:.6f} {:.6f} {:.6f}".format(*p) for p in pos]  # unit sphere: normal = position
    for name, material, quads in groups:
        lines.append(f"g {name}")
        lines.append(f"usemtl {material}")
        lines.append("s 1")
        for q in quads:
            lines.append("f " + " ".join(f"{v + 1}/{t + 1}/{nm + 1}" for v, t, nm in q))
    write_bytes("textured.obj", ("\n".join(lines) + "\n").encode("ascii"))

    mtl = [
        "# textured.mtl: materials for textured.obj",
        f"# written by {GENERATOR}",
        "",
        "newmtl checker",
        "Ka 0.000000 0.000000 0.000000",
        "Kd 1.000000 1.000000 1.000000",
        "Ks 0.200000 0.200000 0.200000",
        "Ns 50.000000",
        "d 1.000000",
        "illum 2",
        "map_Kd textured.png",
        "",
        "newmtl paint",
        "Ka 0.000000 0.000000 0.000000",
        "Kd 0.800000 0.250000 0.150000",
        "Ks 0.500000 0.500000 0.500000",
        "Ns 100.000000",
        "d 1.000000",
        "illum 2",
    ]
    write_bytes("textured.mtl", ("\n".join(mtl) + "\n").encode("ascii"))
    write_bytes("textured.png", png_bytes(checker_image(64, 4, (250, 250, 240), (200, 40, 40))))


# --------------------------------------------------------------------------------------------
# e: colored.ply / colored_ascii.ply (plyfile)
# --------------------------------------------------------------------------------------------
def make_ply() -> None:
    # a torus (genus 1, closed): 64 x 24 sections -> 1536 vertices, 3072 faces. Kept to this
    # size because plyfile writes ASCII floats as %.18g (about 25 characters each).
    tor = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=64, minor_sections=24)
    v = np.asarray(tor.vertices, dtype=np.float64)
    f = np.asarray(tor.faces, dtype=np.int64)
    weld_check(v, f)
    n = smooth_normals(v, f)
    rng = np.random.default_rng(20240611)
    bumps = 0.04 * np.sin(5 * v[:, 0]) * np.sin(4 * v[:, 1]) * np.sin(6 * v[:, 2] + 0.5)
    noise = rng.normal(0.0, 0.003, len(v))
    disp = bumps + noise
    v = (v + n * disp[:, None]).astype(np.float32)
    weld_check(v, f)
    t = (disp - disp.min()) / (disp.max() - disp.min())
    vert = np.empty(
        len(v),
        dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("red", "u1"), ("green", "u1"),
               ("blue", "u1"), ("alpha", "u1"), ("quality", "<f4")],
    )
    vert["x"], vert["y"], vert["z"] = v[:, 0], v[:, 1], v[:, 2]
    vert["red"] = np.round(255 * t)
    vert["green"] = np.round(80 + 100 * (1 - t))
    vert["blue"] = np.round(255 * (1 - t))
    vert["alpha"] = np.where(v[:, 2] > 0, 255, 200)
    vert["quality"] = disp.astype(np.float32)
    fn = trimesh.Trimesh(vertices=v, faces=f, process=False).face_normals
    face = np.empty(
        len(f),
        dtype=[("vertex_indices", "<i4", (3,)), ("red", "u1"), ("green", "u1"), ("blue", "u1"),
               ("flags", "u1")],
    )
    face["vertex_indices"] = f
    face["red"] = np.round(127.5 * (fn[:, 0] + 1))
    face["green"] = np.round(127.5 * (fn[:, 1] + 1))
    face["blue"] = np.round(127.5 * (fn[:, 2] + 1))
    face["flags"] = (np.arange(len(f)) % 4 == 0).astype(np.uint8) | ((fn[:, 2] > 0).astype(np.uint8) << 1)
    els = [
        PlyElement.describe(vert, "vertex"),
        PlyElement.describe(face, "face", len_types={"vertex_indices": "u1"}, val_types={"vertex_indices": "i4"}),
    ]
    comments = [
        f"written by {GENERATOR} with plyfile",
        "bumpy torus; vertex quality = radial displacement; face flags bit0 = every 4th face, bit1 = normal z > 0; vertex alpha 255 where z > 0 else 200",
    ]
    PlyData(els, text=False, byte_order="<", comments=comments).write(os.path.join(OUT, "colored.ply"))
    PlyData(els, text=True, comments=comments).write(os.path.join(OUT, "colored_ascii.ply"))


def main() -> int:
    os.makedirs(OUT, exist_ok=True)
    make_scene_files()
    make_morph()
    make_skinned()
    make_obj()
    make_ply()
    for name in sorted(os.listdir(OUT)):
        print(f"{os.path.getsize(os.path.join(OUT, name)):8d}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
