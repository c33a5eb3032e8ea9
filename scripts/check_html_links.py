"""Check that every internal link of a built HTML site resolves (``make docs`` runs it).

Every ``href`` and ``src`` of every page (``.html`` file) under the folder is read with the
standard library's HTML parser; ``_static/`` holds the theme's and extensions' assets (an
HTML template among them), which are targets but not pages. A link with a scheme
(``https:``, ``mailto:``) or to another host is external and left to Sphinx's
``linkcheck`` builder; every other one is internal and must point at a file that exists
in the site, and its ``#anchor``, if any, at an ``id`` (or an ``<a name>``) in that file.
A link with a scheme a browser cannot follow from a page (``tcp:``, ``file:``) is
reported too: it is text that became a link.

``python scripts/check_html_links.py docs/_build/html`` prints each broken link as
``page: target (why)`` and exits 1 if there is one, 0 otherwise.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

#: Schemes a link in a page may have that leave the site: checked by ``linkcheck``.
EXTERNAL_SCHEMES = frozenset({"http", "https", "mailto", "ftp", "data", "javascript"})


@dataclass(frozen=True)
class BrokenLink:
    """One link that does not resolve: the page it is on, its target and why."""

    page: str
    target: str
    why: str

    def __str__(self) -> str:
        return f"{self.page}: {self.target} ({self.why})"


class _Page(HTMLParser):
    """The links (``href``, ``src``) and the anchors (``id``, ``<a name>``) of one page."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.links: list[str] = []
        self.anchors: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = dict(attrs)
        if values.get("id"):
            self.anchors.add(values["id"] or "")
        if tag == "a" and values.get("name"):
            self.anchors.add(values["name"] or "")
        for name in ("href", "src"):
            if tag in ("a", "link", "img", "script", "iframe", "source") and values.get(name):
                self.links.append(values[name] or "")


def _parse(path: Path) -> _Page:
    page = _Page()
    page.feed(path.read_text(encoding="utf-8", errors="replace"))
    page.close()
    return page


def site_pages(root: Path) -> list[Path]:
    """The pages of the site at ``root``: its ``.html`` files outside ``_static/``."""
    return sorted(p for p in root.rglob("*.html") if "_static" not in p.relative_to(root).parts)


def broken_links(site: str | Path) -> list[BrokenLink]:
    """The internal links of the HTML files under ``site`` that do not resolve.

    Parameters
    ----------
    site : str or Path
        The built site's folder (``docs/_build/html``).

    Returns
    -------
    list of BrokenLink
        In page order, then link order; empty when every internal link resolves.
    """
    root = Path(site).resolve()
    if not root.is_dir():
        raise FileNotFoundError(f"{site}: no such folder; build the site first (make docs)")
    pages = {p: _parse(p) for p in site_pages(root)}
    broken = []
    for path, page in pages.items():
        name = path.relative_to(root).as_posix()
        for link in page.links:
            parts = urlsplit(link)
            if parts.scheme in EXTERNAL_SCHEMES or (not parts.scheme and parts.netloc):
                continue
            if parts.scheme:
                broken.append(BrokenLink(name, link, f"{parts.scheme}: is not a web link"))
                continue
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            if target.is_dir():
                target = target / "index.html"
            if root not in target.parents and target != root:
                broken.append(BrokenLink(name, link, "outside the site"))
                continue
            if not target.is_file():
                broken.append(BrokenLink(name, link, "no such file"))
                continue
            anchor = unquote(parts.fragment)
            if anchor and target.suffix == ".html":
                if target not in pages:
                    pages[target] = _parse(target)
                if anchor not in pages[target].anchors:
                    broken.append(BrokenLink(name, link, f"no anchor #{anchor} in that page"))
    return broken


def main(argv: list[str] | None = None) -> int:
    """Print the broken internal links of the site named in ``argv``; 1 if any, else 0."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python scripts/check_html_links.py SITE_FOLDER", file=sys.stderr)
        return 2
    try:
        broken = broken_links(args[0])
    except FileNotFoundError as exc:
        print(f"check_html_links: {exc}", file=sys.stderr)
        return 2
    for link in broken:
        print(link)
    pages = len(site_pages(Path(args[0]).resolve()))
    if broken:
        print(f"{len(broken)} broken internal link(s) in {pages} pages", file=sys.stderr)
        return 1
    print(f"every internal link of {pages} pages resolves")
    return 0


if __name__ == "__main__":
    sys.exit(main())
