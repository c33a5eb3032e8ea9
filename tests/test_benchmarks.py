"""The benchmark scripts run on a tiny size (no timing is asserted: machines are shared)."""

from __future__ import annotations

import importlib.util
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_mesher_benchmark_runs_on_the_smallest_size(tmp_path: Path) -> None:
    pytest.importorskip("pyvista")
    pytest.importorskip("trimesh")
    has_gmsh = importlib.util.find_spec("gmsh") is not None
    out = tmp_path / "bench.json"
    cmd = [sys.executable, str(ROOT / "benchmarks" / "mesher.py"), "--quick", "--json", str(out)]
    if not has_gmsh:
        cmd.append("--no-gmsh")
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    assert "paper double ring" in proc.stdout
    assert "stats() s" in proc.stdout

    doc = json.loads(out.read_text())
    names = {w["name"] for w in doc["workloads"]}
    expected = {"paper double ring", "conforming double ring", "square patch array"}
    if has_gmsh:
        expected.add("conforming split ring")
    assert names == expected
    for w in doc["workloads"]:
        assert w["size"] == "10k"
        assert w["triangles"] > 1000
        assert w["ours"]["median"] > 0
        assert w["ours"]["peak_mib"] > 0
        assert len(w["stats"]["times"]) == len(w["build_mesh"]["times"]) == 2
        assert w["stats"]["median"] > 0 and w["build_mesh"]["median"] > 0
        bound = w["bound"]
        for floor in ("warm", "fresh", "computed"):
            assert bound[floor]["median"] > 0
            assert all(f >= 0 for f in bound[floor]["faults"])
        assert bound["computed_over_warm"] == pytest.approx(
            bound["computed"]["median"] / bound["warm"]["median"]
        )
        alone = w["ours-alone"]  # the build in a process of its own
        assert len(alone["times"]) == len(alone["faults"]) == 2
        assert alone["median"] > 0 and alone["first"]["wall"] > 0
        assert all(
            isinstance(f, int) and f >= 0 for f in [*alone["faults"], alone["first"]["faults"]]
        )
        for peer in {"a-exact", "a-tol", "gmsh"} & w.keys():
            assert w[peer]["median"] > 0
            assert w[peer]["ratio"] == pytest.approx(w[peer]["median"] / w["ours"]["median"])
    ring = next(w for w in doc["workloads"] if w["name"] == "paper double ring")
    # n = 4 at 2.5 degrees: 144 patches per ring, 32 triangles each
    assert ring["triangles"] == 2 * 144 * 32
    if has_gmsh:
        split = next(w for w in doc["workloads"] if w["name"] == "conforming split ring")
        assert abs(split["gmsh_triangles"] - split["triangles"]) < 0.1 * split["triangles"]
        assert 0 < split["gmsh_min_angle_deg"] < 60


def test_mesher_benchmark_has_paper_n4_rows_at_1m_and_4m(monkeypatch) -> None:
    spec = importlib.util.spec_from_file_location("mesher", ROOT / "benchmarks" / "mesher.py")
    mesher = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "mesher", mesher)  # its dataclasses look themselves up
    spec.loader.exec_module(mesher)
    rows = [w for w in mesher.workloads(list(mesher.SIZES), []) if w.name.endswith("n=4")]
    assert [w.size for w in rows] == ["1M", "4M"]
    for w in rows:
        assert w.params.subdivisions == 4 and w.params.mode == "paper"
        # ceil(360 / Δθ) patches per ring, two rings, 32 triangles per patch
        patches = 2 * math.ceil(360 / w.params.angle_step - 1e-9)
        assert w.params.predicted_triangles() == patches * 32
    assert [w.params.predicted_triangles() for w in rows] == [1_000_000, 4_000_000]


def test_mesher_benchmark_conforming_rows_reach_their_nominal_sizes(monkeypatch) -> None:
    from barymesh.sectors import sector_plan

    spec = importlib.util.spec_from_file_location("mesher", ROOT / "benchmarks" / "mesher.py")
    mesher = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "mesher", mesher)
    spec.loader.exec_module(mesher)
    rows = [w for w in mesher.workloads(list(mesher.SIZES), []) if w.name.startswith("conf")]
    assert [w.size for w in rows] == list(mesher.SIZES)  # not the n = 4 rows' parameters
    nominal = {"10k": 1e4, "100k": 1e5, "1M": 1e6, "4M": 4e6}
    counts = []
    for w in rows:
        plan = sector_plan(w.params)
        n = w.params.subdivisions
        n_v = len(plan.template.sides[1]) - 1  # cells along each sector's arc
        # m_i sectors in ring i, n x n_v cells of two triangles each
        counts.append(w.params.predicted_triangles())
        assert counts[-1] == 2 * n * n_v * sum(plan.sectors)
        assert abs(counts[-1] / nominal[w.size] - 1) < 0.1, w.size
    assert counts == [9_600, 105_984, 982_016, 3_928_064]


def test_mesher_benchmark_rejects_unknown_sizes() -> None:
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "mesher.py"), "--sizes", "7M"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 2
    assert "7M" in proc.stderr


def test_latency_benchmark_runs_a_few_frames_in_the_window(tmp_path: Path) -> None:
    pytest.importorskip("pyvistaqt")
    out = tmp_path / "latency.json"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "latency.py"), "--quick", "--json", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert doc["frames"] == 6
    assert doc["triangles"] == [23_040]  # the paper's Fig. 12(a)
    parts = doc["seconds"]
    assert set(parts) == {"meshing", "update", "rendering", "other", "total"}
    for part in ("meshing", "update", "rendering", "total"):
        assert len(parts[part]["samples"]) == 6
        assert parts[part]["median"] > 0
    assert parts["total"]["median"] >= parts["meshing"]["median"]
    assert "whole frame median" in proc.stdout


def test_latency_teaching_round_reports_each_case(tmp_path: Path) -> None:
    """``latency.py --teaching``: a longest event-loop block for every case, measured
    while the windows show what they should (no timing is asserted)."""
    pytest.importorskip("pyvistaqt")
    out = tmp_path / "teaching.json"
    cmd = [sys.executable, str(ROOT / "benchmarks" / "latency.py"), "--teaching"]
    cmd += ["--repeats", "1", "--big", "0", "--load", "test", "--json", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    cases = doc["cases"]
    assert set(cases) == {
        "matrix_open_fig10",
        "matrix_open_fig12a",
        "construction_open",
        "construction_step",
        "construction_n_change",
        "compare_open",
        "compare_param_change",
        "auto_solve_slider_step",
        "animate_step",
    }
    for case in cases.values():
        assert case["longest_block"] > 0 and case["longest_cpu"] >= 0
    # what the windows showed meanwhile: Eq. 27's ones are twice the interior edges
    assert cases["matrix_open_fig10"]["runs"][0]["nonzeros"] == 80
    assert cases["matrix_open_fig12a"]["runs"][0]["nonzeros"] == 57_600
    assert cases["matrix_open_fig12a"]["triangles"] == 23_040
    assert cases["construction_open"]["runs"][0]["triangles_last_step"] == 32  # 2 n²
    assert cases["construction_step"]["steps"] == 8
    auto = cases["auto_solve_slider_step"]
    assert auto["unknowns"] == 40 and auto["meshes"] >= 1 and auto["solves"] >= 1
    assert cases["animate_step"]["phase_steps"] >= 1
    assert doc["load"]["note"] == "test"
    assert "compare_open" in proc.stdout


def test_latency_interaction_round_reports_each_case(tmp_path: Path) -> None:
    """``latency.py --interaction`` (issue 30, item 13): for each of the four cases the
    longest block with the GUI thread's CPU time in that gap, per step for the wheel and
    the rotation, and the load average (no timing is asserted)."""
    pytest.importorskip("pyvistaqt")
    out = tmp_path / "interaction.json"
    cmd = [sys.executable, str(ROOT / "benchmarks" / "latency.py"), "--interaction"]
    cmd += ["--drag", "0.5", "--load", "test", "--json", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, check=False)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    cases = doc["cases"]
    assert list(cases) == [
        "slider_drag_fig12a",
        "slider_drag_fig12d",
        "wheel_zoom_200k",
        "rotate_1M",
    ]
    for case in cases.values():
        assert case["longest_block"] > 0
        assert 0 <= case["longest_block_cpu"] <= case["longest_cpu"]
        assert len(case["loadavg"]) == 3
    assert cases["slider_drag_fig12a"]["meshes"] >= 1
    assert cases["wheel_zoom_200k"]["triangles"] == 720 * 2 * 12**2
    assert len(cases["wheel_zoom_200k"]["steps"]) == 8
    assert len(cases["rotate_1M"]["steps"]) == 30 + 1  # the moves and the release
    assert doc["load"]["note"] == "test" and doc["load"]["cores"] >= 1
    assert "wheel_zoom_200k" in proc.stdout


def test_the_performance_page_renders_the_stored_window_results() -> None:
    """The Performance page's window tables read the files they were written for: the
    dense rounds (``latency-big``; the name "latency" picked the teaching round's file and
    rendered an empty table) and the interaction round."""
    sys.path.insert(0, str(ROOT / "docs" / "_ext"))
    try:
        import benchmark_tables
    finally:
        sys.path.remove(str(ROOT / "docs" / "_ext"))
    head, rows, note = benchmark_tables.table_data("latency-big")
    assert "latency-big-" in note and len(rows) >= 3
    head, rows, note = benchmark_tables.table_data("latency-interaction")
    assert "latency-interaction-" in note and len(rows) == 4
    assert "GUI thread CPU ms" in head and "load average" in head.pop()


def _interior_edge_count(triangles) -> int:
    """Edges on exactly two triangles, counted from the triangles alone."""
    import numpy as np

    edges = np.sort(np.asarray(triangles)[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int((counts == 2).sum())


def _angles_and_aspects(points, triangles):
    """Smallest angle (law of cosines) and l_max / (2 √3 inradius) of every triangle."""
    import numpy as np

    p = np.asarray(points)[np.asarray(triangles)]  # (T, 3, 3)
    sides = np.linalg.norm(p[:, [1, 2, 0]] - p, axis=2)  # side k from vertex k to k + 1
    a, b, c = sides[:, 1], sides[:, 2], sides[:, 0]  # a opposite vertex 0, ...
    cosines = np.stack(
        [
            (b**2 + c**2 - a**2) / (2 * b * c),
            (c**2 + a**2 - b**2) / (2 * c * a),
            (a**2 + b**2 - c**2) / (2 * a * b),
        ],
        axis=1,
    )
    angles = np.degrees(np.arccos(np.clip(cosines, -1, 1))).min(axis=1)
    s = sides.sum(axis=1) / 2
    area = np.sqrt(np.maximum(s * (s - a) * (s - b) * (s - c), 0))  # Heron
    return angles, sides.max(axis=1) / (2 * math.sqrt(3) * (area / s))


def test_quality_benchmark_measures_presets_and_the_split_ring(tmp_path: Path) -> None:
    from barymesh import MeshParams, build_mesh
    from barymesh.presets import load_preset, preset_names

    spec = importlib.util.spec_from_file_location("gmsh_peer", ROOT / "benchmarks" / "gmsh_peer.py")
    gmsh_peer = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gmsh_peer)
    has_gmsh = importlib.util.find_spec("gmsh") is not None
    out = tmp_path / "quality.json"
    # this checkout as its own baseline: the "today" figures must be the "new" ones
    cmd = [
        sys.executable,
        str(ROOT / "benchmarks" / "quality.py"),
        "--sizes",
        "10k",
        "--baseline",
        str(ROOT),
        "--markdown",
        "--json",
        str(out),
    ]
    if not has_gmsh:
        cmd.append("--no-gmsh")
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    rows = {row["name"]: row for row in doc["rows"]}
    assert set(rows) == {"split ring 10k", *preset_names()}
    assert proc.stdout.count("\n| ") == len(rows) + 1  # header rule and one line per row

    for row in rows.values():
        assert 0 < row["min_angle_deg"] <= 60
        assert row["max_aspect_ratio"] >= 1
        assert 0 < row["unknowns"] <= 3 * row["triangles"] / 2
        for key in ("triangles", "unknowns", "min_angle_deg", "max_aspect_ratio"):
            assert row["baseline"][key] == row[key]
        if row["mode"] == "paper":
            # right isosceles sub-triangles: 45°, aspect √2 (2 + √2) / (4 √3 / 2) = (1 + √2) / √3
            assert row["min_angle_deg"] == pytest.approx(45.0, abs=1e-9)
            assert row["max_aspect_ratio"] == pytest.approx((1 + math.sqrt(2)) / math.sqrt(3))
            assert "gmsh" not in row

    cases = {
        "srr-openmodes": load_preset("srr-openmodes")[0],
        "split ring 10k": MeshParams(**gmsh_peer.split_ring_fields("10k")),
    }
    for name, params in cases.items():
        mesh = build_mesh(params)
        row = rows[name]
        assert row["triangles"] == len(mesh.triangles)
        assert row["unknowns"] == _interior_edge_count(mesh.triangles)
        angles, aspects = _angles_and_aspects(mesh.points, mesh.triangles)
        assert row["min_angle_deg"] == pytest.approx(angles.min(), abs=1e-7)
        assert row["max_aspect_ratio"] == pytest.approx(aspects.max(), rel=1e-9)
        if has_gmsh:
            g = row["gmsh"]
            assert abs(g["triangles"] - row["triangles"]) < 0.1 * row["triangles"]
            assert 0 < g["min_angle_deg"] <= 60 and g["max_aspect_ratio"] >= 1
            assert g["junction_edges"] == 0
            # the same geometry: ours is inscribed in gmsh's curved boundary
            assert row["area_mm2"] == pytest.approx(g["area_mm2"], rel=2e-3)


def test_quality_benchmark_rejects_a_baseline_without_core(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "quality.py"), "--baseline", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 2
    assert str(tmp_path) in proc.stderr and "core/__init__.py" in proc.stderr


def test_grading_benchmark_uniform_series_converges_to_its_reference(tmp_path: Path) -> None:
    out = tmp_path / "grading.json"
    png = tmp_path / "grading.png"
    proc = subprocess.run(
        [
            sys.executable,
            str(ROOT / "benchmarks" / "grading.py"),
            "--quick",
            "--json",
            str(out),
            "--png",
            str(png),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert png.stat().st_size > 10_000
    doc = json.loads(out.read_text())
    uniform = [r for r in doc["rows"] if r["series"] == "uniform"]
    assert [r["subdivisions"] for r in uniform] == [1, 2, 3, 4]
    # the cut lies one sector from the slot side, across the 0.5 mm track
    near, far = doc["slot_distance_mm"]
    assert 0.2 < near < far < 0.5
    for r in doc["rows"]:
        current = complex(*r["I_cut"])
        assert math.isfinite(abs(current)) and abs(current) > 1e-9  # A, for 1 V/m
        # charge conservation: the current through the cut is −jω × the charge before it
        assert r["continuity_error"] < 1e-9
        assert r["residual"] < 1e-8
    for key in ("I_cut", "m_z"):
        errors = [r[f"{key}_error"] for r in uniform]
        # refinement brings each mesh closer to the extrapolated value, ...
        assert all(b < a * 1.02 for a, b in zip(errors[1:], errors[2:], strict=False)), errors
        assert errors[-1] < errors[0] / 3, errors
        # ... the reference: Richardson of order 1 in h = N^(-1/2) through the last two
        # meshes, and the two meshes before them extrapolate to within 5 % of it
        ref = doc["reference"][key]
        (h1, q1), (h2, q2) = ((r["unknowns"] ** -0.5, complex(*r[key])) for r in uniform[-2:])
        limit = complex(*ref["value"])
        assert limit == pytest.approx(q2 + (q2 - q1) * h2 / (h1 - h2), rel=1e-12)
        assert 0 < ref["uncertainty"] < 0.05
        assert abs(complex(*ref["previous_pair"]) - limit) <= ref["uncertainty"] * abs(limit)
    graded = [r for r in doc["rows"] if r["series"] != "uniform"]
    if doc["graded"] != "run":
        assert not graded and "skipped" in proc.stdout
        return
    # grading toward the circles and the slot sides: at about the unknowns of the finest
    # uniform mesh (within 5 %), the current leaving the slot side is closer to the limit
    assert [r["growth_ratio"] for r in graded] == [2.0, 2.0]
    finest = uniform[-1]
    peer = min(graded, key=lambda r: abs(r["unknowns"] - finest["unknowns"]))
    assert abs(peer["unknowns"] - finest["unknowns"]) < 0.05 * finest["unknowns"]
    assert peer["min_edge_mm"] < finest["min_edge_mm"] / 2
    assert peer["I_cut_error"] < finest["I_cut_error"] / 2
    # both series approach the limit from the same side: the graded one is further along
    assert abs(complex(*peer["I_cut"])) > abs(complex(*finest["I_cut"])) * 1.005


def test_array_live_benchmark_sweeps_the_cell_after_a_mouse_drag(tmp_path: Path) -> None:
    """``array_live.py --quick``: one mouse drag of the ring's inner radius in the window,
    after which the tab shows the 21-point curve of the new cell mesh (no time asserted)."""
    pytest.importorskip("pyvistaqt")
    pytest.importorskip("matplotlib")
    from dataclasses import replace

    from barymesh.app.panels.array_sweep import INTERPOLATE_POINTS
    from barymesh.cell import build_cell, load_cell_preset
    from barymesh.mom import periodic_geometry

    out = tmp_path / "array-live.json"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "array_live.py"), "--quick"]
        + ["--json", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert doc["benchmark"] == "array-live"
    assert doc["targets"] == {"time_to_curve_s": 1.5, "longest_block_s": 0.1}
    assert set(doc["met"]) == {
        "time_to_curve",
        "longest_block_after_release",
        "longest_block_during_drag",
        "longest_block",
    }
    assert len(doc["machine"]["load_averages_1_5_15_min"]) == 3
    # the window showed the preset's ring at n = 3: the same cell built here
    cell = load_cell_preset("hexagonal-rings")
    ring = cell.elements[0]
    ring = replace(ring, params=replace(ring.params, subdivisions=3))
    mesh = build_cell(replace(cell, elements=(ring,))).mesh
    c = doc["cell"]
    assert (c["triangles"], c["unknowns"]) == (
        mesh.n_triangles,
        periodic_geometry(mesh).n_unknowns,
    )
    assert 400 <= c["unknowns"] <= 600  # "a cell of about 500 unknowns"
    assert doc["first_curve"]["frequencies"] == 21
    (row,) = doc["rows"]
    assert row["mesh_changed"]
    # the drag moved the radius off the preset's 3 mm, towards where the mouse went
    assert row["inner_radius_mm"] != ring.params.inner_radius
    assert (row["inner_radius_mm"] - 3.0) * (row["target_inner_radius_mm"] - 3.0) > 0
    assert row["frequencies"] == 21 < INTERPOLATE_POINTS  # the typed band, point by point
    assert row["band_hz"] == pytest.approx([5e9, 30e9])
    assert row["solves"] == 21
    assert row["paints"] >= 1
    assert row["time_to_curve_s"] >= row["worker_s"] > 0
    assert row["longest_block_drag_s"] > 0 and row["longest_block_after_release_s"] > 0
    assert doc["memory"]["window_rss_after"] > 0 and doc["memory"]["solver_rss_after"] > 0
    assert "round" in proc.stdout and "unknowns" in proc.stdout


def test_phase_live_benchmark_times_a_typed_frequency_preview_then_curve(tmp_path: Path) -> None:
    """``phase_live.py --quick``: one frequency typed into the Reflection phase tab, after
    which the preview (every 4th value and the last: 2 of 5) and then the 5-value curve come (no
    time asserted), at the frequency typed."""
    pytest.importorskip("pyvistaqt")
    pytest.importorskip("matplotlib")
    out = tmp_path / "phase-live.json"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "phase_live.py"), "--quick"]
        + ["--json", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert doc["benchmark"] == "phase-live"
    assert doc["targets"] == {
        "time_to_preview_s": 0.5,
        "time_to_curve_s": 1.5,
        "longest_block_s": 0.1,
    }
    assert set(doc["met"]) == {"time_to_preview", "time_to_curve", "longest_block"}
    (row,) = doc["rows"]
    assert (row["values"], row["preview_values"], row["frequency_ghz"]) == (5, 2, 10.5)
    assert row["time_to_curve_s"] >= row["time_to_preview_s"] > 0
    assert row["time_to_curve_s"] >= row["worker_s"] > 0
    assert 0 < row["covers_deg"] < 360 and row["longest_block_s"] > 0
    assert "round 1" in proc.stdout


def test_startup_benchmark_times_each_case_and_its_baseline(tmp_path: Path) -> None:
    """benchmarks/startup.py (one run a case, HEAD as the baseline) and its Performance
    table: every case has its times, the load average beside them and the baseline's."""
    out = tmp_path / "startup.json"
    cmd = [sys.executable, str(ROOT / "benchmarks" / "startup.py"), "--repeats", "1"]
    cmd += ["--baseline", "HEAD", "--json", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert doc["repeats"] == 1 and len(doc["baseline"]["commit"]) == 40
    assert list(doc["cases"]) == [
        "import numpy",
        "import barymesh",
        "from barymesh import build_mesh",
        "barymesh --help",
        "barymesh mesh --preset paper-fig10 --stats-json -",
        "barymesh window: first frame",
    ]
    window = doc["cases"]["barymesh window: first frame"]
    assert window["target"] == 2.0 and window["cpu_median"] > 0  # the window ran
    for case in doc["cases"].values():
        for row in (case, case["baseline"]):
            assert len(row["times"]) == len(row["cpu_times"]) == 1
            assert row["median"] > 0 and row["cpu_median"] >= 0
        assert len(case["loadavg"]) == 2
    sys.path.insert(0, str(ROOT / "docs" / "_ext"))
    try:
        import benchmark_tables
    finally:
        sys.path.remove(str(ROOT / "docs" / "_ext"))
    head, rows, note = benchmark_tables.startup(doc)
    assert len(rows) == 6 and "load average" in head and "Before: the same case on HEAD" in note


def test_library_benchmark_solves_both_ways_and_they_agree(tmp_path: Path) -> None:
    """``library.py --quick``: 4 patch sizes on the grounded substrate, one fill per value
    against two points per value; the script refuses to write unless they agree to 1e-12
    of max |R| (no time asserted)."""
    out = tmp_path / "library.json"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "library.py"), "--quick"] + ["--json", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert doc["benchmark"] == "library"
    assert doc["library"]["values_mm"] == [5.0, 9.5, 4]
    assert doc["library"]["largest_unknowns"] > 100
    rows = doc["rows"]
    assert set(rows) == {"here", "two_points"}  # no cluster in --quick
    assert rows["two_points"]["largest_difference_to_here"] <= 1e-12
    assert rows["here"]["wall_s"] > 0 and rows["two_points"]["wall_s"] > 0
    # a patch over a ground plane: its phase moves with its size, less than a full turn
    assert 90 < doc["library"]["covers_deg"] < 360
    assert "one fill for TE and TM" in proc.stdout
