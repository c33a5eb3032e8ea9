"""gmsh's 2D mesher on the geometry of a conforming structure, for the benchmarks.

Shared by ``mesher.py`` (speed) and ``quality.py`` (triangle shape). The metal
is built with gmsh's OpenCASCADE kernel: one annulus (or square frame) of width
``patch_size`` per radius, cut by the slots (half-strips of width
``gap_width`` from the centre along ``gap_angle``, and the opposite direction
for the doubly split rings), then meshed at a uniform size calibrated so that
the triangle count is close to a target.

``SPLIT`` and :func:`split_ring_fields` give the benchmarks' split ring at
about 10k, 100k, 1M and 4M triangles. Nothing here imports barymesh's ``core``,
so the quality benchmark can measure another checkout's ``core`` beside it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: (inner_radius, subdivisions) of the conforming split ring for gmsh; near-square sectors.
SPLIT = {"10k": (4.0, 14), "100k": (20.0, 20), "1M": (20.0, 63), "4M": (80.0, 63)}

#: Structures whose geometry :class:`Gmsh` can build.
GMSH_STRUCTURES = (
    "ring",
    "double_ring",
    "split_ring",
    "split_double_ring",
    "square_split_double_ring",
)

#: gmsh's 2D algorithm numbers (``Mesh.Algorithm``) by name; 6 is gmsh's default.
ALGORITHMS = {"meshadapt": 1, "delaunay": 5, "frontal-delaunay": 6}


def split_ring_fields(size: str) -> dict[str, Any]:
    """``MeshParams`` fields of the benchmarks' conforming split ring at ``size``.

    One ring from the inner radius r of :data:`SPLIT` to r + h (h = 1 mm; a
    single ring does not use ``outer_radius``), a 1 mm slot at 0°, n × n
    subdivisions with n from :data:`SPLIT`, and an angle step that makes the
    sectors about as long as they are wide (h / (r + h/2) radians).
    """
    r, n = SPLIT[size]
    h = 1.0
    return {
        "structure": "split_ring",
        "mode": "conforming",
        "inner_radius": r,
        "outer_radius": r + 5 * h,
        "patch_size": h,
        "subdivisions": n,
        "angle_step": math.degrees(h / (r + h / 2)),
        "gap_width": 1.0,
    }


class Gmsh:
    """gmsh's 2D mesher on a conforming structure's geometry at about ``target`` triangles.

    Parameters
    ----------
    params : MeshParams
        Any object with the fields ``structure``, ``inner_radius``,
        ``outer_radius``, ``patch_size``, ``gap_width``, ``gap_angle`` and
        ``origin``; ``structure`` one of :data:`GMSH_STRUCTURES`.
    target : int
        Wanted number of triangles; the mesh size is calibrated on meshes of at
        most 20k triangles, where gmsh is quick.
    algorithm : int
        gmsh's ``Mesh.Algorithm`` (6: Frontal-Delaunay, its default).
    """

    def __init__(self, params: Any, target: int, algorithm: int = 6) -> None:
        import gmsh

        if params.structure not in GMSH_STRUCTURES:
            raise ValueError(
                f"structure={params.structure!r}: gmsh geometry exists only for "
                f"{', '.join(GMSH_STRUCTURES)}"
            )
        self.gmsh = gmsh
        self.params = params
        self.algorithm = algorithm
        if not gmsh.isInitialized():
            gmsh.initialize(["-noenv"], readConfigFiles=False)
        gmsh.option.setNumber("General.Terminal", 0)
        area = self._geometry()
        # equilateral triangles of side s: T = 4 A / (sqrt(3) s^2)
        size = math.sqrt(4 * area / (math.sqrt(3) * target))
        coarse = max(1.0, target / 20_000)
        for _ in range(2):
            got = len(self.run(size * math.sqrt(coarse))[1])
            size *= math.sqrt(got * coarse / target)
        self.size = size

    def _geometry(self) -> float:
        """Build the metal in a fresh model; its area (mm²)."""
        gmsh = self.gmsh
        p = self.params
        h, g = p.patch_size, p.gap_width
        x0, y0 = p.origin
        gmsh.clear()
        occ = gmsh.model.occ
        double = p.structure in ("double_ring", "split_double_ring", "square_split_double_ring")
        radii = [p.inner_radius, p.outer_radius] if double else [p.inner_radius]
        metal = []
        for r in radii:
            if p.structure == "square_split_double_ring":
                outer = occ.addRectangle(x0 - r - h, y0 - r - h, 0, 2 * (r + h), 2 * (r + h))
                inner = occ.addRectangle(x0 - r, y0 - r, 0, 2 * r, 2 * r)
            else:
                outer = occ.addDisk(x0, y0, 0, r + h, r + h)
                inner = occ.addDisk(x0, y0, 0, r, r)
            frame, _ = occ.cut([(2, outer)], [(2, inner)])
            metal += frame
        directions = {
            "split_ring": [p.gap_angle],
            "split_double_ring": [p.gap_angle, p.gap_angle + 180.0],
            "square_split_double_ring": [p.gap_angle, p.gap_angle + 180.0],
        }
        reach = 2 * (max(radii) + h)
        for angle in directions.get(p.structure, []):
            slot = occ.addRectangle(x0, y0 - g / 2, 0, reach, g)
            occ.rotate([(2, slot)], x0, y0, 0, 0, 0, 1, math.radians(angle))
            metal, _ = occ.cut(metal, [(2, slot)])
        occ.synchronize()
        return sum(occ.getMass(dim, tag) for dim, tag in metal)

    def run(self, size: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Mesh the geometry at ``size`` (mm; default the calibrated one).

        Returns
        -------
        nodes : (V, 3) float64
        triangles : (T, 3) int64
        """
        gmsh = self.gmsh
        size = self.size if size is None else size
        self._geometry()
        gmsh.option.setNumber("Mesh.Algorithm", self.algorithm)
        gmsh.option.setNumber("Mesh.MeshSizeMin", size)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, node_tags = gmsh.model.mesh.getElementsByType(2)
        index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
        index[tags] = np.arange(len(tags))
        return coords.reshape(-1, 3), index[node_tags.astype(np.int64)].reshape(-1, 3)
