"""mypy over the package finds no error, the core (issue 18, point 6) and the window's
``app/`` (issue 31), as configured in pyproject.toml (``typecheck/`` maps the folders to
``barymesh`` and ``barymesh.app``).

Its cache is pytest's (``.pytest_cache/d/mypy``), so the checkout gets no .mypy_cache and
later runs are incremental: 1-2 s with nothing changed and about 15 s after an edit, against
2.5 minutes for the first (on two busy cores: numpy's, scipy's, PySide6's and VTK's stubs
are read once). A run over a tiny module with a known error shows that the same command
does fail.
"""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

pytest.importorskip("mypy", reason="mypy is in the test extra: pip install -e '.[test]'")


def _mypy(cache: Path, *args: str) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "mypy", "--cache-dir", str(cache), *args]
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=900)


@pytest.fixture
def cache(request: pytest.FixtureRequest, tmp_path: Path) -> Path:
    """pytest's cache folder for mypy (a fresh one under ``-p no:cacheprovider``)."""
    pytest_cache = getattr(request.config, "cache", None)
    return pytest_cache.mkdir("mypy") if pytest_cache is not None else tmp_path / "mypy-cache"


def test_the_core_and_the_window_type_check(cache):
    # packages = ["barymesh", "barymesh.app"] and the overrides, from pyproject.toml
    run = _mypy(cache)
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.startswith("Success: no issues found")
    checked = int(run.stdout.split("in ")[1].split()[0])
    modules = [*(ROOT / "core").rglob("*.py"), *(ROOT / "app").rglob("*.py")]
    assert checked >= len(modules)


def test_the_same_command_reports_an_error(cache, tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("import numpy as np\n\n\ndef count() -> int:\n    return np.zeros(3)\n")
    run = _mypy(cache, "--config-file", str(ROOT / "pyproject.toml"), str(bad))
    assert run.returncode == 1
    assert "bad.py:5: error: Incompatible return value type" in run.stdout
