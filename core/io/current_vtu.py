"""A surface current on a triangle mesh as a VTU file for ParaView.

An ASCII VTK XML unstructured grid (doubles written exactly), one triangle per cell.

- Cell data per triangle: ``J_abs`` (A/m), ``J_real`` and ``J_imag`` (3 components each),
  and any further arrays given (e.g. ``charge_abs``, C/m²).
- Field data (ParaView's *Information* tab, ``pyvista.read(path).field_data``), so the file
  says what it holds: ``frequency_hz``; ``excitation``, a sentence (a plane wave's
  direction, polarisation and amplitude, a voltage source's segment and voltage, or an
  infinite array's incidence) with its numbers also as arrays (``direction``,
  ``polarization``, ``amplitude_v_per_m``; ``feed_start_mm``, ``feed_end_mm``,
  ``voltage_v``); ``units``, one ``"name: unit"`` line per array and for the coordinates
  (mm); and ``time_convention``, ``exp(+j w t)``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .atomic import atomic_path
from .vtk_ascii import data_array, string_array

#: VTK's cell type of a triangle.
VTK_TRIANGLE = 5
#: Units of the arrays the writer knows (others are written as given, "as given").
UNITS = {
    "points": "mm",
    "J_abs": "A/m",
    "J_real": "A/m",
    "J_imag": "A/m",
    "charge_abs": "C/m^2",
    "frequency_hz": "Hz",
}

__all__ = ["UNITS", "describe_excitation", "excitation_fields", "write_current_vtu"]


def _vector(v: Any) -> str:
    return "(" + ", ".join(f"{float(c):.6g}" for c in np.asarray(v, dtype=float)) + ")"


def describe_excitation(excitation: Any) -> str:
    """A sentence for a plane wave or a voltage source (read from their attributes).

    >>> from barymesh.mom import PlaneWave
    >>> describe_excitation(PlaneWave(polarization=(0, 1, 0)))
    'plane wave travelling along (0, 0, -1), E along (0, 1, 0), amplitude 1 V/m'
    """
    if hasattr(excitation, "voltage"):
        return (
            f"delta-gap voltage source of {float(excitation.voltage):.6g} V on the mesh edges "
            f"along {_vector(excitation.start)} to {_vector(excitation.end)} mm"
        )
    return (
        f"plane wave travelling along {_vector(excitation.direction)}, E along "
        f"{_vector(np.real(excitation.polarization))}, amplitude "
        f"{float(excitation.amplitude):.6g} V/m"
    )


def excitation_fields(excitation: Any) -> dict[str, np.ndarray]:
    """The numbers of an excitation as field arrays (see the module's description)."""
    if hasattr(excitation, "voltage"):
        return {
            "feed_start_mm": np.asarray(excitation.start, dtype=float),
            "feed_end_mm": np.asarray(excitation.end, dtype=float),
            "voltage_v": np.array([float(excitation.voltage)]),
        }
    return {
        "direction": np.asarray(excitation.direction, dtype=float),
        "polarization": np.real(np.asarray(excitation.polarization)).astype(float),
        "amplitude_v_per_m": np.array([float(excitation.amplitude)]),
    }


def write_current_vtu(
    path: str | Path,
    mesh: Any,
    current_density: np.ndarray,
    *,
    frequency: float | None = None,
    excitation: Any = None,
    description: str | None = None,
    **cell_data: np.ndarray,
) -> None:
    """Write ``current_density`` (T, 3) complex, one value per triangle of ``mesh``, to ``path``.

    Parameters
    ----------
    path : str or Path
        A ``.vtu`` file, written atomically.
    mesh : TriMesh
        ``points`` (V, 3) mm and ``triangles`` (T, 3).
    current_density : (T, 3) complex
        J at the centroids (A/m).
    frequency : float, optional
        Hz; recorded as the field array ``frequency_hz``.
    excitation : PlaneWave or VoltageSource, optional
        Recorded as the field data ``excitation`` (a sentence) and its numbers.
    description : str, optional
        Replaces the sentence of ``excitation`` (e.g. an infinite array's incidence).
    **cell_data : (T,) or (T, k) float
        More arrays per triangle, written under their keyword.
    """
    j = np.asarray(current_density)
    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    points = np.asarray(mesh.points, dtype=np.float64)
    if j.shape != (len(triangles), 3):
        raise ValueError(
            f"current_density has shape {j.shape}; expected ({len(triangles)}, 3), one "
            "3-vector per triangle"
        )
    cells: dict[str, np.ndarray] = {
        "J_abs": np.linalg.norm(j, axis=1),
        "J_real": np.ascontiguousarray(j.real, dtype=np.float64),
        "J_imag": np.ascontiguousarray(j.imag, dtype=np.float64),
    }
    for name, value in cell_data.items():
        array = np.asarray(value, dtype=np.float64)
        if array.shape[0] != len(triangles):
            raise ValueError(
                f"{name} has {array.shape[0]} values; expected {len(triangles)}, one per triangle"
            )
        cells[name] = array
    fields = ""
    if frequency is not None:
        fields += data_array("frequency_hz", np.array([float(frequency)]), field=True)
    text = description
    if excitation is not None:
        text = text or describe_excitation(excitation)
        for name, value in excitation_fields(excitation).items():
            fields += data_array(name, value, value.size, field=True)  # one tuple
    if text:
        fields += string_array("excitation", [text])
    units = [f"{name}: {UNITS.get(name, 'as given')}" for name in ("points", *cells)]
    if frequency is not None:
        units.append("frequency_hz: Hz")
    fields += string_array("units", units)
    fields += string_array("time_convention", ["exp(+j w t)"])

    def components(a: np.ndarray) -> int:
        return 1 if a.ndim == 1 else a.shape[1]

    parts = [
        '<?xml version="1.0"?>\n',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n<UnstructuredGrid>\n',
        f"<FieldData>\n{fields}</FieldData>\n",
        f'<Piece NumberOfPoints="{len(points)}" NumberOfCells="{len(triangles)}">\n',
        "<Points>\n",
        data_array("Points", points, 3),
        "</Points>\n<Cells>\n",
        data_array("connectivity", triangles.reshape(-1)),
        data_array("offsets", 3 * np.arange(1, len(triangles) + 1, dtype=np.int64)),
        data_array("types", np.full(len(triangles), VTK_TRIANGLE, dtype=np.int64)),
        '</Cells>\n<CellData Scalars="J_abs" Vectors="J_real">\n',
        *(data_array(name, a, components(a)) for name, a in cells.items()),
        "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n",
    ]
    with atomic_path(path) as tmp:
        Path(tmp).write_text("".join(parts), encoding="utf-8")
