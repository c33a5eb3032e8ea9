"""Text the window shows: a field's value, bytes, seconds, the statistics rows, and one
sentence for a file that could not be read or written."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from barymesh.app.model.build import MeshResult


def format_value(value: Any) -> str:
    """The text a field shows for ``value``: exact, shortest, with a decimal point.

    >>> format_value(4.5), format_value(1000.0), format_value(1e-9), format_value(None)
    ('4.5', '1000', '1e-09', '')
    """
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    if isinstance(value, (tuple, list)):
        if value and isinstance(value[0], (tuple, list)):
            return "; ".join(format_value(p) for p in value)
        return ", ".join(format_value(v) for v in value)
    if isinstance(value, int):
        return str(value)
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def mom_matrix_bytes(unknowns: int) -> int:
    """Memory of a dense N x N complex128 MoM impedance matrix: 16 N² bytes."""
    return 16 * int(unknowns) ** 2


def format_bytes(n: float) -> str:
    """``1536 -> '1.5 KiB'``, binary prefixes as memory is sold."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:,.0f} {unit}" if unit == "B" else f"{n:,.1f} {unit}"
        n /= 1024
    return f"{n:.1f} TiB"  # pragma: no cover


def format_seconds(s: float) -> str:
    return f"{s * 1e3:,.1f} ms" if s < 1 else f"{s:,.2f} s"


#: Statistics panel rows: key -> label.
STAT_LABELS = {
    "patches": "Patches",
    "vertices": "Vertices",
    "triangles": "Triangles",
    "edges": "Edges",
    "interior_edges": "Interior edges (RWG unknowns N)",
    "boundary_edges": "Boundary edges",
    "junction_edges": "Junction edges",
    "min_edge": "Shortest edge",
    "max_edge": "Longest edge",
    "min_angle_deg": "Smallest angle",
    "max_aspect_ratio": "Largest aspect ratio",
    "overlap_ratio": "Overlap ratio (paper mode)",
    "euler_characteristic": "Euler characteristic V − E + F",
    "mesh_time": "Mesh time",
    "mom_memory": "Dense MoM matrix (16 N² bytes)",
}


def stats_texts(result: MeshResult | None) -> dict[str, str]:
    """The statistics panel's text for every key of :data:`STAT_LABELS`."""
    if result is None or result.mesh is None:
        return dict.fromkeys(STAT_LABELS, "–")
    s = result.stats
    out = {}
    for key in (
        "patches",
        "vertices",
        "triangles",
        "edges",
        "interior_edges",
        "boundary_edges",
        "junction_edges",
        "euler_characteristic",
    ):
        out[key] = f"{s[key]:,}"
    out["min_edge"] = f"{s['min_edge']:.4g} mm"
    out["max_edge"] = f"{s['max_edge']:.4g} mm"
    out["min_angle_deg"] = f"{s['min_angle_deg']:.2f}°"
    out["max_aspect_ratio"] = f"{s['max_aspect_ratio']:.3f}"
    ratio = s.get("overlap_ratio")
    out["overlap_ratio"] = "–" if ratio is None else f"{100 * ratio:.2f} %"
    out["mesh_time"] = format_seconds(result.seconds) if result.source == "parameters" else "–"
    out["mom_memory"] = format_bytes(mom_matrix_bytes(s["interior_edges"]))
    return {key: out[key] for key in STAT_LABELS}


# -- the model -----------------------------------------------------------------------------


def file_error_sentence(
    title: str, exc: BaseException, path: str | os.PathLike[str] | None = None
) -> str:
    """``"Could not open a.msh: the file ends after 12 of 423 nodes."``: one sentence.

    The path is said once (``title`` names the file; a message that starts with the path
    or the file name again has it dropped), an operating-system error says what the system
    said (not its errno and repeated path), and a text file that is not UTF-8 says so in
    those words rather than in the codec's.

    >>> file_error_sentence("Could not open a.msh", ValueError("/x/a.msh: a.msh: empty"),
    ...                     "/x/a.msh")
    'Could not open a.msh: empty.'
    """
    if isinstance(exc, UnicodeDecodeError):
        bad = exc.object[exc.start : exc.start + 1]
        code = f"0x{bad[0]:02x}" if bad else "?"
        reason = f"it is not UTF-8 text (byte {code} at offset {exc.start})"
    elif isinstance(exc, OSError) and exc.strerror:
        reason = exc.strerror[:1].lower() + exc.strerror[1:]
    else:
        reason = str(exc) or type(exc).__name__
    reason = " ".join(part.strip() for part in reason.splitlines() if part.strip())
    prefixes = []
    if path is not None:
        full = str(path)
        prefixes = [full, os.path.abspath(full), Path(full).name]
    changed = True
    while changed:  # "path: path: reason" -> "reason"
        changed = False
        for prefix in prefixes:
            for sep in (": ", " "):
                if prefix and reason.startswith(prefix + sep):
                    reason = reason[len(prefix) + len(sep) :].lstrip()
                    changed = True
    reason = reason.rstrip(". ")
    return f"{title}: {reason}." if reason else f"{title}."
