"""Figures drawn at build time with matplotlib from meshes that barymesh builds.

``.. mesh-figure:: KIND`` (MyST: a ``{mesh-figure}`` fence) draws the figure ``KIND`` into
``docs/_generated/KIND.png`` and shows it with the directive's content as its caption, so
the figures always show what the installed barymesh builds.
"""

from __future__ import annotations

from pathlib import Path

from docutils import nodes
from sphinx.util.docutils import SphinxDirective

OUT = Path(__file__).resolve().parents[1] / "_generated"


def _draw_mesh(ax, mesh, *, centroids: bool = True, colour=None) -> None:  # noqa: ANN001
    from matplotlib.collections import PolyCollection

    xy = mesh.points[:, :2][mesh.triangles]
    faces = PolyCollection(
        xy,
        facecolors=colour if colour is not None else "#cfe3f5",
        edgecolors="#33506b",
        linewidths=0.4,
    )
    ax.add_collection(faces)
    if centroids:
        c = mesh.centroids
        ax.plot(c[:, 0], c[:, 1], ".", color="#c0392b", markersize=2.5)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xticks([])
    ax.set_yticks([])
    for side in ax.spines.values():
        side.set_visible(False)


def subdivision(path: Path) -> None:
    """One 10 mm patch at n = 1 … 4: 2n² triangles, (n + 1)² vertices."""
    import matplotlib.pyplot as plt

    from barymesh import MeshParams, build_mesh

    fig, axes = plt.subplots(1, 4, figsize=(10, 2.9))
    for ax, n in zip(axes, (1, 2, 3, 4), strict=True):
        mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0, subdivisions=n))
        s = mesh.stats()
        _draw_mesh(ax, mesh)
        ax.set_title(f"n = {n}: {s['triangles']} triangles\n{s['interior_edges']} shared edges")
    fig.tight_layout()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def rings(path: Path) -> None:
    """The paper's Fig. 12(c) (2 mm patches every 10°) in paper mode, and conforming."""
    import matplotlib.pyplot as plt
    import numpy as np

    from barymesh import build_mesh
    from barymesh.presets import load_preset

    params = load_preset("paper-fig12c")[0]
    paper = build_mesh(params)
    half = params.patch_size / 2  # a paper ring is centred at origin + (s/2, s/2)
    conforming = build_mesh(
        params.__class__(**{**params.to_dict(), "mode": "conforming", "origin": (half, half)})
    )
    fig, axes = plt.subplots(1, 2, figsize=(10, 5))
    palette = plt.get_cmap("tab10")(np.arange(10))
    _draw_mesh(
        axes[0], paper, centroids=False, colour=palette[paper.patch_ids % 10] * [1, 1, 1, 0.55]
    )
    sp = paper.stats()
    axes[0].set_title(
        f"paper mode: {sp['patches']} patches, {sp['triangles']:,} triangles,\n"
        f"overlap ratio {sp['overlap_ratio']:.2f}"
    )
    _draw_mesh(axes[1], conforming, centroids=False)
    sc = conforming.stats()
    axes[1].set_title(
        f"conforming mode: {sc['triangles']:,} triangles,\n"
        f"{sc['boundary_edges']} boundary edges, {sc['junction_edges']} junction edges"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)


KINDS = {"subdivision": subdivision, "rings": rings}


class MeshFigure(SphinxDirective):
    required_arguments = 1
    has_content = True

    def run(self):  # noqa: ANN201
        kind = self.arguments[0]
        if kind not in KINDS:
            raise self.error(f"mesh-figure: unknown figure {kind!r}; known: {sorted(KINDS)}")
        import matplotlib

        matplotlib.use("Agg", force=True)
        OUT.mkdir(exist_ok=True)
        KINDS[kind](OUT / f"{kind}.png")
        alt = (KINDS[kind].__doc__ or kind).strip().splitlines()[0]
        figure = nodes.figure()
        figure += nodes.image(uri=f"/_generated/{kind}.png", alt=alt)
        if self.content:
            caption = nodes.container()
            self.state.nested_parse(self.content, self.content_offset, caption)
            paragraphs = caption.children
            if paragraphs and isinstance(paragraphs[0], nodes.paragraph):
                figure += nodes.caption("", "", *paragraphs[0].children)
                figure += paragraphs[1:]
        return [figure]


def setup(app):  # noqa: ANN001
    app.add_directive("mesh-figure", MeshFigure)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
