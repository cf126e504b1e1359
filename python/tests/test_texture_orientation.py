"""Textures stay the right way up through `fairmesh convert` and `fairmesh fair`, as trimesh (an
independent reader) sees them: a textured plane whose image is red in its top half and blue in
its bottom half, written by trimesh as OBJ, GLB and PLY, is converted into the other formats, and
trimesh's per-vertex colours (it samples the texture at each vertex's UV) of every output match
the input's. A PLY holds no image: there trimesh's UVs (it keeps OBJ's convention inside, and
reads and writes PLY's `s t` as they are) must match the input's. Faired, each vertex's UV is
the plane's map where the vertex went.

Needs trimesh and Pillow (scripts/test_python.sh installs both) and the command-line tool (the
`cli` fixture). A PLY converted into another format is checked by tests/texture_orientation.rs:
trimesh keeps no UVs from an OBJ or glTF without a texture, which is what a PLY, naming no image,
becomes."""

import subprocess

import numpy as np
import pytest
import trimesh
from PIL import Image

QUADS = 5


def _plane():
    """The plane (x right, y up), its UVs in trimesh's (OBJ's) convention: the top row of the
    plane maps to the image's top row. No vertex lies on the middle row of the image."""
    n = QUADS + 1
    xs, ys = np.meshgrid(np.arange(n) / QUADS, np.arange(n) / QUADS)
    vertices = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(n * n)])
    faces = []
    for j in range(QUADS):
        for i in range(QUADS):
            a = j * n + i
            faces += [[a, a + 1, a + 1 + n], [a, a + 1 + n, a + n]]
    image = Image.new("RGB", (16, 16))
    for y in range(16):
        for x in range(16):
            image.putpixel((x, y), (255, 0, 0) if y < 8 else (0, 0, 255))
    uv = vertices[:, :2].copy()
    visual = trimesh.visual.TextureVisuals(uv=uv, image=image)
    return trimesh.Trimesh(vertices, np.array(faces), visual=visual, process=False)


def _load(path):
    return trimesh.load(str(path), force="mesh", process=False)


def _by_position(mesh, values):
    """`values` per vertex, keyed by the vertex's position (rounded to 1e-5)."""
    keys = [tuple(np.round(v, 5)) for v in np.asarray(mesh.vertices)]
    return dict(zip(keys, [tuple(v) for v in np.asarray(values)]))


def _colours(mesh):
    return _by_position(mesh, mesh.visual.to_color().vertex_colors[:, :3])


def _uvs(mesh):
    return _by_position(mesh, np.round(np.asarray(mesh.visual.uv), 5))


def _has_uvs(mesh):
    return getattr(mesh.visual, "uv", None) is not None


@pytest.mark.parametrize(
    ("source", "target"),
    [(s, t) for s in ("obj", "glb") for t in ("obj", "glb", "gltf", "ply") if s != t],
)
def test_conversions_keep_each_vertex_colour(tmp_path, cli, source, target):
    plane = _plane()
    input_path = tmp_path / f"in.{source}"
    plane.export(str(input_path))
    output_path = tmp_path / f"out.{target}"
    subprocess.run([cli, "convert", str(input_path), "-o", str(output_path)], check=True,
                   capture_output=True)
    before, after = _load(input_path), _load(output_path)
    # What both say about the UVs, in trimesh's one convention.
    assert _has_uvs(after)
    assert _uvs(after) == _uvs(before)
    # A PLY names no image (trimesh gives it a grey one of its own): colours where both have it.
    if "ply" not in (source, target):
        colours = _colours(after)
        assert colours == _colours(before)
        # And the colours are the plane's: red above its middle, blue below.
        for (x, y, z), colour in colours.items():
            assert colour == ((255, 0, 0) if y > 0.5 else (0, 0, 255)), (x, y, colour)


@pytest.mark.parametrize("target", ["obj", "glb", "ply"])
def test_fair_keeps_each_vertex_colour(tmp_path, cli, target):
    plane = _plane()
    input_path = tmp_path / "in.obj"
    plane.export(str(input_path))
    output_path = tmp_path / f"out.{target}"
    subprocess.run([cli, "fair", str(input_path), "-o", str(output_path)], check=True,
                   capture_output=True)
    after = _load(output_path)
    # Wherever a vertex went on the plane, its UV is the input's map there (u = x, v = y).
    uv = np.asarray(after.visual.uv)
    np.testing.assert_allclose(uv, np.asarray(after.vertices)[:, :2], atol=1e-4)
