"""Probe files and steady-state observables from Python (the command line's ``--probe`` and
the library's ``analysis::observables``)."""

import math
import pathlib

import pytest

import afmdyn

ROOT = pathlib.Path(__file__).resolve().parents[3]
PM = ROOT / "examples" / "probe-point-mass-dmt.toml"
BEAM = ROOT / "examples" / "probe-beam-dmt.toml"


def test_probe_params_and_scales():
    pr = afmdyn.probe(PM)
    p = pr["params"]
    assert p.structure == "point-mass" and p.modes == 1
    # the point mass at f = f0: alpha3 = 1/Q, Omega = 1 (closed forms of the probe mapping)
    assert p.alpha3 == pytest.approx(1 / 400, rel=1e-14)
    assert p.omega == pytest.approx(1.0, rel=1e-14)
    si = pr["si"]
    assert si["scales"]["length_m"] == pytest.approx(10e-9)
    assert si["scales"]["force_n"] == pytest.approx(40.0 * 10e-9)
    assert si["z_c_m"] == pytest.approx(8e-9)
    assert afmdyn.Params.from_probe(PM) == p
    b = afmdyn.Params.from_probe(BEAM, modes=2)
    assert b.structure == "beam" and b.modes == 2


def test_bad_probe_lists_every_problem(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text('model = "beam"\ncolour = 1\n[sample]\nlaw = "hertz"\n')
    with pytest.raises(ValueError) as e:
        afmdyn.Params.from_probe(f)
    msg = str(e.value)
    for needle in ("unknown key colour", "missing key modes", "missing table [cantilever]",
                   "missing table [drive]"):
        assert needle in msg


def test_observe_free_oscillation_matches_closed_form():
    # far from the sample the point mass at f = f0 oscillates with A = A0 (1 in units of A0)
    # and lags the force by 90 degrees (harmonic oscillator at resonance)
    # (at z_c = 10⁴ A₀ = 100 µm the van der Waals force H̃/d² is 1e-13 of kA₀)
    p = afmdyn.Params.from_probe(PM, z_c=1e-4)
    o = afmdyn.observe(p)
    assert o.period == 1
    # (the adaptive integrator at its default tolerance 1e-12; the library's own test reaches
    # 1e-9 at 1e-14)
    assert float(o.amplitude) == pytest.approx(1.0, rel=1e-8)
    assert float(o.phase_deg) == pytest.approx(90.0, abs=1e-7)
    assert o.contact_fraction == 0.0
    doc = o.afmdyn.to_dict()
    assert math.degrees(doc["phase"]) == float(o.phase_deg) and doc["period"] == 1


def test_observe_tapping_repulsive_regime():
    # z_c = 8 nm < A0 = 10 nm: the amplitude drops below A0 and, in
    # the repulsive regime (phase < 90 deg), the virial is negative (San Paulo & Garcia 2001)
    o = afmdyn.observe(afmdyn.Params.from_probe(PM)).afmdyn.to_dict()
    assert 0.5 < o["amplitude"] < 1.0
    assert o["peak_force"] > 0 and o["contact_fraction"] > 0
    # DMT without viscosity is conservative: no energy goes into the sample
    assert abs(o["energy_dissipated"]) < 1e-9
    if o["phase"] < math.pi / 2:
        assert o["virial"] < 0
    with pytest.raises(ValueError):
        afmdyn.observe(afmdyn.Params.from_probe(PM), periods=0)


def test_cantilever_library(tmp_path):
    """``afmdyn.cantilevers()`` is the command line's library; a probe file naming one of its
    cantilevers gives the parameters of the file written out with the library's values."""
    df = afmdyn.cantilevers()
    assert len(df) >= 12 and df.loc["RTESPA-300", "spring_constant"] == 40.0
    assert df["source"].str.startswith("https://").all()
    sample = ('[sample]\nlaw = "hertz"\nyoungs_modulus = 1e9\npoisson_ratio = 0.3\n'
              "z_c = 12e-9\n[drive]\nfree_amplitude = 15e-9\n")
    named = tmp_path / "named.toml"
    named.write_text('[cantilever]\nname = "rtespa-300"\n' + sample)
    full = tmp_path / "full.toml"
    full.write_text('model = "point-mass"\n[cantilever]\nspring_constant = 40.0\n'
                    "resonance_frequency = 300e3\nquality_factor = 500\n[tip]\nradius = 8e-9\n"
                    "youngs_modulus = 130e9\npoisson_ratio = 0.27\n" + sample)
    assert afmdyn.Params.from_probe(str(named)).to_dict() == afmdyn.Params.from_probe(str(full)).to_dict()
    bad = tmp_path / "bad.toml"
    bad.write_text('[cantilever]\nname = "rtespa"\n' + sample)
    with pytest.raises(ValueError, match="RTESPA-150, RTESPA-300"):
        afmdyn.Params.from_probe(str(bad))


def test_observe_with_a_probe_is_in_si():
    """Issue 28 item 8: ``observe(probe=...)`` returned dimensionless values with the phase in
    radians; its dataset is in SI (the probe's scales times the library's dimensionless
    observables, which the summary keeps) with degrees, units in the attrs."""
    ds = afmdyn.observe(probe=str(PM))
    doc = ds.afmdyn.to_dict()
    s = afmdyn.probe(PM)["si"]["scales"]
    assert float(ds.amplitude) == pytest.approx(doc["amplitude"] * s["length_m"], rel=1e-15)
    assert 5e-9 < float(ds.amplitude) < 1e-8  # A0 = 10 nm, z_c = 8 nm
    assert float(ds.peak_force) == pytest.approx(doc["peak_force"] * s["force_n"], rel=1e-15)
    assert float(ds.virial) == pytest.approx(doc["virial"] * s["energy_j"], rel=1e-15)
    assert float(ds.contact_time) == pytest.approx(doc["contact_time"] * s["time_s"], rel=1e-15)
    assert float(ds.phase_deg) == pytest.approx(math.degrees(doc["phase"]), rel=1e-15)
    h = ds.harmonic_amplitude.sel(harmonic=2)
    assert float(h) == pytest.approx(doc["harmonics"][1]["amplitude"] * s["length_m"], rel=1e-15)
    units = {v: ds[v].attrs["units"] for v in ("amplitude", "peak_force", "virial", "phase_deg")}
    assert units == {"amplitude": "m", "peak_force": "N", "virial": "J", "phase_deg": "degree"}
    assert float(ds.mode_sample.sel(mode=0)) == pytest.approx(
        doc["mode_balance"][0]["sample"] * s["energy_j"], rel=1e-15, abs=1e-40)


def test_simulate_with_a_probe_is_in_si_as_the_command_line(cli, tmp_path):
    """``simulate(probe=...)`` returns the command line's SI time series (``simulate --probe``
    writes s, m, m/s, N): the same numbers, the units in the attrs; without a probe the
    model's units (the point mass's force in k g0)."""
    import numpy as np

    ds = afmdyn.simulate(probe=str(PM), periods=40)
    run = cli("simulate", "--probe", PM, "--periods", "40", "--files", "data", "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    npy = np.load(tmp_path / "timeseries.npy")
    names = ["t", "v_t", "w_tip", "w_tip_dot", "in_contact", "contact_force"]
    # the time coordinate is t in s, as the command line's column (issue 42: it was tau)
    assert ds.w_tip.dims == ("t",) and "tau" not in ds.coords
    for k, (name, var) in enumerate(zip(names, ["t", "v_t", "w_tip", "w_tip_dot"])):
        np.testing.assert_array_equal(ds[var].values, npy[:, k], err_msg=name)
    np.testing.assert_array_equal(ds.contact_force.values, npy[:, 5])
    np.testing.assert_array_equal(ds.a.values[:, 0], npy[:, 6])
    units = {v: ds[v].attrs["units"] for v in ("t", "w_tip", "w_tip_dot", "contact_force",
                                               "energy_start", "frequency")}
    assert units == {"t": "s", "w_tip": "m", "w_tip_dot": "m/s", "contact_force": "N",
                     "energy_start": "J", "frequency": "Hz"}
    period = afmdyn.probe(PM)["si"]["period_s"]
    assert abs(ds.section_tau.values[1] - ds.section_tau.values[0] - period) < 1e-9 * period
    plain = afmdyn.simulate(afmdyn.Params.from_probe(PM), periods=2)
    # the model's units as the library names them (report::SeriesUnits, timeseries.csv's)
    assert plain.contact_force.attrs["units"] == "k g0" and plain.tau.attrs["units"] == "τ (eq. 5)"


RTESPA_PS = """[cantilever]
name = "RTESPA-300"
spring_constant = 40.0
resonance_frequency = 300e3
quality_factor = 500
[sample]
law = "dmt"
youngs_modulus = 2.5e9
poisson_ratio = 0.33
hamaker = 6.6e-20
viscosity = 10.0
[drive]
free_amplitude = 15e-9
"""


@pytest.mark.parametrize(
    "keyword, value, hint",
    [
        ("hamaker", 6.6e-20, "[sample] hamaker (J)"),
        ("drive_amplitude", 20e-9, "[drive] free_amplitude (m)"),
        ("alpha2", 20e-9, "[drive] free_amplitude (m)"),
        ("gap", 1.0, "z_c=8e-9 in Python"),
        ("omega", 1.0, "drive_frequency=300e3 in Python"),
        ("beam_damping", 0.002, "[cantilever] quality_factor"),
        ("contact_law", "hertz", "[sample] law"),
    ],
)
def test_a_probe_refuses_the_dimensionless_values_it_sets(tmp_path, keyword, value, hint):
    # issue 42: hamaker=6.6e-20 under a probe was taken as H̃ (the peak force moved from 7.27
    # to 5.76 nN) and drive_amplitude=20e-9 ran with no drive; the command line refuses alike
    probe = tmp_path / "ps.toml"
    probe.write_text(RTESPA_PS)
    for call in (
        lambda: afmdyn.orbit(probe=probe, **{keyword: value}),
        lambda: afmdyn.approach(probe=probe, points=3, branches=False, **{keyword: value}),
        lambda: afmdyn.Params.from_probe(probe, **{keyword: value}),
    ):
        with pytest.raises(ValueError) as e:
            call()
        assert hint in str(e.value), str(e.value)
    # without a probe the dimensionless value is taken (the law groups with their law)
    if keyword not in ("hamaker",):
        afmdyn.Params(**{keyword: value})
    # what a probe leaves open: N (point mass: 1), z_c in m, the drive frequency in Hz
    p = afmdyn.Params.from_probe(probe, z_c=14.3e-9, drive_frequency=299e3, modes=1)
    assert p.omega == pytest.approx(299e3 / 300e3, rel=1e-12)


def test_probe_as_text_or_dict_and_a_library_cantilever(cli_json, tmp_path):
    """Issue 42 §4: ``approach(probe=…, cantilever="RTESPA-300")`` was refused (``unknown
    model parameter 'cantilever'``) and ``probe=`` took a path only. ``cantilever=`` is
    ``--cantilever`` (the library's cantilever fills the keys the probe leaves out), and the
    probe may be TOML text or a dict of its sections: the library's ``Probe::source_text``
    gives every form the same parameters and SI block as the file."""
    import tomllib

    text = PM.read_text()
    table = tomllib.loads(text)
    by_path = afmdyn.probe(PM)
    assert afmdyn.probe(text) == by_path
    assert afmdyn.probe(table) == by_path
    assert afmdyn.Params.from_probe(table) == by_path["params"]
    o = afmdyn.orbit(probe=table, z_c=8e-9).to_dict()
    assert o == afmdyn.orbit(probe=str(PM), z_c=8e-9).to_dict()

    # the probe without its calibration: RTESPA-300 from the library supplies k, f0 and Q
    bare = {k: v for k, v in table.items() if k != "cantilever"}
    f = tmp_path / "bare.toml"
    f.write_text("\n".join(line for line in text.splitlines()
                           if not line.startswith(("[cantilever]", "spring_constant",
                                                   "resonance_frequency", "quality_factor"))))
    want = cli_json("units", "--probe", f, "--cantilever", "RTESPA-300")
    got = afmdyn.probe(bare, cantilever="RTESPA-300")
    assert got["si"] == want["si"]
    row = afmdyn.cantilevers().loc["RTESPA-300"]
    cal = got["si"]["calibration"]
    for key in ("spring_constant", "resonance_frequency", "quality_factor"):
        assert cal[key] == row[key], key
    assert cal["quality_factor"] != table["cantilever"]["quality_factor"]
    ds = afmdyn.approach(probe=bare, cantilever="RTESPA-300", points=8)
    import json

    assert json.loads(ds.attrs["summary"])["si"]["calibration"] == cal
    with pytest.raises(ValueError, match="cantilever"):
        afmdyn.approach(probe=bare, cantilever="NO-SUCH-LEVER", points=8)
    with pytest.raises(ValueError, match="needs probe"):
        afmdyn.orbit(cantilever="RTESPA-300")


def test_a_tapping_call_on_an_off_resonance_probe_names_the_drive_mode():
    """Issue 77 §9: an approach curve or FM on a PeakForce probe is refused naming
    ``drive.mode`` (the library's door, ``Probe::serves``), not an inner sweep's bound."""
    probe = str(ROOT / "examples" / "probe-peakforce-air.toml")
    for call in (afmdyn.approach, afmdyn.fm):
        with pytest.raises(ValueError, match="drive.mode = off-resonance: .* taps near a resonance"):
            call(probe=probe)
