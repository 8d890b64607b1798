"""afmdyn.image: the ideal-feedback image as an xarray.Dataset, the same document as
``afmdyn image --json``; the line's domains at their operating points; refusals named."""

import json

import numpy as np
import pytest
import xarray as xr

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


def test_a_height_map_file_in_the_sample_map_is_the_array_keyword(tmp_path, monkeypatch):
    """``height_map = "h.npy"`` (``np.save``) or ``"h.csv"`` in the sample TOML gives the
    Dataset of the same array passed as ``height_map=``: relative to the sample file's
    directory for a path, to the current directory for TOML text."""
    grid = np.array([[0.0, 1.25e-9, 2.5e-9], [3e-9, -1e-9, 7.123456789e-10]])
    np.save(tmp_path / "h.npy", grid)
    np.savetxt(tmp_path / "h.csv", grid, delimiter=",", fmt="%.17g")
    size = "size = [1e-6, 1e-6]\n"
    want = afmdyn.image(PROBE, size, 0.7, pixels=5, lines=3, height_map=grid)
    # the true height is the array's bilinear interpolation (SciPy's, nodes at x = 0, Lx/2, Lx
    # and y = 0, Ly) at the pixel centres
    from scipy.interpolate import RegularGridInterpolator

    bilinear = RegularGridInterpolator(([0.0, 1e-6], [0.0, 0.5e-6, 1e-6]), grid)
    yy, xx = np.meshgrid(want.y.values, want.x.values, indexing="ij")
    expected = bilinear(np.stack([yy.ravel(), xx.ravel()], axis=-1)).reshape(3, 5)
    np.testing.assert_allclose(want.true_height.values, expected, rtol=0, atol=1e-24)
    for name in ("h.npy", "h.csv"):
        sample = tmp_path / f"s-{name}.toml"
        sample.write_text(size + f'height_map = "{name}"\n')
        xr.testing.assert_identical(afmdyn.image(PROBE, sample, 0.7, pixels=5, lines=3), want)
        xr.testing.assert_identical(
            afmdyn.image(PROBE, str(sample), 0.7, pixels=5, lines=3), want
        )
    # the keyword takes the file too (a path, absolute or from the current directory)
    for path in (tmp_path / "h.npy", str(tmp_path / "h.csv")):
        got = afmdyn.image(PROBE, size, 0.7, pixels=5, lines=3, height_map=path)
        xr.testing.assert_identical(got, want)
    monkeypatch.chdir(tmp_path)
    text = size + 'height_map = "h.npy"\n'
    xr.testing.assert_identical(afmdyn.image(PROBE, text, 0.7, pixels=5, lines=3), want)
    xr.testing.assert_identical(
        afmdyn.image(PROBE, size, 0.7, pixels=5, lines=3, height_map="h.csv"), want
    )
    # the array keyword replaces the file's map; a bad file is refused naming it
    np.save(tmp_path / "f32.npy", grid.astype(np.float32))
    with pytest.raises(ValueError, match=r'height_map = "f32.npy".*must be float64'):
        afmdyn.image(PROBE, size + 'height_map = "f32.npy"\n', 0.7)
    with pytest.raises(ValueError, match=r'height_map = "f32.npy".*must be float64'):
        afmdyn.image(PROBE, size, 0.7, height_map="f32.npy")


def test_the_dataset_is_image_nc(cli, tmp_path):
    """The Dataset's numeric maps are the command line's ``image.nc`` variables: values,
    units and long names (both from the library's one layout)."""
    with pytest.warns(afmdyn.AfmdynWarning):
        ds = afmdyn.image(PROBE, STRIPE, 0.7, pixels=24)
    run = cli(
        "image", "--probe", PROBE, "--sample", STRIPE, "--setpoint", "0.7", "--pixels", "24",
        "--out", tmp_path,
    )
    assert run.returncode == 0, run.stderr
    nc = xr.open_dataset(tmp_path / "image.nc").load()
    numeric = [k for k in ds.data_vars if ds[k].dtype.kind == "f"]
    assert len(numeric) == 9 and "height" in numeric and "indentation" in numeric
    for k in numeric + ["x", "y"]:
        np.testing.assert_array_equal(ds[k].values, nc[k].values, err_msg=k)
        assert ds[k].attrs == nc[k].attrs, k
    # the codes of the file are the Dataset's words
    regimes = nc.regime.attrs["flag_meanings"].split()
    words = np.array([regimes[c] for c in nc.regime.values.ravel()]).reshape(nc.regime.shape)
    named = np.where(ds.regime.values == "", "not_reached", ds.regime.values)
    np.testing.assert_array_equal(named, words)
    assert float(nc.reference_z_c) == ds.attrs["reference_z_c"]


def _lever_q100(tmp_path):
    """The point-mass probe with Q = 100 (a short loop time: a quick scan)."""
    text = PROBE.read_text().replace("quality_factor = 400", "quality_factor = 100")
    path = tmp_path / "probe.toml"
    path.write_text(text)
    return path


def test_the_pi_scan_is_the_command_lines_document(cli_json, tmp_path):
    probe = _lever_q100(tmp_path)
    # no material of the stripe reaches A/A0 = 0.1 on its approach curve with this lever (the
    # rubber's curve runs deep enough for 0.5 since the default range follows a soft sample):
    # the controller presses to its range's limit, and says so
    with pytest.warns(afmdyn.AfmdynWarning, match="sat at a limit"):
        ds = afmdyn.image(
            probe, STRIPE, 0.1, pixels=8, feedback="pi", scan_rate=40.0, gains=(0.1, 2000.0),
            time_constant=20e-6, threads=2, progress=False,
        )
    doc = cli_json(
        "image", "--probe", probe, "--sample", STRIPE, "--setpoint", "0.1", "--pixels", "8",
        "--feedback", "pi", "--scan-rate", "40", "--gains", "0.1,2000", "--time-constant",
        "20e-6", "--threads", "1", "--out", tmp_path / "out",
    )
    assert afmdyn.summary(ds) == doc
    assert ds.attrs["feedback"] == "pi"
    assert ds.height.shape == (1, 8) and ds.height_retrace.shape == (1, 8)
    assert json.loads(ds.attrs["scan"])["proportional_gain"] == 0.1
    assert ds.tracking_error.attrs["units"] == "m"
    assert ds.lost_contact.dtype == bool
    # the document summarises the recorded trace (its maps are image.nc's), in m
    for name in ("height", "tracking_error"):
        v = ds[name].values[np.isfinite(ds[name].values)]
        m = doc["image"]["maps"][name]
        assert m["units"] == "m" and m["finite"] == v.size, name
        want = (v.min(), v.max()) if v.size else (None, None)
        assert (m["min"], m["max"]) == want, name
    # and image.nc's (the one layout): every recorded map, its units
    nc = xr.open_dataset(tmp_path / "out" / "image.nc")
    for name in ("height", "height_retrace", "tracking_error", "phase_deg", "ideal_height"):
        assert np.array_equal(nc[name].values, ds[name].values, equal_nan=True), name
        assert nc[name].attrs["units"] == ds[name].attrs["units"]


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
    # the library's one check of the options (ImageOptions::check, the command line's too)
    with pytest.raises(ValueError, match="scan_rate = 2: only with feedback = pi"):
        afmdyn.image(probe, STRIPE, 0.5, scan_rate=2.0)
    with pytest.raises(ValueError, match="threads = 2: only with feedback = pi"):
        afmdyn.image(probe, STRIPE, 0.5, threads=2)


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


def test_a_pi_scan_with_a_temperature_is_the_command_lines_and_its_seeds(cli_json, tmp_path):
    # the water beam over a linear sample (the thermal force is the linear law's): the scan is
    # the command line's for the same seed, another seed gives another image; an impact stripe
    # runs, warning that its number of impacts depends on the grid; a temperature without the
    # PI scan is refused naming the temperature
    water = (EXAMPLES / "probe-water-beam.toml").read_text()
    head, rest = water[: water.index("[sample]")], water[water.index("[sample]"):]
    probe = tmp_path / "water-linear.toml"
    probe.write_text(head + '[sample]\nlaw = "linear"\nstiffness = 1.0\n'
                     + rest[rest.index("[drive]"):])
    flat = "size = [1.0e-6, 0.0]\n"
    (tmp_path / "flat.toml").write_text(flat)
    keywords = dict(pixels=6, feedback="pi", temperature=295.0, progress=False)
    ds = afmdyn.image(probe, flat, 0.7, seed=3, **keywords)
    doc = cli_json(
        "image", "--probe", probe, "--sample", tmp_path / "flat.toml", "--setpoint", "0.7",
        "--pixels", "6", "--feedback", "pi", "--temperature", "295", "--seed", "3",
        "--out", tmp_path / "out",
    )
    assert afmdyn.summary(ds) == doc
    scan = json.loads(ds.attrs["scan"])
    assert (scan["temperature"], scan["seed"]) == (295.0, 3)
    other = afmdyn.image(probe, flat, 0.7, seed=4, **keywords)
    assert not np.array_equal(ds.height.values, other.height.values)
    impact = tmp_path / "impact.toml"
    impact.write_text('size = [1e-6, 0]\n[[domain]]\nname = "j"\nx = [3e-7, 5e-7]\n'
                      '[domain.sample]\nlaw = "impact"\nrestitution = 0.5\n')
    with pytest.warns(afmdyn.AfmdynWarning, match="impact law's thermal run"):
        hot = afmdyn.image(_lever_q100(tmp_path), impact, 0.5, pixels=4, feedback="pi",
                           temperature=295.0)
    assert np.isfinite(hot.height.values).all()
    with pytest.raises(ValueError, match="temperature = 295: only with feedback = pi"):
        afmdyn.image(probe, flat, 0.7, temperature=295.0)
