"""MeshParams: defaults, validation messages, JSON round trip, triangle budget."""

import json
import math

import pytest

from barymesh import MeshParams
from barymesh.params import MAX_BUDGET, STRUCTURES


def test_defaults_draw_fig12a():
    p = MeshParams()
    assert (p.structure, p.mode, p.inner_radius, p.outer_radius) == ("double_ring", "paper", 4, 9)
    assert (p.patch_size, p.angle_step, p.subdivisions, p.diagonal) == (1, 1, 4, "BC")
    assert (p.gap_width, p.gap_angle, p.origin, p.tolerance) == (1, 0, (0, 0), None)
    assert p.predicted_triangles() == 23_040
    assert math.isclose(p.weld_tolerance, 1e-9 * 2 * (9 + 1))


@pytest.mark.parametrize("structure", STRUCTURES)
def test_dict_round_trip_through_json(structure):
    p = MeshParams(structure=structure, mode="conforming", angle_step=10, origin=(1.5, -2))
    back = MeshParams.from_dict(json.loads(json.dumps(p.to_dict())))
    assert back == p


def test_triangle_vertices_round_trip():
    p = MeshParams(structure="triangle", triangle_vertices=((0, 0), (3, 0), (0, 4)))
    assert MeshParams.from_dict(json.loads(json.dumps(p.to_dict()))) == p


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"structure": "hexagon"}, "structure='hexagon' is unknown; expected one of patch"),
        ({"mode": "exact"}, "mode='exact' is unknown; expected one of paper, conforming"),
        ({"diagonal": "AC"}, "diagonal='AC' is unknown; expected one of BC, AD"),
        ({"scheme": "loop"}, "scheme='loop' is unknown"),
        ({"patch_size": 0}, "patch_size=0 is invalid; expected a finite length > 0 mm"),
        ({"patch_size": -1}, "patch_size=-1 is invalid"),
        ({"inner_radius": float("nan")}, "inner_radius=nan is invalid"),
        ({"outer_radius": float("inf")}, "outer_radius=inf is invalid"),
        ({"patch_size": "big"}, "patch_size='big' is not a number"),
        ({"gap_width": 0.0}, "gap_width=0.0 is invalid"),
        ({"patch_width": -2}, "patch_width=-2 is invalid"),
        ({"angle_step": 0}, "angle_step=0 is outside (0, 360] degrees"),
        ({"angle_step": 361}, "angle_step=361 is outside (0, 360] degrees"),
        ({"angle_step": -5}, "angle_step=-5 is outside (0, 360]"),
        ({"subdivisions": 0}, "subdivisions=0 is outside 1..64 for the uniform scheme"),
        ({"subdivisions": 65}, "subdivisions=65 is outside 1..64"),
        ({"subdivisions": 2.5}, "subdivisions=2.5 is not an integer"),
        ({"scheme": "barycentric", "subdivisions": 7}, "subdivisions=7 is outside 1..6"),
        ({"gap_angle": float("nan")}, "gap_angle=nan is invalid"),
        ({"origin": (1, 2, 3)}, "origin=(1, 2, 3) is invalid; expected two numbers"),
        ({"tolerance": -1e-3}, "tolerance=-0.001 is invalid"),
        ({"tolerance": 0.2}, "tolerance=0.2 mm is too large"),
        ({"max_triangles": 0}, "max_triangles=0 is invalid"),
        ({"outer_radius": 3.0}, "outer_radius=3.0 mm must be larger than inner_radius=4.0 mm"),
        (
            {"mode": "conforming", "outer_radius": 4.5},
            "outer_radius=4.5 mm makes the rings overlap in conforming mode; "
            "expected outer_radius >= inner_radius + patch_size = 5 mm",
        ),
        (
            {"structure": "split_ring", "gap_width": 8.0},
            "gap_width=8.0 mm is too wide for inner_radius=4.0 mm",
        ),
        (
            {"structure": "square_split_double_ring", "mode": "conforming", "gap_angle": 45},
            "gap_angle=45.0 is not supported for conforming square rings",
        ),
        (
            {"structure": "split_ring", "inner_radius": 1, "gap_width": 1.9, "gap_angle": 3},
            "gap_width=1.9 mm removes every patch of the split_ring",
        ),
        (
            {"structure": "square_split_double_ring", "mode": "conforming", "outer_radius": 5},
            "outer_radius=5.0 mm makes the square tracks touch",
        ),
        (
            {"structure": "triangle", "triangle_vertices": ((0, 0), (1, 1), (2, 2))},
            "are collinear",
        ),
        ({"structure": "triangle", "triangle_vertices": ((0, 0), (1, 1))}, "expected three"),
    ],
)
def test_invalid_values_are_named(changes, message):
    with pytest.raises(ValueError) as err:
        MeshParams(**changes)
    assert message in str(err.value)


def test_budget_refuses_before_building_and_names_the_count():
    with pytest.raises(
        ValueError,
        match=r"would make 5,760,000 triangles, above the budget "
        r"max_triangles=5,000,000",
    ):
        MeshParams(angle_step=0.1, subdivisions=20)  # 7200 patches * 800 = 5.76M
    p = MeshParams(angle_step=10, max_triangles=2304)
    assert p.predicted_triangles() == 2304
    with pytest.raises(ValueError, match="2,304 triangles, above the budget max_triangles=2,303"):
        MeshParams(angle_step=10, max_triangles=2303)


def test_the_budget_ends_where_int32_indices_do():
    # issue 30's seventh fuzz run: a budget of 10**400 let 320 million triangles through
    assert MAX_BUDGET == 715_827_882 == (2**31 - 1) // 3
    assert MeshParams(max_triangles=MAX_BUDGET).max_triangles == MAX_BUDGET
    with pytest.raises(ValueError, match=r"^max_triangles=715827883 is above 715,827,882, "):
        MeshParams(max_triangles=MAX_BUDGET + 1)


def test_from_dict_rejects_unknown_keys():
    with pytest.raises(ValueError, match="unknown parameter 'radius'"):
        MeshParams.from_dict({"radius": 3})


@pytest.mark.parametrize(
    ("key", "said"),
    [
        ("inner_radiu", "did you mean inner_radius or outer_radius?"),
        ("subdivision", "did you mean subdivisions?"),
        ("gap", "did you mean gap_angle or gap_width?"),
        ("colour", "expected one of 23 names (angle_step, cells_per_wavelength, diagonal, ...)"),
    ],
)
def test_an_unknown_parameter_gets_the_closest_names_not_all_23(key, said):
    # issue 30: "unknown parameter" messages ran to 330 characters, listing all 23 names
    with pytest.raises(ValueError) as err:
        MeshParams.from_dict({key: 3})
    assert str(err.value) == f"unknown parameter {key!r}; {said}"


def test_params_are_frozen():
    p = MeshParams()
    with pytest.raises(AttributeError):
        p.patch_size = 2.0  # type: ignore[misc]
    assert p.replace(patch_size=2.0).patch_size == 2.0


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"patch_size": -1}, "patch_size"),
        ({"structure": "hexagon"}, "structure"),
        ({"angle_step": 0}, "angle_step"),
        ({"subdivisions": 2.5}, "subdivisions"),
        ({"origin": (1, 2, 3)}, "origin"),
        ({"structure": "split_ring", "gap_width": 9}, "gap_width"),
        ({"tolerance": 0.5}, "tolerance"),
        ({"frequency": -1}, "frequency"),
        ({"grading": True, "scheme": "barycentric"}, "grading"),
        ({"outer_radius": 3}, "outer_radius"),
        (
            {"structure": "triangle", "triangle_vertices": [(0, 0), (1, 1), (2, 2)]},
            "triangle_vertices",
        ),
        ({"mode": "conforming", "structure": "ring", "angle_step": 1e-14}, "angle_step"),
    ],
)
def test_a_refused_value_carries_its_field_as_data(changes, field):
    """Presets and cell files point at the source of a bad value by ``exc.field``, not by
    reading the message; the message names the same field first."""
    from barymesh.values import InvalidValue

    with pytest.raises(InvalidValue) as err:
        MeshParams(**changes)
    assert err.value.field == field
    assert str(err.value).startswith(f"{field}=")
