"""fairmesh: take noise and unwanted detail out of triangle meshes without shrinking them.

Constrained fairing (Liu, Bao, Heng, Wong, Peng, "Constrained Fairing for Meshes") on numpy
arrays: ``vertices`` is an (n, 3) float array (float32 or float64), ``faces`` an (m, 3) integer
array of vertex indices; results are new numpy arrays and the inputs are never changed.

    import fairmesh
    mesh = fairmesh.load("scan.ply")                # or any (vertices, faces) arrays
    smooth, report = fairmesh.fair(mesh.vertices, mesh.faces)
    print(report["rounds_run"], report["volume_change_percent"])
    mesh.save("scan_faired.ply", smooth)            # the file comes back with new positions

- ``fair``: the command line's ``fair``, options as keyword arguments with its names and
  defaults; the report has the fields of ``fairmesh fair --json``.
- ``noise``, ``compare``: seeded noise; distances and volume change between two meshes.
- ``hierarchy``: the decimation hierarchy, whose ``multires(start_level)`` fairs from a coarse
  level and can be run again and again without building anything again.
- ``follow_texture``: texture coordinates kept with the texture when vertices slide, for a
  program that keeps its own (as ``Mesh.save`` does for files).
- ``load`` / ``Mesh.save``: files kept as the command line keeps them (written back into
  their own format with only the positions changed); ``save`` writes a bare mesh.
- ``fairmesh.trimesh`` and ``fairmesh.open3d``: the same on trimesh meshes and scenes and on
  Open3D meshes, with the copies of a position across UV and normal seams faired as one.
- ``FairReport``, ``CompareReport``, ``DenoiseReport``: the keys and types of the dicts returned.

Long calls release the GIL (other Python threads run meanwhile), take ``progress=callable``
(called with every new fraction done; returning False stops the call with ``Cancelled``) and
stop on Ctrl+C with ``KeyboardInterrupt`` when called on the main thread. Every process runs its
own thread pool, so a ``multiprocessing`` pool works with any start method (``fork`` included),
before or after the parent used fairmesh; a ``Mesh`` pickles (as its file, read again). For
batches of files, see ``help(fairmesh.batch)``.
"""

from ._fairmesh import (
    Cancelled,
    Hierarchy,
    Mesh,
    MeshFileError,
    MeshWarning,
    __version__,
    compare,
    fair,
    follow_texture,
    hierarchy,
    load,
    noise,
    save,
)
from ._reports import CompareReport, DenoiseReport, Distance, FairPhases, FairReport

__all__ = [
    "Cancelled",
    "CompareReport",
    "DenoiseReport",
    "Distance",
    "FairPhases",
    "FairReport",
    "Hierarchy",
    "Mesh",
    "MeshFileError",
    "MeshWarning",
    "__version__",
    "compare",
    "fair",
    "follow_texture",
    "hierarchy",
    "load",
    "noise",
    "save",
]
