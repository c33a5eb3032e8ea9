"""benchmarks/solver.py runs on tiny sizes (no timing is asserted: machines are shared)."""

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_solver_benchmark_runs_quick(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("solver_bench", ROOT / "benchmarks" / "solver.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)  # in-process: no second interpreter start-up
    out = tmp_path / "solver.json"
    assert bench.main(["--quick", "--json", str(out)]) == 0
    assert "Makarov-style" in capsys.readouterr().out
    doc = json.loads(out.read_text())
    plate, ring = doc["workloads"]
    assert plate["unknowns"] == 176 and ring["unknowns"] == 139
    assert plate["ours_s"] > 0 and plate["makarov_s"] > 0
    # our time is reported in its three steps (a separate cold run)
    assert all(plate[k] > 0 for k in ("ours_geometry_s", "ours_fill_s", "ours_lu_s"))
    # both solvers see the same physics: the same current to a few per cent
    assert abs(plate["ours_max_j"] / plate["makarov_max_j"] - 1) < 0.05
    # ours is the closer to the converged answer
    assert plate["ours_error"] < plate["makarov_error"]
    assert abs(ring["ours_resonance_hz"] / ring["makarov_resonance_hz"] - 1) < 0.02
