"""The browser test's downloads against the command-line tool (scripts/test_web.sh runs it).

For each run (`<tag>-export.json` in the results folder): the exported .zip holds the OBJ, its
.mtl and its texture; the OBJ's positions equal `fairmesh multires --level N` of the same file
within 1e-5 of the bounding box's diagonal, its other lines (mtllib, usemtl, vt, f) are the
CLI's, and the .mtl and texture are the input's bytes. The level chain's .zip holds one GLB per
level, each byte for byte the file `fairmesh hierarchy --write-levels --format glb
--keep-creases` writes (the editor keeps sharp edges by default, as `--keep-creases` asks). The
broken file's error in the page ends with the error `fairmesh info` prints for it. Prints one
line per check and the count.
"""

import json
import pathlib
import subprocess
import sys
import tempfile
import zipfile

results, data, fairmesh = (pathlib.Path(a) for a in sys.argv[1:4])
passed = failed = 0


def check(name, ok, detail=""):
    global passed, failed
    passed += ok
    failed += not ok
    print(f"{'ok' if ok else 'FAILED'} {name}{': ' + detail if detail else ''}")


def positions(text):
    return [tuple(float(x) for x in line.split()[1:4]) for line in text.splitlines() if line.startswith("v ")]


for export in sorted(results.glob("*-export.json")):
    tag = export.name[: -len("-export.json")]
    run = json.loads(export.read_text())
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        subprocess.run([str(fairmesh), "multires", str(data / "textured.obj"), "--level", str(run["level"]),
                        "-o", str(tmp / "textured_faired.obj")], check=True, capture_output=True)
        with zipfile.ZipFile(run["file"]) as archive:
            names = sorted(archive.namelist())
            got = {name: archive.read(name) for name in names}
        check(f"[{tag}] the zip holds the OBJ, its .mtl and texture", names == ["textured.mtl", "textured.png", "textured_faired.obj"], str(names))
        web_obj = got.get("textured_faired.obj", b"").decode()
        cli_obj = (tmp / "textured_faired.obj").read_text()
        a, b = positions(web_obj), positions(cli_obj)
        if len(a) == len(b) and a:
            lows = [min(p[i] for p in b) for i in range(3)]
            highs = [max(p[i] for p in b) for i in range(3)]
            diagonal = sum((h - l) ** 2 for h, l in zip(highs, lows)) ** 0.5
            worst = max(max(abs(p[i] - q[i]) for i in range(3)) for p, q in zip(a, b)) / diagonal
            check(f"[{tag}] the export equals fairmesh multires --level {run['level']}", worst <= 1e-5,
                  f"{len(a)} vertices, largest difference {worst:.2e} of the diagonal")
        else:
            check(f"[{tag}] the export equals fairmesh multires --level {run['level']}", False,
                  f"{len(a)} vertices in the page's export, {len(b)} in the CLI's")
        rest = lambda text: [l for l in text.splitlines() if not l.startswith("v ") and not l.startswith("#")]
        check(f"[{tag}] the export keeps the OBJ's other lines (mtllib, usemtl, vt, f)", rest(web_obj) == rest(cli_obj))
        for companion in ("textured.mtl", "textured.png"):
            check(f"[{tag}] {companion} is the input's", got.get(companion) == (data / companion).read_bytes())
        if "levels" in run:
            subprocess.run([str(fairmesh), "hierarchy", str(data / "textured.obj"), "--write-levels", str(tmp / "levels"),
                            "--format", "glb", "--keep-creases"], check=True, capture_output=True)
            cli_levels = sorted((tmp / "levels").glob("level_*.glb"))
            with zipfile.ZipFile(run["levels"]) as archive:
                names = sorted(archive.namelist())
                wanted = [f"textured_levels/textured_L{n:02}.glb" for n in range(len(cli_levels))]
                check(f"[{tag}] the level chain's zip holds every level as a GLB", names == wanted and len(names) == run["level_count"],
                      f"{len(names)} files in the zip, {len(cli_levels)} levels from the CLI, {run['level_count']} in the page")
                differ = [name for name, cli in zip(wanted, cli_levels) if name not in names or archive.read(name) != cli.read_bytes()]
            check(f"[{tag}] each level equals fairmesh hierarchy --write-levels --format glb, byte for byte", not differ and names == wanted,
                  f"differing: {differ}" if differ else f"{len(wanted)} levels")

cli = subprocess.run([str(fairmesh), "info", str(data / "broken.obj")], capture_output=True, text=True)
cli_error = cli.stderr.strip().split("broken.obj", 1)[-1]
for error_file in sorted(results.glob("*-broken-error.txt")):
    tag = error_file.name[: -len("-broken-error.txt")]
    page_error = error_file.read_text()
    check(f"[{tag}] the broken file's error is the CLI's", cli_error != "" and page_error.endswith(cli_error) and "broken.obj" in page_error,
          f"page: {page_error!r}; CLI: {cli.stderr.strip()!r}")

print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed or passed == 0 else 0)
