"""Atomic writes: a failed export leaves no partial file and keeps the existing one."""

import functools
import os

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.io import ExportError, atomic_write_text, export, meshio_formats, write_mesh


@functools.cache
def patch_mesh():
    """The 10 mm patch (built on first use, not at import)."""
    return build_mesh(MeshParams(structure="patch", patch_size=10.0))


def leftovers(folder):
    return sorted(p.name for p in folder.iterdir() if ".tmp" in p.name)


def test_parent_is_a_file(tmp_path):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("x")
    target = blocker / "mesh.msh"
    with pytest.raises(ExportError) as info:
        write_mesh(patch_mesh(), target)
    assert str(target) in str(info.value) and "is not a folder" in str(info.value)
    assert blocker.read_text() == "x"


def test_missing_folder(tmp_path):
    target = tmp_path / "missing" / "mesh.stl"
    with pytest.raises(ExportError, match="does not exist"):
        write_mesh(patch_mesh(), target)
    assert not target.parent.exists()


@pytest.mark.parametrize("ext", [".msh", ".vtu", ".stl", ".obj"])
def test_failure_mid_write_keeps_existing_file(tmp_path, monkeypatch, ext):
    target = tmp_path / f"mesh{ext}"
    target.write_bytes(b"the old file")

    def half_then_fail(mesh, path, ext, factor, wavelength=None, msh_version="2.2"):
        path.write_bytes(b"half a mesh")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(export, "write_meshio", half_then_fail)
    with pytest.raises(ExportError) as info:
        write_mesh(patch_mesh(), target)
    assert str(target) in str(info.value) and "No space left on device" in str(info.value)
    assert target.read_bytes() == b"the old file"
    assert leftovers(tmp_path) == []


def test_failure_without_existing_file_leaves_nothing(tmp_path, monkeypatch):
    def fail(mesh, path, ext, factor, wavelength=None, msh_version="2.2"):
        path.write_bytes(b"partial")
        raise ValueError("the writer broke")

    monkeypatch.setattr(export, "write_meshio", fail)
    with pytest.raises(ExportError, match="the writer broke"):
        write_mesh(patch_mesh(), tmp_path / "new.msh")
    assert list(tmp_path.iterdir()) == []


def test_interrupt_mid_write(tmp_path, monkeypatch):
    target = tmp_path / "mesh.mat"
    target.write_bytes(b"old")

    def interrupted(mesh, path, factor):
        path.write_bytes(b"par")
        raise KeyboardInterrupt

    monkeypatch.setattr(export, "write_makarov", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_mesh(patch_mesh(), target)
    assert target.read_bytes() == b"old"
    assert leftovers(tmp_path) == []


def test_real_writer_failure(tmp_path, monkeypatch):
    """meshio itself failing half way (here: on a bad value) leaves no file behind."""
    target = tmp_path / "mesh.vtu"

    def broken(mesh, ext, factor):
        m = real(mesh, ext, factor)
        m.cell_data["bad"] = [np.array(["x"] * mesh.n_triangles, dtype=object)]
        return m

    real = meshio_formats.to_meshio
    monkeypatch.setattr(meshio_formats, "to_meshio", broken)
    with pytest.raises(ExportError, match=str(target)):
        write_mesh(patch_mesh(), target)
    assert list(tmp_path.iterdir()) == []


def test_success_replaces_and_keeps_permissions(tmp_path):
    target = tmp_path / "mesh.obj"
    target.write_text("old")
    os.chmod(target, 0o640)
    write_mesh(patch_mesh(), target)
    assert target.read_text().lstrip().startswith(("#", "v"))
    assert target.stat().st_mode & 0o777 == 0o640
    assert leftovers(tmp_path) == []


def test_new_file_gets_umask_permissions(tmp_path):
    umask = os.umask(0o022)
    try:
        write_mesh(patch_mesh(), tmp_path / "m.stl")
    finally:
        os.umask(umask)
    assert (tmp_path / "m.stl").stat().st_mode & 0o777 == 0o644


def test_text_helper(tmp_path):
    atomic_write_text(tmp_path / "a.json", "{}\n")
    assert (tmp_path / "a.json").read_text() == "{}\n"


def test_csv_companions_are_atomic(tmp_path, monkeypatch):
    from barymesh.io import rwg

    target = tmp_path / "rwg.csv"
    write_mesh(patch_mesh(), target)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert set(before) == {"rwg.csv", "rwg_connectivity.csv", "rwg_centroids.csv"}

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(rwg, "csv_tables", fail)
    with pytest.raises(OSError):
        write_mesh(build_mesh(MeshParams(structure="patch", subdivisions=2)), target)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_csv_set_is_replaced_only_when_every_file_is_written(tmp_path, monkeypatch):
    """Issue 10 #13: the centroids file failing keeps all three old files."""
    from barymesh.io import rwg

    target = tmp_path / "rwg.csv"
    write_mesh(patch_mesh(), target)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real = rwg.csv_tables

    def centroids_fail(*args, **kwargs):
        tables = real(*args, **kwargs)
        tables["_centroids"] = None  # writing it raises, after the other two were written
        return tables

    monkeypatch.setattr(rwg, "csv_tables", centroids_fail)
    with pytest.raises(ExportError, match="rwg.csv"):
        write_mesh(build_mesh(MeshParams(structure="patch", subdivisions=2)), target)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_writing_through_a_symlink_writes_its_target(tmp_path):
    real = tmp_path / "store" / "mesh.stl"
    real.parent.mkdir()
    real.write_text("old")
    link = tmp_path / "mesh.stl"
    link.symlink_to(real)
    write_mesh(patch_mesh(), link)
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_text().startswith("solid")
    assert leftovers(tmp_path) == [] and leftovers(real.parent) == []


def test_stale_temp_files_of_dead_exports_are_removed(tmp_path):
    import subprocess
    import sys

    from barymesh.io.atomic import TEMP_MARK

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    live = os.getppid()
    stale = tmp_path / f".mesh.msh{TEMP_MARK}{dead.pid}-abc.tmp.msh"
    busy = tmp_path / f".mesh.msh{TEMP_MARK}{live}-def.tmp.msh"
    other_target = tmp_path / f".other.msh{TEMP_MARK}{dead.pid}-ghi.tmp.msh"
    not_ours = tmp_path / ".mesh.msh.xyz.tmp.msh"
    for path in (stale, busy, other_target, not_ours):
        path.write_bytes(b"half")
        os.utime(path, (1e9, 1e9))  # 2001: older than this process
    write_mesh(patch_mesh(), tmp_path / "mesh.msh")
    assert leftovers(tmp_path) == sorted(p.name for p in (busy, other_target, not_ours))


# The child takes SIGINT as an interactive Python does even when the test run itself was
# started with SIGINT ignored (a shell's background job inherits SIG_IGN, and Python then
# installs no handler), and it "writes" until a signal ends it: the test waits for the
# signal's effect, never for a sleep to run out.
CHILD = """
import signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)
from barymesh import MeshParams, build_mesh
from barymesh.io import export, write_mesh

def slow(mesh, path, ext, factor, wavelength=None, msh_version="2.2"):
    path.write_bytes(b"half a mesh")
    print("writing", flush=True)
    while True:
        time.sleep(1)

export.write_meshio = slow
write_mesh(build_mesh(MeshParams(structure="patch")), sys.argv[1])
"""


@pytest.mark.parametrize("how", ["SIGTERM", "SIGINT", "SIGKILL"])
def test_killed_mid_write(tmp_path, how):
    """A process killed while writing: the target stays, no temp file outlives the next write."""
    import signal
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    target = tmp_path / "mesh.msh"
    target.write_bytes(b"the old file")
    env = dict(os.environ, PYTHONPATH=str(root))
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(target)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert child.stdout.readline() == "writing\n"
    assert len(leftovers(tmp_path)) == 1
    child.send_signal(getattr(signal, how))
    code = child.wait(timeout=600)  # a bound for a hung child, not a speed test
    child.stdout.close()
    child.stderr.close()
    assert target.read_bytes() == b"the old file"
    if how == "SIGKILL":
        assert code == -signal.SIGKILL and len(leftovers(tmp_path)) == 1  # nothing can run
        os.utime(tmp_path / leftovers(tmp_path)[0], (1e9, 1e9))
        write_mesh(patch_mesh(), target)  # the next export removes what the killed one left
    else:  # the temp file was removed as the process ended (SIGTERM: exit 143 like the default)
        assert code == (143 if how == "SIGTERM" else -signal.SIGINT)
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("suffix", [".msh", ".stl", ".vtp", ".mat", ".npz", ".csv"])
@pytest.mark.parametrize("when", [1, 2])
def test_cancelled_write_leaves_no_file(tmp_path, suffix, when):
    """Cancel asked before the write (when = 1) or once it is written (when = 2): no
    target and no temporary file; an existing file stays as it was."""
    from barymesh.io import ExportCancelled

    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0))
    asked = []

    def cancelled():
        asked.append(True)
        return len(asked) >= when

    with pytest.raises(ExportCancelled, match="cancelled"):
        write_mesh(mesh, tmp_path / f"a{suffix}", cancelled=cancelled)
    assert len(asked) == when
    assert list(tmp_path.iterdir()) == []
    kept = tmp_path / f"b{suffix}"
    kept.write_text("old")
    with pytest.raises(ExportCancelled):
        write_mesh(mesh, kept, cancelled=lambda: True)
    assert kept.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == [kept.name]
