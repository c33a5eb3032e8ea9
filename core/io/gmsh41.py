"""Read Gmsh MSH 4.1 files (ASCII and binary), checking every count and every node tag.

Nodes and elements come in entity blocks; each block is read whole (one
numpy call), after its declared size is checked against what the file still
holds. Triangles (type 2) keep the first physical tag of their entity as
region and the entity tag as patch, as meshio did; other elements are counted
in ``ignored_cells``. Every element must refer to nodes the ``$Nodes``
section defines (Gmsh node tags are positive integers).
"""

from __future__ import annotations

import builtins
import re
import warnings

import numpy as np

from .limits import MAX_CELLS, MAX_POINTS, Damaged, check_count
from .msh_sections import ELEMENT_TYPES, TRIANGLE, node_indices, section, tags_valid


def msh4_kind(head: bytes) -> str | None:
    """``"ascii"`` or ``"binary"`` for a file starting with ``head`` in MSH 4.1, else None."""
    match = re.match(rb"\s*\$MeshFormat\s+(\S+)\s+(\S+)", head)
    if not match or not match.group(1).startswith(b"4.1"):
        return None
    return {b"0": "ascii", b"1": "binary"}.get(match.group(2))


class _Numbers:
    """A cursor over one section's numbers: ASCII text or binary ints, size_t and doubles."""

    def __init__(self, body: bytes, binary: bool, order: str, section: str) -> None:
        self.binary, self.order, self.section, self.pos = binary, order, section, 0
        self.data: bytes | np.ndarray  # the bytes (binary) or the numbers parsed (ASCII)
        if binary:
            self.data = body
            return
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                self.data = np.fromstring(body.decode("latin-1"), dtype=np.float64, sep=" ")
            except (DeprecationWarning, ValueError):
                raise Damaged(f"the ${section} section holds text that is not a number") from None

    def _take(self, n: int, dtype: str) -> np.ndarray:
        if n < 0:
            raise Damaged(f"the ${self.section} section declares a negative count")
        if self.binary:
            dt = np.dtype(self.order + dtype)
            if self.pos + n * dt.itemsize > len(self.data):
                raise Damaged(
                    f"the ${self.section} section declares more than the file holds "
                    "(it is truncated or a count is wrong)"
                )
            out = np.frombuffer(self.data, dtype=dt, count=n, offset=self.pos)
            self.pos += n * dt.itemsize
            return out
        if self.pos + n > len(self.data):
            raise Damaged(
                f"the ${self.section} section declares more numbers than it holds "
                "(it is truncated or a count is wrong)"
            )
        out = np.asarray(self.data[self.pos : self.pos + n])  # an ndarray already (ASCII)
        self.pos += n
        return out

    def ints(self, n: int, size_t: bool = False) -> np.ndarray:
        values = self._take(n, "u8" if size_t else "i4")
        if not self.binary and (not np.all(np.isfinite(values)) or np.any(values % 1 != 0)):
            raise Damaged(f"the ${self.section} section holds a count or tag that is not whole")
        if values.size and values.max() >= 2**62:
            raise Damaged(
                f"the ${self.section} section holds a number of {values.max():.3g}, "
                "beyond any count or tag"
            )
        return values.astype(np.int64)

    def int(self, size_t: bool = False) -> int:
        return int(self.ints(1, size_t)[0])

    def floats(self, n: builtins.int) -> np.ndarray:
        return self._take(n, "f8").astype(np.float64)

    def left(self) -> builtins.int:  # ``int`` is the method above in the class body
        return len(self.data) - self.pos

    def check_end(self) -> None:
        """Nothing but a line break may follow the last block."""
        if self.left() > (2 if self.binary else 0):
            raise Damaged(f"the ${self.section} section holds more than its blocks declare")


def _binary_body(data: bytes, name: str, start: int) -> tuple[bytes, int]:
    """The bytes between ``$name`` and ``$Endname`` (searched from ``start``), and the end."""
    at = data.find(f"${name}\n".encode(), start)
    if at < 0:
        return b"", -1
    end = data.find(f"$End{name}".encode(), at)
    if end < 0:
        raise Damaged(f"its ${name} section has no $End{name} (the file is truncated)")
    return data[at + len(name) + 2 : end], end


def _physical_tags(numbers: _Numbers) -> dict[tuple[int, int], int]:
    """(dimension, entity tag) -> its first physical tag, from ``$Entities``."""
    counts = numbers.ints(4, size_t=True).tolist()
    for dim, count in enumerate(counts):
        check_count(count, f"dimension-{dim} entities", MAX_CELLS)
    physical = {}
    for dim, count in enumerate(counts):
        for _ in range(count):
            tag = numbers.int()
            numbers.floats(3 if dim == 0 else 6)
            n_physical = numbers.int(size_t=True)
            tags = numbers.ints(check_count(n_physical, "physical tags", 1000))
            if len(tags):
                physical[(dim, tag)] = int(tags[0])
            if dim:
                numbers.ints(check_count(numbers.int(size_t=True), "bounding entities", 10**6))
    return physical


def _block_count(numbers: _Numbers, what: str, total: int) -> int:
    count = numbers.int(size_t=True)
    if count > total:
        raise Damaged(
            f"a block declares {count:,} {what}, more than the {total:,} of the "
            f"whole ${numbers.section} section"
        )
    return count


def read_gmsh41(data: bytes):
    """``(points, triangles, regions, patch_ids, ignored_cells)`` of an MSH 4.1 file."""
    binary = msh4_kind(data[:256]) == "binary"
    order = "<"
    head = re.match(rb"\s*\$MeshFormat\s+\S+\s+\S+\s+(\S+)[ \t\r]*\n", data)
    if head is None:
        raise Damaged("its $MeshFormat line is incomplete")
    if binary:
        if head.group(1) != b"8":
            raise Damaged("its $MeshFormat line does not declare 8-byte size_t")
        one = data[head.end() : head.end() + 4]
        orders = {(1).to_bytes(4, "little"): "<", (1).to_bytes(4, "big"): ">"}
        if one not in orders:
            raise Damaged("its $MeshFormat section lacks the binary integer 1 (byte order)")
        order = orders[one]

    def body(name: str, start: int = 0) -> tuple[bytes | None, int]:
        if binary:
            found, end = _binary_body(data, name, start)
            return (found if end >= 0 else None), end
        text = section(data.decode("latin-1"), name)
        return (None if text is None else text.encode("latin-1")), 0

    entities, _ = body("Entities")
    physical = (
        {} if entities is None else _physical_tags(_Numbers(entities, binary, order, "Entities"))
    )
    nodes_body, nodes_end = body("Nodes")
    if nodes_body is None:
        raise Damaged("it has no $Nodes section")
    numbers = _Numbers(nodes_body, binary, order, "Nodes")
    n_blocks, n_nodes = numbers.ints(4, size_t=True).tolist()[:2]
    check_count(n_nodes, "nodes", MAX_POINTS)
    check_count(n_blocks, "node blocks", MAX_POINTS)
    tags, coords = [], []
    for _ in range(n_blocks):
        dim, _entity, parametric = numbers.ints(3).tolist()
        count = _block_count(numbers, "nodes", n_nodes)
        width = 3 + (dim if parametric else 0)
        if count * (width + 1) > numbers.left():
            raise Damaged(f"a node block declares {count:,} nodes; the $Nodes section holds fewer")
        tags.append(numbers.ints(count, size_t=True))
        coords.append(numbers.floats(count * width).reshape(count, width)[:, :3])
    numbers.check_end()
    node_tags = tags_valid(np.concatenate(tags) if tags else np.empty(0))
    if len(node_tags) != n_nodes:
        raise Damaged(f"its $Nodes section declares {n_nodes:,} nodes but holds {len(node_tags):,}")
    points = np.concatenate(coords) if coords else np.empty((0, 3))

    elements_body, _ = body("Elements", max(nodes_end, 0))
    if elements_body is None:
        raise Damaged("it has no $Elements section")
    numbers = _Numbers(elements_body, binary, order, "Elements")
    n_blocks, n_elements = numbers.ints(4, size_t=True).tolist()[:2]
    check_count(n_elements, "elements", MAX_CELLS)
    check_count(n_blocks, "element blocks", MAX_CELLS)
    tri, regions, patches, numbers_of, other, other_numbers = [], [], [], [], [], []
    ignored: dict[str, int] = {}
    seen = 0
    for _ in range(n_blocks):
        dim, entity, kind = numbers.ints(3).tolist()
        count = _block_count(numbers, "elements", n_elements)
        if kind not in ELEMENT_TYPES:
            raise Damaged(f"an element block has type {kind}, which MSH 4.1 does not define")
        name, n_nodes = ELEMENT_TYPES[kind]
        block = numbers.ints(count * (1 + n_nodes), size_t=True).reshape(count, 1 + n_nodes)
        seen += count
        if kind == TRIANGLE:
            tri.append(block[:, 1:])
            numbers_of.append(np.repeat(block[:, 0], 3))
            regions.append(np.full(count, physical.get((dim, entity), 0), dtype=np.int64))
            patches.append(np.full(count, entity, dtype=np.int64))
        else:
            ignored[name] = ignored.get(name, 0) + count
            other.append(block[:, 1:].reshape(-1))
            other_numbers.append(np.repeat(block[:, 0], n_nodes))
    numbers.check_end()
    if seen != n_elements:
        raise Damaged(
            f"its $Elements section declares {n_elements:,} elements but its blocks hold {seen:,}"
        )

    def joined(parts: list[np.ndarray], shape: tuple[int, ...]) -> np.ndarray:
        return np.concatenate(parts) if parts else np.empty(shape, dtype=np.int64)

    node_indices(node_tags, joined(other, (0,)), joined(other_numbers, (0,)))
    triangles = node_indices(node_tags, joined(tri, (0, 3)), joined(numbers_of, (0,)))
    return points, triangles, joined(regions, (0,)), joined(patches, (0,)), ignored
