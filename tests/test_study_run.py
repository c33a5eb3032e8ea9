"""Studies on a 2-worker Dask LocalCluster (process workers, as barymesh study starts them).

The serial reference runs on one of the workers: there, as in every task, BLAS has one
thread (Dask's nanny sets OPENBLAS_NUM_THREADS=1), so "equal" means equal to the last bit;
a serial run in the test process, with two BLAS threads, differs in the last bits.
"""

from __future__ import annotations

import os
import signal

import numpy as np
import pandas as pd
import pytest

distributed = pytest.importorskip("distributed")

from barymesh.study import Progress, parse_spec, read_result, run, run_serial  # noqa: E402
from barymesh.study.results import parts_folder  # noqa: E402

PATCH = {"structure": "patch", "patch_size": 15.0, "patch_width": 15.0, "subdivisions": 2}
#: 3 x 3 points x 11 frequencies
SPEC = {
    "base": {"params": PATCH},
    "axes": {"patch_size": [13.0, 14.0, 15.0], "patch_width": [10.0, 12.0, 14.0]},
    "sample": "product",
    "solve": {
        "kind": "free_space",
        "frequencies": "6GHz:12GHz:11",
        "direction": [0, 0, -1],
        "polarization": [1, 0, 0],
    },
    "derive": [
        "resonance_frequency",
        "quality_factor",
        "bandwidth_3db",
        {"extinction_cross_section_at": ["9GHz"]},
    ],
}


@pytest.fixture(scope="module")
def client():
    with (
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


@pytest.fixture(scope="module")
def reference(client):
    """The serial loop's result, run on a worker (one BLAS thread, as the tasks)."""
    return client.submit(run_serial, parse_spec(SPEC), pure=False).result()


def assert_same(a, b):
    pd.testing.assert_frame_equal(a.table, b.table, check_exact=True)
    pd.testing.assert_frame_equal(a.derived, b.derived, check_exact=True)


def test_a_3x3x11_study_equals_the_serial_run_exactly(client, reference, tmp_path):
    out = tmp_path / "study.parquet"
    seen = []
    result = run(parse_spec(SPEC), client, output=out, progress=seen.append)
    assert_same(result, reference)
    assert len(result.derived) == 9 and len(result.table) == 9 * 11
    assert (result.derived.status == "ok").all()
    assert result.computed == 9 and result.meta["resumed"] == 0
    # progress: from 0 to 9 points, one call per finished point
    assert [p.done for p in seen] == list(range(10)) and seen[-1].eta == 0.0
    assert all(isinstance(p, Progress) and p.total == 9 for p in seen)
    # the resonance moves down as the patch grows along E (x: patch_size)
    f0 = result.derived.set_index(["patch_size", "patch_width"])["resonance_frequency_hz"]
    for width in (10.0, 12.0, 14.0):
        assert f0.xs(width, level="patch_width").is_monotonic_decreasing
    assert len(list(parts_folder(result.spec, out).glob("point-*.parquet"))) == 9


def test_the_parquet_files_round_trip_and_the_xarray_has_the_axes(client, reference, tmp_path):
    out = tmp_path / "s.parquet"
    result = run(parse_spec(SPEC), client, output=out)
    back = read_result(out)
    assert_same(back, result)
    assert (tmp_path / "s.derived.parquet").exists() and (tmp_path / "s.meta.json").exists()
    assert back.meta["digest"] == result.spec.digest()
    assert {"dask", "distributed", "pyarrow", "xarray"} <= set(back.meta["versions"])
    assert back.meta["machine"]["cpu_count"] == os.cpu_count()
    ds = back.to_xarray()
    assert ds["extinction_cross_section_m2"].dims == ("patch_size", "patch_width", "frequency_hz")
    assert ds["resonance_frequency_hz"].dims == ("patch_size", "patch_width")
    assert list(ds["patch_size"].values) == [13.0, 14.0, 15.0]
    assert list(ds["patch_width"].values) == [10.0, 12.0, 14.0]
    np.testing.assert_array_equal(ds["frequency_hz"].values, np.linspace(6e9, 12e9, 11))
    # a cell of the Dataset is the row of the table
    row = reference.table[
        (reference.table.patch_size == 14.0) & (reference.table.patch_width == 10.0)
    ]
    np.testing.assert_array_equal(
        ds["extinction_cross_section_m2"].sel(patch_size=14.0, patch_width=10.0).values,
        row["extinction_cross_section_m2"].to_numpy(),
    )


def test_a_rerun_after_an_interruption_solves_only_the_missing_points(client, reference, tmp_path):
    out = tmp_path / "r.parquet"

    def stop_after_four(p):
        if p.done == 4:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run(parse_spec(SPEC), client, output=out, progress=stop_after_four)
    folder = parts_folder(parse_spec(SPEC), out)
    kept = {p.name: p.stat().st_mtime_ns for p in folder.glob("point-*.parquet")}
    assert len(kept) == 4 and not out.exists()
    result = run(parse_spec(SPEC), client, output=out)
    assert result.computed == 5 and result.meta["resumed"] == 4
    assert_same(result, reference)
    # the four finished points were read back, not solved and written again
    assert {name: (folder / name).stat().st_mtime_ns for name in kept} == kept
    # a third run solves nothing
    assert run(parse_spec(SPEC), client, output=out).computed == 0


def test_a_worker_that_dies_mid_study_has_its_tasks_rerun(client, reference, tmp_path):
    spec = parse_spec({**SPEC, "base": {"params": {**PATCH, "subdivisions": 5}}})
    expected = client.submit(run_serial, spec, pure=False).result()
    pids = client.run(os.getpid)
    victim = sorted(pids)[0]
    killed = []

    def kill_once(p):  # SIGKILL: the worker process dies mid-study, with tasks on it
        if p.done == 2 and not killed:
            killed.append(victim)
            os.kill(pids[victim], signal.SIGKILL)

    result = run(spec, client, output=tmp_path / "k.parquet", progress=kill_once)
    assert killed
    assert_same(result, expected)
    assert (result.derived.status == "ok").all() and result.computed == 9
    client.wait_for_workers(2, timeout=60)
    assert victim not in set(client.scheduler_info()["workers"])  # the nanny started another


def test_bad_points_are_error_rows_and_the_study_goes_on(client, tmp_path):
    spec = parse_spec(
        {
            **SPEC,
            "axes": {"patch_size": [14.0, -1.0], "subdivisions": [2, 40]},
            "solve": {**SPEC["solve"], "memory_limit": 2**27},
        }
    )
    result = run(spec, client, output=tmp_path / "b.csv")
    status = result.derived.set_index(["patch_size", "subdivisions"])["status"]
    assert status[(14.0, 2)] == "ok"
    assert status[(-1.0, 2)].startswith("patch_size=-1.0 is invalid")
    assert status[(-1.0, 40)].startswith("patch_size=-1.0 is invalid")
    # 40 x 40 x 2 triangles: up to 4,800 unknowns, 0.8 GB, refused before submission
    assert "need" in status[(14.0, 40)] and "0.125 GB" in status[(14.0, 40)]
    assert result.computed == 1 and result.meta["refused"] == 3
    assert sorted(set(result.table.index)) == [0]
    assert result.derived.loc[result.derived.status != "ok", "quality_factor"].isna().all()
    back = read_result(tmp_path / "b.csv")
    pd.testing.assert_frame_equal(back.derived, result.derived, check_exact=True)


def test_a_study_runs_on_a_scheduler_by_address_or_from_the_dask_config(client, reference):
    import dask

    address = client.scheduler.address
    assert address.startswith("tcp://127.0.0.1:")
    by_address = run(parse_spec(SPEC), scheduler=address)
    assert_same(by_address, reference)
    assert by_address.meta["workers"] == 2  # the fixture's two workers, no new cluster
    with dask.config.set({"scheduler-address": address}):
        from_config = run(parse_spec(SPEC))
    assert_same(from_config, reference)
    assert from_config.meta["workers"] == 2
    with pytest.raises(ValueError, match="workers= sizes a local cluster"):
        run(parse_spec(SPEC), scheduler=address, workers=2)


def test_the_meta_records_the_workers_that_solved_the_points(tmp_path):
    """Not the scheduler's count at the end: a worker that leaves mid-study still counts."""
    import json

    with (
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        retired = []

        def retire_the_busiest(p):  # after 4 points, the worker holding most results leaves
            if p.done == 4 and not retired:
                held = c.run(lambda dask_worker: len(dask_worker.data))
                busiest = max(held, key=held.get)
                assert held[busiest] >= 3  # the shared context and 2 of the 4 points at least
                retired.append(busiest)
                c.retire_workers([busiest], close_workers=True)

        out = tmp_path / "w.parquet"
        result = run(parse_spec(SPEC), c, output=out, progress=retire_the_busiest)
        remaining = set(c.scheduler_info()["workers"])
    meta = json.loads((tmp_path / "w.meta.json").read_text())
    assert retired and retired[0] not in remaining
    assert result.computed == 9 and (result.derived.status == "ok").all()
    assert meta["workers_at_start"] == 2 and meta["workers_at_end"] == len(remaining)
    assert retired[0] in meta["worker_points"] and meta["worker_points"][retired[0]] >= 2
    assert meta["workers"] == len(meta["worker_points"]) >= 2
    assert sum(meta["worker_points"].values()) == 9
    assert set(meta["worker_points"]) <= {retired[0], *remaining}
