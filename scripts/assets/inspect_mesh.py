#!/usr/bin/env python3
"""Print a plain summary of mesh files, as an independent loader sees them.

Usage (from the repository root):

    .venv/bin/python scripts/assets/inspect_mesh.py FILE [FILE...]
    .venv/bin/python scripts/assets/inspect_mesh.py --json FILE   # one JSON object per file

For every file it prints what trimesh loads (geometries, vertex/face counts, UVs, normals,
colours, materials, closed or not after welding by position) and a format-level view:
  .gltf/.glb  with pygltflib: node tree, meshes/primitives and their attributes, materials,
              textures/images, morph targets, skins, animations
  .obj        line-level: v/vt/vn/f counts, face sizes, o/g/usemtl/mtllib/s lines
  .ply        with plyfile: format, elements and their properties
It never stops on a missing attribute or a section it cannot read: it prints the error for that
section and goes on. Exit status: 0 if every file could be opened by at least one reader, 1
otherwise.
"""

from __future__ import annotations

import collections
import json
import os
import sys
import traceback

SUMMARY: dict = {}


def out(line: str = "", indent: int = 0) -> None:
    print("  " * indent + line)


def section(name: str, fn, *args, indent=1) -> bool:
    try:
        fn(*args)
        return True
    except Exception as e:  # noqa: BLE001 - we want to keep going
        out(f"[{name}] could not read: {type(e).__name__}: {e}", indent)
        if os.environ.get("INSPECT_DEBUG"):
            traceback.print_exc()
        return False


# --------------------------------------------------------------------------------------------
# trimesh view
# --------------------------------------------------------------------------------------------
def trimesh_view(path: str, facts: dict) -> None:
    import numpy as np
    import trimesh

    out("trimesh:", 1)
    scene = trimesh.load(path, force="scene", process=False)
    facts["trimesh_geometries"] = {}
    out(f"geometries: {len(scene.geometry)}", 2)
    try:
        graph_nodes = [n for n in scene.graph.nodes if n != scene.graph.base_frame]
        out(f"scene graph nodes (excluding base frame '{scene.graph.base_frame}'): {graph_nodes}", 2)
        facts["trimesh_nodes"] = graph_nodes
    except Exception as e:  # noqa: BLE001
        out(f"scene graph: unreadable ({e})", 2)
    try:
        meshes = [m for m in scene.dump() if hasattr(m, "faces") and len(m.faces) > 0]
        if meshes:
            combined = trimesh.util.concatenate(meshes)
            combined.merge_vertices(merge_tex=True, merge_norm=True)
            facts["combined_closed_after_weld"] = bool(combined.is_watertight)
            out(
                f"all geometry in world space, welded by position: {len(combined.vertices)} vertices,"
                f" {len(combined.faces)} faces, closed: {combined.is_watertight}",
                2,
            )
    except Exception as e:  # noqa: BLE001
        out(f"combined weld check failed: {e}", 2)
    for name, geom in scene.geometry.items():
        g: dict = {"type": type(geom).__name__}
        facts["trimesh_geometries"][name] = g
        out(f"- {name} ({type(geom).__name__})", 2)
        verts = getattr(geom, "vertices", None)
        faces = getattr(geom, "faces", None)
        g["vertices"] = 0 if verts is None else int(len(verts))
        g["faces"] = 0 if faces is None else int(len(faces))
        out(f"vertices: {g['vertices']}  faces: {g['faces']}", 3)
        visual = getattr(geom, "visual", None)
        kind = getattr(visual, "kind", None)
        g["visual_kind"] = kind
        uv = getattr(visual, "uv", None) if visual is not None else None
        g["uv"] = uv is not None and len(uv) > 0
        colors = None
        try:
            if kind == "vertex":
                colors = "vertex"
            elif kind == "face":
                colors = "face"
            elif visual is not None and "color" in getattr(visual, "vertex_attributes", {}):
                colors = "vertex (COLOR_0 alongside a material)"
        except Exception:  # noqa: BLE001
            pass
        g["colors"] = colors
        mat = getattr(visual, "material", None) if visual is not None else None
        mat_name = getattr(mat, "name", None)
        tex = None
        if mat is not None:
            tex = getattr(mat, "baseColorTexture", None) or getattr(mat, "image", None)
        g["material"] = mat_name
        g["material_texture"] = None if tex is None else list(getattr(tex, "size", ()))
        normals_in_file = False
        try:
            normals_in_file = "vertex_normals" in geom._cache.cache
        except Exception:  # noqa: BLE001
            pass
        g["normals_loaded"] = normals_in_file
        out(
            f"visual: {kind}; uv: {g['uv']}; colours: {colors}; material: {mat_name!r}"
            f"; texture: {g['material_texture']}; normals loaded from file: {normals_in_file}",
            3,
        )
        try:
            attrs = sorted(getattr(geom, "vertex_attributes", {}).keys())
            fattrs = sorted(getattr(geom, "face_attributes", {}).keys())
            if attrs or fattrs:
                out(f"extra vertex attributes: {attrs}; face attributes: {fattrs}", 3)
            g["vertex_attributes"] = attrs
            g["face_attributes"] = fattrs
        except Exception:  # noqa: BLE001
            pass
        if faces is not None and len(faces) > 0:
            try:
                if normals_in_file:
                    vn = np.asarray(geom.vertex_normals)
                    fn = np.asarray(geom.face_normals)
                    per_face = np.all(
                        np.einsum("fkj,fj->fk", vn[geom.faces], fn) > 0.9999
                    )
                    split = len(np.unique(geom.faces)) == 3 * len(geom.faces)
                    g["flat_normals"] = bool(per_face)
                    g["vertices_split_per_face"] = bool(split)
                    out(f"normals equal face normals (flat): {bool(per_face)}; vertices split per face: {split}", 3)
                welded = geom.copy()
                welded.merge_vertices(merge_tex=True, merge_norm=True)
                g["welded_vertices"] = int(len(welded.vertices))
                g["closed_after_weld"] = bool(welded.is_watertight)
                out(
                    f"after welding by position: {len(welded.vertices)} vertices, closed: {welded.is_watertight}"
                    f", euler: {welded.euler_number}",
                    3,
                )
            except Exception as e:  # noqa: BLE001
                out(f"weld check failed: {e}", 3)


# --------------------------------------------------------------------------------------------
# glTF view
# --------------------------------------------------------------------------------------------
def gltf_view(path: str, facts: dict) -> None:
    from pygltflib import GLTF2

    out("glTF (pygltflib):", 1)
    g = GLTF2().load(path)
    asset = g.asset
    out(f"asset: version {getattr(asset, 'version', None)}, generator {getattr(asset, 'generator', None)!r}", 2)
    nodes = g.nodes or []
    facts["nodes"] = [n.name for n in nodes]
    facts["node_count"] = len(nodes)
    out(f"nodes: {len(nodes)}", 2)

    def describe_node(i: int) -> str:
        n = nodes[i]
        name = getattr(n, "name", None)
        parts = [f"[{i}] {name!r}"]
        mesh = getattr(n, "mesh", None)
        if mesh is not None:
            mname = g.meshes[mesh].name if mesh < len(g.meshes or []) else "?"
            parts.append(f"mesh={mesh} ({mname!r})")
        for key in ("skin", "camera"):
            if getattr(n, key, None) is not None:
                parts.append(f"{key}={getattr(n, key)}")
        if getattr(n, "matrix", None) is not None:
            parts.append("matrix")
        trs = [k for k in ("translation", "rotation", "scale") if getattr(n, k, None) is not None]
        if trs:
            parts.append("TRS(" + ",".join(k[0].upper() for k in trs) + ")")
        # node.weights is not modelled by every pygltflib version
        weights = getattr(n, "weights", None)
        if weights:
            parts.append(f"weights={weights}")
        return " ".join(parts)

    seen = set()

    def walk(i: int, depth: int) -> None:
        if i in seen or i >= len(nodes):
            out(f"[{i}] (cycle or bad index)", depth)
            return
        seen.add(i)
        out(describe_node(i), depth)
        for c in getattr(nodes[i], "children", None) or []:
            walk(c, depth + 1)

    tree = []
    for si, sc in enumerate(g.scenes or []):
        out(f"scene {si} {sc.name!r}{' (default)' if g.scene == si else ''}: roots {sc.nodes}", 2)
        for r in sc.nodes or []:
            walk(r, 3)
            tree.append(r)
    orphans = [i for i in range(len(nodes)) if i not in seen]
    if orphans:
        out(f"nodes not reachable from a scene: {orphans}", 2)

    parents = {}
    for i, n in enumerate(nodes):
        for c in getattr(n, "children", None) or []:
            parents[c] = i
    facts["node_parents"] = {
        nodes[c].name if c < len(nodes) else c: nodes[p].name for c, p in parents.items()
    }

    materials = g.materials or []
    facts["materials"] = [m.name for m in materials]
    out(f"materials: {len(materials)}", 2)
    for i, m in enumerate(materials):
        pbr = m.pbrMetallicRoughness
        tex = getattr(pbr, "baseColorTexture", None) if pbr is not None else None
        factor = getattr(pbr, "baseColorFactor", None) if pbr is not None else None
        out(f"[{i}] {m.name!r} baseColorTexture={None if tex is None else tex.index} baseColorFactor={factor}", 3)
    for i, img in enumerate(g.images or []):
        where = f"uri={img.uri[:60]!r}" if img.uri else f"bufferView={img.bufferView}"
        out(f"image [{i}] {img.name!r} {where} mimeType={img.mimeType}", 2)
    for i, t in enumerate(g.textures or []):
        out(f"texture [{i}] source={t.source} sampler={t.sampler}", 2)

    accessors = g.accessors or []

    def count(acc):
        try:
            return accessors[acc].count
        except Exception:  # noqa: BLE001
            return None

    facts["meshes"] = []
    out(f"meshes: {len(g.meshes or [])}", 2)
    for mi, mesh in enumerate(g.meshes or []):
        mf = {"name": mesh.name, "primitives": []}
        facts["meshes"].append(mf)
        extras = mesh.extras if isinstance(mesh.extras, dict) else {}
        tn = extras.get("targetNames")
        out(f"[{mi}] {mesh.name!r}: {len(mesh.primitives)} primitive(s); weights={mesh.weights}; targetNames={tn}", 3)
        for pi, p in enumerate(mesh.primitives):
            attrs = {}
            a = p.attributes
            for key, val in (a.__dict__ if hasattr(a, "__dict__") else {}).items():
                if val is not None:
                    attrs[key] = val
            nverts = count(attrs.get("POSITION")) if "POSITION" in attrs else None
            nidx = count(p.indices) if p.indices is not None else None
            mode = p.mode if p.mode is not None else 4
            nfaces = (nidx if nidx is not None else nverts or 0) // 3 if mode == 4 else None
            mat = materials[p.material].name if p.material is not None and p.material < len(materials) else None
            targets = p.targets or []
            pf = {
                "attributes": sorted(attrs),
                "vertices": nverts,
                "faces": nfaces,
                "mode": mode,
                "material": mat,
                "targets": [sorted(t.keys()) if isinstance(t, dict) else str(t) for t in targets],
            }
            mf["primitives"].append(pf)
            out(
                f"primitive {pi}: mode {mode}, vertices {nverts}, triangles {nfaces}, material {mat!r}",
                4,
            )
            out(f"attributes: {sorted(attrs)}", 5)
            if targets:
                out(f"morph targets: {len(targets)}: {pf['targets']}", 5)

    facts["skins"] = []
    for si, s in enumerate(g.skins or []):
        jn = [nodes[j].name if j < len(nodes) else j for j in s.joints or []]
        facts["skins"].append({"name": s.name, "joints": jn})
        ibm = count(s.inverseBindMatrices) if s.inverseBindMatrices is not None else None
        out(f"skin [{si}] {s.name!r}: joints {jn}; skeleton {s.skeleton}; inverseBindMatrices count {ibm}", 2)
    if not g.skins:
        out("skins: none", 2)

    facts["animations"] = []
    for ai, an in enumerate(g.animations or []):
        chans = []
        for c in an.channels or []:
            t = c.target
            nname = nodes[t.node].name if t is not None and t.node is not None and t.node < len(nodes) else None
            chans.append(f"{nname}.{getattr(t, 'path', None)}")
        facts["animations"].append({"name": an.name, "channels": chans})
        out(f"animation [{ai}] {an.name!r}: {len(an.samplers or [])} sampler(s); channels {chans}", 2)
    if not g.animations:
        out("animations: none", 2)
    out(f"extensionsUsed: {g.extensionsUsed or []}; extensionsRequired: {g.extensionsRequired or []}", 2)


# --------------------------------------------------------------------------------------------
# OBJ view
# --------------------------------------------------------------------------------------------
def obj_view(path: str, facts: dict) -> None:
    out("OBJ lines:", 1)
    counts = collections.Counter()
    face_sizes = collections.Counter()
    face_forms = collections.Counter()
    names = collections.defaultdict(list)
    comments = []
    with open(path, "r", encoding="utf-8", errors="replace") as f:
        for line in f:
            s = line.strip()
            if not s:
                continue
            if s.startswith("#"):
                if len(comments) < 5:
                    comments.append(s)
                continue
            key, _, rest = s.partition(" ")
            counts[key] += 1
            if key == "f":
                corners = rest.split()
                face_sizes[len(corners)] += 1
                c = corners[0].split("/")
                form = "v" + ("/vt" if len(c) > 1 and c[1] else "") + ("/vn" if len(c) > 2 and c[2] else "")
                face_forms[form] += 1
            elif key in ("o", "g", "usemtl", "mtllib", "s"):
                if rest not in names[key]:
                    names[key].append(rest)
    facts["obj"] = {
        "counts": dict(counts),
        "face_sizes": {str(k): v for k, v in sorted(face_sizes.items())},
        "face_forms": dict(face_forms),
        "names": dict(names),
    }
    out(f"header comments: {comments}", 2)
    out(f"v {counts['v']}, vt {counts['vt']}, vn {counts['vn']}, f {counts['f']}", 2)
    out(f"face sizes (corners: count): {dict(sorted(face_sizes.items()))}; index forms: {dict(face_forms)}", 2)
    for key in ("mtllib", "o", "g", "usemtl", "s"):
        out(f"{key}: {names.get(key, [])}", 2)
    for lib in names.get("mtllib", []):
        lib_path = os.path.join(os.path.dirname(path), lib)
        if not os.path.exists(lib_path):
            out(f"material library {lib!r}: MISSING", 2)
            continue
        mats = []
        cur = None
        with open(lib_path, "r", encoding="utf-8", errors="replace") as f:
            for line in f:
                parts = line.split()
                if not parts:
                    continue
                if parts[0] == "newmtl":
                    cur = {"name": " ".join(parts[1:])}
                    mats.append(cur)
                elif cur is not None and parts[0].startswith("map_"):
                    tex = " ".join(parts[1:])
                    cur[parts[0]] = tex
                    cur[parts[0] + "_exists"] = os.path.exists(os.path.join(os.path.dirname(path), tex))
                elif cur is not None and parts[0] in ("Kd", "Ka", "Ks"):
                    cur[parts[0]] = parts[1:]
        facts.setdefault("mtl", []).extend(mats)
        out(f"material library {lib!r}: {mats}", 2)


# --------------------------------------------------------------------------------------------
# PLY view
# --------------------------------------------------------------------------------------------
def ply_view(path: str, facts: dict) -> None:
    from plyfile import PlyData

    out("PLY (plyfile):", 1)
    ply = PlyData.read(path)
    fmt = "ascii" if ply.text else f"binary_{'little' if ply.byte_order in ('<', '=') else 'big'}_endian"
    facts["ply_format"] = fmt
    facts["ply_elements"] = {}
    out(f"format: {fmt}; comments: {list(ply.comments)}", 2)
    for el in ply.elements:
        props = []
        for p in el.properties:
            if hasattr(p, "len_dtype"):
                props.append(f"list {p.len_dtype} {p.val_dtype} {p.name}")
            else:
                props.append(f"{p.val_dtype} {p.name}")
        facts["ply_elements"][el.name] = {"count": int(el.count), "properties": [p.name for p in el.properties]}
        out(f"element {el.name} {el.count}: {props}", 2)


def inspect(path: str) -> dict:
    facts: dict = {"file": path}
    out(f"== {path}")
    if not os.path.exists(path):
        out("file does not exist", 1)
        facts["error"] = "missing"
        return facts
    facts["bytes"] = os.path.getsize(path)
    out(f"size: {facts['bytes']} bytes", 1)
    ext = os.path.splitext(path)[1].lower()
    ok = []
    if ext in (".gltf", ".glb"):
        ok.append(section("glTF", gltf_view, path, facts))
    elif ext == ".obj":
        ok.append(section("OBJ", obj_view, path, facts))
    elif ext == ".ply":
        ok.append(section("PLY", ply_view, path, facts))
    ok.append(section("trimesh", trimesh_view, path, facts))
    facts["readable"] = any(ok)
    return facts


def main(argv: list[str]) -> int:
    as_json = "--json" in argv
    files = [a for a in argv if a != "--json"]
    if not files:
        print(__doc__)
        return 2
    results = []
    for path in files:
        if as_json:
            # keep the human lines off stdout so the JSON stays parseable
            real = sys.stdout
            sys.stdout = sys.stderr
            try:
                results.append(inspect(path))
            finally:
                sys.stdout = real
            print(json.dumps(results[-1], default=str))
        else:
            results.append(inspect(path))
    return 0 if all(r.get("readable") for r in results) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
