"""No import circle in the core, function-level imports counted (issue 18, point 3).

The graph is grimp's (tests/import_graph.py); these tests also show that it sees the
imports it must see, so that an empty list of circles means something.
"""

import importlib
import textwrap

import pytest
from import_graph import NOT_CORE, circles, describe, import_edges


@pytest.fixture(scope="module")
def core_edges():
    return import_edges("barymesh", NOT_CORE)


def test_the_core_has_no_import_circle(core_edges):
    found = circles(core_edges)
    assert found == [], "\n".join(describe(c, core_edges) for c in found)


def test_the_graph_sees_module_level_and_function_level_imports(core_edges):
    # module level: the layout asks the sector planner
    assert ("barymesh.structures", "barymesh.sectors") in core_edges
    # inside a method: TriMesh.periodic_pairs imports the periodic matching when asked
    assert ("barymesh.mesh", "barymesh.cell.periodic") in core_edges
    # the window is not the core, and the core's modules are all there
    assert not any(a.startswith("barymesh.app") for a, _ in core_edges)
    assert {"barymesh.params", "barymesh.sectors", "barymesh.mom.operator"} <= {
        m for edge in core_edges for m in edge
    }


def test_the_sector_planner_and_the_placement_are_below_the_parameters(core_edges):
    above = {"barymesh.params", "barymesh.structures", "barymesh.sizing", "barymesh.mesh"}
    for low in ("barymesh.kinds", "barymesh.sectors", "barymesh.placement"):
        reached = _reachable(core_edges, low)
        assert reached.isdisjoint(above), (low, sorted(reached & above))
    assert ("barymesh.params", "barymesh.sectors") in core_edges
    assert ("barymesh.params", "barymesh.placement") in core_edges


def test_the_periodic_matching_does_not_import_the_mesh(core_edges):
    assert "barymesh.mesh" not in _reachable(core_edges, "barymesh.cell.periodic")


def test_the_constants_are_defined_once(core_edges):
    importers = {a for a, b in core_edges if b == "barymesh.constants"}
    assert {"barymesh.mom.operator", "barymesh.sizing", "barymesh.quality"} <= importers
    assert _reachable(core_edges, "barymesh.constants") == set()


def _reachable(edges, start):
    """The modules that ``start`` imports, directly or through others."""
    seen, todo = set(), [start]
    while todo:
        module = todo.pop()
        for b in {b for a, b in edges if a == module} - seen:
            seen.add(b)
            todo.append(b)
    return seen


def _package(root, name, files):
    pkg = root / name
    pkg.mkdir()
    for file, text in files.items():
        (pkg / file).write_text(textwrap.dedent(text))
    importlib.invalidate_caches()


def test_a_circle_through_a_function_level_import_is_found(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    _package(
        tmp_path,
        "circle_probe",
        {
            "__init__.py": "",
            "low.py": """
                def late():
                    from . import high  # a lazy import gets round the circle at run time

                    return high.VALUE
            """,
            "high.py": "from .low import late\n\nVALUE = 1\n",
            "leaf.py": "from . import high\n",
        },
    )
    edges = import_edges("circle_probe")
    assert {
        ("circle_probe.low", "circle_probe.high"),
        ("circle_probe.high", "circle_probe.low"),
        ("circle_probe.leaf", "circle_probe.high"),
    } <= edges
    assert circles(edges) == [["circle_probe.high", "circle_probe.low"]]
    assert "circle_probe.low -> circle_probe.high" in describe(circles(edges)[0], edges)


def test_type_checking_imports_and_left_out_packages_make_no_circle(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    _package(
        tmp_path,
        "typing_probe",
        {
            "__init__.py": "",
            "low.py": """
                from typing import TYPE_CHECKING

                if TYPE_CHECKING:
                    from .high import Thing  # for annotations only: never runs
            """,
            "high.py": "from . import low\n\nThing = int\n",
        },
    )
    (tmp_path / "typing_probe" / "app").mkdir()
    (tmp_path / "typing_probe" / "app" / "__init__.py").write_text("from .. import high\n")
    (tmp_path / "typing_probe" / "high.py").write_text("from . import app, low\n\nThing = int\n")
    importlib.invalidate_caches()
    assert circles(import_edges("typing_probe")) == [["typing_probe.app", "typing_probe.high"]]
    assert circles(import_edges("typing_probe", ("typing_probe.app",))) == []
