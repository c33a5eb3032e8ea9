"""Presets: every one loads and builds with the expected counts; files and --set combine."""

import json

import pytest

from barymesh import MeshParams, build_mesh
from barymesh.presets import (
    PRESET_DIR,
    load_params_file,
    load_preset,
    parse_assignment,
    preset_names,
    resolve_params,
    save_params_file,
)

REQUIRED = {
    "paper-fig10",
    "paper-fig11-12mm",
    "paper-fig11-8mm",
    "paper-fig11-4mm",
    "paper-fig12a",
    "paper-fig12b",
    "paper-fig12c",
    "paper-fig12d",
    "paper-fig8-dsdr",
    "paper-fig9-square-dsdr",
    "makarov-plate",
    "makarov-platefine",
    "srr-openmodes",
}

#: Triangle counts: 32 per patch; Fig. 12 has 2 rings x 360/Δθ patches.
EXPECTED_TRIANGLES = {
    "paper-fig10": 32,
    "paper-fig11-12mm": 32,
    "paper-fig11-8mm": 32,
    "paper-fig11-4mm": 32,
    "paper-fig12a": 2 * 360 * 32,  # 23040
    "paper-fig12b": 2 * 360 * 32,
    "paper-fig12c": 2 * 36 * 32,
    "paper-fig12d": 2 * 18 * 32,
    "makarov-plate": 128,
    "makarov-platefine": 512,
}


def test_required_presets_exist():
    assert REQUIRED <= set(preset_names())
    assert preset_names() == sorted(preset_names())


@pytest.mark.parametrize("name", preset_names())
def test_preset_loads_and_builds(name):
    params, description = load_preset(name)
    assert isinstance(params, MeshParams)
    assert description and "\n" not in description and len(description) < 200
    mesh = build_mesh(params)
    assert mesh.n_triangles == params.predicted_triangles() > 0
    if name in EXPECTED_TRIANGLES:
        assert mesh.n_triangles == EXPECTED_TRIANGLES[name]
    if params.mode == "conforming":
        assert mesh.stats()["junction_edges"] == 0


@pytest.mark.parametrize("name", preset_names())
def test_preset_file_holds_only_known_keys(name):
    data = json.loads((PRESET_DIR / f"{name}.json").read_text())
    assert set(data) - {"description"} <= set(MeshParams().to_dict())


@pytest.mark.parametrize(
    ("name", "size"),
    [
        ("paper-fig11-12mm", 12.0),
        ("paper-fig11-8mm", 8.0),
        ("paper-fig11-4mm", 4.0),
        ("paper-fig10", 10.0),
    ],
)
def test_square_patch_presets(name, size):
    params, _ = load_preset(name)
    assert (params.structure, params.patch_size, params.subdivisions) == ("patch", size, 4)
    assert build_mesh(params).stats()["area"] == pytest.approx(size * size)


@pytest.mark.parametrize(
    ("name", "patch", "step"),
    [
        ("paper-fig12a", 1, 1),
        ("paper-fig12b", 2, 1),
        ("paper-fig12c", 2, 10),
        ("paper-fig12d", 1, 20),
    ],
)
def test_fig12_presets(name, patch, step):
    p, _ = load_preset(name)
    assert (p.structure, p.mode, p.inner_radius, p.outer_radius) == ("double_ring", "paper", 4, 9)
    assert (p.patch_size, p.angle_step) == (patch, step)


def test_makarov_and_srr_presets():
    plate, _ = load_preset("makarov-plate")
    fine, _ = load_preset("makarov-platefine")
    for p, n in ((plate, 8), (fine, 16)):
        assert (p.structure, p.patch_size, p.origin, p.diagonal) == (
            "patch",
            1000.0,
            (-500.0, -500.0),
            "AD",
        )
        assert p.subdivisions == n
    srr, _ = load_preset("srr-openmodes")
    assert (srr.structure, srr.mode, srr.inner_radius, srr.patch_size, srr.outer_radius) == (
        "split_ring",
        "conforming",
        3.5,
        0.5,
        4.0,
    )
    assert (srr.gap_width, srr.gap_angle) == (1.0, 180.0)
    mesh = build_mesh(srr)
    assert mesh.stats()["euler_characteristic"] == 1  # one ring cut once: a disc topologically


def test_unknown_preset():
    with pytest.raises(ValueError, match="unknown preset 'nope'; expected one of .*paper-fig10"):
        load_preset("nope")


def test_params_file_round_trip(tmp_path):
    params = MeshParams(structure="split_ring", mode="conforming", origin=(1.0, 2.0))
    path = tmp_path / "mine.json"
    save_params_file(params, path, description="my ring")
    assert json.loads(path.read_text())["description"] == "my ring"
    assert load_params_file(path) == params


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ('{"structure": "patch", "colour": 3}', "unknown parameter 'colour'"),
        ('{"subdivisions": 0}', "subdivisions=0 is outside 1..64"),
        ('{"structure": "hexagon"}', "structure='hexagon' is unknown"),
        ('{"structure": "patch",', "invalid JSON at line 1"),
        ("[1, 2]", "expected a JSON object"),
        ('{"description": 5}', "description=5 is not a string"),
    ],
)
def test_bad_params_file_names_file_and_key(tmp_path, content, message):
    path = tmp_path / "bad.json"
    path.write_text(content)
    with pytest.raises(ValueError) as info:
        load_params_file(path)
    assert str(path) in str(info.value) and message in str(info.value)


def test_missing_params_file(tmp_path):
    with pytest.raises(ValueError, match="no such parameter file"):
        load_params_file(tmp_path / "none.json")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("subdivisions=8", ("subdivisions", 8)),
        ("origin=[1,2]", ("origin", [1, 2])),
        ("mode=conforming", ("mode", "conforming")),
        ('mode="paper"', ("mode", "paper")),
        ("tolerance=null", ("tolerance", None)),
        (" angle_step = 2.5 ", ("angle_step", 2.5)),
    ],
)
def test_parse_assignment(text, expected):
    assert parse_assignment(text) == expected


@pytest.mark.parametrize("text", ["subdivisions", "=3", ""])
def test_parse_assignment_rejects(text):
    with pytest.raises(ValueError, match="expected name=value"):
        parse_assignment(text)


def test_later_sources_win(tmp_path):
    path = tmp_path / "p.json"
    path.write_text('{"patch_size": 3.0, "subdivisions": 2}')
    p = resolve_params("paper-fig10", path, ["subdivisions=5", "subdivisions=6"])
    assert (p.structure, p.patch_size, p.subdivisions) == ("patch", 3.0, 6)
    assert resolve_params(None, None, []) == MeshParams()
    assert resolve_params("paper-fig10", None, []) == load_preset("paper-fig10")[0]


def test_intermediate_combinations_need_not_be_valid():
    # inner 10 > outer 9 alone, fixed by the next setting
    p = resolve_params("paper-fig12d", None, ["inner_radius=10", "outer_radius=12"])
    assert (p.inner_radius, p.outer_radius) == (10, 12)


def test_resolve_errors_name_their_source(tmp_path):
    with pytest.raises(ValueError, match=r"--set 'subdivisions=0': subdivisions=0"):
        resolve_params("paper-fig10", None, ["subdivisions=0"])
    with pytest.raises(ValueError, match=r"--set 'colour=1': unknown parameter 'colour'"):
        resolve_params(None, None, ["colour=1"])
    path = tmp_path / "p.json"
    path.write_text('{"angle_step": -1}')
    with pytest.raises(ValueError, match=rf"{path}: angle_step=-1"):
        resolve_params("paper-fig12a", path, ["subdivisions=2"])
