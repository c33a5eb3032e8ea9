"""Read Gmsh MSH 2.2 files (ASCII and binary), checking every count and every node tag.

Triangles (element type 2) are kept with their physical and elementary tags;
other elements are counted by kind in ``ignored_cells``. Every element must
refer to nodes the ``$Nodes`` section defines (Gmsh node tags are positive
integers), and every declared count must match the numbers present.
MSH 4.x files are read by meshio (see ``import_``).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np

from .limits import MAX_CELLS, MAX_POINTS, Damaged, parse_count
from .msh_sections import ELEMENT_TYPES, TRIANGLE, node_indices, section, tags_valid


def msh2_kind(head: bytes) -> str | None:
    """``"ascii"`` or ``"binary"`` for a file starting with ``head`` in MSH 2.x, else None."""
    match = re.match(rb"\s*\$MeshFormat\s+(\S+)\s+(\S+)", head)
    if not match or not match.group(1).startswith(b"2"):
        return None
    return {b"0": "ascii", b"1": "binary"}.get(match.group(2))


def _integers(body: str, what: str) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return np.fromstring(body, dtype=np.int64, sep=" ")
        except (DeprecationWarning, ValueError):
            raise Damaged(f"the {what} section holds text that is not a whole number") from None


def _split_count(body: str, what: str, limit: int) -> tuple[int, str]:
    first, _, rest = body.lstrip().partition("\n")
    return parse_count(first, what, limit), rest


def _nodes(text: str) -> tuple[np.ndarray, np.ndarray]:
    """``(tags (V,), points (V, 3))`` of the ``$Nodes`` section."""
    body = section(text, "Nodes")
    if body is None:
        raise Damaged("it has no $Nodes section")
    count, rest = _split_count(body, "nodes", MAX_POINTS)
    most = (len(rest) + 1) // 8  # "t x y z\n" is at least 8 characters
    if count > most:
        raise Damaged(f"its $Nodes section declares {count:,} nodes but holds at most {most:,}")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            values = np.fromstring(rest, dtype=np.float64, sep=" ")
        except (DeprecationWarning, ValueError):
            raise Damaged("the $Nodes section holds text that is not a number") from None
    if len(values) != 4 * count:
        raise Damaged(
            f"its $Nodes section declares {count:,} nodes but holds "
            f"{len(values) / 4:,.4g} (4 numbers per node)"
        )
    values = values.reshape(-1, 4)
    return tags_valid(values[:, 0]), values[:, 1:]


def read_gmsh22(path: Path):
    """``(points, triangles, regions, patch_ids, ignored_cells)`` of an MSH 2.2 file."""
    data = path.read_bytes()
    if msh2_kind(data[:256]) == "binary":
        return _read_binary(data)
    text = data.decode("latin-1")
    tags, points = _nodes(text)
    body = section(text, "Elements")
    if body is None:
        raise Damaged("it has no $Elements section")
    count, rest = _split_count(body, "elements", MAX_CELLS)
    flat = _integers(rest, "$Elements")
    if count > len(flat) // 4:  # an element line holds at least 4 numbers
        raise Damaged(
            f"its $Elements section declares {count:,} elements but holds at most "
            f"{len(flat) // 4:,}"
        )
    values = flat.tolist()
    tri_nodes: list[list[int]] = []
    physical: list[int] = []
    elementary: list[int] = []
    ignored: dict[str, int] = {}
    numbers: list[int] = []
    other: list[int] = []
    other_numbers: list[int] = []
    pos, parsed = 0, 0
    for _ in range(count):  # element lines differ in length: walk them
        if pos + 3 > len(values):
            break
        parsed += 1
        number, kind, n_tags = values[pos : pos + 3]
        if kind not in ELEMENT_TYPES:
            raise Damaged(f"element {number} has type {kind}, which MSH 2.2 does not define")
        name, n_nodes = ELEMENT_TYPES[kind]
        if n_tags < 0 or pos + 3 + n_tags + n_nodes > len(values):
            pos = len(values) + 1
            break
        element_tags = values[pos + 3 : pos + 3 + n_tags]
        nodes = values[pos + 3 + n_tags : pos + 3 + n_tags + n_nodes]
        pos += 3 + n_tags + n_nodes
        if kind == TRIANGLE:
            tri_nodes.append(nodes)
            numbers.append(number)
            physical.append(element_tags[0] if n_tags >= 1 else 0)
            elementary.append(element_tags[1] if n_tags >= 2 else 0)
        else:
            ignored[name] = ignored.get(name, 0) + 1
            other.extend(nodes)
            other_numbers.extend([number] * n_nodes)
    if pos != len(values) or parsed != count:
        raise Damaged(
            f"its $Elements section declares {count:,} elements but its numbers do "
            "not match that many element lines"
        )
    node_indices(tags, np.asarray(other, dtype=np.int64), np.asarray(other_numbers))
    tri = np.asarray(tri_nodes, dtype=np.int64).reshape(-1, 3)
    triangles = node_indices(tags, tri, np.repeat(np.asarray(numbers, dtype=np.int64), 3))
    return points, triangles, np.asarray(physical), np.asarray(elementary), ignored


def _binary_section(data: bytes, name: bytes, start: int, limit: int, what: str):
    """``(count, offset of the first binary byte)`` of section ``$name`` after ``start``."""
    at = data.find(b"$" + name + b"\n", start)
    if at < 0:
        raise Damaged(f"it has no ${name.decode()} section")
    line_end = data.find(b"\n", at + len(name) + 2)
    if line_end < 0:
        raise Damaged(f"its ${name.decode()} section is cut short (the file is truncated)")
    return parse_count(data[at + len(name) + 2 : line_end], what, limit), line_end + 1


def _read_binary(data: bytes):
    """MSH 2.2 binary: nodes as (int tag, 3 doubles), elements in blocks of one type."""
    head = re.match(rb"\s*\$MeshFormat\s+\S+\s+1\s+(\S+)[ \t\r]*\n", data)
    if head is None or head.group(1) != b"8":
        raise Damaged("its $MeshFormat line is not MSH 2.2 binary with 8-byte reals")
    one = data[head.end() : head.end() + 4]
    orders = {(1).to_bytes(4, "little"): "<", (1).to_bytes(4, "big"): ">"}
    order = orders.get(one, "")
    if not order:
        raise Damaged("its $MeshFormat section lacks the binary integer 1 (byte order)")
    count, at = _binary_section(data, b"Nodes", head.end() + 4, MAX_POINTS, "nodes")
    node = np.dtype([("tag", order + "i4"), ("x", order + "f8", (3,))])
    if at + count * node.itemsize > len(data):
        most = (len(data) - at) // node.itemsize
        raise Damaged(f"its $Nodes section declares {count:,} nodes but holds at most {most:,}")
    nodes = np.frombuffer(data, dtype=node, count=count, offset=at)
    tags, points = tags_valid(nodes["tag"]), nodes["x"].astype(np.float64)
    end = at + count * node.itemsize
    if not data[end : end + 12].lstrip().startswith(b"$EndNodes"):
        raise Damaged(f"its $Nodes section does not end after {count:,} nodes")
    count, pos = _binary_section(data, b"Elements", end, MAX_CELLS, "elements")
    word = np.dtype(order + "i4")
    tri, physical, elementary, numbers, other, other_numbers = [], [], [], [], [], []
    ignored: dict[str, int] = {}
    parsed = 0
    while parsed < count:
        if pos + 12 > len(data):
            raise Damaged(
                f"its $Elements section declares {count:,} elements but holds "
                f"{parsed:,} (the file is truncated)"
            )
        kind, follow, n_tags = np.frombuffer(data, dtype=word, count=3, offset=pos).tolist()
        if kind not in ELEMENT_TYPES:
            raise Damaged(f"an element block has type {kind}, which MSH 2.2 does not define")
        if not 1 <= follow <= count - parsed or not 0 <= n_tags <= 64:
            raise Damaged(
                f"an element block declares {follow:,} elements with {n_tags} tags, "
                f"which the $Elements count ({count:,}) cannot hold"
            )
        name, n_nodes = ELEMENT_TYPES[kind]
        width = 1 + n_tags + n_nodes
        if pos + 12 + follow * width * 4 > len(data):
            raise Damaged(
                f"its $Elements section declares {count:,} elements but the file "
                "ends before them (truncated)"
            )
        block = np.frombuffer(data, dtype=word, count=follow * width, offset=pos + 12)
        block = block.reshape(follow, width).astype(np.int64)
        if kind == TRIANGLE:
            tri.append(block[:, 1 + n_tags :])
            numbers.append(np.repeat(block[:, 0], 3))
            zeros = np.zeros(follow, dtype=np.int64)
            physical.append(block[:, 1] if n_tags >= 1 else zeros)
            elementary.append(block[:, 2] if n_tags >= 2 else zeros)
        else:
            ignored[name] = ignored.get(name, 0) + follow
            other.append(block[:, 1 + n_tags :].reshape(-1))
            other_numbers.append(np.repeat(block[:, 0], n_nodes))
        pos += 12 + follow * width * 4
        parsed += follow
    if not data[pos : pos + 16].lstrip().startswith(b"$EndElements"):
        raise Damaged(f"its $Elements section does not end after {count:,} elements")

    def joined(parts: list[np.ndarray], shape: tuple[int, ...]) -> np.ndarray:
        return np.concatenate(parts) if parts else np.empty(shape, dtype=np.int64)

    node_indices(tags, joined(other, (0,)), joined(other_numbers, (0,)))
    triangles = node_indices(tags, joined(tri, (0, 3)), joined(numbers, (0,)))
    return points, triangles, joined(physical, (0,)), joined(elementary, (0,)), ignored
