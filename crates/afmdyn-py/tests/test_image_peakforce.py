"""afmdyn.image(mode="peakforce"): the PeakForce image with ideal peak-force feedback (issue
61 §3) as an xarray.Dataset: the command line's ``image.nc`` variables, every pixel's peak
force at the setpoint, refusals named; on Dask (materials' engages, then lines, as tasks) the
local image bit for bit."""

import numpy as np
import pytest
import xarray as xr

import afmdyn

from conftest import EXAMPLES

PROBE = EXAMPLES / "probe-peakforce-amo-garcia.toml"
BLEND = EXAMPLES / "sample-peakforce-blend.toml"
KEYWORDS = dict(pixels=4, lines=2)


def _image(**extra):
    with pytest.warns(afmdyn.AfmdynWarning):
        return afmdyn.image(PROBE, BLEND, 2e-9, mode="peakforce", progress=False,
                            **KEYWORDS, **extra)


def test_the_peakforce_image_is_image_nc(cli, tmp_path):
    ds = _image()
    run = cli("image", "--mode", "peakforce", "--probe", PROBE, "--sample", BLEND,
              "--setpoint", "2nN", "--pixels", "4", "--lines", "2", "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    nc = xr.open_dataset(tmp_path / "image.nc").load()
    numeric = [k for k in ds.data_vars if ds[k].dtype.kind == "f"]
    assert {"height", "peak_force", "modulus_dmt", "adhesion", "deformation",
            "dissipation"} <= set(numeric)
    for k in numeric + ["x", "y"]:
        np.testing.assert_array_equal(ds[k].values, nc[k].values, err_msg=k)
        assert ds[k].attrs == nc[k].attrs, k
    # the ideal feedback holds the peak force at the setpoint on every pixel it reached
    peak = ds.peak_force.values
    reached = np.isfinite(peak)
    assert reached.all()
    np.testing.assert_allclose(peak[reached], 2e-9, rtol=1e-6)
    assert set(np.unique(ds.material.values)) == {"background", "stiff"}


def test_peakforce_image_refusals_name_their_field():
    with pytest.raises(ValueError, match="mode"):
        afmdyn.image(PROBE, BLEND, 2e-9, mode="force-volume")
    with pytest.raises(ValueError, match="feedback = pi: not with mode = peakforce"):
        afmdyn.image(PROBE, BLEND, 2e-9, mode="peakforce", feedback="pi")
    with pytest.raises(ValueError, match="curve_points = 20: not with mode = peakforce"):
        afmdyn.image(PROBE, BLEND, 2e-9, mode="peakforce", curve_points=20)
    # an AM probe has no modulation to tap with
    with pytest.raises(ValueError, match="excitation"):
        afmdyn.image(EXAMPLES / "probe-point-mass-dmt.toml", BLEND, 2e-9, mode="peakforce",
                     **KEYWORDS)


def test_the_dask_peakforce_image_equals_the_local_one():
    distributed = pytest.importorskip("distributed")
    import afmdyn.dask

    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    try:
        with pytest.warns(afmdyn.AfmdynWarning):
            ds = afmdyn.dask.image(PROBE, BLEND, 2e-9, mode="peakforce", client=client,
                                   progress=False, **KEYWORDS)
    finally:
        client.close()
        cluster.close()
    xr.testing.assert_identical(ds, _image())


def test_a_temperature_maps_each_materials_tap_noise(cli, tmp_path):
    """``temperature=`` gives the maps ``peak_force_noise`` and ``deformation_noise``: the
    command line's ``image.nc`` with ``--temperature``, the background's pixels the single
    tap's σ (``afmdyn.peakforce(setpoint=, temperature=)``); a seed is refused (nothing is
    drawn)."""
    ds = _image(temperature=295.0)
    run = cli("image", "--mode", "peakforce", "--probe", PROBE, "--sample", BLEND,
              "--setpoint", "2nN", "--pixels", "4", "--lines", "2", "--temperature", "295",
              "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    nc = xr.open_dataset(tmp_path / "image.nc").load()
    with pytest.warns(afmdyn.AfmdynWarning):
        single = afmdyn.peakforce(probe=PROBE, setpoint=2e-9, temperature=295.0)
    for k in ("peak_force_noise", "deformation_noise"):
        np.testing.assert_array_equal(ds[k].values, nc[k].values, err_msg=k)
        background = ds[k].values[ds.material.values == "background"]
        assert background.size > 0
        np.testing.assert_allclose(background, single.attrs[k], rtol=1e-12, err_msg=k)
    assert "peak_force_noise" not in _image().data_vars
    with pytest.raises(ValueError, match="seed = 3: only with feedback = pi"):
        afmdyn.image(PROBE, BLEND, 2e-9, mode="peakforce", temperature=295.0, seed=3)
