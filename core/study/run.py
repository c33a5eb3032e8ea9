"""Running a study on Dask (``distributed``), or serially, resumably.

:func:`run` submits one task per point (build the mesh, solve with
:func:`barymesh.mom.sweep`, derive) to a Dask cluster: a ``LocalCluster`` over this
machine's cores by default, the scheduler at ``scheduler=`` (``tcp://host:8786``), the
``scheduler-address`` of the user's Dask configuration, or any ``client=`` (dask-jobqueue,
dask-kubernetes). What every task shares (the base design, the solve settings) is
scattered to the workers once. Each point that finishes is written at once as a part file
(:func:`barymesh.study.results.write_part`); a rerun of the same spec reads them back and
solves only the missing points, so Ctrl-C loses nothing that was finished. A worker that
dies has its tasks rerun elsewhere (Dask's own rescheduling, and ``retries=``).

Why processes: a point spends a third to a half of its time in Python and numpy code that
holds the GIL (mesh building, the geometry, the far field), so two threads on two cores ran
a 64-point study 1.2 times faster than one, and two processes 1.9 times (see
``benchmarks/study.py`` and ``benchmarks/results/study-2026-12-02.json``). Worker
processes get one BLAS thread each (Dask's nanny sets ``OMP_NUM_THREADS=1`` and the like).
"""

from __future__ import annotations

import contextlib
import logging
import os
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..mom.periodic_checks import periodic_memory_needed
from ..mom.solve import ProblemTooLarge, memory_needed
from .point import (
    PointResult,
    StudyContext,
    design,
    error_point,
    one_line,
    predicted_unknowns,
    solve_columns,
)
from .point import solve_point as _solve_point
from .results import (
    StudyResult,
    machine,
    parts_folder,
    read_parts,
    tables,
    versions,
    write_part,
)
from .spec import StudySpec, load_spec

log = logging.getLogger(__name__)

MALLOC_TRIM = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"
#: glibc's trim threshold (bytes) in the workers of a local cluster: freed memory above it
#: goes back to the system.
WORKER_TRIM_THRESHOLD = 1 << 30

#: Retries of a task whose worker died (on top of Dask's own rescheduling).
RETRIES = 2


@dataclass(frozen=True)
class Progress:
    """Where a running study is: points finished (ok and failed) out of all, and the time.

    ``eta`` is the seconds left at the rate of the points this run solved (NaN before
    the first); ``dashboard`` is the Dask dashboard's address (or "").
    """

    done: int
    failed: int
    total: int
    elapsed: float
    eta: float
    dashboard: str = ""


def solve_point(context: StudyContext, index: int, values: dict[str, Any]) -> PointResult:
    """The Dask task of one point: :func:`barymesh.study.point.solve_point` within the
    running worker's memory limit."""
    limit = None
    try:
        from distributed import get_worker

        limit = get_worker().memory_manager.memory_limit or None
    except (ImportError, ValueError, AttributeError):
        pass
    return _solve_point(context, index, values, limit)


def _refusal(
    context: StudyContext, index: int, values: dict[str, Any], limit: float | None
) -> PointResult | None:
    """The error row of a point refused before submission (bad parameters, too large)."""
    try:
        item = design(context, values)
    except (ValueError, TypeError) as exc:
        return error_point(context, index, values, one_line(exc))
    limits = [v for v in (limit, context.solve.memory_limit) if v]
    if limits:
        n = predicted_unknowns(item)
        if context.solve.kind == "free_space":
            need, what = memory_needed(n), f"up to N = {n:,} unknowns"
        else:  # the infinite array: its geometry's T² tables too
            t = int(item.predicted_triangles())
            need = periodic_memory_needed(t, n)
            what = f"up to T = {t:,} triangles and N = {n:,} unknowns of an infinite array"
        if need > min(limits):
            text = (
                f"{what} need {need / 2**30:.3g} GB at the peak of a solve, "
                f"more than a worker's {min(limits) / 2**30:.3g} GB; use a coarser mesh"
            )
            return error_point(context, index, values, one_line(ProblemTooLarge(text)))
    return None


class _Collector:
    """Finished points of one study: read back from parts, written as they come."""

    def __init__(self, spec: StudySpec, output: str | Path | None, resume: bool, progress):
        self.spec = spec
        self.output = output
        self.folder = parts_folder(spec, output) if output is not None else None
        if self.folder is not None:  # before any cluster starts: one clear error, no Dask log
            try:
                self.folder.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise OSError(
                    f"cannot write the study to {output}: its parts folder {self.folder} cannot "
                    f"be made ({exc.strerror or exc})"
                ) from None
        self.points = spec.points()
        self.finished: dict[int, PointResult] = {}
        if self.folder is not None and resume:
            self.finished = {
                i: p
                for i, p in read_parts(self.folder, solve_columns(spec.solve.kind)).items()
                if i < len(self.points)
            }
        self.resumed = len(self.finished)
        self.computed = 0
        self.refused = 0
        self.lost = 0
        self.progress = progress
        self.start = time.monotonic()
        self.dashboard = ""

    @property
    def todo(self) -> list[int]:
        return [i for i in range(len(self.points)) if i not in self.finished]

    def add(self, point: PointResult, computed: bool = True) -> None:
        self.finished[point.index] = point
        if self.folder is not None:
            write_part(self.folder, point)
        self.computed += computed
        self.refused += not computed
        self.report()

    def report(self) -> None:
        if self.progress is None:
            return
        elapsed = time.monotonic() - self.start
        left = len(self.points) - len(self.finished) - self.lost
        rate = self.computed / elapsed if self.computed and elapsed > 0 else 0.0
        eta = left / rate if rate else (0.0 if left == 0 else float("nan"))
        failed = sum(p.status != "ok" for p in self.finished.values())
        self.progress(
            Progress(len(self.finished), failed, len(self.points), elapsed, eta, self.dashboard)
        )

    def result(self, **meta: Any) -> StudyResult:
        table, derived = tables(self.spec, list(self.finished.values()))
        info = {
            "spec": self.spec.document,
            "digest": self.spec.digest(),
            "points": len(self.points),
            "finished": len(self.finished),
            "computed": self.computed,
            "resumed": self.resumed,
            "refused": self.refused,
            "lost": self.lost,
            "seconds": round(time.monotonic() - self.start, 3),
            "versions": versions(),
            "machine": machine(),
            **meta,
        }
        result = StudyResult(self.spec, table, derived, info)
        if self.output is not None:
            result.write(self.output)
        return result


def run_serial(
    spec: StudySpec | dict[str, Any] | str | Path,
    *,
    output: str | Path | None = None,
    progress: Callable[[Progress], None] | None = None,
    resume: bool = True,
) -> StudyResult:
    """Run a study point after point in this process (no Dask): the reference of :func:`run`.

    Parameters as for :func:`run`.
    """
    spec = spec if isinstance(spec, StudySpec) else load_spec(spec)
    study = _Collector(spec, output if output is not None else spec.output, resume, progress)
    context = StudyContext.of(spec)
    study.report()
    for i in study.todo:
        refused = _refusal(context, i, study.points[i], None)
        if refused is not None:
            study.add(refused, computed=False)
        else:
            study.add(_solve_point(context, i, study.points[i]))
    return study.result(
        scheduler="serial",
        workers=1,
        worker_points={"serial": study.computed},
        workers_at_start=1,
        workers_at_end=1,
    )


def run(
    spec: StudySpec | dict[str, Any] | str | Path,
    client: Any = None,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    processes: bool = True,
    output: str | Path | None = None,
    progress: Callable[[Progress], None] | None = None,
    resume: bool = True,
    retries: int = RETRIES,
) -> StudyResult:
    """Run a study on Dask: one task per point, results written as they complete.

    Parameters
    ----------
    spec : StudySpec, dict or path
        The study (:func:`barymesh.study.spec.load_spec` reads a dict or a JSON file).
    client : distributed.Client, optional
        Run on this client's cluster. Without it: the ``scheduler`` address, else the
        ``scheduler-address`` of the Dask configuration, else a ``LocalCluster`` started
        (and closed) here.
    scheduler : str, optional
        A scheduler address, ``tcp://host:8786``.
    workers : int, optional
        Workers of the ``LocalCluster`` (default: one per core), one thread each.
    processes : bool
        Process workers (default) or threads in this process, for the ``LocalCluster``.
    output : path, optional
        Overrides the spec's ``output``. Without either, nothing is written and nothing
        can be resumed.
    progress : callable, optional
        ``progress(Progress)`` at the start and after each finished point (in this thread).
    resume : bool
        Read back the points a run of the same spec finished (default); False solves all.
    retries : int
        Reruns of a task whose worker died.

    Returns
    -------
    StudyResult

    Raises
    ------
    KeyboardInterrupt
        After Ctrl-C, once the running tasks are cancelled: every finished point is kept
        in the parts folder, so a rerun goes on from there.
    """
    spec = spec if isinstance(spec, StudySpec) else load_spec(spec)
    study = _Collector(spec, output if output is not None else spec.output, resume, progress)
    with _client(client, scheduler, workers, processes) as c:
        from distributed import as_completed, get_task_stream

        study.dashboard = c.dashboard_link or ""
        context = StudyContext.of(spec)
        at_start = c.scheduler_info()["workers"]
        limits = [w.get("memory_limit") or 0 for w in at_start.values()]
        limit = min(limits) if limits and min(limits) > 0 else None
        study.report()
        submit = []
        for i in study.todo:
            refused = _refusal(context, i, study.points[i], limit)
            if refused is not None:
                study.add(refused, computed=False)
            else:
                submit.append(i)
        futures: list[Any] = []
        index_of: dict[Any, int] = {}
        # the scheduler's record of which worker ran each task: the workers that really
        # solved the points (a worker may join, die or leave while the study runs)
        with get_task_stream(client=c) as stream:
            try:
                if submit:
                    shared = c.scatter(context, broadcast=True, hash=False)
                    futures = [
                        c.submit(
                            solve_point,
                            shared,
                            i,
                            study.points[i],
                            key=f"barymesh-study-{spec.digest()}-{i}-{id(study):x}",
                            retries=retries,
                            pure=False,
                        )
                        for i in submit
                    ]
                    index_of = {f.key: i for f, i in zip(futures, submit, strict=True)}
                for future in as_completed(futures):
                    study.add(_outcome(context, future, index_of[future.key], study))
            except KeyboardInterrupt:
                c.cancel(futures)
                log.info(
                    "interrupted: %d of %d points kept", len(study.finished), len(study.points)
                )
                raise
        ran = Counter(str(r["worker"]) for r in stream.data if r.get("key") in index_of)
        at_end = len(c.scheduler_info()["workers"])
    return study.result(
        scheduler=study.dashboard and "dask",
        workers=len(ran),
        worker_points=dict(sorted(ran.items())),
        workers_at_start=len(at_start),
        workers_at_end=at_end,
    )


def _outcome(context: StudyContext, future: Any, index: int, study: _Collector) -> PointResult:
    try:
        return future.result()
    except Exception as exc:  # noqa: BLE001 - a task's failure is the point's error row
        return error_point(
            context, index, study.points[index], f"{type(exc).__name__}: {one_line(exc)}"
        )


@contextlib.contextmanager
def _client(
    client: Any, scheduler: str | None, workers: int | None, processes: bool
) -> Iterator[Any]:
    """The client to run on: the one given, or one made (and closed) here."""
    if client is not None:
        if scheduler is not None:
            raise ValueError("give client= or scheduler=, not both")
        yield client
        return
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError as exc:
        raise ImportError(
            f"a study runs on Dask: pip install 'barymesh[study]' (missing {exc.name})"
        ) from None
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise ValueError(f"workers={workers!r} is invalid; expected a whole number >= 1")
    if scheduler is None:
        scheduler = dask.config.get("scheduler-address", None)
    if scheduler is not None:
        if workers is not None:
            raise ValueError("workers= sizes a local cluster; a scheduler has its own workers")
        try:
            c = Client(scheduler, timeout="10s")
        except OSError as exc:
            raise OSError(f"cannot reach the Dask scheduler {scheduler}: {exc}") from None
        with c:
            yield c
        return
    n = workers or os.cpu_count() or 1
    with (
        # Dask starts workers with MALLOC_TRIM_THRESHOLD_=65536, which hands freed memory back
        # to the system at once; a solve allocates and frees large numpy temporaries in a
        # loop, so every one faults its pages in again: the 64-point benchmark's workers
        # spent 1.5 times the serial loop's CPU time per point with it (benchmarks/study.py)
        dask.config.set({MALLOC_TRIM: str(WORKER_TRIM_THRESHOLD)}),
        LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=processes,
            dashboard_address="127.0.0.1:0",
            **({"host": "127.0.0.1"} if processes else {}),  # threads talk in-process
        ) as cluster,
        Client(cluster) as c,
    ):
        yield c
