"""The documentation stays true: the site builds, the README is short and its claims hold.

* The Sphinx site (``docs/``) builds with warnings as errors and nitpicky references, so
  every page parses, every internal link and heading anchor resolves, and every
  cross-reference into barymesh in a docstring names something that exists.
* The README stays under 15 KB, its Python example prints what its comments say, its
  headline figures are those of the result files it names, and its commands parse with the
  program's own parser and name presets and parameters that exist.
* Every relative link in the README, CONTRIBUTING.md, CHANGELOG.md and the documentation's
  pages points at a file that exists.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import shlex
import subprocess
import sys
from dataclasses import fields
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
RESULTS = ROOT / "benchmarks" / "results"
PAGES = sorted(
    [README, ROOT / "CONTRIBUTING.md", ROOT / "CHANGELOG.md"]
    + [p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts]
    + [p for p in (ROOT / "docs").glob("*.rst")]
    + [ROOT / "docs" / "api" / "index.rst"]
)

#: Markdown links and images, ``[text](target)`` / ``![alt](target)``; the target ends at
#: the first space (a title may follow) or the closing parenthesis.
_LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
#: MyST figure and include directives: ```{figure} PATH / ```{include} PATH
_DIRECTIVE = re.compile(r"^```\{(?:figure|image|include)\}\s+(\S+)", re.MULTILINE)


def _fenced(text: str, language: str) -> list[str]:
    """The bodies of the ```language fenced blocks of a Markdown text."""
    return re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)


def _relative_targets(path: Path) -> list[str]:
    text = path.read_text(encoding="utf-8")
    # links inside code are examples, not links
    prose = re.sub(r"^```.*?^```", "", text, flags=re.MULTILINE | re.DOTALL)
    prose = re.sub(r"``.*?``|`[^`\n]*`", "", prose)
    targets = _LINK.findall(prose) + _DIRECTIVE.findall(text)
    return [
        t
        for t in targets
        if not re.match(r"^[a-z][a-z0-9+.-]*:", t)  # http:, https:, mailto:
        and not t.startswith("#")
    ]


def test_readme_is_at_most_15_kb():
    size = README.stat().st_size
    assert size <= 15_000, f"README.md is {size:,} bytes; keep it at most 15,000"


def test_readme_python_example_prints_what_it_says():
    blocks = _fenced(README.read_text(encoding="utf-8"), "python")
    assert blocks, "README.md has no ```python example"
    code = blocks[0]
    expected = [line.split("# -> ", 1)[1].strip() for line in code.splitlines() if "# -> " in line]
    assert len(expected) >= 3, "the README example should say what it prints (# -> ...)"
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md example", "exec"), {"__name__": "readme_example"})
    assert out.getvalue().splitlines() == expected


def _result(name: str) -> dict:
    return json.loads((RESULTS / name).read_text(encoding="utf-8"))


def _row(text: str, start: str) -> str:
    rows = [line for line in text.splitlines() if line.startswith(f"| {start}")]
    assert len(rows) == 1, f"README.md: expected one headline row starting {start!r}"
    return rows[0]


def test_readme_headline_figures_are_those_of_the_result_files():
    text = README.read_text(encoding="utf-8")
    mesher = {(w["name"], w["size"]): w for w in _result("mesher-2026-12-02.json")["workloads"]}
    ring = mesher[("paper double ring", "1M")]
    row = _row(text, "paper double ring")
    assert f"{ring['triangles']:,} triangles" in row
    assert f"{ring['ours']['median']:.3f} s" in row
    assert f"{ring['a-exact']['median']:.3f} s ({ring['a-exact']['ratio']:.1f}×)" in row
    row = _row(text, "peak memory")
    assert f"{ring['ours']['bytes_per_triangle']:.0f} bytes per triangle" in row

    quality = {r["name"]: r for r in _result("quality-2026-12-02.json")["rows"]}
    split = quality["split ring 1M"]
    row = _row(text, "conforming split ring")
    assert f"{split['triangles']:,} triangles" in row
    assert f"smallest angle {split['min_angle_deg']:.1f}°" in row
    assert f"largest aspect ratio {split['max_aspect_ratio']:.2f}" in row

    plate = _result("solver.json")["workloads"][0]
    assert plate["name"] == "plate 736"
    row = _row(text, "RWG solve")
    assert f"{plate['unknowns']} unknowns" in row
    assert f"{plate['ours_s']:.3f} s against {plate['makarov_s']:.3f} s" in row
    assert f"({plate['speedup']:.1f}×)" in row

    big = _result("latency-big-2026-12-02.json")["big"]["4.8M"]
    row = _row(text, "the window")
    assert f"{big['triangles']:,}-triangle" in row
    assert f"{big['shown']['median']:.2f} s" in row
    assert f"{big['longest_block']['median'] * 1e3:.0f} ms" in row


def _commands(path: Path) -> list[str]:
    lines = []
    for block in _fenced(path.read_text(encoding="utf-8"), "sh"):
        for line in block.splitlines():
            line = line.strip()
            if line.startswith("barymesh "):
                lines.append(line)
    return lines


@pytest.mark.parametrize(
    "path",
    [README, ROOT / "docs" / "formats-cli.md", ROOT / "docs" / "solving.md"],
    ids=lambda p: p.name,
)
def test_documented_commands_parse_and_name_real_presets_and_parameters(path):
    from barymesh import MeshParams
    from barymesh.app.cli import VERBS, build_parser
    from barymesh.cell import cell_preset_names
    from barymesh.presets import preset_names

    parser = build_parser()
    names = {f.name for f in fields(MeshParams)}
    checked = 0
    for line in _commands(path):
        argv = shlex.split(line, comments=True)[1:]
        if not argv or argv[0] not in VERBS:
            continue  # the window's options: parsed by the window
        args = parser.parse_args(argv)
        if getattr(args, "preset", None) is not None:
            assert args.preset in preset_names(), f"{path.name}: {line}"
        if getattr(args, "cell_preset", None) is not None:
            assert args.cell_preset in cell_preset_names(), f"{path.name}: {line}"
        for item in getattr(args, "set", None) or []:
            assert item.split("=", 1)[0] in names, f"{path.name}: {line}"
        checked += 1
    assert checked >= 4, f"{path.name}: expected its command examples to be found"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_point_at_files_that_exist(page):
    missing = []
    for target in _relative_targets(page):
        file = target.split("#", 1)[0]
        if file and not (page.parent / file).exists():
            missing.append(target)
    assert not missing, f"{page.relative_to(ROOT)} links to files that do not exist: {missing}"


def test_links_are_found_at_all():
    # the link finder itself: a page known to link to the docs and to a figure
    targets = _relative_targets(README)
    assert "docs/method.md" in targets
    assert "assets/window.png" in targets


def test_docs_build_with_warnings_as_errors(tmp_path):
    try:
        import sphinx  # noqa: F401
    except ImportError:  # make test installs the docs extra; a bare venv may not have it
        pytest.fail("Sphinx is not installed: pip install -e '.[docs]' (make test does)")
    cmd = [
        sys.executable,
        "-m",
        "sphinx",
        "-b",
        "html",
        "-W",
        "--keep-going",
        "-n",
        "-q",
        "-d",
        str(tmp_path / "doctrees"),
        str(ROOT / "docs"),
        str(tmp_path / "html"),
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, check=False)
    assert proc.returncode == 0, f"sphinx-build failed:\n{proc.stderr[-6000:]}"
    html = tmp_path / "html"
    for page in ("index", "method", "performance", "cli-reference", "development"):
        assert (html / f"{page}.html").is_file()
    # the performance tables are made from the result files at build time
    performance = (html / "performance.html").read_text(encoding="utf-8")
    for result in (
        "mesher-2026-12-02.json",
        "solver.json",
        "quality-2026-12-02.json",
        "latency-big-2026-12-02.json",
        "latency-interaction-2026-12-03.json",
    ):
        assert result in performance
    # mesher, quality, solver, the window's dense rounds and its drags, wheel and rotation
    assert performance.count("<table") == 5
    solving = (html / "solving.html").read_text(encoding="utf-8")
    # validation, infinite-array validation, and the edge-refinement, infinite-array
    # speed, sweep accuracy, infinite-array sweep and live infinite-array tables made at
    # build time
    assert "grading-2026-12-02.json" in solving and solving.count("<table") == 7
    assert "sweep-accuracy-2026-12-02.json" in solving
    assert "periodic-2026-12-02.json" in solving
    assert "periodic-sweep-2026-12-02.json" in solving
    assert "array-live-2026-12-02.json" in solving
    # the method page's figures drawn from build_mesh at build time
    for figure in ("subdivision.png", "rings.png"):
        assert (html / "_images" / figure).is_file()
    # the API reference reaches the packages and the window's modules
    for module in ("barymesh", "barymesh.io", "barymesh.mom", "barymesh.cell", "barymesh.app.cli"):
        assert (html / "api" / "generated" / f"{module}.html").is_file()
    # every verb of the command line is in the generated reference
    reference = (html / "cli-reference.html").read_text(encoding="utf-8")
    from barymesh.app.cli import VERBS

    for verb in VERBS:
        assert f">{verb}<" in reference or f"barymesh {verb}" in reference, verb
