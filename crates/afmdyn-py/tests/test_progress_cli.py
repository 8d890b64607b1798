"""The command line shows progress on a terminal (issue 28 item 2): a run longer than a second
draws an indicatif bar on stderr, counting its units with the total and an estimate of the
time left; piped, it prints none (scripts and logs stay clean)."""

from __future__ import annotations

import os
import pty
import re
import select
import subprocess
import sys

import pytest

from conftest import _binary

# 400 random starts of the impact oscillator: about 4 s on this machine (2 cores; 96 starts
# had become 1 s, when the bar, drawn after the first second, may not show), so the bar shows
SLOW = ["attractors", "--contact-law", "impact", "--restitution", "0.7", "--omega", "2.6",
        "--samples", "400"]


@pytest.mark.skipif(sys.platform == "win32", reason="needs a pseudo-terminal")
def test_a_slow_run_shows_a_progress_bar_on_a_terminal():
    master, slave = pty.openpty()
    proc = subprocess.Popen([str(_binary()), *SLOW], stdout=subprocess.DEVNULL, stderr=slave,
                            close_fds=True)
    os.close(slave)
    seen = b""
    while True:
        ready, _, _ = select.select([master], [], [], 60)
        if not ready:
            break
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        seen += chunk
    assert proc.wait(timeout=120) == 0
    text = seen.decode("utf-8", "replace")
    # "████░░ 23/400 starts  1s / ~3s": done/total, the unit, elapsed and the estimate
    assert re.search(r"\d+/400 starts", text), text[-500:]


def test_piped_runs_print_no_bar(cli):
    run = cli(*SLOW)
    assert run.returncode == 0 and "starts" not in run.stderr, run.stderr
