"""Shared fixtures: the command-line binary of the same checkout, whose --json documents and
output files are the reference the Python results must equal (the Rust library's results)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any, Callable, Dict

import pytest

REPO = Path(__file__).resolve().parents[3]
EXAMPLES = REPO / "examples"


def _binary() -> Path:
    env = os.environ.get("AFMDYN_BIN")
    # absolute, so that a run in another working directory finds it
    return Path(env).resolve() if env else REPO / "target" / "release" / "afmdyn"


@pytest.fixture(scope="session")
def cli() -> Callable[..., subprocess.CompletedProcess]:
    """Run the ``afmdyn`` binary (``target/release/afmdyn``, or ``$AFMDYN_BIN``)."""
    exe = _binary()
    if not exe.exists():
        pytest.fail(
            f"{exe} not found: build it with `cargo build --release` (scripts/test.sh does) "
            "or set AFMDYN_BIN"
        )

    def run(*args: Any, cwd: Any = None) -> subprocess.CompletedProcess:
        return subprocess.run(
            [str(exe), *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600
        )

    return run


@pytest.fixture(scope="session")
def cli_json(cli: Callable[..., subprocess.CompletedProcess]) -> Callable[..., Dict[str, Any]]:
    """The JSON document of ``afmdyn <args> --json``."""

    def run(*args: Any, cwd: Any = None) -> Dict[str, Any]:
        out = cli(*args, "--json", cwd=cwd)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    return run
