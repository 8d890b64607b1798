"""Ctrl-C during a computation raises KeyboardInterrupt promptly, without a crash, and leaves
the extension usable: every analysis is cancelled (every loop that integrates checks the run's
cancel flag at each step: within a second in the library, crates/afmdyn/tests/door.rs) and
waited for, so nothing runs on in the background."""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

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


EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

#: Every request kind of the library's registry (``afmdyn::request::named::NAMES``, exposed as
#: ``afmdyn._afmdyn.REQUEST_NAMES``): the data it needs (made in the child, ``np`` and ``EX``
#: the examples directory at hand) and its call at a size that runs for seconds (the long sizes
#: of crates/afmdyn/tests/door.rs's ``case()``; ``p`` is the progress callback that prints
#: "start"); ``None`` where it ends at once (door.rs gives it no long size either).
LONG = {
    "modes": None,
    "simulate": ("", "afmdyn.simulate(periods=5 * 10**6, samples_per_period=1, progress=p)"),
    # (door.rs's 10 modes and 1 sample per period end within 0.4 s at converge's Ω = 4.1)
    "converge": ("", "afmdyn.converge(max_modes=20, periods=10000, samples_per_period=10, "
                     "progress=p)"),
    "attractors": ("", "afmdyn.attractors(samples=5000, progress=p)"),
    "global_continuation": ("", "afmdyn.global_continuation(samples=64, steps=400, progress=p)"),
    # an undamped lever far from the sample: the steady-state search runs to its cap
    "orbit": ("", "afmdyn.orbit(beam_damping=0, gap=10, max_periods=10**7, progress=p)"),
    # (3 modes without switch end within 0.5 s)
    "continuation": ("", "afmdyn.continuation(from_=5.0, to=0.05, switch=True, modes=6, "
                         "progress=p)"),
    "lyapunov": ("", "afmdyn.lyapunov(periods=10**7, blocks=10, progress=p)"),
    "observe": ("", "afmdyn.observe(beam_damping=0, gap=10, max_periods=10**7, progress=p)"),
    "approach": ("", "afmdyn.approach(points=5000, progress=p)"),
    "bimodal": ("", "afmdyn.bimodal(probe=EX + '/probe-bimodal.toml', points=5000, progress=p)"),
    "resonance": ("", "afmdyn.resonance(points=5000, progress=p)"),
    "basins": ("", "afmdyn.basins(x_steps=400, y_steps=400, progress=p)"),
    "fm": ("", "afmdyn.fm(probe=EX + '/probe-point-mass-dmt.toml', points=100000, progress=p)"),
    # an evenly spaced curve of a million distances, inverted exactly (door.rs's shift_curve)
    "reconstruct": (
        """
        d = np.linspace(0.3e-9, 10e-9, 1_000_000)
        curve = dict(distance=d, frequency_shift=-10 * (1e-9 / d) ** 1.5, spring_constant=40.0,
                     resonance_frequency=300e3, amplitude=1e-9, inversion="exact")
        """,
        "afmdyn.reconstruct(**curve, progress=p)",
    ),
    # 2000 values of z_c from 18 nm in steps of 1 pm
    "peakforce": ("", "afmdyn.peakforce(probe=EX + '/probe-peakforce-amo-garcia.toml', "
                      "z_c=18e-9 - 1e-12 * np.arange(2000), progress=p)"),
    # a quasi-static Hertz approach of a million rows on the probe's lever and sample
    # (door.rs's hertz_curve), with the profile likelihood intervals
    "fit": (
        """
        x = np.linspace(1e-6, -1.5e-6, 1_000_000)
        f = 4 / 3 * (10e3 / 0.75) * np.sqrt(5e-6) * np.clip(-x, 0, None) ** 1.5
        curve = {"height": x - f / 0.05, "force": f}
        """,
        "afmdyn.fit(data=curve, probe=EX + '/probe-fit-hertz.toml', profiles=True, progress=p)",
    ),
    # a 50 × 50 map of such curves of 6000 rows (seconds of fitting, so that the signal lands
    # in the fits, not in the Dataset's assembly after them), written by export_map
    "fit_map": (
        """
        import tempfile
        x = np.linspace(1e-6, -1.5e-6, 6000)
        f = 4 / 3 * (10e3 / 0.75) * np.sqrt(5e-6) * np.clip(-x, 0, None) ** 1.5
        curves = [{"x": (c % 50) * 1e-6, "y": (c // 50) * 1e-6, "height": x - f / 0.05,
                   "force": f} for c in range(2500)]
        tmp = tempfile.mkdtemp()
        afmdyn.export_map(curves, tmp + "/map.nc")
        """,
        "afmdyn.fit_map(data=tmp + '/map.nc', probe=EX + '/probe-fit-hertz.toml', progress=p)",
    ),
    # a million frequencies of a twenty-mode beam (seconds)
    "thermal": ("", "afmdyn.thermal(probe=EX + '/probe-beam-dmt.toml', modes=20, "
                    "points=10**6, progress=p)"),
    # a million rows of a broad (Q = 2) peak at the beam's 300 kHz: every row fitted (seconds)
    "calibrate": (
        """
        import numpy as np
        f = np.linspace(10e3, 740e3, 10**6)
        r = f / 300e3
        s = 1e-27 / ((1 - r * r) ** 2 + r * r / 4) + 1e-30
        """,
        "afmdyn.calibrate(probe=EX + '/probe-beam-dmt.toml', frequency=f, "
        "spectral_density=s, progress=p)",
    ),
}


def test_every_request_kind_has_its_interrupt_case():
    """Every name of the library's registry has its case in ``LONG`` (a new request kind cannot
    go untested); the one without a long size ends at once, so there is nothing to cancel."""
    from afmdyn import _afmdyn as core

    assert sorted(LONG) == sorted(core.REQUEST_NAMES)
    assert [n for n, c in LONG.items() if c is None] == ["modes"]
    t0 = time.monotonic()
    afmdyn.modes(modes=20)
    assert time.monotonic() - t0 < 5


def _interrupt_timed(script: str, after: float = 0.1, timeout: float = 60):
    """Run ``script`` in a child Python, send it SIGINT ``after`` seconds after it printed
    "start": its exit code, its other lines each with the seconds from the signal to when it
    was read, its stderr, and the seconds from the signal to its exit."""
    p = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(script)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    lines: "queue.Queue" = queue.Queue()
    err = []

    def read_out():
        for line in p.stdout:
            lines.put((line.strip(), time.monotonic()))
        lines.put((None, time.monotonic()))

    threading.Thread(target=read_out, daemon=True).start()
    reader = threading.Thread(target=lambda: err.append(p.stderr.read()), daemon=True)
    reader.start()

    def fail(why: str):
        p.kill()
        p.wait()
        reader.join(10)
        pytest.fail(f"{why}: {''.join(err)[-2000:]}")

    try:
        first, _ = lines.get(timeout=timeout)
    except queue.Empty:
        fail(f"no start within {timeout} s")
    if first != "start":
        fail(f"printed {first!r} instead of start")
    time.sleep(after)  # inside the computation (each takes far longer)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    try:
        code = p.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        fail(f"still running {timeout} s after SIGINT")
    exited = time.monotonic() - sent
    out = []
    while True:
        line, t = lines.get(timeout=timeout)
        if line is None:
            break
        out.append((line, t - sent))
    reader.join(timeout)
    return code, out, "".join(err), exited


@pytest.mark.parametrize("name", [n for n, c in LONG.items() if c is not None])
def test_ctrl_c_cancels_every_request_kind_within_a_second(name):
    """Issue 77 item 2: every request kind, started at a size that runs for seconds and sent
    SIGINT 100 ms into its computation (the child prints "start" from the progress callback,
    which the waiting thread calls at its first poll, so the work is running by then), raises
    KeyboardInterrupt within 1 s of the signal: the call cancels the run and waits for it
    (``run.rs``), so "interrupted" is printed once the computation has stopped. The process
    then exits (its teardown is not part of the bound)."""
    setup, call = LONG[name]
    code, out, err, exited = _interrupt_timed(
        f"""
        import numpy as np
        import afmdyn
        EX = {str(EXAMPLES)!r}
        {textwrap.indent(textwrap.dedent(setup), " " * 8).strip()}
        started = []

        def p(done, total):
            if not started:
                started.append(True)
                print("start", flush=True)

        try:
            {call}
            print("finished", flush=True)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
        """
    )
    print(f"{name}: interrupted {out[0][1] if out else float('nan'):.3f} s after SIGINT, "
          f"exited after {exited:.3f} s")
    assert code == 0, err
    assert [line for line, _ in out] == ["interrupted"], (out, err)
    assert out[0][1] < 1.0, f"{name}: KeyboardInterrupt {out[0][1]:.2f} s after SIGINT"
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
