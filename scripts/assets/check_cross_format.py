#!/usr/bin/env python3
"""Check fairmesh's cross-format outputs in independent loaders (trimesh, pygltflib).

Usage (from the repository root, after building fairmesh):

    OUT=$(mktemp -d)
    target/release/fairmesh fair tests/data/roundtrip/scene.glb -o $OUT/scene.obj
    target/release/fairmesh fair tests/data/roundtrip/textured.obj -o $OUT/textured.glb
    target/release/fairmesh fair tests/data/roundtrip/textured.obj -o $OUT/sub/textured.gltf
    target/release/fairmesh fair tests/data/roundtrip/scene.glb -o $OUT/scene.ply
    .venv/bin/python scripts/assets/check_cross_format.py $OUT

It asserts what the outputs must keep: glTF -> OBJ: the node names as objects, the
two materials with the texture image beside the .mtl, UVs; OBJ -> glTF: named nodes and meshes,
one primitive per material, pbrMetallicRoughness with the texture, UVs and normals; glTF -> PLY:
colours, UVs and normals. Prints what it checked; exits non-zero on the first failure.
"""

import os
import sys

import numpy as np
import pygltflib
import trimesh


def check_obj(out):
    path = os.path.join(out, "scene.obj")
    scene = trimesh.load(path, force="scene", group_material=False, split_objects=True)
    names = sorted(scene.geometry.keys())
    print("scene.obj: trimesh geometries", names)
    assert any("ball" in n for n in names) and any("block" in n for n in names), names
    materials = {}
    for name, geometry in scene.geometry.items():
        material = geometry.visual.material
        materials[material.name] = material
        uv = getattr(geometry.visual, "uv", None)
        if "ball" in name:
            assert uv is not None and len(uv) == len(geometry.vertices), "ball UVs"
            assert np.isfinite(uv).all()
            print(f"  {name}: {len(geometry.vertices)} vertices with UVs, material {material.name}")
    assert {"checker", "paint"} <= set(materials), materials.keys()
    image = getattr(materials["checker"], "image", None)
    assert image is not None and image.size == (64, 64), "checker texture loaded"
    print("  materials", sorted(materials), "checker texture", image.size)


def check_gltf(path):
    gltf = pygltflib.GLTF2().load(path)
    nodes = [n.name for n in gltf.nodes]
    meshes = [m.name for m in gltf.meshes]
    materials = [m.name for m in gltf.materials]
    print(os.path.basename(path), "pygltflib nodes", nodes, "materials", materials)
    assert nodes[0] == "quadsphere" or "quadsphere" in nodes, nodes
    assert sorted(meshes) == sorted(["px", "nx", "py", "ny", "pz", "nz"]), meshes
    assert materials == ["paint", "checker"], materials
    checker = gltf.materials[1].pbrMetallicRoughness
    assert checker.baseColorTexture is not None
    for mesh in gltf.meshes:
        assert len(mesh.primitives) == 1
        attributes = mesh.primitives[0].attributes
        assert attributes.TEXCOORD_0 is not None and attributes.NORMAL is not None
    scene = trimesh.load(path, force="scene")
    total = 0
    for name, geometry in scene.geometry.items():
        uv = geometry.visual.uv
        assert uv is not None and len(uv) == len(geometry.vertices) and np.isfinite(uv).all()
        total += len(geometry.faces)
    print(f"  trimesh: {len(scene.geometry)} geometries with UVs, {total} faces")
    assert total == 768, total


def check_ply(out):
    path = os.path.join(out, "scene.ply")
    mesh = trimesh.load(path, process=False)
    # trimesh reads s t as UVs (and then keeps the colours aside): check those, and the
    # colours with plyfile.
    uv = mesh.visual.uv
    print("scene.ply: trimesh", len(mesh.vertices), "vertices, UVs", uv.shape)
    assert uv.shape == (len(mesh.vertices), 2) and np.isfinite(uv).all()
    import plyfile

    ply = plyfile.PlyData.read(path)
    names = [p.name for p in ply["vertex"].properties]
    print("  plyfile vertex properties", names)
    assert names == ["x", "y", "z", "nx", "ny", "nz", "s", "t", "red", "green", "blue", "alpha"]
    rgb = np.stack([ply["vertex"][c] for c in ("red", "green", "blue")], axis=1)
    assert (rgb != 255).any(), "the block's colours"
    n = np.stack([ply["vertex"][c] for c in ("nx", "ny", "nz")], axis=1)
    assert np.allclose(np.linalg.norm(n, axis=1), 1, atol=1e-5)


def main():
    out = sys.argv[1]
    check_obj(out)
    check_gltf(os.path.join(out, "textured.glb"))
    check_gltf(os.path.join(out, "sub", "textured.gltf"))
    check_ply(out)
    print("all checks passed")


if __name__ == "__main__":
    main()
