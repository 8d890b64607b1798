"""``afmdyn.approach()`` and ``afmdyn.resonance()`` return datasets whose
``ds.afmdyn.to_dict()`` is the command line's document (``afmdyn approach --json``,
``afmdyn resonance --json``): the same library call, so the same numbers; the dataset's
variables are the document's columns in SI with their units; bad input raises ValueError
naming the option."""

from __future__ import annotations

from pathlib import Path

import pytest

import afmdyn

REPO = Path(__file__).resolve().parents[3]
PROBE = REPO / "examples" / "probe-point-mass-dmt.toml"


def test_approach_equals_the_command_line(cli_json):
    args = dict(from_=11e-9, to=5e-9, points=7, branches=False)
    ds = afmdyn.approach(afmdyn.Params.from_probe(PROBE), probe=PROBE, **args)
    doc = ds.afmdyn.to_dict()
    ref = cli_json(
        "approach", "--probe", str(PROBE), "--from", "11e-9", "--to", "5e-9", "--points", "7",
        "--no-branches", "--files", "none",
    )
    for sweep in ("approach", "retract"):
        for key in ("z_c", "amplitude", "phase_deg", "energy_dissipated", "virial", "stable"):
            assert doc[sweep][key] == ref[sweep][key], (sweep, key)
    assert doc["jumps"] == ref["jumps"]
    # the dataset: both sweeps over the approach's grid, the retract's values at its z_c
    assert ds.z_c.values.tolist() == ref["approach"]["z_c"]
    assert ds.amplitude.sel(sweep="approach").values.tolist() == ref["approach"]["amplitude"]
    retract = ds.phase_deg.sel(sweep="retract").values[::-1].tolist()
    assert retract == ref["retract"]["phase_deg"]
    assert ds.amplitude.attrs["units"] == "m" and ds.phase_deg.attrs["units"] == "degree"
    assert ds.energy_dissipated.attrs["units"] == "J" and ds.peak_force.attrs["units"] == "N"


def test_resonance_equals_the_command_line(cli_json):
    ds = afmdyn.resonance(points=5, branches=False)
    ref = cli_json("resonance", "--points", "5", "--no-branches", "--files", "none")
    assert ds.afmdyn.to_dict() == ref
    assert ds.omega.values.tolist() == ref["up"]["omega"]
    assert ds.amplitude.sel(sweep="down").values[::-1].tolist() == ref["down"]["amplitude"]
    assert ds.amplitude.attrs["units"] == "g0" and ds.sizes["branch_point"] == 0


def test_a_curve_killed_on_the_command_line_resumes_in_python(cli, tmp_path):
    # one store for both front ends: the command line is killed during the approach, Python
    # resumes the chain of points from the last stored one to the uninterrupted curve
    killed = cli("approach", "--probe", PROBE, "--abort-after", 40, "--out", tmp_path)
    assert killed.returncode != 0
    points = tmp_path / ".curve.points.jsonl"
    assert len(points.read_text().splitlines()) == 40
    p = afmdyn.Params.from_probe(PROBE)
    ds = afmdyn.approach(p, probe=PROBE, store=tmp_path, resume=True)
    ref = afmdyn.approach(p, probe=PROBE)
    assert ds.afmdyn.to_dict() == ref.afmdyn.to_dict()
    assert len(points.read_text().splitlines()) == 2 * ds.sizes["z_c"]
    with pytest.raises(ValueError, match="tolerance"):
        afmdyn.approach(p, probe=PROBE, tolerance=1e-9, store=tmp_path, resume=True)


def test_bad_grids_raise_value_error():
    with pytest.raises(ValueError, match="points"):
        afmdyn.approach(points=1)
    with pytest.raises(ValueError, match="step or points"):
        afmdyn.approach(step=0.1, points=10)
    with pytest.raises(ValueError, match="mode"):
        afmdyn.resonance(mode=7)
    with pytest.raises(ValueError, match="tolerance"):
        afmdyn.resonance(tolerance=0.0)


@pytest.mark.parametrize(
    "call,needle",
    [
        # the grid's refusals quote the value as written, in metres or hertz (issue 27: they
        # said "to = 0.8", "step = 100000000", "step = -0.00133…")
        (lambda: afmdyn.approach(probe=PROBE, from_=8e-9, to=8e-9), "to = 8e-9: must differ"),
        (lambda: afmdyn.approach(probe=PROBE, step=1.0), "step = 1 m: must lie within ±1e-4 m"),
        (lambda: afmdyn.approach(probe=PROBE, step=5e-8), "step = 5e-8: is longer than the range"),
        (lambda: afmdyn.resonance(probe=PROBE, step=-400.0), "step = -400: must be finite and > 0"),
    ],
)
def test_curve_refusals_quote_the_users_units(call, needle):
    with pytest.raises(ValueError, match=needle):
        call()


def test_setpoint_equals_the_command_line(cli_json):
    """``setpoint=`` adds the command line's ``"setpoint"`` block: operating points on the
    stable branches where A/A₀ equals it, the attractive one with its phase above 90°."""
    args = dict(from_=11e-9, to=5e-9, points=31, setpoint=0.85)
    doc = afmdyn.approach(probe=str(PROBE), **args).afmdyn.to_dict()
    cli = cli_json("approach", "--probe", str(PROBE), "--from", "11e-9", "--to", "5e-9",
                   "--points", "31", "--setpoint", "0.85", "--files", "none")
    assert doc["setpoint"] == cli["setpoint"]
    sp = doc["setpoint"]
    assert sp["ratio"] == 0.85 and abs(sp["amplitude"] - 0.85e-8) < 1e-20
    regimes = {p["regime"]: p for p in sp["points"]}
    assert set(regimes) == {"attractive", "repulsive"}
    assert regimes["attractive"]["phase_deg"] > 90 > regimes["repulsive"]["phase_deg"]
    for p in sp["points"]:
        # the exact orbit at the setpoint, to the refinement's tolerance (issue 77)
        assert abs(p["amplitude_ratio"] - 0.85) < 1e-9
    with pytest.raises(ValueError, match="setpoint = 1.5"):
        afmdyn.approach(probe=str(PROBE), setpoint=1.5)


def test_traces_equal_the_command_line(cli_json, tmp_path):
    """``traces=N`` keeps one steady-state cycle per z_c: the command line's document and
    approach-traces.nc hold the same arrays; the force–distance loop of the point mass has
    V_T − W constant (the gap)."""
    import numpy as np
    import xarray as xr

    args = dict(from_=11e-9, to=5e-9, points=5, branches=False, traces=16)
    ds = afmdyn.approach(probe=str(PROBE), **args)
    doc = ds.afmdyn.to_dict()
    cli = cli_json("approach", "--probe", str(PROBE), "--from", "11e-9", "--to", "5e-9",
                   "--points", "5", "--no-branches", "--traces", "16", "--out", str(tmp_path),
                   "--files", "data")
    assert doc["traces"] == cli["traces"]
    t = doc["traces"]
    assert t["z_c"] == doc["approach"]["z_c"] and len(t["time_periods"]) == 16
    nc = xr.open_dataset(tmp_path / "approach-traces.nc")
    np.testing.assert_allclose(nc.force.values, np.array(t["force"]), rtol=0, atol=0)
    np.testing.assert_array_equal(ds.trace_force.values, nc.force.values)
    assert ds.trace_z_c.values.tolist() == t["z_c"] and ds.trace_force.attrs["units"] == "N"
    gap = np.array(t["distance"]) - np.array(t["deflection"])
    assert np.allclose(gap, gap[:, :1], rtol=0, atol=1e-18)
    with pytest.raises(ValueError, match="traces = 1"):
        afmdyn.approach(probe=str(PROBE), traces=1)


def test_approach_temperature_gives_the_lock_in_noise(cli_json):
    """``temperature=``: the dataset gains ``amplitude_noise`` (m) and ``phase_noise_deg``
    over (sweep, z_c), the command line's numbers; far from the sample σ_A is the free lever's
    √(k_BT/k · τ_c/(τ_c + τ_L)) (the lock-in's default τ_L = τ_c/4)."""
    ds = afmdyn.approach(afmdyn.Params.from_probe(PROBE), probe=PROBE, from_=11e-9, to=5e-9,
                         points=5, branches=False, temperature=295.0)
    ref = cli_json(
        "approach", "--probe", str(PROBE), "--from", "11e-9", "--to", "5e-9", "--points", "5",
        "--no-branches", "--temperature", "295", "--files", "none",
    )
    sigma = ds.amplitude_noise.sel(sweep="approach").values.tolist()
    assert sigma == ref["approach"]["amplitude_noise"]
    assert ds.amplitude_noise.attrs["units"] == "m"
    assert ds.phase_noise_deg.attrs["units"] == "degree"
    assert ds.afmdyn.to_dict()["thermal"]["temperature"] == 295.0
    k = ref["si"]["calibration"]["spring_constant"]
    free = (1.380649e-23 * 295.0 / k * 0.8) ** 0.5
    assert sigma[0] == pytest.approx(free, rel=0.01)
    with pytest.raises(ValueError, match="time_constant"):
        afmdyn.approach(afmdyn.Params.from_probe(PROBE), probe=PROBE, time_constant=1e-3)
