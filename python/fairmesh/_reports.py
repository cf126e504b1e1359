"""The dicts fairmesh returns, as ``TypedDict``s: ``fairmesh.FairReport`` (what ``fair`` returns
beside the vertices), ``fairmesh.CompareReport`` (``compare``) and ``fairmesh.DenoiseReport``
(``Hierarchy.denoise``). They are plain dicts at run time; these name their keys and types for
editors and type checkers, and the tests check every key against what the calls return."""

from typing import List, Literal, Optional, TypedDict


class FairPhases(TypedDict):
    """Where a fairing's time went, in milliseconds (``fairmesh fair --json``'s ``phases_ms``)."""

    set_up: float
    iterations: float
    volume: float
    relaxation: float
    risk: float


class _FairReportFields(TypedDict):
    method: Literal["constrained", "laplacian", "taubin", "hc"]
    variant: Optional[Literal["improved", "paper"]]
    input: Optional[str]
    output: None
    vertices: int
    faces: int
    closed: bool
    iterations_run: int
    rounds_run: int
    noise_estimate: Optional[float]
    tangential_noise: Optional[float]
    crease_edges: int
    loose_triangles: int
    time_ms: float
    detection_ms: float
    phases_ms: FairPhases
    risk_by_round: List[float]
    volume_change_percent: Optional[float]
    max_move: float
    masked_vertices: Optional[int]
    texture_slide: Optional[float]
    texture_follows: None


class FairReport(_FairReportFields, total=False):
    """What ``fair`` did: the fields of ``fairmesh fair --json``.

    - ``method``; ``variant``: the constrained operator as ``fairmesh fair --json`` names it
      ("improved" or "paper"), None for a baseline.
    - ``input``: the loaded file's path (``fair(mesh)``), else None; ``output``: None.
    - ``vertices``, ``faces``, ``closed``: the mesh faired.
    - ``iterations_run``, ``rounds_run``: what ran; ``risk_by_round``: the estimated error
      after each round (``rounds=None``), by which the rounds stopped.
    - ``noise_estimate``: the noise read from the input, in mean edge lengths (None when not
      estimated); ``tangential_noise``: the part along the surface.
    - ``crease_edges``: sharp edges kept; ``loose_triangles``: triangles left out at
      non-manifold edges.
    - ``time_ms``, ``detection_ms``, ``phases_ms``: timings.
    - ``volume_change_percent``: None for a mesh of no volume; ``max_move``: the largest
      vertex move, in mean edge lengths.
    - ``masked_vertices``: the vertices the mask lets move (None without one).
    - ``texture_slide``: how far vertices slid along the surface, in mean edge lengths (a
      loaded textured file only); ``texture_follows``: None (it depends on where it is saved).
    - With ``measure=True`` only: ``mean_surface_distance``, ``hausdorff`` (to the input), and
      ``rms``, ``normal_error_deg`` (the same connectivity: always, for ``fair``).
    """

    mean_surface_distance: float
    hausdorff: float
    rms: float
    normal_error_deg: float


class Distance(TypedDict):
    """One way of a two-way surface distance."""

    mean: float
    max: float


class _CompareReportFields(TypedDict):
    mean_surface_distance: float
    hausdorff: float
    volume_change_percent: Optional[float]
    reference_to_other: Distance
    other_to_reference: Distance
    same_connectivity: bool
    reference_mean_edge_length: float


class CompareReport(_CompareReportFields, total=False):
    """What ``compare`` measured: the fields of ``fairmesh compare --json``. With the same
    connectivity (``same_connectivity``) also ``rms``, ``max_distance``, ``normal_error_deg``,
    ``barycenter_drift`` and, where the reference has sharp edges, ``sharpened_edges``."""

    rms: float
    max_distance: float
    normal_error_deg: float
    barycenter_drift: float
    sharpened_edges: int


class DenoiseReport(TypedDict):
    """What the denoise before a hierarchy's build found (``Hierarchy.denoise``)."""

    rounds_run: int
    noise_estimate: Optional[float]
    crease_edges: int


__all__ = ["CompareReport", "DenoiseReport", "Distance", "FairPhases", "FairReport"]
