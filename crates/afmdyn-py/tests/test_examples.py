"""The examples cannot rot: the notebook is executed and the script is run (quick mode)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import REPO

EXAMPLES = REPO / "examples" / "python"


def test_notebook_executes_and_shows_the_results():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(EXAMPLES / "afmdyn_tour.ipynb", as_version=4)
    nbclient.NotebookClient(
        nb,
        timeout=600,
        kernel_name="python3",
        allow_errors=False,
        resources={"metadata": {"path": str(EXAMPLES)}},  # run where Jupyter would
    ).execute()
    text = []
    figures = 0
    for cell in nb.cells:
        # a cell's stdout and stderr each as one string: the kernel may split a stream into
        # several outputs anywhere (under load, inside a line)
        streams = {"stdout": "", "stderr": ""}
        for out in cell.get("outputs", []):
            assert out.output_type != "error", out
            if out.output_type == "stream":
                streams[out.name] = streams.get(out.name, "") + out.text
            data = out.get("data", {})
            text.append(data.get("text/plain", ""))
            figures += "image/png" in data
        text.extend(streams.values())
    text = "\n".join(text)
    assert "7.79,  20.33,  55.81" in text  # paper eq. 25
    assert "Attractor(nonperiodic" in text
    assert "chaotic" in text and "'critical': 'period-doubling'" in text
    # the SI approach curve from a probe file: its bistable range and both setpoint regimes
    assert "bistable z_c (nm): [[" in text and "'attractive'" in text and "'repulsive'" in text
    assert figures == 4


def test_script_writes_the_figures(tmp_path):
    run = subprocess.run(
        [sys.executable, str(EXAMPLES / "fig5_attractors.py"), "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    assert "Fig. 5:" in run.stdout and "Orbit(period-1, unstable" in run.stdout
    for name in ["fig5.png", "omega-2.6.png"]:
        assert (tmp_path / name).stat().st_size > 10_000
