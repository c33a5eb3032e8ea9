"""The path of a build: the modules build.py calls into, in the order its docstring lists."""

import re
import sys

import pytest

import barymesh.build
from barymesh import MeshParams, build_mesh

STEP = re.compile(r"^\d+\. :mod:`(barymesh\.\w+)`", re.MULTILINE)


def documented_steps():
    """The modules of the numbered list in build.py's module docstring."""
    return STEP.findall(barymesh.build.__doc__)


def modules_called(params):
    """The barymesh modules whose functions build.py calls, in call order, runs merged.

    Only calls made from build.py itself are recorded (what those functions call in
    turn is their module's business); subpackages count as their package.
    """
    seen = []
    build_file = barymesh.build.__file__

    def profile(frame, event, arg):
        if event != "call" or frame.f_back is None:
            return
        if frame.f_back.f_code.co_filename != build_file:
            return
        name = frame.f_globals.get("__name__", "")
        if not name.startswith("barymesh.") or name == "barymesh.build":
            return
        top = ".".join(name.split(".")[:2])
        if not seen or seen[-1] != top:
            seen.append(top)

    sys.setprofile(profile)
    try:
        mesh = build_mesh(params)
    finally:
        sys.setprofile(None)
    return mesh, seen


def test_the_docstring_lists_five_steps():
    assert documented_steps() == [
        "barymesh.params",
        "barymesh.structures",
        "barymesh.repeat",
        "barymesh.mesh",
        "barymesh.check",
    ]


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(),  # Fig. 12(a): paper mode, unwelded copies
        MeshParams(structure="patch", patch_size=10.0),
        MeshParams(structure="double_ring", mode="conforming"),  # chains of sectors
        MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.5),
    ],
)
def test_a_build_visits_each_module_once_in_the_documented_order(params):
    mesh, seen = modules_called(params)
    assert seen == documented_steps()
    assert mesh.repetition is not None and mesh.params is params


def test_a_single_triangle_takes_the_subdivision_instead_of_layout_and_record():
    mesh, seen = modules_called(MeshParams(structure="triangle"))
    steps = documented_steps()
    assert seen == [steps[0], "barymesh.subdivision", steps[3], steps[4]]
    assert mesh.repetition is None


def test_a_sized_build_repeats_steps_one_to_four_then_checks_once():
    mesh, seen = modules_called(MeshParams(structure="split_ring", mode="conforming", max_edge=0.2))
    first, *middle, last = documented_steps()
    assert seen[:2] == [first, "barymesh.sizing"] and seen[-1] == last
    tries, rest = divmod(len(seen) - 3, 4)  # the sizing tries at least one subdivision
    assert rest == 0 and tries >= 1
    assert seen[2:-1] == [first, *middle] * tries
