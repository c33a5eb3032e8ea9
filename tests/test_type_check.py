"""mypy over the core finds no error (issue 18, point 6), as configured in pyproject.toml.

Its cache goes to the test's temporary folder, so the checkout gets no .mypy_cache. A run
over a tiny module with a known error shows that the same command does fail.
"""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

pytest.importorskip("mypy", reason="mypy is in the test extra: pip install -e '.[test]'")


def _mypy(tmp_path, *args):
    cmd = [sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "mypy-cache"), *args]
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)


def test_the_core_type_checks(tmp_path):
    run = _mypy(tmp_path)  # files = ["core"] and the overrides, from pyproject.toml
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.startswith("Success: no issues found")
    checked = int(run.stdout.split("in ")[1].split()[0])
    assert checked >= len(list((ROOT / "core").rglob("*.py")))


def test_the_same_command_reports_an_error(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("import numpy as np\n\n\ndef count() -> int:\n    return np.zeros(3)\n")
    run = _mypy(tmp_path, "--config-file", str(ROOT / "pyproject.toml"), str(bad))
    assert run.returncode == 1
    assert "bad.py:5: error: Incompatible return value type" in run.stdout
