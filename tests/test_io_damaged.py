"""A corpus of damaged and hostile mesh files, generated at test time: every one refused.

Each case is a file of a format we read, broken in one way: a count that lies
(10^12, negative, one too many), an index or tag that does not exist (0, -3,
one past the end), a non-finite coordinate, a truncation, a decompression bomb,
a header that cannot be true. Each must be refused with one ``MeshFileError``
line that names the file, and the reader must check before it allocates: the
peak of Python's and numpy's allocations while reading stays far below what the
file declares (tracemalloc), which also keeps every case fast.
"""

from __future__ import annotations

import base64
import os
import struct
import tracemalloc
import zlib

import meshio
import numpy as np
import pytest
import scipy.io
from helpers import run_capped

from barymesh import MeshParams, build_mesh
from barymesh.io import MeshFileError, read_mesh, write_mesh

MESH = build_mesh(MeshParams(structure="patch", patch_size=10.0, subdivisions=2))
N_POINTS, N_TRIANGLES = MESH.n_vertices, MESH.n_triangles  # 9 and 8
#: No case may need more than this while it is refused.
PEAK_BYTES = 200 * 2**20
#: Words of a parser's internals that a message about a file must not show.
INTERNALS = (
    "reshape",
    "codec",
    "array of size",
    "out of bounds",
    "exception",
    "error",
    "unpack",
    "buffer",
    "dtype",
    "numpy",
    "meshio",
    "scipy",
    "traceback",
)
HUGE_COUNTS = ["1000000000000", "-1", "abc", "4294967296", "99999999", "1e3"]


def _sub(text: str, old: str, new: str, count: int = 1) -> str:
    assert old in text, old
    return text.replace(old, new, count)


def _truncations(name: str, data: bytes, fractions=(0.1, 0.3, 0.5, 0.7, 0.9)):
    return {f"{name}-truncated-{int(f * 100)}": data[: int(len(data) * f)] for f in fractions}


# -- VTK XML written by hand, so each field can lie --------------------------------------


def _b64_block(raw: bytes, compress: bool, declared: int | None = None) -> str:
    """One binary DataArray body: UInt32 header(s) and data, optionally zlib-compressed."""
    if not compress:
        size = len(raw) if declared is None else declared
        return base64.b64encode(struct.pack("<I", size) + raw).decode()
    packed = zlib.compress(raw)
    size = len(raw) if declared is None else declared
    header = struct.pack("<4I", 1, size, size, len(packed))
    return base64.b64encode(header).decode() + base64.b64encode(packed).decode()


def _data_array(name, dtype, values, comps=1, mode="ascii", declared=None, body=None):
    vtk = {"f8": "Float64", "i8": "Int64", "u1": "UInt8", "i4": "Int32"}[dtype]
    values = np.asarray(values, dtype=dtype)
    if body is None:
        if mode == "ascii":
            body = " ".join(map(str, values.reshape(-1).tolist()))
        else:
            body = _b64_block(values.tobytes(), mode == "zlib", declared)
    fmt = "ascii" if mode == "ascii" else "binary"
    return (
        f'<DataArray type="{vtk}" Name="{name}" NumberOfComponents="{comps}" '
        f'format="{fmt}">{body}</DataArray>\n'
    )


def vtk_xml(
    kind="PolyData",
    mode="ascii",
    n_points=None,
    n_cells=None,
    points_body=None,
    points_declared=None,
    conn=None,
    offsets=None,
    extra_attrs="",
    root_attrs="",
    verts=None,
):
    """A VTK XML file of MESH with any field overridden."""
    pts = MESH.points
    conn = MESH.triangles.reshape(-1) if conn is None else np.asarray(conn)
    offsets = 3 * np.arange(1, N_TRIANGLES + 1) if offsets is None else np.asarray(offsets)
    compressor = ' compressor="vtkZLibDataCompressor"' if mode == "zlib" else ""
    head = (
        f'<?xml version="1.0"?>\n<VTKFile type="{kind}" version="1.0" '
        f'byte_order="LittleEndian" header_type="UInt32"{compressor}{root_attrs}>\n'
        f"<{kind}>\n"
    )
    npts = N_POINTS if n_points is None else n_points
    ncells = N_TRIANGLES if n_cells is None else n_cells
    points = _data_array("Points", "f8", pts, 3, mode, points_declared, points_body)
    arrays = _data_array("connectivity", "i8", conn, 1, mode) + _data_array(
        "offsets", "i8", offsets, 1, mode
    )
    region = _data_array("region", "i4", np.ones(N_TRIANGLES), 1, mode)
    if kind == "PolyData":
        nverts = "0" if verts is None else verts
        piece = (
            f'<Piece NumberOfPoints="{npts}" NumberOfVerts="{nverts}" NumberOfLines="0" '
            f'NumberOfStrips="0" NumberOfPolys="{ncells}"{extra_attrs}>\n'
            f"<Points>{points}</Points><Polys>{arrays}</Polys>"
            f"<CellData>{region}</CellData></Piece>\n"
        )
    else:
        types = _data_array("types", "u1", np.full(N_TRIANGLES, 5), 1, mode)
        piece = (
            f'<Piece NumberOfPoints="{npts}" NumberOfCells="{ncells}"{extra_attrs}>\n'
            f"<Points>{points}</Points><Cells>{arrays}{types}</Cells>"
            f"<CellData>{region}</CellData></Piece>\n"
        )
    return (head + piece + f"</{kind}>\n</VTKFile>\n").encode()


def _zlib_bomb(n_bytes: int) -> bytes:
    """zlib stream of ``n_bytes`` zeros, made in 1 MiB steps (about 1 kB per MiB)."""
    c = zlib.compressobj(9)
    chunk = bytes(1 << 20)
    parts = [c.compress(chunk) for _ in range(n_bytes >> 20)]
    return b"".join(parts) + c.flush()


def _vtk_xml_cases() -> dict[str, bytes]:
    cases = {}
    for ext, kind in ((".vtp", "PolyData"), (".vtu", "UnstructuredGrid")):
        for mode in ("ascii", "binary", "zlib"):
            key = f"{ext}-{mode}"
            assert vtk_xml(kind, mode)  # the undamaged file is built the same way
            for value in HUGE_COUNTS + [str(N_POINTS + 1), str(N_POINTS - 1)]:
                cases[f"{key}-points-{value}"] = vtk_xml(kind, mode, n_points=value)
            for value in HUGE_COUNTS + [str(N_TRIANGLES + 1)]:
                cases[f"{key}-cells-{value}"] = vtk_xml(kind, mode, n_cells=value)
            for bad in (-3, N_POINTS, 2**40):
                conn = MESH.triangles.reshape(-1).astype(np.int64)
                conn[4] = bad
                cases[f"{key}-index-{bad}"] = vtk_xml(kind, mode, conn=conn)
            decreasing = 3 * np.arange(1, N_TRIANGLES + 1)
            decreasing[3] = 2
            cases[f"{key}-offsets-decreasing"] = vtk_xml(kind, mode, offsets=decreasing)
            cases[f"{key}-offsets-beyond"] = vtk_xml(kind, mode, offsets=decreasing * 50)
            cases.update(_truncations(key, vtk_xml(kind, mode)))
            if mode != "ascii":
                for declared in (0, 71, 73, 2**31):  # the points need 9 * 3 * 8 = 216 bytes
                    cases[f"{key}-declares-{declared}-bytes"] = vtk_xml(
                        kind, mode, points_declared=declared
                    )
                cases[f"{key}-not-base64"] = vtk_xml(kind, mode, points_body="!!!!" * 20)
                cases[f"{key}-header-type"] = vtk_xml(kind, mode).replace(
                    b'header_type="UInt32"', b'header_type="UInt16"'
                )
            else:
                cases[f"{key}-nan"] = vtk_xml(kind, mode, points_body="nan " * (3 * N_POINTS))
                cases[f"{key}-words"] = vtk_xml(kind, mode, points_body="one two three " * 9)
        # bombs: 1.5 GiB of zeros declared by a count; 256 MiB behind a header that lies;
        # a block that claims more than zlib can reach
        n = 1536 * 2**20 // 24
        header = struct.pack("<4I", 1, 2**31 - 1, 2**31 - 1, 100)
        body = base64.b64encode(header).decode() + base64.b64encode(b"x" * 100).decode()
        cases[f"{ext}-bomb-count"] = vtk_xml(kind, "zlib", n_points=n, points_body=body)
        lie = _zlib_bomb(256 * 2**20)
        header = struct.pack("<4I", 1, 216, 216, len(lie))
        body = base64.b64encode(header).decode() + base64.b64encode(lie).decode()
        cases[f"{ext}-bomb-lie"] = vtk_xml(kind, "zlib", points_body=body)
        header = struct.pack("<4I", 1, 2**30, 2**30, 16)
        body = base64.b64encode(header).decode() + base64.b64encode(b"\x78\x9c" * 8).decode()
        cases[f"{ext}-bomb-ratio"] = vtk_xml(kind, "zlib", n_points=2**30 // 24, points_body=body)
        cases[f"{ext}-entities"] = (
            b'<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "aaaaaaaaaa">'
            b'<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]><VTKFile>&b;</VTKFile>'
        )
        cases[f"{ext}-compressor"] = vtk_xml(kind, "zlib").replace(b"ZLib", b"LZ4")
        cases[f"{ext}-wrong-kind"] = vtk_xml("ImageData", "ascii")
        cases[f"{ext}-no-piece"] = vtk_xml(kind).split(b"<Piece")[0] + b"</VTKFile>"
    cases[".vtp-verts-1e12"] = vtk_xml("PolyData", verts="1000000000000")
    cases[".vtp-verts-missing"] = vtk_xml("PolyData", verts="5")
    return cases


# -- Gmsh ----------------------------------------------------------------------------------


def _msh_cases(tmp_path) -> dict[str, bytes]:
    path = write_mesh(MESH, tmp_path / "base.msh")
    text = path.read_text()
    cases = {}
    nodes_head = f"$Nodes\n{N_POINTS}\n"
    elements_head = f"$Elements\n{N_TRIANGLES}\n"
    for value in HUGE_COUNTS + [str(N_POINTS + 1), str(N_POINTS - 1), ""]:
        cases[f"msh-nodes-{value}"] = _sub(text, nodes_head, f"$Nodes\n{value}\n")
    for value in HUGE_COUNTS + [str(N_TRIANGLES + 1), str(N_TRIANGLES - 1)]:
        cases[f"msh-elements-{value}"] = _sub(text, elements_head, f"$Elements\n{value}\n")
    first_node = nodes_head + "1 "
    for tag in ("-3", "0", "2.5", "x", "2"):
        cases[f"msh-node-tag-{tag}"] = _sub(text, first_node, nodes_head + tag + " ")
    lines = text.splitlines()
    k = lines.index("$Elements") + 2  # the first element line
    for position in (5, 6, 7):  # "number type ntags physical elementary n1 n2 n3"
        for bad in ("-3", "0", str(N_POINTS + 1), "99999999999", "x"):
            broken = lines.copy()
            tokens = broken[k].split()
            tokens[position] = bad
            broken[k] = " ".join(tokens)
            cases[f"msh-element-node{position - 4}-{bad}"] = "\n".join(broken) + "\n"
    for position, bad in ((1, "99"), (1, "-1"), (2, "-1"), (2, "1000")):
        broken = lines.copy()
        tokens = broken[k].split()
        tokens[position] = bad
        broken[k] = " ".join(tokens)
        cases[f"msh-element-field{position}-{bad}"] = "\n".join(broken) + "\n"
    coordinate = lines[lines.index("$Nodes") + 2].split()[1]
    for bad in ("nan", "inf", "-inf", "1e999", "x"):
        cases[f"msh-coordinate-{bad}"] = text.replace(coordinate, bad, 1)
    for section in ("$EndNodes", "$EndElements"):
        cases[f"msh-no-{section}"] = _sub(text, section + "\n", "")
    for section in ("Nodes", "Elements"):
        start, end = text.index(f"${section}\n"), text.index(f"$End{section}\n")
        cases[f"msh-without-{section}"] = text[:start] + text[end + len(section) + 5 :]
    cases = {k: v.encode() for k, v in cases.items()}
    cases.update(_truncations("msh-ascii", text.encode(), (0.2, 0.4, 0.6, 0.8, 0.95)))
    # binary MSH 2.2 and MSH 4.1 (read through meshio after our count checks)
    m = meshio.Mesh(MESH.points, [("triangle", MESH.triangles)])
    for fmt, binary in (("gmsh22", True), ("gmsh", False), ("gmsh", True)):
        out = tmp_path / f"{fmt}-{binary}.msh"
        meshio.write(out, m, file_format=fmt, binary=binary)
        data = out.read_bytes()
        name = f"msh-{fmt}-{'binary' if binary else 'ascii'}"
        cases.update(_truncations(name, data, (0.3, 0.5, 0.7, 0.9)))
        if fmt == "gmsh22":
            for value in (b"1000000000000", b"-1", b"abc", b"10"):
                cases[f"{name}-nodes-{value.decode()}"] = data.replace(
                    b"$Nodes\n9\n", b"$Nodes\n" + value + b"\n", 1
                )
            cases.update(_binary_msh22_cases(data))
        elif not binary:
            cases.update(_ascii_msh41_cases(data.decode()))
        else:
            cases.update(_binary_msh41_cases(data))
    return cases


def _binary_msh22_cases(data: bytes) -> dict[str, bytes]:
    """Node tags and element node references broken inside binary MSH 2.2."""
    cases = {}
    nodes = data.index(b"$Nodes\n9\n") + len(b"$Nodes\n9\n")
    for bad in (0, -3):  # node records: int32 tag, 3 float64
        broken = bytearray(data)
        broken[nodes : nodes + 4] = struct.pack("<i", bad)
        cases[f"msh-gmsh22-binary-node-tag-{bad}"] = bytes(broken)
    elements = data.index(b"$Elements\n8\n") + len(b"$Elements\n8\n")
    kind, follow, n_tags = struct.unpack("<3i", data[elements : elements + 12])
    assert (kind, follow) == (2, N_TRIANGLES)
    first_node = elements + 12 + 4 * (1 + n_tags)  # after the element number and its tags
    for bad in (0, -3, N_POINTS + 1, 2**31 - 1):
        broken = bytearray(data)
        broken[first_node : first_node + 4] = struct.pack("<i", bad)
        cases[f"msh-gmsh22-binary-element-node-{bad}"] = bytes(broken)
    for field, bad in ((0, 99), (1, 1000), (1, 0), (2, -1)):  # type, count, number of tags
        broken = bytearray(data)
        broken[elements + 4 * field : elements + 4 * field + 4] = struct.pack("<i", bad)
        cases[f"msh-gmsh22-binary-block-{field}-{bad}"] = bytes(broken)
    return cases


def _ascii_msh41_cases(text: str) -> dict[str, bytes]:
    """Counts, node tags and element references broken inside MSH 4.1 ASCII."""
    cases = {}
    nodes = text.index("$Nodes\n") + len("$Nodes\n")
    header = text[nodes : text.index("\n", nodes)]
    blocks, count, low, high = header.split()
    for value in ("1000000000000", "-1", "x", str(int(count) + 1)):
        cases[f"msh-gmsh-ascii-nodes-{value}"] = text.replace(
            "$Nodes\n" + header, f"$Nodes\n{blocks} {value} {low} {high}", 1
        )
    cases["msh-gmsh-ascii-node-blocks-5"] = text.replace(
        "$Nodes\n" + header, f"$Nodes\n5 {count} {low} {high}", 1
    )
    lines = text.splitlines()
    k = lines.index("$Nodes") + 3  # the first node tag of the first block
    for bad in ("0", "-3", "2.5"):
        broken = lines.copy()
        broken[k] = bad
        cases[f"msh-gmsh-ascii-node-tag-{bad}"] = "\n".join(broken) + "\n"
    k = lines.index("$Elements") + 3  # the first element line of the first block
    for bad in ("0", "-3", str(N_POINTS + 1), "x"):
        broken = lines.copy()
        tokens = broken[k].split()
        tokens[2] = bad
        broken[k] = " ".join(tokens)
        cases[f"msh-gmsh-ascii-element-node-{bad}"] = "\n".join(broken) + "\n"
    for field, bad in ((2, "99"), (3, "1000"), (3, "0")):  # type, count of the first block
        broken = lines.copy()
        tokens = broken[k - 1].split()
        tokens[field] = bad
        broken[k - 1] = " ".join(tokens)
        cases[f"msh-gmsh-ascii-block-{field}-{bad}"] = "\n".join(broken) + "\n"
    return {key: value.encode() for key, value in cases.items()}


def _binary_msh41_cases(data: bytes) -> dict[str, bytes]:
    """Counts, node tags and element references broken inside MSH 4.1 binary."""
    cases = {}
    nodes = data.index(b"$Nodes\n") + len(b"$Nodes\n")
    for value in (10**12, N_POINTS + 1, 2**64 - 1):
        broken = bytearray(data)
        broken[nodes + 8 : nodes + 16] = struct.pack("<Q", value)
        cases[f"msh-gmsh-binary-nodes-{value}"] = bytes(broken)
    first_tag = nodes + 32 + 12 + 8  # header (4 size_t), block (3 int, 1 size_t)
    for bad in (0, 2**63):
        broken = bytearray(data)
        broken[first_tag : first_tag + 8] = struct.pack("<Q", bad)
        cases[f"msh-gmsh-binary-node-tag-{bad}"] = bytes(broken)
    elements = data.index(b"$Elements\n") + len(b"$Elements\n")
    first_node = elements + 32 + 12 + 8 + 8  # header, block header, element tag
    for bad in (0, N_POINTS + 1, 2**40):
        broken = bytearray(data)
        broken[first_node : first_node + 8] = struct.pack("<Q", bad)
        cases[f"msh-gmsh-binary-element-node-{bad}"] = bytes(broken)
    broken = bytearray(data)
    broken[elements + 32 + 12 : elements + 32 + 20] = struct.pack("<Q", 10**9)
    cases["msh-gmsh-binary-element-block-1e9"] = bytes(broken)
    return cases


# -- legacy VTK, STL, OBJ ------------------------------------------------------------------


def _vtk_legacy_cases(tmp_path) -> dict[str, bytes]:
    cases = {}
    m = meshio.Mesh(MESH.points, [("triangle", MESH.triangles)])
    for binary in (False, True):
        out = tmp_path / f"legacy-{binary}.vtk"
        meshio.write(out, m, file_format="vtk", binary=binary)
        data = out.read_bytes()
        name = f"vtk-{'binary' if binary else 'ascii'}"
        points_line = next(ln for ln in data.split(b"\n") if ln.startswith(b"POINTS"))
        cells_line = next(ln for ln in data.split(b"\n") if ln.startswith(b"CELLS"))
        for value in (b"1000000000000", b"-1", b"abc", b"99999999"):
            cases[f"{name}-points-{value.decode()}"] = data.replace(
                points_line, b"POINTS " + value + b" " + points_line.split()[2], 1
            )
            cases[f"{name}-cells-{value.decode()}"] = data.replace(
                cells_line, b"CELLS " + value + b" " + cells_line.split()[2], 1
            )
        cases.update(_truncations(name, data, (0.3, 0.5, 0.7, 0.9)))
        with_data = meshio.Mesh(
            MESH.points, [("triangle", MESH.triangles)], cell_data={"q": [np.ones(N_TRIANGLES)]}
        )
        meshio.write(out, with_data, file_format="vtk", binary=binary)
        data = out.read_bytes()
        field = f"q 1 {N_TRIANGLES} double".encode()
        for value in (b"q 1 1000000000000 double", b"q 100000000 8 double"):
            cases[f"{name}-field-{value.split()[1].decode()}x{value.split()[2].decode()}"] = (
                data.replace(field, value, 1)
            )
    ascii_text = (tmp_path / "legacy-False.vtk").read_text()
    rows = ascii_text.split("\n")
    k = rows.index(next(r for r in rows if r.startswith("CONNECTIVITY"))) + 2
    for bad in ("-3", str(N_POINTS), "99999999999"):
        broken = rows.copy()
        broken[k] = bad  # meshio writes one index a line
        cases[f"vtk-ascii-index-{bad}"] = "\n".join(broken).encode()
    point_row = rows.index(next(r for r in rows if r.startswith("POINTS"))) + 1
    broken = rows.copy()
    broken[point_row] = "nan " + broken[point_row].split(" ", 1)[1]
    cases["vtk-ascii-nan"] = "\n".join(broken).encode()
    return cases


def _stl_cases(tmp_path) -> dict[str, bytes]:
    cases = {}
    out = tmp_path / "b.stl"
    meshio.write(out, meshio.Mesh(MESH.points, [("triangle", MESH.triangles)]), binary=True)
    data = out.read_bytes()
    for count in (10**9, 0, N_TRIANGLES + 1, N_TRIANGLES - 1, 2**32 - 1):
        cases[f"stl-binary-count-{count}"] = data[:80] + struct.pack("<I", count) + data[84:]
    nan = bytearray(data)
    nan[84 + 12 : 84 + 16] = struct.pack("<f", float("nan"))
    cases["stl-binary-nan"] = bytes(nan)
    cases.update(_truncations("stl-binary", data))
    text = write_mesh(MESH, tmp_path / "a.stl").read_text()
    vertex = next(ln for ln in text.splitlines() if "vertex" in ln)
    for name, new in (
        ("two-coordinates", "vertex 1 2"),
        ("words", "vertex x y z"),
        ("nan", "vertex nan 0 0"),
        ("inf", "vertex inf 0 0"),
    ):
        cases[f"stl-ascii-{name}"] = text.replace(vertex, "      " + new, 1).encode()
    cases["stl-ascii-two-vertices"] = text.replace(vertex + "\n", "", 1).encode()
    cases["stl-ascii-no-facets"] = b"solid empty\nendsolid empty\n"
    # issue 30: cut after a whole facet, meshio read the facets before the cut
    last = text.rindex("endfacet") + len("endfacet")
    cases["stl-ascii-cut-after-endfacet"] = (text[:last] + "\n").encode()
    first = text.index("endfacet") + len("endfacet")
    cases["stl-ascii-cut-after-the-first-facet"] = (text[:first] + "\n").encode()
    cases.update(_truncations("stl-ascii", text.encode()))
    return cases


def _obj_cases(tmp_path) -> dict[str, bytes]:
    text = write_mesh(MESH, tmp_path / "a.obj").read_text()
    face = next(ln for ln in text.splitlines() if ln.startswith("f "))
    vertex = next(ln for ln in text.splitlines() if ln.startswith("v "))
    cases = {}
    for position in range(3):
        for bad in ("0", f"-{N_POINTS + 1}", str(N_POINTS + 1), "2199023255552", "x", "1.5"):
            tokens = face.split()
            tokens[1 + position] = bad
            cases[f"obj-face{position}-{bad}"] = text.replace(face, " ".join(tokens), 1)
    cases["obj-face-two-corners"] = text.replace(face, "f 1 2", 1)
    for name, new in (
        ("two-coordinates", "v 1 2"),
        ("words", "v x y z"),
        ("nan", "v nan 0 0"),
        ("inf", "v 0 inf 0"),
        ("huge", "v 1e999 0 0"),
    ):
        cases[f"obj-vertex-{name}"] = text.replace(vertex, new, 1)
    cases["obj-no-faces"] = "\n".join(ln for ln in text.splitlines() if not ln.startswith("f"))
    cases["obj-only-quads"] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
    cases["obj-relative-before-any-vertex"] = "f -1 -2 -3\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
    return {k: v.encode() for k, v in cases.items()}


def _mat_bytes(variables: dict, compress: bool = True) -> bytes:
    import io

    buf = io.BytesIO()
    scipy.io.savemat(buf, variables, do_compression=compress, oned_as="column")
    return buf.getvalue()


def _mat_cases() -> dict[str, bytes]:
    p = MESH.points.T * 1e-3
    t = np.vstack([MESH.triangles.T + 1, np.ones(N_TRIANGLES)])
    cases = {}
    for bad in (0, -4, N_POINTS + 1, 1.5, np.nan, np.inf, 2**40):
        broken = t.copy()
        broken[1, 2] = bad
        cases[f"mat-index-{bad}"] = _mat_bytes({"p": p, "t": broken})
    cases["mat-t-logical"] = _mat_bytes({"p": p, "t": t.astype(bool)})
    cases["mat-t-complex"] = _mat_bytes({"p": p, "t": t + 1j})
    cases["mat-p-complex"] = _mat_bytes({"p": p + 1j, "t": t})
    cases["mat-p-text"] = _mat_bytes({"p": "not numbers", "t": t})
    cases["mat-t-cell"] = _mat_bytes({"p": p, "t": np.array([[t]], dtype=object)})
    cases["mat-p-5-rows"] = _mat_bytes({"p": np.zeros((5, N_POINTS)), "t": t})
    cases["mat-t-6-rows"] = _mat_bytes({"p": p, "t": np.ones((6, N_TRIANGLES))})
    cases["mat-no-p"] = _mat_bytes({"t": t})
    cases["mat-no-t"] = _mat_bytes({"p": p})
    cases["mat-p-nan"] = _mat_bytes({"p": np.full_like(p, np.nan), "t": t})
    whole = _mat_bytes({"p": p, "t": t}, compress=False)
    cases.update(_truncations("mat", whole))
    cases.update(_truncations("mat-compressed", _mat_bytes({"p": p, "t": t})))
    # declared dimensions of p as 3 x 2^31-1 (the data stays small)
    dims = struct.pack("<ii", 3, N_POINTS)
    assert whole.count(dims) == 1
    cases["mat-p-declares-2e9-columns"] = whole.replace(dims, struct.pack("<ii", 3, 2**31 - 1))
    cases["mat-v73"] = b"MATLAB 7.3 MAT-file".ljust(116, b" ") + bytes(8) + b"\x00\x02IM"
    return cases


def corpus(tmp_path) -> dict[str, bytes]:
    """File name -> bytes of every damaged case (the extension picks the reader)."""
    files = {}
    for name, data in _vtk_xml_cases().items():
        ext, rest = name.split("-", 1)
        files[f"{rest}{ext}"] = data
    groups = (
        (_msh_cases(tmp_path), ".msh"),
        (_vtk_legacy_cases(tmp_path), ".vtk"),
        (_stl_cases(tmp_path), ".stl"),
        (_obj_cases(tmp_path), ".obj"),
        (_mat_cases(), ".mat"),
    )
    for cases, ext in groups:
        files.update({f"{name}{ext}": data for name, data in cases.items()})
    garbage = bytes(range(256)) * 4
    for ext in (".msh", ".vtk", ".vtu", ".vtp", ".stl", ".obj", ".mat"):
        files[f"garbage{ext}"] = garbage
        files[f"text{ext}"] = b"this is not a mesh file\n" * 10
        files[f"nul{ext}"] = bytes(4096)
        files[f"nul-then-text{ext}"] = bytes(64) + b"this is not a mesh file\n" * 10
    return files


@pytest.fixture(scope="module")
def damaged(tmp_path_factory):
    folder = tmp_path_factory.mktemp("damaged")
    files = corpus(folder)
    for name, data in files.items():
        (folder / name).write_bytes(data)
    return folder, sorted(files)


def test_corpus_covers_every_format_with_300_files(damaged):
    _, names = damaged
    assert len(names) >= 300
    extensions = {name[name.rindex(".") :] for name in names}
    assert extensions == {".msh", ".vtk", ".vtu", ".vtp", ".stl", ".obj", ".mat"}


def test_every_damaged_file_is_refused_in_one_line_within_bounded_memory(damaged):
    folder, names = damaged
    accepted, bad_messages, heavy = [], [], []
    for name in names:
        path = folder / name
        tracemalloc.start()
        try:
            mesh = read_mesh(path)
        except MeshFileError as exc:
            message = str(exc)
            said = message[len(str(path)) + 2 :]
            internal = [word for word in INTERNALS if word in said.lower()]
            if not message.startswith(f"{path}: ") or "\n" in message or str(path) in said:
                bad_messages.append((name, message))
            elif internal or name in said:
                bad_messages.append((name, message))
        else:
            accepted.append((name, mesh.n_triangles))
        finally:
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
        if peak > PEAK_BYTES:
            heavy.append((name, peak))
    assert accepted == []
    assert bad_messages == []
    assert heavy == []


# -- the cases of the issue, each with the words its message must hold --------------------

NAMED = {
    "msh-element-node1--3.msh": "element 1 refers to node -3, which the $Nodes section does not",
    "msh-element-node1-0.msh": "element 1 refers to node 0, which the $Nodes section does not",
    "msh-node-tag-0.msh": "node tag 0 is invalid",
    "mat-t-logical.mat": "its t is of MATLAB class logical",
    "mat-index--4.mat": "its t refers to vertex -4; indices are 1-based",
    "mat-t-complex.mat": "its t holds complex numbers",
    "verts-1e12.vtp": "it declares 1,000,000,000,000 verts; barymesh reads at most",
    "ascii-index--3.vtu": "a cell refers to point -3; point indices start at 0",
    "ascii-index--3.vtp": "a polygon refers to point -3",
    "obj-face0-0.obj": "a face refers to vertex 0; OBJ indices start at 1",
    "obj-face0--10.obj": "a face refers to vertex -10, but only 9 vertices precede it",
    "bomb-lie.vtp": "inflates to more than the 216 bytes it declares",
    "bomb-count.vtu": "it declares 67,108,864 points",
    "stl-binary-count-1000000000.stl": "declares 1,000,000,000 triangles",
    "stl-ascii-cut-after-endfacet.stl": "does not end with 'endsolid': the file is cut short",
    "nul.obj": "not a readable Wavefront OBJ file (byte 0 is a NUL byte, in a text format)",
    "nul.msh": "not a readable Gmsh MSH 2.2/4.1, ASCII or binary file (it does not start with",
    "nul-then-text.vtk": "not a readable VTK legacy file (it does not start with '# vtk",
    "text.vtu": "it is not valid XML (it does not start with '<')",
    "msh-elements-9.msh": "declares 9 elements",
    "msh-gmsh22-binary-element-node-0.msh": "element 1 refers to node 0, which the $Nodes",
    "msh-gmsh22-binary-element-node--3.msh": "element 1 refers to node -3, which the $Nodes",
    "msh-gmsh22-binary-node-tag-0.msh": "node tag 0 is invalid",
    "msh-gmsh-ascii-element-node-0.msh": "refers to node 0, which the $Nodes section does not",
    "msh-gmsh-ascii-element-node--3.msh": "refers to node -3, which the $Nodes section",
    "msh-gmsh-binary-element-node-0.msh": "refers to node 0, which the $Nodes section does not",
    "msh-gmsh-ascii-node-tag-0.msh": "node tag 0 is invalid",
}


@pytest.mark.parametrize("name", sorted(NAMED))
def test_named_damage_is_described_in_the_files_terms(damaged, name):
    folder, _ = damaged
    path = folder / name
    with pytest.raises(MeshFileError) as info:
        read_mesh(path)
    assert str(info.value) == f"{path}: {info.value.args[0].split(': ', 1)[1]}"
    assert NAMED[name] in str(info.value)


def test_mat_complex_values_warn_nothing(damaged, recwarn):
    folder, _ = damaged
    with pytest.raises(MeshFileError):
        read_mesh(folder / "mat-p-complex.mat")
    assert [str(w.message) for w in recwarn] == []


def test_what_a_path_really_is(tmp_path):
    import os

    fifo = tmp_path / "pipe.msh"
    os.mkfifo(fifo)
    (tmp_path / "zero.msh").symlink_to("/dev/zero")
    (tmp_path / "loop.msh").symlink_to(tmp_path / "loop.msh")
    (tmp_path / "dangling.stl").symlink_to(tmp_path / "gone.stl")
    expected = {
        "pipe.msh": "the path is a named pipe (FIFO), not a file",
        "zero.msh": "the path is a symbolic link to /dev/zero, which is a character device",
        "loop.msh": "the path is a symbolic link loop",
        "dangling.stl": f"symbolic link to {tmp_path / 'gone.stl'}, which does not exist",
    }
    for name, words in expected.items():
        with pytest.raises(MeshFileError) as info:
            read_mesh(tmp_path / name)
        assert str(info.value).startswith(f"{tmp_path / name}: ")
        assert words in str(info.value)


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root reads all")
def test_unreadable_file(tmp_path):
    path = write_mesh(MESH, tmp_path / "locked.msh")
    path.chmod(0)
    with pytest.raises(MeshFileError, match="cannot be read: Permission denied"):
        read_mesh(path)


def test_obj_with_texture_normals_and_relative_indices_is_read(tmp_path):
    """The OBJ specification's corner forms and negative indices (counted back)."""
    path = tmp_path / "full.obj"
    path.write_text(
        "# a unit square in two triangles\nmtllib x.mtl\no square\n"
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
        "g first\nusemtl red\nf 1/1/1 2/2/1 3/3/1\n"
        "s off\nf -4//1 -2//1 -1//1\n"  # = 1 3 4
        "v 5 5 0\nv 6 5 0\nv 5 6 0\nf -3/1 -2/2 -1/3\n"  # = 5 6 7
        "l 1 2\n"
    )
    mesh = read_mesh(path)
    assert mesh.n_triangles == 3 and mesh.n_vertices == 7
    assert mesh.ignored_cells == {"line": 1}
    assert mesh.areas.sum() == pytest.approx(1.5)
    np.testing.assert_array_equal(mesh.points[mesh.triangles[1]], [[0, 0, 0], [1, 1, 0], [0, 1, 0]])


BOMB_CHILD = """
import resource, sys
from barymesh.io import MeshFileError, read_mesh
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
for path in sys.argv[1:]:
    try:
        read_mesh(path)
    except MeshFileError:
        pass
    else:
        sys.exit(f"{path} was accepted")
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before)  # kB
"""


def test_bombs_are_refused_without_the_memory_they_declare(damaged):
    """Peak RSS of a real process (C allocations included) while it refuses every bomb."""
    import subprocess
    import sys
    from pathlib import Path

    folder, names = damaged
    bombs = [str(folder / name) for name in names if "bomb" in name]
    assert len(bombs) == 6
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root))
    r = subprocess.run(
        [sys.executable, "-c", BOMB_CHILD, *bombs],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert r.returncode == 0, r.stderr
    grown_kb = int(r.stdout.strip().splitlines()[-1])
    assert grown_kb < 50 * 1024  # the bombs declare 256 MiB to 1.5 GiB


def test_unreadable_file_is_named_as_such(tmp_path, monkeypatch):
    """Issue 10 #10: permission denied is said as such (root reads everything, so simulate)."""
    from barymesh.io import import_

    path = write_mesh(MESH, tmp_path / "locked.msh")

    def denied(name, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(name))

    monkeypatch.setattr(import_, "open", denied, raising=False)
    with pytest.raises(MeshFileError) as info:
        read_mesh(path)
    assert str(info.value) == f"{path}: cannot be read: Permission denied"


# -- issue 30: huge files are refused from their size and first bytes ---------------------


def sparse(path, size):
    """A file of ``size`` NUL bytes that takes no disk space (a hole)."""
    with open(path, "wb") as fh:
        fh.truncate(size)
    return path


def test_huge_files_are_refused_from_their_size_and_first_bytes(tmp_path):
    # issue 30: a 1 GiB sparse file of NUL bytes named .obj was refused after 111 s at
    # 2.1 GB; 2-3 GiB .msh and .vtu files took over 30 s at 2-3.7 GB. Under a 1 GiB cap:
    files = {
        sparse(
            tmp_path / "nul.obj", 2**30
        ): "not a readable Wavefront OBJ file (byte 0 is a NUL byte",
        sparse(tmp_path / "big.msh", 3 * 2**30): "the file is 3 GiB, more than the 2 GiB",
        sparse(tmp_path / "big.vtu", 5 * 2**29): "the file is 2.5 GiB, more than the 2 GiB",
    }
    out = run_capped(
        f"""
        from barymesh.io import MeshFileError, read_mesh
        for path in {[str(p) for p in files]!r}:
            try:
                read_mesh(path)
            except MeshFileError as exc:
                print(exc)
        """
    )
    assert out.returncode == 0, out.stderr[-1500:]
    lines = out.stdout.splitlines()
    assert len(lines) == 3
    for line, (path, fragment) in zip(lines, files.items(), strict=True):
        assert line.startswith(f"{path}: {fragment}"), line
    assert "read_mesh(max_bytes=...) or BARYMESH_MAX_FILE_BYTES" in lines[1]


def test_the_file_size_limit_is_raised_by_the_environment_or_the_argument(tmp_path, monkeypatch):
    big = sparse(tmp_path / "big.msh", 3 * 2**30)
    monkeypatch.setenv("BARYMESH_MAX_FILE_BYTES", "4GiB")
    with pytest.raises(MeshFileError, match=r"\(it does not start with \$MeshFormat\)"):
        read_mesh(big)  # past the size check: refused from its first bytes
    monkeypatch.setenv("BARYMESH_MAX_FILE_BYTES", "500")
    small = write_mesh(MESH, tmp_path / "small.msh")
    assert small.stat().st_size > 500
    with pytest.raises(MeshFileError, match=r"more than the 500 bytes barymesh reads"):
        read_mesh(small)
    assert read_mesh(small, max_bytes=10**6).n_triangles == N_TRIANGLES
    monkeypatch.setenv("BARYMESH_MAX_FILE_BYTES", "lots")
    with pytest.raises(ValueError, match=r"BARYMESH_MAX_FILE_BYTES='lots' is not a size"):
        read_mesh(small)


def test_a_binary_stl_whose_header_says_solid_is_still_read(tmp_path):
    out = tmp_path / "b.stl"
    meshio.write(out, meshio.Mesh(MESH.points, [("triangle", MESH.triangles)]), binary=True)
    data = out.read_bytes()
    out.write_bytes(b"solid exported by a CAD tool".ljust(80) + data[80:])
    assert read_mesh(out).n_triangles == N_TRIANGLES
