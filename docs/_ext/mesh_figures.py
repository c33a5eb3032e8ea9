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


def reflectarray(path: Path) -> None:
    """The page's reflectarray: its patch's S-curve, the 15 x 15 layout and the pattern."""
    import matplotlib.pyplot as plt
    import numpy as np

    from barymesh import reflectarray as ra
    from barymesh.cell import cell_from_dict
    from barymesh.mom import parse_stack, reflection_library

    cell = cell_from_dict(
        {
            "format": "barymesh-cell",
            "version": 1,
            "lattice": {"rectangular": [15.0, 15.0]},
            "elements": [
                {"structure": "patch", "patch_size": 8.0, "subdivisions": 6, "position": [-6, -6]}
            ],
        }
    )
    lib = reflection_library(
        cell,
        "elements[0].patch_size",
        np.linspace(6.0, 11.0, 6),
        frequencies=10e9,
        stack=parse_stack("1.575mm eps=2.2; ground"),
    )
    design = ra.design(lib, (15, 15), (0, 0, 150.0), (20.0, 0.0), 10e9)
    one_bit = ra.design(lib, (15, 15), (0, 0, 150.0), (20.0, 0.0), 10e9, bits=1)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.0))
    ax = axes[0]
    ax.plot(lib.values, lib.phase_deg[:, 0], "o-", color="#1f5f8b")
    ax.set_xlabel("patch size (mm)")
    ax.set_ylabel("∠R (°), at the stack's top face", color="#1f5f8b")
    twin = ax.twinx()
    twin.plot(lib.values, lib.magnitude[:, 0], "s--", color="#c0392b", markersize=4)
    twin.set_ylim(0, 1.05)
    twin.set_ylabel("|R|", color="#c0392b")
    covered = float(np.ptp(lib.phase_deg[:, 0]))
    ax.set_title(f"S-curve at 10 GHz: covers {covered:.0f}° of 360°")
    ax = axes[1]
    xy = design.positions[:, :2]
    dots = ax.scatter(xy[:, 0], xy[:, 1], c=design.parameter, s=40, marker="s", cmap="viridis")
    fig.colorbar(dots, ax=ax, label="patch size (mm)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title("15 × 15 layout, feed at 150 mm")
    ax = axes[2]
    theta = np.linspace(-60.0, 60.0, 481)
    for array, label in ((design, "continuous"), (one_bit, "1 bit")):
        cut = array.pattern_db(np.abs(theta), np.where(theta < 0, 180.0, 0.0))
        ax.plot(theta, cut, label=label)
    ax.axvline(20.0, color="#888888", linestyle=":", linewidth=1)
    ax.set_ylim(float(design.gain) - 40.0, float(design.gain) + 3.0)
    ax.set_xlabel("θ in the plane φ = 0 (°)")
    ax.set_ylabel("gain (dBi)")
    ax.set_title(f"pattern: beam at {design.beam_direction[0]:.1f}°")
    ax.legend(loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)


KINDS = {"subdivision": subdivision, "rings": rings, "reflectarray": reflectarray}


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
