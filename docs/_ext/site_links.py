"""Links of the built site that Sphinx gets wrong for barymesh, set right.

``scripts/check_html_links.py`` (run by ``make docs`` and ``tests/test_docs.py``) found
them; each fix keeps it at zero broken internal links.

* **Addresses that are not web links.** Docutils turns any ``scheme://…`` in prose into a
  link, so the command line's help text "a running Dask scheduler, e.g. tcp://host:8786"
  became a link no browser can follow. A reference whose scheme a browser does not open
  from a page becomes the literal text it was.
* **The source pages' "[docs]" back-links.** ``sphinx.ext.viewcode`` keeps one anchor
  prefix per module (the first module name an object of it was documented under) but the
  page of the last one: an object documented twice, once in its package's ``__all__``
  (``barymesh.MeshParams``) and once in its own module (``barymesh.params.MeshParams``),
  got a link to ``barymesh.params.MeshParams.html#barymesh.MeshParams``, which does not
  exist. Before viewcode writes its pages, each back-link is pointed at the page that
  documents the object under the module that defines it, or, where only another name
  documents it, under that one (the module's anchor prefix then being that name's
  module); a name documented under neither gets no back-link rather than a broken one.
  Modules whose source viewcode could not read (compiled ones, ``PySide6.QtCore``) are
  dropped from the list of module pages, which linked to pages never written.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from docutils import nodes

#: URI schemes a reader's browser follows from a page.
WEB_SCHEMES = ("http:", "https:", "mailto:", "ftp:")


def _unlink_other_schemes(app: Any, doctree: nodes.document) -> None:
    for ref in list(doctree.findall(nodes.reference)):
        uri = ref.get("refuri", "")
        if "://" in uri and not uri.startswith(WEB_SCHEMES):
            ref.replace_self(nodes.literal(ref.astext(), ref.astext()))


def _fix_viewcode_backlinks(app: Any) -> None:
    modules = getattr(app.env, "_viewcode_modules", None)
    if not modules:
        return
    # an object autodoc documents under another module's name is also entered under its
    # defining module's name as an alias (":canonical:"), whose anchor is the other one's
    objects = {k: v for k, v in app.env.get_domain("py").objects.items() if not v.aliased}
    for modname in [m for m, entry in modules.items() if not entry]:
        del modules[modname]  # no source: viewcode writes no page for it
    for modname, (code, tags, used, refname) in list(modules.items()):
        # the prefix under which most of this module's names are documented
        votes = Counter(
            prefix
            for name in used
            for prefix in dict.fromkeys((modname, refname))
            if f"{prefix}.{name}" in objects
        )
        prefix = votes.most_common(1)[0][0] if votes else refname
        fixed = {}
        for name in used:
            entry = objects.get(f"{prefix}.{name}")
            if entry is not None and entry.node_id == f"{prefix}.{name}":  # its anchor
                fixed[name] = entry.docname
        modules[modname] = (code, tags, fixed, prefix)


def setup(app: Any) -> dict[str, Any]:
    app.connect("doctree-read", _unlink_other_schemes)
    # before viewcode's own html-collect-pages handler (priority 500) writes the pages
    app.connect("html-collect-pages", _fix_viewcode_backlinks_pages, priority=400)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


def _fix_viewcode_backlinks_pages(app: Any) -> list[Any]:
    _fix_viewcode_backlinks(app)
    return []  # html-collect-pages handlers yield pages; this one adds none
