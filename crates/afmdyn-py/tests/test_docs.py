"""The README's commands cannot drift: every ``cargo run --release -- …`` line of its code blocks
is run, in the README's order, with the binary of this checkout in a scratch directory (the
repository's ``examples/`` linked into it, so relative paths resolve and ``afmdyn-out/`` is
written there), and must exit 0 with nothing on stderr but warnings and progress.
(``bash scripts/…`` lines are scripts of their own and not run here.)"""

from __future__ import annotations

import re
import shlex
from typing import List

from conftest import REPO


def readme_commands() -> List[List[str]]:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    commands = []
    for block in re.findall(r"```(?:sh|bash)?\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            line = line.strip()
            if line.startswith("cargo run --release -- "):
                commands.append(shlex.split(line[len("cargo run --release -- "):], comments=True))
    return commands


def test_readme_lists_the_commands():
    names = {c[0] for c in readme_commands()}
    # the main job, and one line for every analysis the README shows
    assert {"bifurcation", "simulate", "attractors", "chart", "basins", "approach",
            "resonance", "cantilevers"} <= names


def test_every_readme_command_runs(cli, tmp_path):
    (tmp_path / "examples").symlink_to(REPO / "examples")
    for args in readme_commands():
        run = cli(*args, cwd=tmp_path)
        assert run.returncode == 0, f"{' '.join(args)}: {run.stderr}"
        for line in run.stderr.splitlines():
            assert "error" not in line.lower() or "warning" in line, f"{' '.join(args)}: {line}"
