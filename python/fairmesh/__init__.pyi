"""Type stubs of fairmesh: constrained fairing of triangle meshes on numpy arrays.

``vertices``: an (n, 3) array of float32 or float64 (read where it lies when it is contiguous);
``faces``: an (m, 3) array of any integer type, indices into ``vertices``. Results are new
arrays; vertex results keep the float type of the vertices given (a loaded ``Mesh``: float64).
"""

import os
from typing import Any, Callable, Dict, List, Literal, Optional, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

Vertices = npt.ArrayLike
Faces = npt.ArrayLike
PathLike = Union[str, os.PathLike]
Progress = Callable[[float], Optional[bool]]
"""Called with the fraction done (0 to 1) on the calling thread; returning False stops the
call, which then raises ``Cancelled``."""

class MeshFileError(ValueError):
    """A mesh file whose content cannot be read or written: the message names the file, the
    place in it (line, byte or element) and what is wrong. A file that cannot be opened at all
    raises ``OSError`` (``FileNotFoundError``, ...) instead."""

    filename: str

class MeshWarning(UserWarning):
    """What loading read leniently or repaired, and what saving could not keep from the file."""

class Cancelled(Exception):
    """The progress callback returned False: the call stopped and gave no result."""

class Mesh:
    """A mesh loaded from a file by ``load``: arrays, and the file kept so that ``save`` writes it
    back with only the positions changed (as ``fairmesh fair IN -o OUT`` does).

    ``fair(mesh)`` works on the loaded mesh itself (no array made, nothing copied but the
    result), so one ``Mesh`` serves one such call at a time: another thread's call on the same
    object meanwhile raises ``RuntimeError`` (``fair(mesh.vertices, mesh.faces)`` has no such
    limit)."""

    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """The welded vertices, (n, 3) float64, read-only."""
    @property
    def faces(self) -> npt.NDArray[np.int64]:
        """The triangles, (m, 3) int64, read-only."""
    @property
    def hard_edges(self) -> npt.NDArray[np.int64]:
        """The file's sharp edges, (k, 2) vertex pairs: split normals and material boundaries
        of an OBJ or glTF. ``fair(mesh)`` keeps them sharp."""
    @property
    def path(self) -> str:
        """The path it was loaded from."""
    @property
    def format(self) -> str:
        """"obj", "gltf", "glb", "ply", "stl" or "off"."""
    @property
    def warnings(self) -> List[str]:
        """What loading read leniently or repaired (also given as ``MeshWarning``)."""
    @property
    def contents(self) -> List[str]:
        """What the file holds beyond positions and triangles (UVs, normals, materials, ...)."""
    @property
    def welded_vertices(self) -> int:
        """How many vertices loading merged because they had the same position."""
    @property
    def closed(self) -> bool:
        """Whether every edge has two triangles."""
    def save(self, path: PathLike, vertices: Optional[Vertices] = None) -> None:
        """Write the mesh with ``vertices`` (n rows; the loaded ones when None) into ``path``,
        format by extension. Into its own format the file comes back with only the positions
        (and what follows them) changed; into another, what that format holds is carried. What
        could not be kept is given as a ``MeshWarning``. Atomic: a failed save leaves no file.

        Raises ``ValueError`` for vertices of another count, ``MeshFileError`` or ``OSError``
        for a path that cannot be written."""

class Hierarchy:
    """The decimation hierarchy of a mesh (``hierarchy(...)``): level 0 is the mesh, each
    further level coarser. ``multires`` can run again and again: each level's set-up is kept."""

    @property
    def level_count(self) -> int:
        """Number of levels, level 0 included."""
    @property
    def coarsest_level(self) -> int:
        """The coarsest level's index (``level_count - 1``)."""
    @property
    def level_sizes(self) -> List[Tuple[int, int]]:
        """(vertices, faces) of every level, level 0 first."""
    @property
    def denoise(self) -> Optional[Dict[str, Any]]:
        """What the denoise before the build found (``rounds_run``, ``noise_estimate``,
        ``crease_edges``), or None when the hierarchy was built without one."""
    def level(
        self, level: int
    ) -> Tuple[npt.NDArray[np.floating], npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """Level ``level`` as (vertices, faces, original): ``original[i]`` is the index in
        level 0 of vertex ``i``, whose position it has."""
    def multires(
        self,
        start_level: int,
        *,
        iterations: int = 5,
        rounds: int = 1,
        boundary: Literal["curve", "fixed"] = "curve",
        fair_finest: bool = True,
        variant: Literal["improved", "paper"] = "improved",
        mask: Optional[npt.ArrayLike] = None,
        mask_falloff: int = 0,
        progress: Optional[Progress] = None,
        threads: Optional[int] = None,
    ) -> npt.NDArray[np.floating]:
        """Multiresolution fairing (``fairmesh multires --level START_LEVEL``, on the hierarchy
        as built: denoised first only if ``hierarchy`` was given ``denoise``): fair from
        ``start_level`` (the coarser, the smoother; 0 is level 0 itself) down to full detail.
        After a denoise, ``mask`` fades the result into the input itself.
        Returns level 0's vertices smoothed, (n, 3); level 0's faces apply. ``mask``: per-vertex
        weights (0 to 1, or bools) or the indices of the vertices to fair; the rest keep their
        positions exactly. Releases the GIL; ``progress`` and Ctrl+C stop it."""

@overload
def fair(
    vertices: Mesh,
    faces: None = None,
    *,
    method: Literal["constrained", "laplacian", "taubin", "hc"] = "constrained",
    iterations: int = 10,
    rounds: Optional[int] = None,
    crease_angle: float = 40.0,
    no_creases: bool = False,
    tangential: Optional[float] = None,
    no_volume_correction: bool = False,
    tolerance: Optional[float] = None,
    boundary: Literal["curve", "fixed"] = "curve",
    variant: Literal["normal-projected", "paper"] = "normal-projected",
    lambda_: Optional[float] = None,
    mu: Optional[float] = None,
    alpha: Optional[float] = None,
    beta: Optional[float] = None,
    mask: Optional[npt.ArrayLike] = None,
    mask_falloff: int = 0,
    hard_edges: Optional[npt.ArrayLike] = None,
    measure: bool = False,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]: ...
@overload
def fair(
    vertices: Vertices,
    faces: Faces,
    *,
    method: Literal["constrained", "laplacian", "taubin", "hc"] = "constrained",
    iterations: int = 10,
    rounds: Optional[int] = None,
    crease_angle: float = 40.0,
    no_creases: bool = False,
    tangential: Optional[float] = None,
    no_volume_correction: bool = False,
    tolerance: Optional[float] = None,
    boundary: Literal["curve", "fixed"] = "curve",
    variant: Literal["normal-projected", "paper"] = "normal-projected",
    lambda_: Optional[float] = None,
    mu: Optional[float] = None,
    alpha: Optional[float] = None,
    beta: Optional[float] = None,
    mask: Optional[npt.ArrayLike] = None,
    mask_falloff: int = 0,
    hard_edges: Optional[npt.ArrayLike] = None,
    measure: bool = False,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.floating], Dict[str, Any]]:
    """Smooth a mesh without shrinking it: ``fairmesh fair`` on arrays.

    Returns ``(vertices, report)``: the smoothed vertices (a new (n, 3) array, float32 for
    float32 input, else float64) and a dict with the fields of ``fairmesh fair --json``
    (``rounds_run``, ``iterations_run``, ``noise_estimate``, ``volume_change_percent``,
    ``time_ms``, ...; ``input`` is the loaded file's path or None, ``output`` None).

    ``vertices`` may be a loaded ``Mesh`` (``faces`` left out): its file's sharp edges are then
    kept too, exactly as the command line does.

    Options (the command line's, ``--no-creases`` as ``no_creases=True``):
    - ``method``: "constrained" (the paper's, default) or a baseline that shrinks:
      "laplacian", "taubin", "hc".
    - ``iterations``: per round for constrained fairing (10).
    - ``rounds``: None (default) estimates the noise (a clean mesh is left as it is) and fairs
      round by round while the estimated error falls; a number fairs exactly that many rounds.
    - ``crease_angle`` (40 degrees) / ``no_creases``: sharp edges kept, or faired across.
    - ``tangential``: weight 0 to 1 of the relaxation along the surface, at every vertex (None:
      0.1 where needed).
    - ``no_volume_correction``: do not give each part its volume back after every round.
    - ``tolerance``: stop a round once no vertex moves more than this many mean edge lengths
      (None: once it has settled, 0.001; 0: run every iteration).
    - ``boundary``: "curve" (boundary loops smoothed as curves) or "fixed".
    - ``variant``: "normal-projected" (default) or "paper" (the paper's method exactly).
    - ``lambda_``, ``mu`` (Laplacian, Taubin), ``alpha``, ``beta`` (HC): the baselines' steps.
    - ``mask``: fair only these vertices: per-vertex weights (0 to 1, or bools) or vertex
      indices; ``mask_falloff`` fades the edge over that many rings.
    - ``hard_edges``: (k, 2) vertex pairs kept sharp with the creases found.
    - ``measure``: add the distances to the input (``mean_surface_distance``, ``hausdorff``,
      ``rms``, ``normal_error_deg``) to the report.
    - ``progress``: called with the fraction done (before every round); return False to stop
      (raises ``Cancelled``). Ctrl+C raises ``KeyboardInterrupt``. The GIL is released.
    - ``threads``: None uses every core; a number runs the call on that many threads of its
      own (``threads=1`` to fair many meshes side by side from Python threads).

    Raises ``ValueError`` or ``TypeError`` naming the argument at fault."""

def noise(
    vertices: Vertices,
    faces: Faces,
    *,
    sigma: float = 0.3,
    seed: int = 1,
    mode: Literal["normal", "direction", "iso"] = "normal",
) -> npt.NDArray[np.floating]:
    """Seeded Gaussian noise (``fairmesh noise``): sigma in mean edge lengths; the same seed
    gives the same noise on every machine. Returns new vertices."""

def compare(
    reference_vertices: Vertices,
    reference_faces: Faces,
    vertices: Vertices,
    faces: Optional[Faces] = None,
) -> Dict[str, Any]:
    """Measure a mesh against a reference (``fairmesh compare --json``): two-way surface
    distance (``mean_surface_distance``, ``hausdorff``), ``volume_change_percent``, and with
    the same connectivity (``faces`` None: the reference's) ``rms``, ``max_distance``,
    ``normal_error_deg``, ``barycenter_drift`` and ``sharpened_edges``."""

@overload
def hierarchy(
    vertices: Mesh,
    faces: None = None,
    *,
    alpha: float = 1.0,
    beta: float = 0.01,
    min_vertices: int = 100,
    max_levels: int = 64,
    keep_boundary: bool = False,
    keep_creases: bool = False,
    crease_angle: Optional[float] = None,
    denoise: Union[None, Literal["auto", "off"], int] = None,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
) -> Hierarchy: ...
@overload
def hierarchy(
    vertices: Vertices,
    faces: Faces,
    *,
    alpha: float = 1.0,
    beta: float = 0.01,
    min_vertices: int = 100,
    max_levels: int = 64,
    keep_boundary: bool = False,
    keep_creases: bool = False,
    crease_angle: Optional[float] = None,
    denoise: Union[None, Literal["auto", "off"], int] = None,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
) -> Hierarchy:
    """Build the decimation hierarchy (``fairmesh hierarchy``), with its options; then
    ``Hierarchy.multires(start_level)`` fairs from any level, again and again.
    ``denoise="auto"`` (or a number of rounds) first denoises the mesh as ``fair`` does and
    builds the levels on the result, as the editor and ``fairmesh multires`` do (with
    ``keep_creases=True`` for their defaults): ``multires(0)`` is then ``fair``'s result and
    ``Hierarchy.denoise`` says what the denoise found."""

def load(path: PathLike, *, weld: bool = True, progress: Optional[Progress] = None) -> Mesh:
    """Read a mesh file (.obj .gltf .glb .ply .stl .off; ``"@bunny"``: the bundled bunny),
    welded and cleaned as the command line reads it. What was repaired is given as
    ``MeshWarning``. Raises ``FileNotFoundError`` (or another ``OSError``) when the file cannot
    be read, ``MeshFileError`` naming the file and the place when its content is wrong."""

def save(path: PathLike, vertices: Vertices, faces: Faces) -> None:
    """Write a bare mesh (positions and triangles) into ``path``, format by extension.
    ``Mesh.save`` keeps what a loaded file held instead."""
