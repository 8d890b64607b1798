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


DOCS = sorted((REPO / "docs").glob("*.md"))


def inline_commands() -> List[tuple]:
    """Every ``afmdyn SUBCOMMAND …`` written in backticks in docs/*.md and the README:
    (file, subcommand, its ``--flags``)."""
    found = []
    for path in [REPO / "README.md", *DOCS]:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"`afmdyn ([a-z]+)((?: [^`]*)?)`", text):
            found.append((path.name, m.group(1), re.findall(r"--[a-z][a-z0-9-]*", m.group(2))))
    return found


def block_commands(refused: bool = False) -> List[tuple]:
    """The ``afmdyn …`` lines of docs/*.md's code blocks (``$ `` prompts stripped); with
    ``refused``, (file, args, message) of those the docs show refused: followed in their block
    by the line ``afmdyn: …`` the command prints."""
    found = []
    shown = []
    for path in DOCS:
        fence = None  # the open block's language, None outside a block
        last = None
        for line in path.read_text(encoding="utf-8").splitlines():
            if line.startswith("```"):
                fence = None if fence is not None else line[3:].strip()
                last = None
                continue
            line = line.strip()
            if line.startswith("afmdyn: ") and last is not None:
                shown.append((path.name, last, line))
                continue
            if line.startswith("$ "):
                line = line[2:]
            last = None
            if fence in ("", "sh", "bash", "console") and line.startswith("afmdyn "):
                last = shlex.split(line[len("afmdyn "):], comments=True)
                found.append((path.name, last))
    if refused:
        return shown
    return [(n, a) for n, a in found if not any(a is s[1] for s in shown)]


def test_every_flag_the_docs_name_exists(cli):
    """Issue 28 item 9: a subcommand or flag written in the docs (inline or in a code block)
    that the command line does not have is drift. Checked against ``--help``, without
    running (the docs' commands are examples with placeholders: P, DIR, α5)."""
    top = cli("--help").stdout
    helps: dict = {}
    cases = inline_commands() + [(f, a[0], [t for t in a if t.startswith("--")])
                                 for f, a in block_commands()]
    assert len(cases) >= 30
    for name, sub, flags in cases:
        assert re.search(rf"^  {sub}\b", top, flags=re.M), f"{name}: no subcommand {sub}"
        if sub not in helps:
            helps[sub] = cli(sub, "--help").stdout
        for flag in flags:
            flag = flag.split("=")[0]
            assert re.search(rf"(^|\s){re.escape(flag)}\b", helps[sub]), \
                f"{name}: afmdyn {sub} has no {flag}"


def test_the_docs_code_block_commands_run(cli, tmp_path):
    """The docs' code-block commands run as written, in short variants: approach, bimodal and
    resonance with 6 points, no branches and no files (the grid and the model are the
    docs'); redirections dropped; a command the docs show failing (``bad.toml``) skipped."""
    (tmp_path / "examples").symlink_to(REPO / "examples")
    ran = 0
    for name, args in block_commands():
        if any("bad" in a for a in args):
            continue
        if ">" in args:
            args = args[: args.index(">")]
        if args[0] in ("approach", "resonance", "bimodal"):
            drop = {"--points", "--step"}
            short = []
            skip = False
            for a in args:
                if skip:
                    skip = False
                    continue
                if a in drop:
                    skip = True
                    continue
                short.append(a)
            args = short + ["--points", "6", "--no-branches", "--files", "none"]
        run = cli(*args, cwd=tmp_path)
        assert run.returncode == 0, f"{name}: afmdyn {' '.join(args)}: {run.stderr}"
        ran += 1
    assert ran >= 4
    # the refusals the docs show are what the command prints (bad.toml's is abridged there)
    for name, args, message in block_commands(refused=True):
        if any("bad" in a for a in args):
            continue
        run = cli(*args, cwd=tmp_path)
        assert run.returncode == 2, f"{name}: afmdyn {' '.join(args)}: {run.stderr}"
        assert run.stderr.strip() == message, f"{name}: {run.stderr!r} vs {message!r}"
