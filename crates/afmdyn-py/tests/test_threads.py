"""The GIL is released while the engine computes: other Python threads keep running, and two
threads' simulations run in parallel."""

from __future__ import annotations

import os
import subprocess
import threading
import time

import numpy as np
import pytest

import afmdyn

from conftest import _binary


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def test_python_threads_run_while_the_engine_computes():
    # a pure-Python counter in another thread advances during a long computation; with the GIL
    # held it would stand still (the waiting thread takes the GIL only every 50 ms, briefly)
    count = 0
    stop = threading.Event()

    def spin():
        nonlocal count
        while not stop.is_set():
            count += 1

    t = threading.Thread(target=spin)
    t.start()
    try:
        time.sleep(0.05)
        before = count
        t0 = time.perf_counter()
        afmdyn.lyapunov(omega=2.6, transient=0, periods=6000, blocks=3, progress=False)
        elapsed = time.perf_counter() - t0
        during = count - before
    finally:
        stop.set()
        t.join()
    assert elapsed > 0.05, "the computation must be long enough to tell"
    # a Python loop makes millions of increments per second; allow for a loaded machine
    assert during > 20_000 * elapsed, (during, elapsed)


def test_results_computed_in_threads_equal_sequential_ones():
    omegas = [2.7, 2.8, 2.9, 3.0]
    seq = [afmdyn.simulate(omega=w, periods=5).w_tip.values for w in omegas]
    par = [None] * len(omegas)

    def work(i):
        par[i] = afmdyn.simulate(omega=omegas[i], periods=5).w_tip.values

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(omegas))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(seq, par):
        np.testing.assert_array_equal(a, b)


def _pair(run) -> float:
    """Wall time of two runs side by side over two runs one after the other."""
    t0 = time.perf_counter()
    run()
    run()
    sequential = time.perf_counter() - t0
    t0 = time.perf_counter()
    run(2)
    return (time.perf_counter() - t0) / sequential


@pytest.mark.skipif(_cores() < 2, reason="needs two cores")
def test_two_threads_simulate_faster_than_one_after_the_other(cli, tmp_path):
    def threads(k=1):
        ts = [
            threading.Thread(target=afmdyn.simulate, kwargs=dict(periods=300, samples_per_period=50, progress=False))
            for _ in range(k)
        ]
        for t in ts:
            t.start()
        for t in ts:
            t.join()

    def processes(k=1):
        # the same run as two command-line processes: what the machine allows without any GIL
        args = ["simulate", "--periods", "300", "--samples-per-period", "50"]
        procs = [
            subprocess.Popen([str(_binary()), *args, "--out", str(tmp_path / f"p{i}")], stdout=subprocess.DEVNULL)
            for i in range(k)
        ]
        for p in procs:
            assert p.wait() == 0

    attempts = []
    for _ in range(4):  # the machine may be shared: interleaved attempts
        t, p = _pair(threads), _pair(processes)
        attempts.append((round(t, 2), round(p, 2)))
        if t < 0.8:
            return  # two threads ran in parallel: the GIL was released (held, the ratio is ≥ 1)
    if min(p for _, p in attempts) >= 0.8:
        pytest.skip(f"the machine is busy: two processes do not run in parallel either {attempts}")
    pytest.fail(f"threads did not run in parallel while processes did: (threads, processes) {attempts}")
