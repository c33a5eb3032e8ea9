"""What a mesh file may declare before we allocate for it.

Readers check every count a file declares against these limits and against
the bytes the file really holds *before* they allocate or inflate anything,
so a damaged or hostile file (a count of 10^12, a zlib bomb) is refused at
once with one sentence, in the file's own terms.
"""

from __future__ import annotations

import os
import re

from ..params import DEFAULT_MAX_TRIANGLES

#: Cells of any kind a file may declare (twice the core's triangle budget).
MAX_CELLS = 2 * DEFAULT_MAX_TRIANGLES
#: Points a file may declare (three per triangle of the budget: even a soup fits).
MAX_POINTS = 3 * DEFAULT_MAX_TRIANGLES
#: Largest ratio of inflated to compressed bytes zlib can reach (deflate's limit
#: is 1032:1), with room for block headers.
ZLIB_MAX_RATIO = 1100


#: Largest mesh file read unless raised (bytes): an ASCII file at the counts above takes
#: up to about this (an ASCII STL of 5 million facets is 1.3 GB); reading more takes
#: minutes and gigabytes of memory.
MAX_FILE_BYTES = 2 * 2**30
#: The environment variable that raises (or lowers) :data:`MAX_FILE_BYTES`, e.g. ``4GiB``.
MAX_FILE_ENV = "BARYMESH_MAX_FILE_BYTES"
_SIZE = re.compile(r"\s*(\d+(?:\.\d+)?)\s*([kmgt]?)i?b?\s*", re.IGNORECASE)


def format_size(size: float) -> str:
    """Bytes for a message: ``2 GiB``, ``3.5 GiB``, ``512 MiB``, ``300 bytes``.

    >>> format_size(2 * 2**30), format_size(3.5 * 2**30), format_size(300)
    ('2 GiB', '3.5 GiB', '300 bytes')
    """
    for unit, scale in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if size >= scale:
            return f"{size / scale:.3g} {unit}"
    return f"{size:.0f} bytes"


def max_file_bytes() -> int:
    """:data:`MAX_FILE_BYTES`, or the size :data:`MAX_FILE_ENV` gives (``4GiB``, ``5e9``).

    Raises
    ------
    ValueError
        When the variable is set but not a size.
    """
    text = os.environ.get(MAX_FILE_ENV)
    if text is None or not text.strip():
        return MAX_FILE_BYTES
    match = _SIZE.fullmatch(text)
    if match is None:
        try:
            return int(float(text))
        except (ValueError, OverflowError):
            raise ValueError(
                f"{MAX_FILE_ENV}={text[:30]!r} is not a size; expected bytes, e.g. 4GiB"
            ) from None
    scale = {"": 1, "k": 2**10, "m": 2**20, "g": 2**30, "t": 2**40}[match.group(2).lower()]
    return int(float(match.group(1)) * scale)


class Damaged(ValueError):
    """What is wrong inside a file, in the file's own terms (the caller adds the path)."""


def check_count(count: int, what: str, limit: int) -> int:
    """``count`` if ``0 <= count <= limit``, else :class:`Damaged` saying which.

    >>> check_count(3, "points", 10)
    3
    >>> check_count(10**12, "points", 10)
    Traceback (most recent call last):
    ...
    barymesh.io.limits.Damaged: it declares 1,000,000,000,000 points; barymesh reads at most 10
    """
    if count < 0:
        raise Damaged(f"it declares {count:,} {what}, a negative count")
    if count > limit:
        raise Damaged(f"it declares {count:,} {what}; barymesh reads at most {limit:,}")
    return count


def parse_count(text: str | bytes, what: str, limit: int) -> int:
    """A declared count from its text, checked by :func:`check_count`."""
    if isinstance(text, bytes):
        text = text.decode("ascii", "replace")
    text = text.strip()
    if not text.lstrip("+-").isdigit() or len(text) > 30:
        raise Damaged(f"the number of {what} is {text[:30]!r}, not a whole number")
    return check_count(int(text), what, limit)
