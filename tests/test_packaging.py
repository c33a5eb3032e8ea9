"""One import package, ``barymesh``: the package list, the editable install the suite runs on,
and a wheel installed into a fresh virtual environment, away from the checkout."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
import venv
import zipfile
from pathlib import Path

import pytest

import barymesh

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
SETUPTOOLS = PYPROJECT["tool"]["setuptools"]
PRESETS = sorted(p.name for p in (ROOT / "assets" / "presets").glob("*.json"))
CELLS = sorted(p.name for p in (ROOT / "assets" / "cells").glob("*.cell.json"))


def _folder_packages() -> set[str]:
    """Every package the mapped folders hold, named as installed."""
    names = set()
    for prefix, folder in SETUPTOOLS["package-dir"].items():
        base = ROOT / folder
        for init in base.rglob("__init__.py"):
            rel = init.parent.relative_to(base).parts
            if "__pycache__" not in rel:
                names.add(".".join((prefix, *rel)))
        for data in SETUPTOOLS["package-data"]:
            if data.startswith(prefix + ".") and data[len(prefix) + 1 :].count(".") == 0:
                names.add(data)
    return names


def _clean_env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "VIRTUAL_ENV"))}
    env["PYTHONNOUSERSITE"] = "1"
    return env


def test_every_folder_is_listed():
    # `find` cannot rename, so the list is by hand: no subpackage may be forgotten
    listed = set(SETUPTOOLS["packages"])
    assert listed >= _folder_packages()
    assert {"barymesh", "barymesh.app", "barymesh.mom", "barymesh.cell", "barymesh.io"} <= listed
    assert all(name == "barymesh" or name.startswith("barymesh.") for name in listed)


def _layout_rows() -> dict[str, str]:
    """CONTRIBUTING's layout table: folder -> the name it imports as."""
    text = (ROOT / "CONTRIBUTING.md").read_text()
    table = text.split("## The layout", 1)[1].split("\n\n")[2]
    rows = {}
    for line in table.splitlines()[2:]:
        cells = [c.strip() for c in line.strip("|").split("|")]
        rows[cells[0].strip("`")] = cells[1].strip("`")
    return rows


def test_the_layout_table_names_every_package_folder_and_only_those():
    """CONTRIBUTING's map of the folders: every subpackage of ``core/`` and the top-level
    folders have a row, each row's folder exists, and it imports as the table says."""
    rows = _layout_rows()
    core = {
        f"core/{p.parent.name}/"
        for p in (ROOT / "core").glob("*/__init__.py")
        if "__pycache__" not in p.parts
    }
    assert core <= set(rows), sorted(core - set(rows))
    assert {"core/", "app/", "assets/", "tests/", "benchmarks/", "docs/"} <= set(rows)
    for folder, name in rows.items():
        assert (ROOT / folder).is_dir(), folder
        if folder.startswith("core/") and folder != "core/":
            assert name == "barymesh." + folder.split("/")[1], (folder, name)


def test_version_is_one():
    assert barymesh.__version__ == PYPROJECT["project"]["version"] == "0.2.0"
    assert "[0.2.0]" in (ROOT / "CHANGELOG.md").read_text()


def test_editable_install_gives_barymesh_alone(tmp_path):
    # the suite's own install (make test: pip install -e): from another folder, with the
    # checkout off the path, barymesh imports from the checkout and core/app do not import
    code = (
        "import importlib.util as u, barymesh, barymesh.app, barymesh.presets as p;"
        "print(barymesh.__file__, barymesh.app.__file__);"
        "print(u.find_spec('core'), u.find_spec('app'));"
        "print(len(p.preset_names()))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env=_clean_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    files, specs, presets = out.stdout.splitlines()
    assert files.split() == [str(ROOT / "core" / "__init__.py"), str(ROOT / "app" / "__init__.py")]
    assert specs == "None None"
    assert int(presets) == len(PRESETS) > 0


def test_python_dash_m_barymesh_is_the_command(tmp_path):
    out = subprocess.run(
        [sys.executable, "-m", "barymesh", "presets"],
        cwd=tmp_path,
        env=_clean_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "paper-fig10" in out.stdout and "hexagonal-rings" in out.stdout


def _stats_json(program: Path, cwd: Path, *prefix: str) -> subprocess.CompletedProcess:
    """``program [prefix] mesh --cell-preset hexagonal-rings --stats-json -``, checked."""
    args = [program, *prefix, "mesh", "--cell-preset", "hexagonal-rings", "--stats-json", "-"]
    out = subprocess.run(
        args, cwd=cwd, env=_clean_env(), capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    return out


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    build = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(out), str(ROOT)],
        cwd=out,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert build.returncode == 0, build.stderr
    (path,) = out.glob("barymesh-0.2.0-*.whl")
    return path


def test_wheel_holds_barymesh_and_its_data(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    tops = {name.split("/")[0] for name in names}
    assert tops == {"barymesh", "barymesh-0.2.0.dist-info"}
    assert "barymesh/app/window.py" in names and "barymesh/mom/solve.py" in names
    assert {f"barymesh/assets/presets/{p}" for p in PRESETS} <= set(names)
    assert {f"barymesh/assets/cells/{c}" for c in CELLS} <= set(names)
    assert "barymesh/app/icons/barymesh.svg" in names
    assert not [n for n in names if n.endswith(".png")]  # the docs' screenshots stay out
    top_level = zipfile.ZipFile(wheel).read("barymesh-0.2.0.dist-info/top_level.txt").decode()
    assert top_level.split() == ["barymesh"]


def test_wheel_metadata_names_the_project_urls_and_the_completion(wheel):
    text = zipfile.ZipFile(wheel).read("barymesh-0.2.0.dist-info/METADATA").decode()
    urls = dict(
        line.split(": ", 1)[1].split(", ", 1)
        for line in text.splitlines()
        if line.startswith("Project-URL: ")
    )
    assert set(urls) == {"Homepage", "Documentation", "Source", "Issues", "Changelog"}
    assert all(url.startswith("https://") for url in urls.values())
    assert urls["Changelog"].endswith("/CHANGELOG.md") and urls["Issues"].endswith("/issues")
    requires = [line for line in text.splitlines() if line.startswith("Requires-Dist: ")]
    assert any(line.startswith("Requires-Dist: shtab") and "extra" not in line for line in requires)


def test_wheel_in_a_fresh_environment(wheel, tmp_path):
    env_dir = tmp_path / "env"
    venv.create(env_dir, with_pip=True)
    python = env_dir / "bin" / "python"
    install = subprocess.run(
        [python, "-m", "pip", "install", "--quiet", str(wheel)],
        cwd=tmp_path,
        env=_clean_env(),
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert install.returncode == 0, install.stderr
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    code = (
        "import importlib.util as u, barymesh;"
        "print(barymesh.__file__);"
        "print(u.find_spec('core'), u.find_spec('app'))"
    )
    out = subprocess.run(
        [python, "-c", code],
        cwd=elsewhere,
        env=_clean_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    where, specs = out.stdout.splitlines()
    assert Path(where).is_relative_to(env_dir) and specs == "None None"
    stats = subprocess.run(
        [env_dir / "bin" / "barymesh", "mesh", "--preset", "paper-fig10", "--stats-json", "-"],
        cwd=elsewhere,
        env=_clean_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert stats.returncode == 0, stats.stderr
    assert json.loads(stats.stdout)["triangles"] == 32
    completion = subprocess.run(
        [env_dir / "bin" / "barymesh", "--print-completion", "bash"],
        cwd=elsewhere,
        env=_clean_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert completion.returncode == 0, completion.stderr
    assert "_shtab_barymesh" in completion.stdout and "--msh-version" in completion.stdout
    cell = _stats_json(env_dir / "bin" / "barymesh", elsewhere)
    here = _stats_json(Path(sys.executable), elsewhere, "-m", "barymesh")
    # the same cell as the checkout's own command line builds it
    assert json.loads(cell.stdout) == json.loads(here.stdout)
    assert json.loads(cell.stdout)["cell"]["triangles"] == 688  # 43 patches of 16
