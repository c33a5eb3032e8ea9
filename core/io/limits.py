"""What a mesh file may declare before we allocate for it.

Readers check every count a file declares against these limits and against
the bytes the file really holds *before* they allocate or inflate anything,
so a damaged or hostile file (a count of 10^12, a zlib bomb) is refused at
once with one sentence, in the file's own terms.
"""

from __future__ import annotations

from ..params import DEFAULT_MAX_TRIANGLES

#: Cells of any kind a file may declare (twice the core's triangle budget).
MAX_CELLS = 2 * DEFAULT_MAX_TRIANGLES
#: Points a file may declare (three per triangle of the budget: even a soup fits).
MAX_POINTS = 3 * DEFAULT_MAX_TRIANGLES
#: Largest ratio of inflated to compressed bytes zlib can reach (deflate's limit
#: is 1032:1), with room for block headers.
ZLIB_MAX_RATIO = 1100


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
