"""ASCII ``DataArray`` elements of VTK XML files (the ``.vtp`` and current ``.vtu`` writers).

Numbers are written with 17 significant digits (doubles exactly), nine a line; strings as
VTK's ``String`` arrays store them: each string's bytes as numbers, ended by a 0.

>>> print(data_array("frequency_hz", np.array([6.19e9])), end="")
<DataArray type="Float64" Name="frequency_hz" NumberOfComponents="1" format="ascii">
6190000000
</DataArray>
>>> print(string_array("units", ["J: A/m"]), end="")
<DataArray type="String" Name="units" NumberOfTuples="1" format="ascii">
74 58 32 65 47 109 0
</DataArray>
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: numpy dtype -> VTK XML type name.
VTK_TYPES = {
    np.dtype(np.float64): "Float64",
    np.dtype(np.int32): "Int32",
    np.dtype(np.int64): "Int64",
}

__all__ = ["VTK_TYPES", "data_array", "string_array"]


def data_array(name: str, data: np.ndarray, components: int = 1, field: bool = False) -> str:
    """One ASCII numeric ``DataArray`` element (float64, int32 or int64), nine values a line.

    ``field``: an array of ``FieldData``, which says its number of tuples (point and cell
    arrays have one tuple per point or cell).
    """
    # xml.sax imports urllib and http.client: here, not at the top (``barymesh --help``)
    from xml.sax.saxutils import quoteattr

    data = np.asarray(data)
    tuples = f' NumberOfTuples="{data.size // components}"' if field else ""
    fmt = "%.17g" if data.dtype.kind == "f" else "%d"
    flat = data.reshape(-1).tolist()
    body = "\n".join(" ".join(map(fmt.__mod__, flat[k : k + 9])) for k in range(0, len(flat), 9))
    return (
        f"<DataArray type={quoteattr(VTK_TYPES[data.dtype])} Name={quoteattr(name)} "
        f'NumberOfComponents="{components}"{tuples} format="ascii">\n{body}\n</DataArray>\n'
    )


def string_array(name: str, values: Sequence[str]) -> str:
    """One ASCII ``String`` ``DataArray`` (UTF-8 bytes of each value, each ended by 0)."""
    from xml.sax.saxutils import quoteattr

    codes = []
    for value in values:
        codes += list(str(value).encode("utf-8")) + [0]
    return (
        f'<DataArray type="String" Name={quoteattr(name)} NumberOfTuples="{len(values)}" '
        f'format="ascii">\n{" ".join(map(str, codes))}\n</DataArray>\n'
    )
