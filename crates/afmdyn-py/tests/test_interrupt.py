"""Ctrl-C during a computation raises KeyboardInterrupt promptly, without a crash, and leaves
the extension usable: every analysis is cancelled (every loop that integrates checks the run's
cancel flag at each step: within a second in the library, crates/afmdyn/tests/door.rs) and
waited for, so nothing runs on in the background."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import afmdyn

pytestmark = pytest.mark.skipif(os.name != "posix", reason="SIGINT to a child process")


def _interrupt(script: str, after: float = 1.5, timeout: float = 120):
    p = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(script)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert p.stdout.readline().strip() == "start"
    time.sleep(after)  # inside the computation (each takes far longer)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        pytest.fail(f"still running {timeout} s after SIGINT: {out!r} {err[-2000:]!r}")
    return p.returncode, out.split(), err, time.monotonic() - sent


def test_ctrl_c_interrupts_a_long_bifurcation_run():
    code, out, err, latency = _interrupt(
        """
        import afmdyn
        print("start", flush=True)
        try:
            afmdyn.bifurcation(steps=4000, starts=2, progress=False)
            print("finished", flush=True)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
        ds = afmdyn.bifurcation(from_=2.0, to=2.2, steps=3)  # usable afterwards
        print("after", ds.sizes["point"], flush=True)
        """
    )
    assert code == 0, err
    assert out == ["interrupted", "after", "6"], (out, err)
    assert latency < 10, latency  # not the end of the 16 000-point sweep


@pytest.mark.parametrize(
    "call",
    [
        "afmdyn.attractors(samples=5000, progress=False)",
        "afmdyn.lyapunov(periods=10**7, blocks=10, progress=False)",
        "afmdyn.simulate(periods=10**7, samples_per_period=1, progress=False)",
        # a steady-state search of an undamped lever runs to its cap: stopped within it
        "afmdyn.orbit(beam_damping=0, gap=10, max_periods=10**7, progress=False)",
        "afmdyn.observe(beam_damping=0, gap=10, max_periods=10**7, progress=False)",
    ],
)
def test_ctrl_c_cancels_analyses_within_their_loops(call):
    code, out, err, latency = _interrupt(
        f"""
        import afmdyn
        print("start", flush=True)
        try:
            {call}
            print("finished", flush=True)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
        print("after", afmdyn.modes().free.omega.size, flush=True)
        """
    )
    assert code == 0, err
    assert out == ["interrupted", "after", "3"], (out, err)
    assert latency < 5, latency
    assert "Traceback" not in err and "panicked" not in err, err


@pytest.mark.parametrize(
    "call",
    [
        # cancelled within its blocks
        "afmdyn.lyapunov, periods=10**7, blocks=10, progress=False",
        # cancelled at its next point
        "afmdyn.bifurcation, steps=4000, starts=2, progress=False",
    ],
)
def test_ctrl_c_cancels_an_analysis_running_in_a_worker_thread(call):
    """Python runs signal handlers in the main thread only: an analysis in a
    ThreadPoolExecutor ran on for minutes after Ctrl-C (issue 42), and the interpreter waited
    for it at exit. Now the KeyboardInterrupt in the main thread cancels it: the future raises
    KeyboardInterrupt too, and the process ends at once."""
    code, out, err, latency = _interrupt(
        f"""
        import concurrent.futures as cf
        import afmdyn
        pool = cf.ThreadPoolExecutor(2)
        futures = [pool.submit({call}) for _ in range(2)]
        print("start", flush=True)
        try:
            futures[0].result()
            print("finished", flush=True)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
        for f in futures:
            try:
                f.result(timeout=5)
                print("finished", flush=True)
            except KeyboardInterrupt:
                print("cancelled", flush=True)
        pool.shutdown()
        print("after", afmdyn.modes().free.omega.size, flush=True)
        """,
        timeout=30,
    )
    assert code == 0, err
    assert out == ["interrupted", "cancelled", "cancelled", "after", "3"], (out, err)
    assert latency < 10, latency
    assert "panicked" not in err, err


def test_cancel_running_is_public_and_leaves_later_calls_alone():
    """Code that installs its own SIGINT handler cancels afmdyn's analyses itself; a call
    started afterwards runs as usual."""
    afmdyn.cancel_running()
    assert afmdyn.modes().free.omega.size == 3


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_an_interrupted_simulate_leaves_no_partial_files(cli, tmp_path, sig):
    """``afmdyn simulate`` streams its series to ``.partial`` files (100 MB within seconds) and
    cannot be resumed: on SIGINT/SIGTERM it stops at its next chunk and removes them, exit 130
    (they stayed until the next run there; issue 27)."""
    from conftest import _binary

    out = tmp_path / "sim"
    p = subprocess.Popen(
        [str(_binary()), "simulate", "--periods", "100000", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    t0 = time.monotonic()
    while not any(out.glob(".*.partial*")) and time.monotonic() - t0 < 30:
        time.sleep(0.05)
    assert any(out.glob(".*.partial*")), "the run did not start writing"
    p.send_signal(sig)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert err.strip() == "afmdyn: interrupted; the partial files of this run were removed"
    left = sorted(f.name for f in out.iterdir())
    assert left == [".afmdyn.lock"], left


def test_ctrl_c_stops_a_reconstruction():
    """``afmdyn.reconstruct`` ran on for 24 s after Ctrl-C (issue 60): the inversion now checks
    the cancel flag between chunks of rows and the call waits for it to stop. Gated on the
    computation itself, not on a delay: the progress callback sends SIGINT to its own process
    once the inversion has counted some rows but not all (an uneven grid at the direct sum's
    limit, 20 000 points: some seconds of work), and once the call has raised no worker thread
    is left computing."""
    code, out, err = _run_script(
        """
        import os, signal
        import numpy as np
        import afmdyn

        d = np.geomspace(3e-10, 6e-8, 20_000)
        sent = []

        def progress(done, total):
            if not sent and total and 0 < done < total:
                sent.append(done)
                os.kill(os.getpid(), signal.SIGINT)

        def workers():
            return sum(open(f"/proc/self/task/{t}/comm").read().strip() == "afmdyn-worker"
                       for t in os.listdir("/proc/self/task"))

        try:
            afmdyn.reconstruct(distance=d, frequency_shift=-(3e-10 / d) ** 1.5,
                               spring_constant=40.0, resonance_frequency=3e5, amplitude=1e-8,
                               progress=progress)
            print("finished", flush=True)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
        # the worker ended with the call (it sends its result, then returns); allow it to exit
        for _ in range(100):
            if workers() == 0:
                break
            import time; time.sleep(0.01)
        print("workers", workers(), flush=True)
        ds = afmdyn.reconstruct(distance=d[:100], frequency_shift=-(3e-10 / d[:100]) ** 1.5,
                                spring_constant=40.0, resonance_frequency=3e5, amplitude=1e-8)
        print("after", ds.sizes["distance"], flush=True)
        """
    )
    assert code == 0, err
    assert out == ["interrupted", "workers", "0", "after", "100"], (out, err)
    assert "panicked" not in err, err


def _run_script(script: str, timeout: float = 120):
    p = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    return p.returncode, p.stdout.split(), p.stderr
