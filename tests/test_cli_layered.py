"""``barymesh solve --periodic --stack``: a sheet on layers from the command line, in-process.

Checked against physics: a PEC patch over a lossless grounded substrate reflects all the
power (|S| unitary, a 2-port with no transmission); the open stack's 4-port from two
sweeps is reciprocal (S = Sᵀ for these power waves) and lossless (SᴴS = 1) below the
first onset; the reference planes printed are the stack's faces.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from barymesh.app import cli
from barymesh.cell import Lattice, PixelGrid, UnitCell, save_cell
from barymesh.mom import Layer, Stack

P = 10.0  # mm


@pytest.fixture(scope="module")
def cell_file(tmp_path_factory):
    """A 5 mm square patch of 10 x 10 pixels (subdivision 1) on a 10 mm lattice."""
    mask = np.zeros((20, 20), dtype=bool)
    mask[5:15, 5:15] = True
    pixels = PixelGrid(mask, pixel_size=P / 20, origin=(-P / 2, -P / 2), subdivisions=1)
    cell = UnitCell(Lattice.rectangular(P), pixels=pixels, mode="conforming", name="patch")
    path = tmp_path_factory.mktemp("cells") / "patch.cell.json"
    save_cell(cell, path)
    return str(path)


def run(capsys, *args):
    code = cli.main(["solve", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_grounded_stack_writes_a_lossless_two_port(cell_file, capsys, tmp_path):
    import skrf

    out_file = tmp_path / "his.s2p"
    code, out, err = run(
        capsys,
        "--cell", cell_file, "--periodic", "--freq", "8GHz:12GHz:5", "--theta", "20",
        "--stack", "1.575mm eps=2.2; ground", "-o", out_file,
    )  # fmt: skip
    assert code == 0, err
    assert "stack: 1.575mm eps=2.2; ground" in out
    assert re.search(r"R at the stack's top face, z = 0 mm over the sheet; T = 0", out)
    network = skrf.Network(str(out_file))
    assert network.s.shape == (5, 2, 2)
    unitary = np.einsum("fji,fjk->fik", network.s.conj(), network.s)
    np.testing.assert_allclose(unitary, np.broadcast_to(np.eye(2), unitary.shape), atol=2e-3)
    text = out_file.read_text()
    assert "! Reference planes: ports 1, 2 at the stack's top face, z = 0 mm" in text
    assert "sheet; 1.575mm eps=2.2; ground" in text


def test_an_open_stack_writes_a_reciprocal_lossless_four_port(cell_file, capsys, tmp_path):
    import skrf

    stack = tmp_path / "stack.json"
    stack.write_text(
        json.dumps(Stack(above=(Layer(0.5, 3.0),), below=(Layer(1.0, 2.2),)).to_dict())
    )
    out_file = tmp_path / "rt.s4p"
    code, out, err = run(
        capsys,
        "--cell", cell_file, "--periodic", "--freq", "9GHz", "--theta", "25", "--phi", "10",
        "--stack", stack, "-o", out_file,
    )  # fmt: skip
    assert code == 0, err
    assert "z = 0.5 mm over the sheet; T at its bottom face, z = -1 mm" in out
    s = skrf.Network(str(out_file)).s[0]
    np.testing.assert_allclose(s, s.T, atol=2e-3)  # reciprocity
    np.testing.assert_allclose(s.conj().T @ s, np.eye(4), atol=2e-3)  # no loss, one order
    text = out_file.read_text()
    assert "ports 3, 4 at its bottom face, z = -1 mm" in text


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--stack", "1.5 eps=2"), "--stack: stack '1.5 eps=2': layer '1.5 eps=2' must start"),
        (("--stack", "1mm eps=-2"), "--stack: Layer.eps_r=-2.0 is invalid"),
        (
            ("--stack", "1mm eps=2; ground", "-o", "x.s4p"),
            "over a ground plane the array has one side",
        ),
        (("--stack", "1mm eps=2", "-o", "x.s2p"), "a 2-port is for a sheet over a ground plane"),
        (("--stack", "missing.json"), "--stack missing.json: cannot read it"),
    ],
)
def test_bad_stacks_are_named(cell_file, capsys, args, message):
    code, _, err = run(capsys, "--cell", cell_file, "--periodic", "--freq", "9GHz", *args)
    assert code == 2
    assert message in err


def test_stack_needs_periodic(cell_file, capsys):
    code, _, err = run(capsys, "--cell", cell_file, "--freq", "9GHz", "--stack", "1mm eps=2")
    assert code == 2 and "--stack applies to --periodic" in err


def test_circuit_prints_the_fitted_lc_of_the_sheet(cell_file, capsys):
    """--circuit prints the series LC of the patches, whose values are those of the API's fit."""
    from barymesh.cell import build_cell, load_cell
    from barymesh.mom import periodic_sweep

    code, out, err = run(
        capsys,
        "--cell", cell_file, "--periodic", "--freq", "6GHz:14GHz:17", "--mesh-as-given",
        "--stack", "1.575mm eps=2.2; ground", "--circuit",
    )  # fmt: skip
    assert code == 0, err
    line = re.search(r"equivalent circuit: series LC: L = ([\d.]+) nH, C = ([\d.]+) fF", out)
    assert line, out
    mesh = build_cell(load_cell(cell_file)).mesh
    stack = Stack(below=(Layer(1.575, 2.2),), ground=True)
    fit = periodic_sweep(
        mesh, np.linspace(6e9, 14e9, 17), stack=stack, polarizations="incident"
    ).equivalent_circuit()
    assert float(line.group(1)) == pytest.approx(fit.inductance * 1e9, rel=1e-3)
    assert float(line.group(2)) == pytest.approx(fit.capacitance * 1e15, rel=1e-3)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--freq", "10GHz"], "--freq A:B:K with K >= 3"),
        (["--freq", "6GHz:14GHz:5", "--no-periodic"], "--circuit applies to --periodic"),
    ],
)
def test_circuit_needs_a_periodic_sweep(cell_file, capsys, extra, message):
    args = ["--cell", cell_file, "--circuit", *extra]
    if "--no-periodic" in args:
        args.remove("--no-periodic")
    else:
        args.append("--periodic")
    code, _, err = run(capsys, *args)
    assert code == 2 and message in err
