"""The documentation stays true: the site builds, the README is short and its claims hold.

* The Sphinx site (``docs/``) builds with warnings as errors and nitpicky references, so
  every page parses, every internal link and heading anchor resolves, and every
  cross-reference into barymesh in a docstring names something that exists.
* The README stays under 15 KB, its Python example prints what its comments say, its
  headline figures are those of the result files it names, and its commands parse with the
  program's own parser and name presets and parameters that exist.
* Every relative link in the README, CONTRIBUTING.md, CHANGELOG.md and the documentation's
  pages points at a file that exists.
* Every Python example of every page runs as written: a page's blocks run in order in one
  namespace, in an empty folder, with the files its other blocks name written there first
  (``srr.json``). A block is skipped only when its first line says why
  (``# not run: <reason>``); a page that needs an extra says so, and is skipped (naming
  it) where that extra is missing.
* The built site's internal links and anchors all resolve (``scripts/check_html_links.py``,
  which ``make docs`` runs too), and its maths needs no network (MathJax is in the site).
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import shlex
import subprocess
import sys
import textwrap
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


#: The documentation's pages (Markdown and reStructuredText) whose Python examples run.
DOC_PAGES = sorted(
    [p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts]
    + [p for p in (ROOT / "docs").glob("*.rst")]
)
#: Pages whose examples need an extra: (extra, modules it brings). The page must say so.
PAGE_EXTRAS = {
    "cells.md": ("cell", ("ezdxf", "gdstk")),
    "study.rst": ("study", ("dask", "distributed", "pandas", "pyarrow", "xarray")),
}
#: The first line of a block that is not run, followed by the reason.
NOT_RUN = "# not run:"
#: A file named just before a code block (``srr.json``: / `srr.json`:), which the page's
#: Python examples read.
_NAMED_FILE = re.compile(
    r"^(?:``|`)(?P<name>[\w.-]+)(?:``|`):\n\n"
    r"(?:```\w*\n(?P<md>.*?)^```|\.\. code-block:: \w+\n\n(?P<rst>(?:(?:   [^\n]*)?\n)+))",
    re.MULTILINE | re.DOTALL,
)


def python_blocks(page: Path) -> list[tuple[int, str]]:
    """(first line number, code) of every Python block of a Markdown or rst page, in order."""
    text = page.read_text(encoding="utf-8")
    found = []
    if page.suffix == ".md":
        for match in re.finditer(r"^```python\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL):
            found.append((text.count("\n", 0, match.start()) + 2, match.group(1)))
    else:
        pattern = r"^\.\. code-block:: python\n\n((?:(?:[ ]{3}.*)?\n)+)"
        for match in re.finditer(pattern, text, flags=re.MULTILINE):
            code = textwrap.dedent(match.group(1))
            found.append((text.count("\n", 0, match.start()) + 3, code))
    return found


def named_files(page: Path) -> dict[str, str]:
    """The files a page shows right after naming them: name -> content."""
    files = {}
    for match in _NAMED_FILE.finditer(page.read_text(encoding="utf-8")):
        body = match.group("md") if match.group("md") is not None else match.group("rst")
        files[match.group("name")] = textwrap.dedent(body)
    return files


def test_the_python_blocks_and_the_files_they_read_are_found():
    blocks = {p.name: python_blocks(p) for p in DOC_PAGES}
    assert len(blocks["solving.md"]) == 7 and len(blocks["study.rst"]) == 2
    assert len(blocks["cells.md"]) == 1 and len(blocks["getting-started.md"]) == 1
    assert blocks["study.rst"][0][1].startswith("from barymesh.study import run\n")
    assert json.loads(named_files(ROOT / "docs" / "study.rst")["srr.json"])["base"] == {
        "preset": "srr-openmodes"
    }


@pytest.mark.parametrize("page", [p for p in DOC_PAGES if python_blocks(p)], ids=lambda p: p.name)
def test_every_python_example_of_a_page_runs_as_written(page, tmp_path, monkeypatch):
    extra = PAGE_EXTRAS.get(page.name)
    if extra is not None:
        name, modules = extra
        text = page.read_text(encoding="utf-8")
        assert f"barymesh[{name}]" in text, f"{page.name} should say it needs the {name} extra"
        for module in modules:
            pytest.importorskip(module, reason=f"{page.name} needs barymesh[{name}]")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    for name, content in named_files(page).items():
        (tmp_path / name).write_text(content, encoding="utf-8")
    namespace: dict = {"__name__": f"docs_{page.stem.replace('-', '_')}"}
    ran = 0
    for line, code in python_blocks(page):
        first = code.lstrip().splitlines()[0]
        if first.startswith(NOT_RUN):
            assert first[len(NOT_RUN) :].strip(), f"{page.name}:{line}: say why it is not run"
            continue
        with contextlib.redirect_stdout(io.StringIO()):
            exec(compile(code, f"{page.relative_to(ROOT)}:{line}", "exec"), namespace)
        ran += 1
    assert ran >= 1
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


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
    mesher = {(w["name"], w["size"]): w for w in _result("mesher-2026-12-06.json")["workloads"]}
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

    plate = _result("solver-2026-12-04.json")["workloads"][0]
    assert plate["name"] == "plate 736"
    row = _row(text, "RWG solve")
    assert f"{plate['unknowns']} unknowns" in row
    assert f"{plate['ours_s']:.3f} s against {plate['makarov_s']:.3f} s" in row
    assert f"({plate['speedup']:.1f}×)" in row

    big = _result("latency-big-2026-12-06.json")["big"]["4.8M"]
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
    [
        README,
        ROOT / "docs" / "formats-cli.md",
        ROOT / "docs" / "solving.md",
        ROOT / "docs" / "reflectarray.md",
    ],
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
    fewest = 1 if path.name == "reflectarray.md" else 4  # that page shows its one verb
    assert checked >= fewest, f"{path.name}: expected its command examples to be found"


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
        "mesher-2026-12-06.json",
        "solver-2026-12-04.json",
        "solver-bempp-2026-12-04.json",
        "quality-2026-12-02.json",
        "latency-big-2026-12-06.json",
        "latency-interaction-2026-12-04.json",
        "startup-2026-12-05.json",
    ):
        assert result in performance
    # mesher, quality, solver, bempp-cl's, the window's dense rounds and its drags, wheel
    # and rotation, start-up
    assert performance.count("<table") == 7
    solving = (html / "solving.html").read_text(encoding="utf-8")
    # validation, infinite-array validation, and the edge-refinement, infinite-array
    # speed, sweep accuracy, infinite-array sweep, live infinite-array and convergence
    # tables made at build time, the layered media's validation, convergence and speed, and
    # the reflection-phase library's
    assert "grading-2026-12-02.json" in solving and solving.count("<table") == 12
    assert "library-2026-12-06.json" in solving
    assert "layered-2026-12-03.json" in solving
    assert "convergence-2026-12-03.json" in solving
    assert "sweep-accuracy-2026-12-02.json" in solving
    assert "periodic-2026-12-06.json" in solving
    assert "periodic-sweep-2026-12-02.json" in solving
    assert "array-live-2026-12-02.json" in solving
    # the method page's figures drawn from build_mesh, and the reflectarray page's, at build time
    for figure in ("subdivision.png", "rings.png", "reflectarray.png"):
        assert (html / "_images" / figure).is_file()
    # the API reference reaches the packages and the window's modules
    for module in ("barymesh", "barymesh.io", "barymesh.mom", "barymesh.cell", "barymesh.app.cli"):
        assert (html / "api" / "generated" / f"{module}.html").is_file()
    # every verb of the command line is in the generated reference
    reference = (html / "cli-reference.html").read_text(encoding="utf-8")
    from barymesh.app.cli import VERBS

    for verb in VERBS:
        assert f">{verb}<" in reference or f"barymesh {verb}" in reference, verb
    # every internal link and anchor resolves, the source pages' "[docs]" back-links too
    check = _check_html_links()
    assert check.broken_links(html) == []
    assert "tcp://host:8786" in reference and 'href="tcp:' not in reference  # text, not a link
    backlinks = sum(
        page.read_text(encoding="utf-8").count('class="viewcode-back"')
        for page in (html / "_modules").rglob("*.html")
    )
    assert backlinks > 300
    # the maths renders offline: MathJax is in the site, and no page loads a script from
    # another host
    method = (html / "method.html").read_text(encoding="utf-8")
    assert 'class="math' in method
    scripts = re.findall(r'<script[^>]*\ssrc="([^"]+)"', method)
    assert "_static/mathjax/tex-chtml.js" in scripts
    assert (html / "_static" / "mathjax" / "tex-chtml.js").stat().st_size > 100_000
    assert (html / "_static" / "mathjax" / "output" / "chtml" / "fonts" / "woff-v2").is_dir()
    for page in check.site_pages(html):
        for src in re.findall(r'<script[^>]*\ssrc="([^"]+)"', page.read_text(encoding="utf-8")):
            assert "://" not in src and not src.startswith("//"), (page.name, src)


def _check_html_links():
    """scripts/check_html_links.py as a module."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "check_html_links", ROOT / "scripts" / "check_html_links.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["check_html_links"] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_the_link_check_finds_broken_links_and_anchors(tmp_path):
    check = _check_html_links()
    (tmp_path / "a").mkdir()
    (tmp_path / "index.html").write_text(
        '<a href="a/b.html#there">ok</a> <a href="a/b.html#nowhere">bad anchor</a> '
        '<a href="missing.html">no file</a> <a href="tcp://host:8786">tcp</a> '
        '<a href="https://example.org/x">external</a> <a href="#top">self</a> <p id="top"></p>'
        '<img src="a/pic.png">'
    )
    (tmp_path / "a" / "b.html").write_text('<h1 id="there">b</h1><a href="../index.html">up</a>')
    (tmp_path / "a" / "pic.png").write_bytes(b"")
    broken = [(b.page, b.target) for b in check.broken_links(tmp_path)]
    assert broken == [
        ("index.html", "a/b.html#nowhere"),
        ("index.html", "missing.html"),
        ("index.html", "tcp://host:8786"),
    ]
    assert check.main([str(tmp_path)]) == 1
    (tmp_path / "index.html").write_text('<a href="a/b.html#there">ok</a>')
    assert check.main([str(tmp_path)]) == 0
