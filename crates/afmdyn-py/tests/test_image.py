"""afmdyn.image: the ideal-feedback image as an xarray.Dataset, the same document as
``afmdyn image --json``; the line's domains at their operating points; refusals named."""

import json

import numpy as np
import pytest

import afmdyn

from conftest import EXAMPLES

PROBE = EXAMPLES / "probe-point-mass-dmt.toml"
STRIPE = EXAMPLES / "sample-stripe.toml"


def test_image_is_the_command_lines_document(cli_json, tmp_path):
    with pytest.warns(afmdyn.AfmdynWarning, match="switch regime"):
        ds = afmdyn.image(PROBE, STRIPE, 0.7, pixels=40)
    doc = cli_json(
        "image", "--probe", PROBE, "--sample", STRIPE, "--setpoint", "0.7", "--pixels", "40",
        "--out", tmp_path,
    )
    assert afmdyn.summary(ds) == doc
    assert ds.height.dims == ("y", "x") and ds.height.shape == (1, 40)
    assert ds.height.attrs["units"] == "m"
    # the step of the background material is at its true height; the background at 0
    step = ds.domain.values[0] == "step"
    background = ds.domain.values[0] == "background"
    assert np.allclose(ds.height.values[0][step], 5e-9, rtol=0, atol=1e-18)
    assert np.all(ds.height.values[0][background] == 0.0)
    # the rubber stripe: one operating point for all its pixels, its own phase
    rubber = ds.domain.values[0] == "rubber"
    assert rubber.any() and len(set(ds.phase_deg.values[0][rubber])) == 1
    points = {m["name"]: m["points"] for m in doc["materials"]}
    assert ds.phase_deg.values[0][rubber][0] in [p["phase_deg"] for p in points["rubber"]]


def test_the_sample_map_may_be_text_and_refusals_name_their_field():
    text = STRIPE.read_text()
    with pytest.warns(afmdyn.AfmdynWarning):
        a = afmdyn.image(PROBE, text, 0.7, pixels=16)
    with pytest.warns(afmdyn.AfmdynWarning):
        b = afmdyn.image(str(PROBE), str(STRIPE), 0.7, pixels=16)
    assert json.loads(a.attrs["summary"]) == json.loads(b.attrs["summary"])
    with pytest.raises(ValueError, match="setpoint"):
        afmdyn.image(PROBE, STRIPE, 1.5)
    with pytest.raises(ValueError, match="lines"):
        afmdyn.image(PROBE, STRIPE, 0.7, lines=3)
    with pytest.raises(ValueError, match="size"):
        afmdyn.image(PROBE, "size = [1e-6]", 0.7)
    with pytest.raises(TypeError, match="pixels"):
        afmdyn.image(PROBE, STRIPE, 0.7, pixels=2.5)


def test_the_setpoint_study_is_the_command_lines(cli_json, tmp_path):
    ds = afmdyn.setpoint_study(PROBE, STRIPE, [0.3, 0.6, 0.9])
    assert ds.apparent_height.dims == ("domain", "setpoint")
    assert list(ds.domain.values) == ["background", "rubber", "step"]
    doc = cli_json(
        "image", "--probe", PROBE, "--sample", STRIPE, "--setpoint", "0.7",
        "--setpoint-study", "0.3:0.9:3", "--pixels", "8", "--out", tmp_path,
    )
    study = doc["setpoint_study"]
    assert json.loads(ds.attrs["summary"]) == study
    # the step is the background 5 nm up at every setpoint; the background at 0
    assert np.allclose(ds.apparent_height.sel(domain="step"), 5e-9, rtol=0, atol=1e-18)
    assert np.all(ds.apparent_height.sel(domain="background") == 0.0)
    with pytest.raises(ValueError, match="setpoint_study"):
        afmdyn.setpoint_study(PROBE, STRIPE, [0.5, 1.2])


def test_a_height_map_from_numpy_is_the_recorded_topography():
    # one material (no domains): the ideal feedback records the true topography exactly
    grid = np.array([[0.0, 1e-9, 2e-9], [4e-9, 5e-9, 6e-9]])
    ds = afmdyn.image(PROBE, "size = [1e-6, 1e-6]", 0.7, pixels=5, lines=3, height_map=grid)
    assert np.allclose(ds.height.values, ds.true_height.values, rtol=0, atol=1e-20)
    # bilinear: at (x, y) the plane through the nodes (x/0.5 µm · 1 nm + y/1 µm · 4 nm)
    x, y = np.meshgrid(ds.x.values, ds.y.values)
    assert np.allclose(ds.true_height.values, x / 0.5e-6 * 1e-9 + y / 1e-6 * 4e-9, atol=1e-20)
    with pytest.raises(ValueError, match="height_map"):
        afmdyn.image(PROBE, "size = [1e-6, 1e-6]", 0.7, height_map=np.ones(3))
    with pytest.raises(ValueError, match="height_map"):
        afmdyn.image(PROBE, "size = [1e-6, 1e-6]", 0.7, height_map=[[0.0, np.nan]])


def _lever_q100(tmp_path):
    """The point-mass probe with Q = 100 (a short loop time: a quick scan)."""
    text = PROBE.read_text().replace("quality_factor = 400", "quality_factor = 100")
    path = tmp_path / "probe.toml"
    path.write_text(text)
    return path


def test_the_pi_scan_is_the_command_lines_document(cli_json, tmp_path):
    probe = _lever_q100(tmp_path)
    # the rubber has no operating point at 0.5 with this lever: the controller presses to its
    # range's limit there, and says so
    with pytest.warns(afmdyn.AfmdynWarning, match="sat at a limit"):
        ds = afmdyn.image(
            probe, STRIPE, 0.5, pixels=8, feedback="pi", scan_rate=40.0, gains=(0.1, 2000.0),
            time_constant=20e-6, threads=2, progress=False,
        )
    doc = cli_json(
        "image", "--probe", probe, "--sample", STRIPE, "--setpoint", "0.5", "--pixels", "8",
        "--feedback", "pi", "--scan-rate", "40", "--gains", "0.1,2000", "--time-constant",
        "20e-6", "--threads", "1", "--out", tmp_path / "out",
    )
    assert afmdyn.summary(ds) == doc
    assert ds.attrs["feedback"] == "pi"
    assert ds.height.shape == (1, 8) and ds.height_retrace.shape == (1, 8)
    assert json.loads(ds.attrs["scan"])["proportional_gain"] == 0.1
    assert ds.tracking_error.attrs["units"] == "m"
    assert ds.lost_contact.dtype == bool
    # the recorded trace is the document's, in m
    assert np.array_equal(ds.height.values[0], np.array(doc["image"]["height"][0], dtype=float))


def test_pi_settings_are_refused_by_name(tmp_path):
    probe = _lever_q100(tmp_path)
    with pytest.raises(ValueError, match="gains"):
        afmdyn.image(probe, STRIPE, 0.5, pixels=8, feedback="pi", gains=(-1.0, 10.0))
    with pytest.raises(ValueError, match="scan_rate"):
        afmdyn.image(probe, STRIPE, 0.5, pixels=8, feedback="pi", scan_rate=1e9)
    with pytest.raises(ValueError, match="time_constant"):
        afmdyn.image(probe, STRIPE, 0.5, pixels=8, feedback="pi", time_constant=-1.0)
    with pytest.raises(ValueError, match="feedback"):
        afmdyn.image(probe, STRIPE, 0.5, feedback="pid")
    with pytest.raises(ValueError, match="only with feedback='pi'"):
        afmdyn.image(probe, STRIPE, 0.5, scan_rate=2.0)


def test_the_dask_scan_equals_the_local_scan(tmp_path):
    # two lines on a LocalCluster of two worker processes: the recipe pickles to the workers,
    # each line comes back as text, and the image is the local one bit for bit
    distributed = pytest.importorskip("distributed")
    import afmdyn.dask
    import xarray as xr

    probe = _lever_q100(tmp_path)
    two = STRIPE.read_text().replace("size = [1.0e-6, 0.0]", "size = [1.0e-6, 0.2e-6]")
    keywords = dict(pixels=8, lines=2, scan_rate=40.0)
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    try:
        with pytest.warns(afmdyn.AfmdynWarning):
            ds = afmdyn.dask.image(probe, two, 0.5, client=client, progress=False, **keywords)
    finally:
        client.close()
        cluster.close()
    with pytest.warns(afmdyn.AfmdynWarning):
        ref = afmdyn.image(probe, two, 0.5, feedback="pi", progress=False, **keywords)
    xr.testing.assert_identical(ds, ref)
