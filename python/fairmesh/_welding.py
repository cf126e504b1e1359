"""Welding for the adapters: trimesh and Open3D keep one vertex per corner kind, so a textured
or normal-split mesh holds one copy of a position per side of each UV or normal seam. Faired
copy by copy, each side of a seam would be smoothed on its own and the seam would open. As
``fairmesh.load`` does for files, the copies of a position are faired as one vertex (exact
equality, the first copy's index order) and every copy is given the result."""

from typing import Any, Dict, Optional, Tuple

import numpy as np

import fairmesh


class Welded:
    """The distinct positions of ``vertices`` (first copies first) and, for every row of
    ``vertices``, the index of its position among them."""

    def __init__(self, vertices: np.ndarray):
        vertices = np.asarray(vertices)
        self.count = len(vertices)
        if self.count == 0:
            self.positions = vertices
            self.of_row = np.zeros(0, dtype=np.int64)
            self.copies = 0
            return
        _, first, inverse = np.unique(vertices, axis=0, return_index=True,
                                      return_inverse=True)
        inverse = inverse.reshape(-1)
        order = np.argsort(first, kind="stable")
        rank = np.empty_like(order)
        rank[order] = np.arange(len(order))
        self.positions = vertices[first[order]]
        self.of_row = rank[inverse]
        self.copies = self.count - len(self.positions)

    def faces(self, faces: np.ndarray) -> np.ndarray:
        """``faces`` over the welded positions."""
        return self.of_row[np.asarray(faces, dtype=np.int64)]

    def spread(self, positions: np.ndarray) -> np.ndarray:
        """Welded positions given back to every row."""
        return positions[self.of_row]

    def mask(self, mask: Any) -> Any:
        """A mask over the rows as one over the welded positions: per-row values become the
        largest value of a position's copies; indices name their positions, each once."""
        if mask is None:
            return None
        array = np.asarray(mask)
        if array.ndim != 1 or array.dtype.kind not in "biuf":
            return mask  # fairmesh.fair says what is wrong with it
        if array.dtype.kind in "bf" and len(array) == self.count:
            welded = np.zeros(len(self.positions), dtype=np.float64)
            np.maximum.at(welded, self.of_row, array.astype(np.float64))
            return welded.astype(bool) if array.dtype.kind == "b" else welded
        if array.dtype.kind in "iu":
            if len(array) == self.count and np.isin(array, (0, 1)).all():
                return mask  # ambiguous: fairmesh.fair refuses it and says how to write it
            if len(array) and (array.min() < 0 or array.max() >= self.count):
                return mask  # fairmesh.fair names the index beyond the vertices
            return np.unique(self.of_row[array.astype(np.int64)])
        return mask

    def edges(self, edges: Any) -> Any:
        """Vertex pairs over the rows as pairs over the welded positions."""
        if edges is None:
            return None
        array = np.asarray(edges)
        if array.ndim != 2 or array.shape[1:] != (2,) or array.dtype.kind not in "iu":
            return edges
        if len(array) and (array.min() < 0 or array.max() >= self.count):
            return edges
        pairs = self.of_row[array.astype(np.int64)]
        return pairs[pairs[:, 0] != pairs[:, 1]]  # an edge between copies is no edge


def fair(vertices: np.ndarray, faces: np.ndarray,
         options: Dict[str, Any]) -> Tuple[np.ndarray, Dict[str, Any]]:
    """``fairmesh.fair`` with the copies of every position faired as one vertex: vertices for
    every row of ``vertices`` (copies of a position stay equal), and the report (whose
    ``vertices`` counts the welded positions)."""
    welded = Welded(vertices)
    if welded.copies == 0:
        return fairmesh.fair(vertices, faces, **options)
    options = dict(options)
    options["mask"] = welded.mask(options.get("mask"))
    options["hard_edges"] = welded.edges(options.get("hard_edges"))
    result, report = fairmesh.fair(welded.positions, welded.faces(faces), **options)
    return welded.spread(result), report


def welded_arrays(vertices: np.ndarray, faces: np.ndarray) -> Tuple[Optional[Welded],
                                                                   np.ndarray, np.ndarray]:
    """The welding of ``vertices`` (None when no position repeats) and the arrays to give
    fairmesh."""
    welded = Welded(vertices)
    if welded.copies == 0:
        return None, vertices, faces
    return welded, welded.positions, welded.faces(faces)
