"""app/jobs.py: background work delivered to the GUI thread, to a live owner only."""

import threading
import time

import pytest

pytest.importorskip("PySide6")

import shiboken6  # noqa: E402
from PySide6.QtCore import QObject  # noqa: E402

from barymesh.app.jobs import Jobs  # noqa: E402


def test_results_come_on_the_gui_thread_with_their_payload(qtbot):
    owner = QObject()
    jobs = Jobs(owner, threads=1)
    got = []
    worker_threads = set()

    def work(x):
        worker_threads.add(threading.get_ident())
        return x * x

    for x in range(5):
        jobs.submit(
            lambda x=x: work(x),
            lambda tag, value: got.append((tag, value, threading.get_ident())),
            f"#{x}",
        )
    assert jobs.wait(10_000)
    qtbot.waitUntil(lambda: len(got) == 5, timeout=5000)
    # one thread at a time: in the order submitted
    assert [(tag, value) for tag, value, _ in got] == [(f"#{x}", x * x) for x in range(5)]
    assert {t for *_, t in got} == {threading.get_ident()}
    assert threading.get_ident() not in worker_threads
    assert jobs.active == 0


@pytest.mark.parametrize(("threads", "expected"), [(1, 1), (2, 2), (None, 4)])
def test_threads_limit_how_many_run_at_once(qtbot, threads, expected):
    owner = QObject()  # held: the jobs go with their owner
    jobs = Jobs(owner, threads=threads)
    lock = threading.Lock()
    now, peak = [0], [0]
    release = threading.Event()

    def work():
        with lock:
            now[0] += 1
            peak[0] = max(peak[0], now[0])
        release.wait(10)
        with lock:
            now[0] -= 1

    for _ in range(4):
        jobs.submit(work, lambda _result: None)
    qtbot.waitUntil(lambda: now[0] == expected, timeout=5000)
    time.sleep(0.05)  # one more would have started by now
    assert now[0] == expected
    release.set()
    assert jobs.wait(10_000)
    assert peak[0] == expected


def test_an_error_goes_to_on_error_or_the_log(qtbot, caplog):
    owner = QObject()
    jobs = Jobs(owner)
    errors, done = [], []

    def fail():
        raise ValueError("no such mesh")

    jobs.submit(fail, done.append, "tag", on_error=lambda tag, exc: errors.append((tag, exc)))
    jobs.submit(fail, done.append)  # no on_error: logged, with its traceback
    assert jobs.wait(10_000)
    qtbot.waitUntil(lambda: len(errors) == 1, timeout=5000)
    qtbot.waitUntil(lambda: "a background job failed" in caplog.text, timeout=5000)
    assert done == []
    assert errors[0][0] == "tag" and isinstance(errors[0][1], ValueError)
    assert str(errors[0][1]) == "no such mesh"
    assert "no such mesh" in caplog.text


def test_errors_keep_the_payload(qtbot):
    owner = QObject()
    jobs = Jobs(owner)
    errors = []
    jobs.submit(lambda: 1 / 0, print, "token-7", on_error=lambda *a: errors.append(a))
    qtbot.waitUntil(lambda: len(errors) == 1, timeout=5000)
    assert errors[0][0] == "token-7" and isinstance(errors[0][1], ZeroDivisionError)


def test_progress_and_cancel(qtbot):
    owner = QObject()
    jobs = Jobs(owner)
    progress, done = [], []
    steps = threading.Event()

    def work(task):
        for i in range(1, 4):
            task.report(i, 3)
        steps.wait(10)
        while not task.cancelled:  # a long job polls its task
            time.sleep(0.005)
        return "finished anyway"

    task = jobs.submit(work, done.append, with_task=True, on_progress=lambda *v: progress.append(v))
    qtbot.waitUntil(lambda: len(progress) == 3, timeout=5000)
    assert progress == [(1, 3), (2, 3), (3, 3)]
    task.cancel()
    steps.set()
    assert task.done.wait(10)
    assert jobs.wait(10_000)
    qtbot.wait(50)
    assert done == []  # a cancelled job's result is dropped


def test_waiting_jobs_are_cancelled_with_the_running_one(qtbot):
    owner = QObject()
    jobs = Jobs(owner, threads=1)
    release = threading.Event()
    ran, done = [], []
    jobs.submit(lambda: release.wait(10), done.append)
    for i in range(3):
        jobs.submit(lambda i=i: ran.append(i), done.append)
    assert jobs.active == 4
    jobs.cancel_all()
    release.set()
    assert jobs.wait(10_000)
    qtbot.wait(50)
    assert ran == [] and done == [] and jobs.active == 0


def test_nothing_is_delivered_after_close(qtbot):
    owner = QObject()
    jobs = Jobs(owner)
    release = threading.Event()
    done = []
    jobs.submit(lambda: release.wait(10) and "late", done.append)
    jobs.close()  # the window closes while the job runs
    release.set()
    assert jobs.wait(10_000)
    qtbot.wait(50)
    assert done == []


def test_an_owner_destroyed_while_its_job_runs_gets_nothing(qtbot):
    # a panel closed while its worker draws (seen once in CI as a teardown error: the
    # worker emitted to a deleted object); a live owner still gets the result
    live, gone = QObject(), QObject()
    got = []
    started, release = threading.Event(), threading.Event()

    def slow(value):
        started.set()
        release.wait(10)
        return value

    with qtbot.captureExceptions() as caught:
        gone_jobs = Jobs(gone)
        gone_jobs.submit(lambda: slow("gone"), got.append)
        assert started.wait(10)
        shiboken6.delete(gone)  # the C++ side goes (with its Jobs) while the job runs
        release.set()
        live_jobs = Jobs(live)
        live_jobs.submit(lambda: "live", got.append)
        assert gone_jobs.wait(10_000) and live_jobs.wait(10_000)
        qtbot.waitUntil(lambda: got == ["live"], timeout=5000)
        qtbot.wait(50)
    assert got == ["live"]
    assert caught == []


def test_threads_must_be_at_least_one():
    with pytest.raises(ValueError, match="threads=0"):
        Jobs(QObject(), threads=0)


def test_background_work_goes_through_jobs_only():
    # one way to run work in the background (issue 31): no thread pools, runnables or
    # relays of their own anywhere else in the app
    from pathlib import Path

    app = Path(__file__).resolve().parents[1] / "app"
    offenders = []
    for path in sorted(app.rglob("*.py")):
        if path.name == "jobs.py":
            continue
        text = path.read_text(encoding="utf-8")
        for name in ("QThreadPool", "QRunnable", "class _Relay", "run_in_thread"):
            if name in text:
                offenders.append(f"{path.relative_to(app)}: {name}")
    assert offenders == []
