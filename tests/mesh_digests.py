"""Digests of meshes that edge grading must leave as they were, bit for bit.

``python tests/mesh_digests.py > tests/data/ungraded_mesh_digests.json`` with the code
before grading was added (the file records the commit) writes the digests that
``tests/test_core_grading.py`` compares today's meshes with. Only APIs that existed
then are used here.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from barymesh import MeshParams, build_mesh
from barymesh.cell import PixelGrid, UnitCell, build_cell, cell_from_dict, tile
from barymesh.cell.files import CELL_PRESET_DIR
from barymesh.presets import load_preset

STRUCTURES = (
    "patch",
    "triangle",
    "ring",
    "double_ring",
    "split_ring",
    "split_double_ring",
    "square_split_double_ring",
)
SMALL = dict(inner_radius=2.0, outer_radius=3.5, patch_size=1.0, angle_step=20.0, gap_width=0.6)


def structure_cases() -> dict[str, dict]:
    """name -> MeshParams keyword arguments: every structure, mode, scheme and diagonal."""
    cases = {}
    for structure in STRUCTURES:
        for mode in ("paper", "conforming"):
            for scheme, n in (("uniform", 3), ("barycentric", 1)):
                for diagonal in ("BC", "AD"):
                    kw = dict(SMALL, structure=structure, mode=mode, scheme=scheme)
                    kw.update(subdivisions=n, diagonal=diagonal)
                    cases[f"{structure}-{mode}-{scheme}-{diagonal}"] = kw
    cases["patch-default"] = {"structure": "patch"}
    cases["patch-rectangle"] = {"structure": "patch", "patch_size": 5.0, "patch_width": 2.0}
    cases["patch-n16"] = {"structure": "patch", "patch_size": 8.0, "subdivisions": 16}
    cases["triangle-vertices"] = {
        "structure": "triangle",
        "triangle_vertices": [(0.0, 0.0), (3.0, 0.5), (1.0, 2.0)],
        "subdivisions": 5,
    }
    cases["patch-sized"] = {"structure": "patch", "patch_size": 10.0, "frequency": 30e9}
    cases["ring-graded"] = dict(SMALL, structure="ring", mode="conforming", grading=True)
    cases["split-ring-graded"] = dict(
        SMALL, structure="split_ring", mode="conforming", grading=True, min_edge=0.05
    )
    cases["double-ring-graded"] = dict(
        SMALL, structure="double_ring", mode="conforming", grading=True, growth_ratio=2.0
    )
    return cases


def digest(points: np.ndarray, triangles: np.ndarray, *extra: np.ndarray) -> str:
    """sha256 of the points (float64), triangles and any further arrays (int64)."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(points, dtype=np.float64).tobytes())
    for a in (triangles, *extra):
        h.update(np.ascontiguousarray(a, dtype=np.int64).tobytes())
    return h.hexdigest()


def mesh_digest(mesh) -> str:  # noqa: ANN001
    return digest(mesh.points, mesh.triangles, mesh.patch_ids, mesh.regions)


def ungraded_cell_preset(name: str) -> UnitCell:
    """A shipped cell preset with the ``grading`` keys of its parts left out (the presets
    before grading had none)."""
    path = Path(CELL_PRESET_DIR) / f"{name}.cell.json"
    document = json.loads(path.read_text(encoding="utf-8"))
    for part in [*document["elements"], document.get("pixels") or {}]:
        part.pop("grading", None)
    return cell_from_dict(document, str(path))


def pixel_cell() -> UnitCell:
    mask = np.array([[1, 1, 0, 1], [0, 1, 1, 1], [1, 1, 0, 0]], dtype=bool)
    return UnitCell(pixels=PixelGrid(mask, pixel_size=0.5, origin=(-1.0, -0.75)))


def all_digests() -> dict[str, str]:
    """Every case's digest: structures, presets, cell presets, a pixel cell and an array."""
    out = {}
    for name, kw in structure_cases().items():
        out[f"params:{name}"] = mesh_digest(build_mesh(MeshParams(**kw)))
    for name in ("paper-fig10", "paper-fig11-8mm", "srr-openmodes", "makarov-plate"):
        out[f"preset:{name}"] = mesh_digest(build_mesh(load_preset(name)[0]))
    for name in ("coding-16x16", "double-ring-patch", "hexagonal-rings", "split-ring-pair"):
        out[f"cell:{name}"] = mesh_digest(build_cell(ungraded_cell_preset(name)).mesh)
    out["cell:pixels"] = mesh_digest(build_cell(pixel_cell()).mesh)
    out["cell:pixels-3x2"] = mesh_digest(tile(pixel_cell(), 3, 2).mesh)
    return out


def main() -> None:
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"],
        cwd=Path(__import__("barymesh").__file__).parent,
        capture_output=True,
        text=True,
        check=False,
    ).stdout.strip()
    doc = {"commit": commit, "digests": all_digests()}
    json.dump(doc, sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
