"""Sphinx configuration of the barymesh documentation (``make docs``)."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import barymesh

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))
# The API pages are generated afresh on every build, so a module renamed or removed leaves
# no stale page behind (it would be an orphan page, a warning, so an error).
shutil.rmtree(DOCS / "api" / "generated", ignore_errors=True)

project = "barymesh"
author = "the barymesh developers"
copyright = "2026, the barymesh developers"
release = barymesh.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    # MathJax 3 from the PyPI package (docs extra), copied into _static/mathjax: the maths
    # renders offline, with no CDN
    "sphinx-mathjax-offline",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinxarg.ext",
    "benchmark_tables",
    "barymesh_refs",
    "mesh_figures",
    "site_links",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
smartquotes = False  # flags such as --big-only stay as typed
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
templates_path = ["_templates"]

# Markdown pages (MyST): headings get anchors so that pages can link to sections.
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 3

# API reference: autosummary writes one page per public name (a module's __all__).
autosummary_generate = True
autosummary_ignore_module_all = False
autosummary_imported_members = False  # a package's __all__ is still followed
autodoc_default_options = {"members": True, "show-inheritance": False}
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc sections state types and shapes
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()

# Warnings are errors (make docs: -W -n). Every reference into barymesh must resolve;
# references to outside projects (numpy, scipy, Qt, VTK, the standard library) cannot be
# resolved without intersphinx, which needs the network, so they are ignored here.
nitpicky = True
_OUTSIDE = (
    "numpy",
    "np",
    "scipy",
    "meshio",
    "PySide6",
    "Qt",
    "QtCore",
    "QtGui",
    "QtWidgets",
    "pyvista",
    "pv",
    "pyvistaqt",
    "vtk",
    "vtkmodules",
    "matplotlib",
    "imageio",
    "ezdxf",
    "gdstk",
    "trimesh",
    "gmsh",
    "argparse",
    "collections",
    "concurrent",
    "dataclasses",
    "functools",
    "io",
    "logging",
    "os",
    "pathlib",
    "threading",
    "typing",
    "weakref",
    "enum",
    "json",
    "signal",
    "subprocess",
    "tempfile",
    "contextlib",
    "abc",
)
nitpick_ignore_regex = [
    (r"py:.*", rf"({'|'.join(_OUTSIDE)})\..*"),
    # builtins and the standard library's names used bare
    (
        r"py:.*",
        r"(int|float|str|bool|bytes|dict|list|tuple|set|frozenset|object|None|"
        r"callable|Callable|Path|Iterator|Iterable|Sequence|Mapping|Any|type|"
        r"Exception|ValueError|TypeError|OSError|KeyError|RuntimeError)",
    ),
]

html_theme = "pydata_sphinx_theme"
html_title = f"barymesh {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_show_sourcelink = False
