"""Resolve the docstrings' references into barymesh the way a reader means them.

Two things the plain nitpicky build gets wrong for a package that re-exports its names:

* A name documented under the package that exports it (``barymesh.TriMesh``) is referred
  to by the module that defines it (``barymesh.mesh.TriMesh.stats``) or unqualified from a
  neighbouring module (``MeshParams``). Such a reference is resolved to the page of the
  same Python object, found by importing both.
* A reference to a real barymesh object that the API pages do not cover (a private helper
  module, a constant) is rendered as plain code, without a link and without a warning.

A reference whose target cannot be imported at all (a function renamed or removed) is
left alone, so the nitpicky build (``make docs``) still reports it.

The docstrings also write magnitudes as ``|J|``; reStructuredText would read those as
substitutions, so bars outside literals are escaped before the docstrings are parsed.
"""

from __future__ import annotations

import importlib
import re
from typing import Any

from sphinx.addnodes import pending_xref

_LITERAL = re.compile(r"(``.*?``|`[^`]*`_?)")


def _lookup(name: str) -> Any:
    """The object that the dotted ``name`` names, or raise LookupError."""
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj: Any = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            for attr in parts[cut:]:
                obj = getattr(obj, attr)
        except AttributeError:
            continue
        return obj
    raise LookupError(name)


def _candidates(target: str, node: pending_xref) -> list[str]:
    """Full names ``target`` may mean from where the reference stands."""
    module = node.get("py:module") or ""
    cls = node.get("py:class") or ""
    target = target.lstrip("~")
    if target.startswith("."):
        target = target.lstrip(".")
    names = [target]
    if module:
        names.append(f"{module}.{target}")
        if cls:
            names.append(f"{module}.{cls}.{target}")
        package = module.rsplit(".", 1)[0]
        names.append(f"{package}.{target}")
    # the docstring's own object, as autodoc names its source: "...:docstring of a.b.c"
    source = node.source or ""
    if "docstring of " in source:
        owner = source.rsplit("docstring of ", 1)[1].split(".")
        names += [".".join(owner[:cut] + [target]) for cut in range(len(owner), 0, -1)]
    names.append(f"barymesh.{target}")
    return [n for n in names if n.split(".")[0] == "barymesh"]


def _same(a: Any, b: Any) -> bool:
    if a is b:
        return True
    fa, fb = getattr(a, "fget", None), getattr(b, "fget", None)  # properties
    if fa is not None and fa is fb:
        return True
    fa, fb = getattr(a, "func", None), getattr(b, "func", None)  # cached_property
    return fa is not None and fa is fb


def _missing_reference(app, env, node, contnode):  # noqa: ANN001
    if node.get("refdomain") != "py":
        return None
    target = node.get("reftarget", "")
    found = None
    for name in _candidates(target, node):
        try:
            found = _lookup(name)
        except LookupError:
            continue
        break
    if found is None:
        return None  # nothing of that name in barymesh: the warning stands
    domain = env.get_domain("py")
    tail = target.lstrip("~.").split(".")[-1]
    for fullname in list(domain.objects):
        if fullname.rsplit(".", 1)[-1] != tail or fullname.split(".")[0] != "barymesh":
            continue
        try:
            documented = _lookup(fullname)
        except LookupError:
            continue
        if _same(documented, found):
            node["refspecific"] = False
            return domain.resolve_xref(
                env, node["refdoc"], app.builder, "obj", fullname, node, contnode
            )
    return contnode  # a real object the API pages do not cover: code, no link


def _escape_bars(line: str) -> str:
    pieces = _LITERAL.split(line)
    return "".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(pieces))


def _process_docstring(app, what, name, obj, options, lines):  # noqa: ANN001
    if not name.startswith("barymesh"):
        return
    literal_indent = None
    previous = ""
    for i, line in enumerate(lines):
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None and stripped and indent <= literal_indent:
            literal_indent = None
        if literal_indent is None and previous.rstrip().endswith("::") and stripped:
            literal_indent = len(previous) - len(previous.lstrip())
        if stripped:
            previous = line
        if literal_indent is not None and indent > literal_indent:
            continue
        if stripped.startswith((">>>", "...", "+-", "+=")) or "|" not in line:
            continue
        lines[i] = _escape_bars(line)


def setup(app):  # noqa: ANN001
    app.connect("missing-reference", _missing_reference)
    app.connect("autodoc-process-docstring", _process_docstring, priority=400)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
