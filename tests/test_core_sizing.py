"""Sizing from frequency: parameters, the subdivision the mesher picks, statistics, files."""

import json
import math
import re

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from barymesh import MeshParams, build_mesh
from barymesh.params import MAX_BUDGET
from barymesh.presets import load_params_file, resolve_params, save_params_file
from barymesh.sizing import largest_area, longest_edge, target_edge, wavelength

#: c0 = 299,792,458 m/s (exact): λ at 10 GHz in mm.
LAMBDA_10GHZ = 29.9792458
PATCH10 = {"structure": "patch", "patch_size": 10.0}


def edge_lengths(mesh):
    """Every edge's length from the edge table (independent of the sizing's triangle sides)."""
    d = mesh.points[mesh.edges[:, 1]] - mesh.points[mesh.edges[:, 0]]
    return np.sqrt((d * d).sum(axis=1))


def unsized(params, n):
    return params.replace(frequency=None, max_edge=None, subdivisions=n)


def predicted(params, n):
    """Triangles of ``params`` at n, whatever the budget (infinite where n is refused)."""
    try:
        return params.replace(
            frequency=None, max_edge=None, subdivisions=n, max_triangles=MAX_BUDGET
        ).predicted_triangles()
    except ValueError:
        return math.inf


# -- parameters -----------------------------------------------------------------------------


def test_wavelength_is_c0_over_f_sqrt_eps():
    assert wavelength(10e9) == pytest.approx(LAMBDA_10GHZ, rel=1e-15)
    assert wavelength(10e9, 4.0) == pytest.approx(LAMBDA_10GHZ / 2, rel=1e-15)
    assert wavelength(1e9, 2.25) == pytest.approx(299.792458 / 1.5, rel=1e-15)


def test_defaults_are_off_and_old_dicts_still_load():
    p = MeshParams()
    assert (p.max_edge, p.frequency, p.cells_per_wavelength, p.relative_permittivity) == (
        None,
        None,
        10.0,
        1.0,
    )
    assert not p.sized and target_edge(p) is None
    old = {
        k: v
        for k, v in p.to_dict().items()
        if k not in ("max_edge", "frequency", "cells_per_wavelength", "relative_permittivity")
    }
    assert MeshParams.from_dict(old) == p


@pytest.mark.parametrize(
    ("changes", "named", "expected"),
    [
        ({"frequency": -1.0}, "frequency=", "> 0 Hz"),
        ({"frequency": 0}, "frequency=", "> 0 Hz"),
        ({"frequency": float("nan")}, "frequency=", "> 0 Hz"),
        ({"frequency": float("inf")}, "frequency=", "> 0 Hz"),
        ({"frequency": "ten"}, "frequency=", "not a number"),
        ({"frequency": True}, "frequency=", "not a number"),
        ({"frequency": 1e300}, "frequency=", "too high"),
        ({"max_edge": 0.0}, "max_edge=", "> 0 mm"),
        ({"max_edge": -2}, "max_edge=", "> 0 mm"),
        ({"max_edge": float("inf")}, "max_edge=", "> 0 mm"),
        ({"cells_per_wavelength": 0.5}, "cells_per_wavelength=", ">= 1"),
        ({"cells_per_wavelength": float("nan")}, "cells_per_wavelength=", ">= 1"),
        ({"cells_per_wavelength": None}, "cells_per_wavelength=", "not a number"),
        ({"relative_permittivity": 0.9}, "relative_permittivity=", ">= 1"),
        ({"relative_permittivity": float("inf")}, "relative_permittivity=", ">= 1"),
        ({"relative_permittivity": False}, "relative_permittivity=", "not a number"),
    ],
)
def test_bad_sizing_values_are_refused_by_name(changes, named, expected):
    with pytest.raises(ValueError, match=named) as info:
        MeshParams(**PATCH10, **changes)
    assert expected in str(info.value)


def test_stricter_of_frequency_and_max_edge_wins():
    both = MeshParams(**PATCH10, frequency=10e9, max_edge=2.0)
    assert target_edge(both) == (2.0, "max_edge")
    loose = both.replace(max_edge=5.0)
    assert target_edge(loose) == pytest.approx((LAMBDA_10GHZ / 10, "frequency"))
    # the 10 mm patch's longest edge is 10 √2 / n: 2 mm needs n = 8, λ/10 (2.998 mm) n = 5
    assert build_mesh(both).params.subdivisions == 8
    assert build_mesh(loose).params.subdivisions == 5
    # Feko's λ/12 in a substrate of εr = 2.2
    feko = MeshParams(**PATCH10, frequency=10e9, cells_per_wavelength=12, relative_permittivity=2.2)
    assert target_edge(feko)[0] == pytest.approx(LAMBDA_10GHZ / math.sqrt(2.2) / 12)


def test_sized_params_skip_the_budget_of_the_unused_subdivisions():
    # n = 64 alone is over a budget of 1,000 triangles (2 x 64² = 8,192)
    with pytest.raises(ValueError, match="max_triangles"):
        MeshParams(**PATCH10, subdivisions=64, max_triangles=1000)
    p = MeshParams(**PATCH10, subdivisions=64, max_triangles=1000, frequency=10e9)
    assert build_mesh(p).n_triangles == 2 * 5 * 5


# -- the subdivision chosen --------------------------------------------------------------------


def test_patch_at_10ghz_takes_n5():
    """A 10 mm square split along its diagonal: the longest edge is 10 √2 / n (a closed
    form of the paper's patch), ≤ λ/10 = 2.998 mm first at n = 5 (2.83 mm; n = 4: 3.54)."""
    mesh = build_mesh(MeshParams(**PATCH10, frequency=10e9))
    s = mesh.stats()
    assert mesh.params.subdivisions == s["subdivisions_chosen"] == 5
    assert s["triangles"] == 2 * 5**2 and s["vertices"] == 6**2
    assert s["max_edge"] == pytest.approx(10 * math.sqrt(2) / 5, rel=1e-14)
    assert s["wavelength"] == pytest.approx(LAMBDA_10GHZ, rel=1e-15)
    assert s["max_edge_wavelengths"] == pytest.approx(10 * math.sqrt(2) / 5 / LAMBDA_10GHZ)
    # the largest triangle: half of a (10/5)^2 square
    assert s["max_area_wavelengths2"] == pytest.approx(2.0 / LAMBDA_10GHZ**2, rel=1e-12)
    assert s["lambda_10_rule"] is True
    assert s["target_edge"] == pytest.approx(LAMBDA_10GHZ / 10)


def test_max_edge_alone_and_the_rule_against_a_looser_target():
    # max_edge = 3 mm: n = 5 (10 √2 / 5 = 2.83); no frequency, so no wavelength keys
    s = build_mesh(MeshParams(**PATCH10, max_edge=3.0)).stats()
    assert s["subdivisions_chosen"] == 5
    assert "wavelength" not in s and "lambda_10_rule" not in s
    # λ/5 at 10 GHz = 5.996 mm: n = 3 (4.71 mm) meets it, but not the λ/10 rule
    s = build_mesh(MeshParams(**PATCH10, frequency=10e9, cells_per_wavelength=5)).stats()
    assert s["subdivisions_chosen"] == 3
    assert s["lambda_10_rule"] is False
    assert s["max_edge_wavelengths"] == pytest.approx(10 * math.sqrt(2) / 3 / LAMBDA_10GHZ)


def test_barycentric_levels():
    """Barycentric levels halve the primary triangle's sides (midpoints): at L levels the
    10 mm patch's diagonal is cut into 2^L pieces of 10 √2 / 2^L, its longest edge."""
    p = MeshParams(**PATCH10, scheme="barycentric", subdivisions=1, max_edge=2.0)
    mesh = build_mesh(p)
    n = mesh.params.subdivisions
    assert longest_edge(mesh.points, mesh.triangles) <= 2.0
    assert n == 1 or longest_edge(*_pt(build_mesh(unsized(p, n - 1)))) > 2.0
    assert mesh.n_triangles == 2 * 6**n


def _pt(mesh):
    return mesh.points, mesh.triangles


def test_sized_mesh_is_the_unsized_mesh_at_the_chosen_n():
    p = MeshParams(
        structure="split_double_ring",
        mode="conforming",
        inner_radius=3.0,
        outer_radius=5.0,
        patch_size=1.0,
        angle_step=30.0,
        frequency=40e9,
    )
    sized = build_mesh(p)
    plain = build_mesh(unsized(p, sized.params.subdivisions))
    assert np.array_equal(sized.points, plain.points)
    assert np.array_equal(sized.triangles, plain.triangles)
    assert sized.stats()["lambda_10_rule"] is True
    assert "subdivisions_chosen" not in plain.stats()


def test_unsized_meshes_carry_their_params_and_no_sizing_keys():
    p = MeshParams(angle_step=20.0)
    mesh = build_mesh(p)
    assert mesh.params is p
    s = mesh.stats()
    assert not {"subdivisions_chosen", "wavelength", "lambda_10_rule"} & set(s)


def test_scheme_limit_refused_with_the_triangles_needed():
    """λ/10 at 1 THz is 0.02998 mm; the patch's n = 64 leaves 10 √2 / 64 = 0.221 mm: it
    needs n = ceil(64 × 0.221 / 0.02998) = 472, that is 2 × 472² = 445,568 triangles."""
    with pytest.raises(ValueError, match=r"^frequency=") as info:
        build_mesh(MeshParams(**PATCH10, frequency=1e12))
    assert "n = 64" in str(info.value) and "445,568 triangles" in str(info.value)


def test_budget_refused_with_the_triangles_needed():
    """max_edge 0.5 mm on the 10 mm patch: n = ceil(10 √2 / 0.5) = 29, 2 × 29² = 1,682
    triangles, over a budget of 1,000."""
    with pytest.raises(ValueError, match=r"^max_edge=") as info:
        build_mesh(MeshParams(**PATCH10, max_edge=0.5, max_triangles=1000))
    assert "1,682 triangles" in str(info.value) and "max_triangles=1,000" in str(info.value)
    # at the budget it fits
    assert build_mesh(MeshParams(**PATCH10, max_edge=0.5, max_triangles=1682)).n_triangles == 1682


def test_largest_area_and_longest_edge_against_the_per_triangle_figures():
    mesh = build_mesh(
        MeshParams(structure="double_ring", mode="conforming", angle_step=15.0, subdivisions=3)
    )
    assert longest_edge(mesh.points, mesh.triangles) == edge_lengths(mesh).max()
    assert largest_area(mesh.points, mesh.triangles) == pytest.approx(mesh.areas.max(), rel=1e-14)


# -- property: λ/cells whenever a frequency is given, and n minimal ---------------------------

RINGS = ["ring", "double_ring", "split_ring", "split_double_ring", "square_split_double_ring"]


@st.composite
def sized_params(draw):
    structure = draw(st.sampled_from(RINGS + ["patch", "triangle"]))
    inner = draw(st.floats(1.0, 6.0))
    size = draw(st.floats(0.3, 2.0))
    kw = dict(
        structure=structure,
        mode=draw(st.sampled_from(["paper", "conforming"])),
        inner_radius=inner,
        outer_radius=inner + size + draw(st.floats(0.1, 3.0)),
        patch_size=size,
        angle_step=draw(st.floats(10.0, 120.0)),
        diagonal=draw(st.sampled_from(["BC", "AD"])),
        scheme=draw(st.sampled_from(["uniform", "uniform", "barycentric"])),
        subdivisions=1,
        gap_width=draw(st.floats(0.1, 1.5)) * min(inner, 1.0),
        gap_angle=draw(st.sampled_from([0.0, 90.0])),
        max_triangles=30_000,
    )
    try:
        coarse = MeshParams(**kw)
    except ValueError:
        assume(False)
    # the target: the coarsest mesh's longest edge over 1 to 12 (n up to about 12)
    first = build_mesh(coarse)
    target = longest_edge(first.points, first.triangles) / draw(st.floats(1.0, 12.0))
    cells = draw(st.sampled_from([10.0, 12.0, 20.0]))
    eps = draw(st.sampled_from([1.0, 2.2, 4.4]))
    frequency = wavelength(1.0, eps) / (target * cells)  # λ = target × cells
    return coarse.replace(
        frequency=frequency,
        cells_per_wavelength=cells,
        relative_permittivity=eps,
        subdivisions=draw(st.integers(1, 6)),
    )


@settings(max_examples=60, deadline=None)
@given(sized_params())
def test_frequency_gives_edges_within_lambda_over_cells_at_the_smallest_n(p):
    target = wavelength(p.frequency, p.relative_permittivity) / p.cells_per_wavelength
    try:
        mesh = build_mesh(p)
    except ValueError as exc:
        # refused only when the budget or the scheme's finest n cannot meet it
        message = str(exc)
        assert message.startswith("frequency=")
        needs = re.search(r"which needs subdivisions=(\d+); there: ", message)
        if needs:  # the geometry cannot be meshed at the n the target needs
            assert predicted(p, int(needs.group(1))) == math.inf
            return
        assert "triangles" in message
        top = 64 if p.scheme == "uniform" else 6
        finest = max(
            (n for n in range(1, top + 1) if predicted(p, n) <= p.max_triangles), default=0
        )
        if finest == 0:
            assert "coarsest" in message
        else:
            assert edge_lengths(build_mesh(unsized(p, finest))).max() > target
        return
    n = mesh.params.subdivisions
    assert mesh.stats()["subdivisions_chosen"] == n
    assert edge_lengths(mesh).max() <= target
    assert mesh.n_triangles <= p.max_triangles
    if n > 1:
        assert edge_lengths(build_mesh(unsized(p, n - 1))).max() > target
    s = mesh.stats()
    # the same figure in wavelengths (one more rounding: the division by λ)
    assert s["max_edge_wavelengths"] <= (1 + 1e-12) / p.cells_per_wavelength
    assert s["lambda_10_rule"] is bool(edge_lengths(mesh).max() <= s["wavelength"] / 10)


# -- files and the command line's --set ----------------------------------------------------------


def test_parameter_file_round_trip(tmp_path):
    p = MeshParams(
        **PATCH10, frequency=2.4e9, max_edge=7.5, cells_per_wavelength=12, relative_permittivity=4.4
    )
    path = tmp_path / "sized.json"
    save_params_file(p, path, "sized patch")
    data = json.loads(path.read_text())
    assert data["frequency"] == 2.4e9 and data["cells_per_wavelength"] == 12.0
    assert load_params_file(path) == p


def test_old_parameter_file_without_sizing_loads(tmp_path):
    path = tmp_path / "old.json"
    path.write_text(json.dumps({"structure": "patch", "patch_size": 10.0, "subdivisions": 4}))
    p = load_params_file(path)
    assert p.frequency is None and p.max_edge is None and not p.sized


def test_set_frequency_on_the_command_line_resolves():
    p = resolve_params("paper-fig10", None, ["frequency=10e9", "cells_per_wavelength=12"])
    assert p.frequency == 10e9 and p.cells_per_wavelength == 12.0
    with pytest.raises(ValueError, match=r"--set 'frequency=-3'.*frequency=-3"):
        resolve_params("paper-fig10", None, ["frequency=-3"])
    assert (
        resolve_params("paper-fig10", None, ["frequency=10e9", "frequency=null"]).frequency is None
    )
