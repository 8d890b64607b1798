"""fit(): the dataset equals the command line's ``afmdyn fit --json`` for the same curve; a
synthetic Hertz curve's modulus comes back within its interval; and nanite (Müller et al.,
BMC Bioinformatics 20 (2019) 465) as a peer: its Hertz paraboloid fit of the same curve, with
the same preprocessing (compute_tip_position, correct_force_offset, correct_tip_offset), the
same fitted parameters (E, contact point, baseline), the whole approach and no contact-point
weighting, gives E within 1 % of afmdyn's.

The synthetic curve: examples/force-curve-hertz.csv (scripts/make-force-curve.py: E = 5 kPa,
R = 5 µm, k = 0.05 N/m, 20 pN of seeded noise, a 0.1 nN offset). The measured one:
examples/force-curve-jpk-spot3-0192.jpk-force (afmformats' test data, MIT), read through
afmformats, against nanite's fit of the same file."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import afmdyn
from conftest import EXAMPLES

PROBE = str(EXAMPLES / "probe-fit-hertz.toml")
CURVE = EXAMPLES / "force-curve-hertz.csv"
K, R, NU, E_TRUE = 0.05, 5e-6, 0.5, 5e3
FIT = ["sample.youngs_modulus", "contact_point", "baseline"]


def _curve():
    data = np.loadtxt(CURVE, delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1]


def _fit(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        return afmdyn.fit(probe=PROBE, **kw)


def test_fit_equals_the_command_line(cli_json, tmp_path):
    doc = cli_json("fit", "--probe", PROBE, "--data", str(CURVE), "--fit", ",".join(FIT),
                   "--out", tmp_path / "fit")
    ds = _fit(data=str(CURVE), fit=FIT)
    for name in FIT:
        assert ds["estimate"].sel(parameter=name).item() == doc["estimates"][name]["value"]
    assert np.array_equal(ds["fit"].values, np.asarray(doc["curve"]["fit"]))
    e = ds["estimate"].sel(parameter="sample.youngs_modulus").item()
    lo = ds["interval_low"].sel(parameter="sample.youngs_modulus").item()
    hi = ds["interval_high"].sel(parameter="sample.youngs_modulus").item()
    assert lo <= E_TRUE <= hi and abs(e / E_TRUE - 1) < 0.01
    assert ds["correlation"].shape == (3, 3)


def test_fit_takes_columns_and_warns_that_the_noise_is_estimated():
    h, f = _curve()
    with pytest.warns(afmdyn.AfmdynWarning, match="noise estimated from residuals"):
        ds = afmdyn.fit(probe=PROBE, data={"height": h, "force": f}, fit=FIT)
    assert ds.sizes["row"] == 500
    with pytest.raises(ValueError, match="fit"):
        afmdyn.fit(probe=PROBE, data={"height": h, "force": f}, fit=["sample.hamaker"])


def test_a_force_curve_fit_takes_a_probe_of_k_tip_and_sample():
    """Issue 77 §10: the fit uses the lever's k, the tip and the sample, and asks for no more
    (the stand-ins of the resonance, Q and drive are named in ``si.assumed``); the estimates
    are the full probe's. An analysis of the oscillating lever still refuses the file."""
    minimal = {"cantilever": {"spring_constant": K}, "tip": {"radius": R},
               "sample": {"law": "hertz", "youngs_modulus": 10e3, "poisson_ratio": NU}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ours = afmdyn.fit(probe=minimal, data=str(CURVE), fit=FIT)
    full = _fit(data=str(CURVE), fit=FIT)
    assert np.array_equal(ours["estimate"].values, full["estimate"].values)
    assert json.loads(ours.attrs["summary"])["si"]["assumed"][0] == "model"
    with pytest.raises(ValueError, match=r"missing table \[drive\]"):
        afmdyn.approach(probe=minimal)


def test_nanite_hertz_paraboloid_gives_the_same_modulus():
    nanite = pytest.importorskip("nanite")
    h, f = _curve()
    n = h.size
    half = n // 2
    segment = np.arange(n) >= half
    metadata = {"spring constant": K, "path": str(CURVE), "enum": 0, "duration": 1.0,
                "sensitivity": 1e-9, "setpoint": 1e-9, "speed approach": 1e-6,
                "speed retract": 1e-6, "imaging mode": "force-distance", "point count": n}
    idnt = nanite.Indentation(
        data={"force": f, "height (measured)": h, "segment": segment,
              "time": np.linspace(0.0, 1.0, n)},
        metadata=metadata,
    )
    idnt.apply_preprocessing(["compute_tip_position", "correct_force_offset",
                              "correct_tip_offset"])
    params = idnt.get_initial_fit_parameters(model_key="hertz_para")
    params["R"].set(value=R)
    params["nu"].set(value=NU)
    params["E"].set(value=10e3)
    idnt.fit_model(model_key="hertz_para", params_initial=params, weight_cp=0,
                   segment="approach", range_x=(0, 0), range_type="absolute",
                   x_axis="tip position", y_axis="force")
    e_nanite = idnt.fit_properties["params_fitted"]["E"].value
    ds = _fit(data={"height": h, "force": f}, fit=FIT)
    e_afmdyn = ds["estimate"].sel(parameter="sample.youngs_modulus").item()
    assert abs(e_afmdyn / e_nanite - 1) < 0.01, (e_afmdyn, e_nanite)
    # the preprocessing is nanite's: the same tip positions and forces
    tip = idnt["tip position"][~segment]
    assert np.allclose(ds["tip_position"].values, tip, rtol=0, atol=1e-15)
    assert np.allclose(ds["force"].values, idnt["force"][~segment], rtol=0, atol=1e-20)


def _afmformats_curve(afmformats, h, f, k=K):
    """The synthetic curve as an afmformats force-distance object (as an instrument file reads)."""
    n = h.size
    metadata = {"spring constant": k, "path": str(CURVE), "enum": 0, "duration": 1.0,
                "sensitivity": 1e-9, "setpoint": 1e-9, "speed approach": 1e-6,
                "speed retract": 1e-6, "imaging mode": "force-distance", "point count": n}
    return afmformats.AFMForceDistance(
        data={"force": f, "height (measured)": h, "segment": np.arange(n) >= n // 2,
              "time": np.linspace(0.0, 1.0, n)},
        metadata=metadata)


def test_an_instrument_curve_read_by_afmformats_fits_as_its_columns(tmp_path):
    afmformats = pytest.importorskip("afmformats")
    h, f = _curve()
    columns = _fit(data={"height": h, "force": f}, fit=FIT)
    obj = _afmformats_curve(afmformats, h, f)
    path = tmp_path / "curve.h5"
    obj.export_data(str(path), fmt="hdf5")
    for data in (obj, path, str(path)):
        ds = _fit(data=data, fit=FIT)
        # the same rows, so the same estimates to the last digit
        assert np.array_equal(ds["estimate"].values, columns["estimate"].values)
    with pytest.raises(ValueError, match="curve"):
        _fit(data=path, fit=FIT, curve=1)
    with pytest.raises(ValueError, match="missing.jpk-force"):
        _fit(data=tmp_path / "missing.jpk-force", fit=FIT)
    # a file calibrated with another spring constant is named (the probe's is used)
    other = tmp_path / "other.h5"
    _afmformats_curve(afmformats, h, f, k=2 * K).export_data(str(other), fmt="hdf5")
    with pytest.warns(afmdyn.AfmdynWarning, match="spring constant"):
        afmdyn.fit(probe=PROBE, data=other, fit=FIT)


JPK = EXAMPLES / "force-curve-jpk-spot3-0192.jpk-force"
JPK_PROBE = str(EXAMPLES / "probe-fit-spot3.toml")


def test_a_measured_jpk_curve_fits_as_nanite_fits_it():
    """A measured curve (afmformats' test file, which nanite's tests fit): read through
    afmformats with the instrument's segments, afmdyn's Hertz fit (E, contact point, baseline;
    nanite's three preprocessing steps) and nanite's of the same file agree; nanite's
    one-step fit reproduces the contact point its own test asserts (1.802931023582261e-05 m,
    tests/test_fit_base.py), so the file and the peer are the ones of that test."""
    nanite = pytest.importorskip("nanite")
    pytest.importorskip("afmformats")

    def nanite_fit(steps, cp=None):
        idnt = nanite.IndentationGroup(JPK)[0]
        idnt.apply_preprocessing(steps)
        params = nanite.model.model_hertz_paraboloidal.get_parameter_defaults()
        params["baseline"].vary = True
        if cp is not None:
            params["contact_point"].set(cp)
        idnt.fit_model(model_key="hertz_para", params_initial=params, range_x=(0, 0),
                       range_type="absolute", x_axis="tip position", y_axis="force",
                       segment="approach", weight_cp=False)
        return idnt, idnt.fit_properties["params_fitted"]

    _, one = nanite_fit(["compute_tip_position"], cp=1.8321e-5)
    assert abs(one["contact_point"].value - 1.802931023582261e-05) < 2e-10
    idnt, ref = nanite_fit(["compute_tip_position", "correct_force_offset", "correct_tip_offset"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ds = afmdyn.fit(probe=JPK_PROBE, data=JPK, fit=FIT)
    est = ds["estimate"]
    e = est.sel(parameter="sample.youngs_modulus").item()
    assert abs(e / ref["E"].value - 1) < 1e-4, (e, ref["E"].value)
    assert abs(est.sel(parameter="contact_point").item() - ref["contact_point"].value) < 1e-11
    # the rows fitted are nanite's approach segment, preprocessed alike
    approach = np.asarray(idnt["segment"]) == 0
    assert ds.sizes["row"] == approach.sum() == 2000
    assert np.allclose(ds["tip_position"].values, idnt["tip position"][approach], rtol=0, atol=1e-15)
    # and E lies in its 95 % interval, the curve being real: its noise estimated
    lo = ds["interval_low"].sel(parameter="sample.youngs_modulus").item()
    hi = ds["interval_high"].sel(parameter="sample.youngs_modulus").item()
    assert lo < ref["E"].value < hi


def _nanite_fit(idnt, model_key, module, **held):
    """nanite 4.2's fit of the indentation ``idnt`` with ``model_key`` (its module's defaults,
    the baseline free, the held parameters ``held`` set) after its three preprocessing steps,
    on the whole approach, unweighted: the fitted parameters."""
    idnt.apply_preprocessing(["compute_tip_position", "correct_force_offset", "correct_tip_offset"])
    params = module.get_parameter_defaults()
    params["baseline"].vary = True
    for key, value in held.items():
        params[key].set(value)
    idnt.fit_model(model_key=model_key, params_initial=params, range_x=(0, 0),
                   range_type="absolute", x_axis="tip position", y_axis="force",
                   segment="approach", weight_cp=False)
    return idnt.fit_properties["params_fitted"]


def _nanite_jpk(model_key, module, **held):
    """nanite 4.2's fit of the JPK curve with ``model_key`` (its module's defaults, the
    baseline free, the held parameters ``held`` set), after its three preprocessing steps: the
    fitted parameters and the largest indentation of the fitted rows (m)."""
    nanite = pytest.importorskip("nanite")
    idnt = nanite.IndentationGroup(JPK)[0]
    ref = _nanite_fit(idnt, model_key, module, **held)
    approach = np.asarray(idnt["segment"]) == 0
    depth = ref["contact_point"].value - np.min(np.asarray(idnt["tip position"])[approach])
    return ref, depth


def _afmdyn_jpk(tip):
    """afmdyn's fit of the JPK curve (E, contact point, baseline) with the ``[tip]`` lines
    ``tip`` in place of the probe's radius: E (Pa)."""
    text = open(JPK_PROBE).read().replace("radius = 10e-6", tip)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ds = afmdyn.fit(probe=text, data=JPK, fit=FIT)
    return ds["estimate"].sel(parameter="sample.youngs_modulus").item()


@pytest.mark.parametrize("model_key, module, angle, tip", [
    ("hertz_cone", "model_conical_indenter", 25.0, 'shape = "cone"\nhalf_angle = 25'),
    ("hertz_pyr3s", "model_hertz_three_sided_pyramid", 15.0,
     'shape = "pyramid-3"\nface_angle = 15'),
])
def test_a_measured_curve_fits_with_a_sharp_tip_as_nanite_fits_it(model_key, module, angle, tip):
    """The JPK curve with nanite's cone (half angle 25°) and three-sided pyramid (face angle
    15°): afmdyn's E agrees with nanite 4.2's within 0.1 %."""
    pytest.importorskip("afmformats")
    nanite = pytest.importorskip("nanite")
    ref, _ = _nanite_jpk(model_key, getattr(nanite.model, module), alpha=angle)
    e = _afmdyn_jpk(tip)
    assert abs(e / ref["E"].value - 1) < 1e-3, (e, ref["E"].value)


def _sneddon_sphere(delta, radius):
    """Sneddon's exact sphere per unit E* (1965, eqs. 6.13 and 6.15): δ = (a/2) ln((R+a)/(R−a)),
    F = ½[(a² + R²) ln((R+a)/(R−a)) − 2aR], a found by bisection."""
    lo, hi = 0.0, radius * (1 - 1e-15)
    for _ in range(200):
        a = 0.5 * (lo + hi)
        if a / 2 * np.log((radius + a) / (radius - a)) < delta:
            lo = a
        else:
            hi = a
    a = 0.5 * (lo + hi)
    log = np.log((radius + a) / (radius - a))
    return 0.5 * ((a * a + radius * radius) * log - 2 * a * radius)


def test_the_exact_sphere_agrees_with_nanites_approximation_within_its_error():
    """nanite's ``sneddon_spher_approx`` (Sneddon's sphere truncated at (δ/R)⁴) against
    afmdyn's exact sphere on the JPK curve (R = 10 µm): the two E agree within the
    approximation's error, the relative difference of the truncated and the exact force at the
    deepest indentation fitted (stated here: computed from both forms), plus the 1e-4 of the
    paraboloid's agreement; and the paraboloid's fit is unchanged by the shapes."""
    pytest.importorskip("afmformats")
    nanite = pytest.importorskip("nanite")
    radius = 10e-6
    ref, depth = _nanite_jpk("sneddon_spher_approx",
                             nanite.model.model_sneddon_spherical_approximation, R=radius)
    d = depth / radius
    series = 1 - d / 10 - d ** 2 / 840 + 11 * d ** 3 / 15120 + 1357 * d ** 4 / 6652800
    paraboloid = 4 / 3 * np.sqrt(radius) * depth ** 1.5
    error = abs(paraboloid * series / _sneddon_sphere(depth, radius) - 1)
    e = _afmdyn_jpk('shape = "sphere"\nradius = 10e-6')
    assert abs(e / ref["E"].value - 1) < error + 1e-4, (e, ref["E"].value, d, error)
    # the paraboloid written out is the default
    assert _afmdyn_jpk('shape = "paraboloid"\nradius = 10e-6') == _afmdyn_jpk("radius = 10e-6")


def test_a_frequency_shift_curve_fits_against_the_fm_model(tmp_path):
    """A Δf curve made by ``afmdyn.fm`` (the probe's E and H, z = z_c − 1 nm, 0.2 Hz of seeded
    noise) is fitted as an FM curve: the Dataset carries the frequency shift's data, fit and
    residual (Hz) over ``row``, and H and z_offset's 95 % intervals hold the truth."""
    probe = str(EXAMPLES / "probe-point-mass-dmt.toml")
    fm = afmdyn.fm(probe=probe, from_=14e-9, to=9.5e-9, points=16)
    rng = np.random.default_rng(62)
    z = fm.z_c.values - 1e-9
    df = fm.frequency_shift.values + 0.2 * rng.standard_normal(z.size)
    path = tmp_path / "fm.csv"
    rows = "\n".join(f"{a:.17g},{b:.17g},0.2" for a, b in zip(z, df))
    path.write_text("z,frequency_shift,sigma_frequency_shift\n" + rows + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ds = afmdyn.fit(probe=probe, data=str(path), fit=["sample.hamaker", "z_offset"])
    assert json.loads(ds.attrs["summary"])["kind"] == "fm"
    assert ds.frequency_shift.attrs["units"] == "Hz"
    np.testing.assert_array_equal(ds.frequency_shift.values, df)
    np.testing.assert_allclose(ds.frequency_shift_residual.values,
                               df - ds.frequency_shift_fit.values, atol=1e-9)
    for name, truth in (("sample.hamaker", 6.6e-20), ("z_offset", 1e-9)):
        lo = ds["interval_low"].sel(parameter=name).item()
        hi = ds["interval_high"].sel(parameter=name).item()
        assert lo <= truth <= hi, (name, lo, hi)


def test_a_viscoelastic_curve_with_a_dwell_fits_in_time(tmp_path):
    """The SLS on examples/force-curve-sls-dwell.csv (scripts/make-sls-curve.py, independent of
    afmdyn: k1 = 10 mN/m, k2 = 20 mN/m, τ = 0.1 s, 50 pN of noise): from the file and from its
    columns as a mapping, the same estimates; each truth inside its 95 % interval; the Dataset
    carries the rows' times in s."""
    probe = str(EXAMPLES / "probe-fit-sls.toml")
    path = EXAMPLES / "force-curve-sls-dwell.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ds = afmdyn.fit(probe=probe, data=str(path))
        t, h, f = np.loadtxt(path, delimiter=",", skiprows=1).T
        cols = afmdyn.fit(probe=probe, data={"height": h, "force": f, "time": t})
    assert list(ds["parameter"].values) == list(cols["parameter"].values)
    np.testing.assert_allclose(ds["estimate"], cols["estimate"], rtol=1e-9)
    truth = {"sample.stiffness": 0.01, "sample.maxwell_stiffness": 0.02,
             "sample.relaxation_time": 0.1}
    for name, value in truth.items():
        e = ds.sel(parameter=name)
        assert float(e["interval_low"]) <= value <= float(e["interval_high"]), name
    assert ds["time"].attrs["units"] == "s" and ds["time"].size == 3001
    assert json.loads(ds.attrs["summary"])["segment"] == "whole"
    # without the times the law cannot run: the error names the column
    with pytest.raises(ValueError, match="time"):
        afmdyn.fit(probe=probe, data={"height": h, "force": f})


def test_the_lever_and_the_samples_viscosity_fit_from_an_am_curve(tmp_path):
    """Issue 62's probe keys on the library's RTESPA-300 over polystyrene (DMT, η = 10 Pa s):
    an AM approach made by ``afmdyn.approach`` (30 rows, z_c = 11 → 5 nm, z = z_c − 1 nm,
    20 pm and 0.1° of seeded noise) fitted for ``sample.viscosity`` (Pa s) and z_offset, and
    for ``cantilever.quality_factor`` and z_offset, by their probe names: the truth (10 Pa s,
    Q = 500, 1 nm) inside each 95 % interval; Q on a Δf curve is refused with the reason, as
    the command line refuses it."""
    probe = str(EXAMPLES / "probe-rtespa300-polystyrene.toml")
    ds = afmdyn.approach(afmdyn.Params.from_probe(probe), probe=probe, from_=11e-9, to=5e-9,
                         points=30, branches=False)
    rng = np.random.default_rng(62)
    zc = ds.z_c.values
    amp = ds.amplitude.sel(sweep="approach").values + 2e-11 * rng.standard_normal(zc.size)
    phase = ds.phase_deg.sel(sweep="approach").values + 0.1 * rng.standard_normal(zc.size)
    path = tmp_path / "am.csv"
    rows = "\n".join(f"{z - 1e-9:.17g},{a:.17g},{p:.17g},2e-11,0.1"
                     for z, a, p in zip(zc, amp, phase))
    path.write_text("z,amplitude,phase,sigma_amplitude,sigma_phase\n" + rows + "\n")
    for name, truth in (("sample.viscosity", 10.0), ("cantilever.quality_factor", 500.0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
            fit = afmdyn.fit(probe=probe, data=str(path), fit=[name, "z_offset"])
        doc = json.loads(fit.attrs["summary"])
        assert doc["kind"] == "am"
        for key, t in ((name, truth), ("z_offset", 1e-9)):
            lo = fit["interval_low"].sel(parameter=key).item()
            hi = fit["interval_high"].sel(parameter=key).item()
            assert lo <= t <= hi, (key, lo, hi)
    fm = tmp_path / "fm.csv"
    fm.write_text("z,frequency_shift\n" + "\n".join(f"{10e-9 - 0.5e-9 * i:.17g},{-i:.17g}"
                                                     for i in range(10)) + "\n")
    with pytest.raises(ValueError, match="does not constrain Q"):
        afmdyn.fit(probe=probe, data=str(fm), fit=["cantilever.quality_factor"])

