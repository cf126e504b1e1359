"""Type stubs of fairmesh: constrained fairing of triangle meshes on numpy arrays.

``vertices``: an (n, 3) array of float32 or float64 (read where it lies when it is contiguous);
``faces``: an (m, 3) array of any integer type, indices into ``vertices``. Results are new
arrays; vertex results keep the float type of the vertices given (a loaded ``Mesh``: float64).
"""

import os
from typing import Any, Callable, List, Literal, Optional, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

from ._reports import CompareReport as CompareReport
from ._reports import DenoiseReport as DenoiseReport
from ._reports import Distance as Distance
from ._reports import FairPhases as FairPhases
from ._reports import FairReport as FairReport

__version__: str

Vertices = npt.ArrayLike
Faces = npt.ArrayLike
PathLike = Union[str, os.PathLike]
Progress = Callable[[float], Optional[bool]]
"""Called on the calling thread with every new fraction done (0 to 1) that the work reports, in
order, then with 1.0 when the call completes (unless the work reported it last): ``fair`` reports
after every round, ``hierarchy`` as it removes vertices, ``multires`` after every level. The work
does not wait for the callback, which is called between polls (every 40 ms) with what came
since. Returning False stops the call at the work's next report: it then raises ``Cancelled``."""
Mask = npt.ArrayLike
"""Which vertices to fair, one of: a bool array of one value per vertex (True: fair it); a float
array of one weight per vertex (0: kept exactly, 1: faired fully, between: faded); an integer
array of the indices of the vertices to fair. An integer array of one 0 or 1 per vertex could be
read either way and is refused: write it as bools (``mask.astype(bool)``) or as indices
(``mask.nonzero()[0]``)."""

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
    limit).

    A ``Mesh`` pickles as its file (for a process pool): unpickling reads the file again, by
    its absolute path, so it must be readable there, and refuses it with ``ValueError`` if it
    changed since."""

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
    def denoise(self) -> Optional[DenoiseReport]:
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
        mask: Optional[Mask] = None,
        mask_falloff: int = 0,
        progress: Optional[Progress] = None,
        threads: Optional[int] = None,
    ) -> npt.NDArray[np.floating]:
        """Multiresolution fairing (``fairmesh multires --level START_LEVEL``, on the hierarchy
        as built: denoised first only if ``hierarchy`` was given ``denoise``): fair from
        ``start_level`` (the coarser, the smoother; 0 is level 0 itself; beyond the coarsest,
        the coarsest) down to full detail. Returns level 0's vertices smoothed, (n, 3); level
        0's faces apply.

        - ``iterations`` (5), ``rounds`` (1): constrained fairing on each level.
        - ``boundary``: "curve" or "fixed", as for ``fair``.
        - ``fair_finest``: also fair level 0 itself at the end.
        - ``variant``: "improved" (default: split vertices placed by Kobbelt's rule, and the
          shrinkage of the low frequencies given back) or "paper" (the paper's placement).
        - ``mask`` (see ``Mask``), ``mask_falloff``: as for ``fair``; the vertices outside keep
          their positions exactly. After a denoise, the result is faded into the input itself.
        - ``progress``, ``threads``: as for ``fair``; Ctrl+C stops it too."""

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
    variant: Literal["improved", "paper", "normal-projected", "projected"] = "improved",
    lambda_: Optional[float] = None,
    mu: Optional[float] = None,
    alpha: Optional[float] = None,
    beta: Optional[float] = None,
    mask: Optional[Mask] = None,
    mask_falloff: int = 0,
    hard_edges: Optional[npt.ArrayLike] = None,
    measure: bool = False,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], FairReport]: ...
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
    variant: Literal["improved", "paper", "normal-projected", "projected"] = "improved",
    lambda_: Optional[float] = None,
    mu: Optional[float] = None,
    alpha: Optional[float] = None,
    beta: Optional[float] = None,
    mask: Optional[Mask] = None,
    mask_falloff: int = 0,
    hard_edges: Optional[npt.ArrayLike] = None,
    measure: bool = False,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.floating], FairReport]:
    """Smooth a mesh without shrinking it: ``fairmesh fair`` on arrays.

    Returns ``(vertices, report)``: the smoothed vertices (a new (n, 3) array, float32 for
    float32 input, else float64) and a ``FairReport`` dict with the fields of
    ``fairmesh fair --json`` (``rounds_run``, ``iterations_run``, ``noise_estimate``,
    ``volume_change_percent``, ``time_ms``, ...; ``input`` is the loaded file's path or None,
    ``output`` None).

    ``vertices`` may be a loaded ``Mesh`` (``faces`` left out): its file's sharp edges are then
    kept too, exactly as the command line does.

    Options (the command line's, ``--no-creases`` as ``no_creases=True``):

    - ``method``: "constrained" (the paper's, default) or a baseline that shrinks:
      "laplacian", "taubin", "hc".
    - ``iterations``: per round for constrained fairing (10); for a baseline, its steps.
    - ``rounds``: None (default) estimates the noise (a clean mesh is left as it is) and fairs
      round by round while the estimated error falls; a number fairs exactly that many rounds.
    - ``crease_angle`` (40 degrees) / ``no_creases``: sharp edges kept, or faired across.
    - ``tangential``: weight 0 to 1 of the relaxation along the surface, at every vertex (None:
      0.1 where needed).
    - ``no_volume_correction``: do not give each part its volume back after every round.
    - ``tolerance``: stop a round once no vertex moves more than this many mean edge lengths
      (None: once it has settled, 0.001; 0: run every iteration).
    - ``boundary``: "curve" (boundary loops smoothed as curves) or "fixed".
    - ``variant``: "improved" (default: the paper's update kept along the normal, so vertices
      do not slide along the surface) or "paper" (the paper's operator exactly), the words
      ``multires`` and ``fairmesh fair --variant`` use. The old names "normal-projected" and
      "projected" are accepted; the report names the variant "improved" or "paper".
    - ``lambda_``, ``mu``: the Laplacian and Taubin steps; ``alpha``, ``beta`` (0 to 1): HC's
      weight of the input in the pull back, and of a vertex's own correction against its
      neighbours' (``hierarchy``'s ``alpha`` and ``beta`` are something else).
    - ``mask``: fair only these vertices (see ``Mask``): one bool or float weight (0 to 1) per
      vertex, or vertex indices; ``mask_falloff`` fades its edge over that many rings.
    - ``hard_edges``: (k, 2) vertex pairs kept sharp with the creases found.
    - ``measure``: add the distances to the input (``mean_surface_distance``, ``hausdorff``,
      ``rms``, ``normal_error_deg``) to the report.
    - ``progress``: called with the fraction done after every round (see ``Progress``); return
      False to stop (raises ``Cancelled``).
    - ``threads``: None runs on this process's pool (every core); a number runs the call on that
      many threads of its own (``threads=1`` to fair many meshes side by side).

    Threads and processes: the GIL is released while the call works, so Python threads run
    meanwhile. Ctrl+C raises ``KeyboardInterrupt`` in a call made on the main thread; Python
    delivers signals to the main thread only, so a call in another thread runs on until its
    ``progress`` callback returns False (have the main thread set a ``threading.Event`` that
    the callback reads). Processes made by ``fork``, ``forkserver`` or ``spawn`` all work, before
    or after the parent used fairmesh: each process runs its own thread pool.

    Raises ``ValueError`` or ``TypeError`` naming the argument at fault."""

def noise(
    vertices: Vertices,
    faces: Faces,
    *,
    sigma: float = 0.3,
    seed: int = 1,
    mode: Literal["normal", "direction", "iso"] = "normal",
) -> npt.NDArray[np.floating]:
    """Seeded Gaussian noise (``fairmesh noise``): returns new vertices, the input's moved.

    - ``sigma``: the noise's standard deviation, in mean edge lengths (0 or more).
    - ``seed``: the same seed gives the same noise on every machine.
    - ``mode``: "normal" (along each vertex normal), "direction" (along one random direction per
      vertex) or "iso" (a Gaussian on each coordinate)."""

def compare(
    reference_vertices: Vertices,
    reference_faces: Faces,
    vertices: Vertices,
    faces: Optional[Faces] = None,
) -> CompareReport:
    """Measure a mesh against a reference (``fairmesh compare --json``), as a
    ``CompareReport``: two-way surface distance (``mean_surface_distance``, ``hausdorff``),
    ``volume_change_percent``, and with the same connectivity ``rms``, ``max_distance``,
    ``normal_error_deg``, ``barycenter_drift`` and ``sharpened_edges``.

    ``faces`` None: ``vertices`` are the reference's, moved (one row per reference vertex); a
    mesh of other connectivity needs its own ``faces``."""

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
    keep_orientation: bool = True,
    keep_creases: bool = False,
    crease_angle: Optional[float] = None,
    hard_edges: Optional[npt.ArrayLike] = None,
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
    keep_orientation: bool = True,
    keep_creases: bool = False,
    crease_angle: Optional[float] = None,
    hard_edges: Optional[npt.ArrayLike] = None,
    denoise: Union[None, Literal["auto", "off"], int] = None,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
) -> Hierarchy:
    """Build the decimation hierarchy (``fairmesh hierarchy``; the paper's section 4.1); then
    ``Hierarchy.multires(start_level)`` fairs from any level, again and again.

    Each level removes an independent set of vertices from the one below by half-edge
    collapses, cheapest first, keeping every level a manifold with the input's boundary loops.
    Options (the command line's):

    - ``alpha`` (1.0), ``beta`` (0.01): the weights of a vertex's shortest and longest edge in
      its removal cost, ``alpha * shortest + beta * longest``: vertices in dense regions go
      first. (Not ``fair``'s HC ``alpha``/``beta``.)
    - ``min_vertices`` (100): no level has fewer vertices than this.
    - ``max_levels`` (64): at most this many levels above level 0.
    - ``keep_boundary``: boundary vertices never collapse (the outline stays exact on every
      level).
    - ``keep_orientation`` (True): no collapse may leave a face pointing away from the input
      surface it stands for, or two faces folded over each other; False builds the paper's
      hierarchy, whose check looks only at the level being collapsed (with
      ``multires(level, variant="paper", fair_finest=False)`` on an undenoised hierarchy without
      creases, the paper's recipe exactly).
    - ``keep_creases``: sharp creases (found at ``crease_angle``, 40 degrees unless given; the
      file's own sharp edges too for a loaded ``Mesh``) stay on every level: a crease vertex
      collapses only along its crease and corners never do. Giving ``crease_angle`` implies it.
    - ``hard_edges``: (k, 2) vertex pairs kept sharp with the creases found, as ``fair``'s
      (for a loaded ``Mesh``, instead of its file's sharp edges); giving them implies
      ``keep_creases``.
    - ``denoise``: None or "off" (none), "auto" or a number of rounds: first denoise the mesh as
      ``fair`` does and build the levels on the result, as the editor and ``fairmesh multires``
      do (with ``keep_creases=True`` for their defaults): ``multires(0)`` is then ``fair``'s
      result and ``Hierarchy.denoise`` says what the denoise found.
    - ``progress``, ``threads``: as for ``fair``."""

def follow_texture(
    before: Vertices,
    after: Vertices,
    faces: Faces,
    uvs: npt.ArrayLike,
    uv_faces: Optional[Faces] = None,
) -> npt.NDArray[np.float64]:
    """Texture coordinates that follow the vertices' slide along the surface, as ``Mesh.save``
    moves a file's: fairing moves vertices mostly across the surface and a little along it, and
    a texture coordinate that stays with a vertex that slid drags the texture with it. Each
    moved vertex's texture coordinates are moved to what the texture held, before the move,
    where the vertex slid to (each side of a UV seam in its own chart).

    - ``before``, ``after``: the (n, 3) vertices before and after the move (``fair``'s input
      and result); ``faces``: the (m, 3) triangles.
    - ``uvs``: (k, 2) texture coordinates; ``uv_faces``: (m, 3) indices into ``uvs``, the
      coordinate of each corner of each triangle (None: ``uvs`` has one row per vertex and
      ``faces`` indexes it). A program that keeps one coordinate per corner passes one index
      per corner, or better the distinct (vertex, coordinate) pairs, so that corners of a vertex
      in one chart move as one.

    Returns the new (k, 2) float64 coordinates; those of vertices that did not move are kept
    exactly. A coordinate several moved vertices share cannot follow them all: it is kept, and
    a ``MeshWarning`` says how many. Raises ``ValueError`` or ``TypeError`` naming the argument
    at fault."""

def load(path: PathLike, *, weld: bool = True, progress: Optional[Progress] = None) -> Mesh:
    """Read a mesh file (.obj .gltf .glb .ply .stl .off; ``"@bunny"``: the bundled bunny),
    welded and cleaned as the command line reads it. What was repaired is given as
    ``MeshWarning``. Raises ``FileNotFoundError`` (or another ``OSError``) when the file cannot
    be read, ``MeshFileError`` naming the file and the place when its content is wrong."""

def save(path: PathLike, vertices: Vertices, faces: Faces) -> None:
    """Write a bare mesh (positions and triangles) into ``path``, format by extension.
    ``Mesh.save`` keeps what a loaded file held instead."""
