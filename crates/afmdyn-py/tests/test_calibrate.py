"""``afmdyn.calibrate`` (issue 79 item 2): a measured thermal spectrum against independent
calculations written here — the harmonic oscillator's spectrum (Hutter & Bechhoefer 1993) with
the scatter of an averaged spectrum, fitted by SciPy's ``curve_fit`` beside afmdyn; Sader's
method k = 0.1906 ρb²LQΓ_i(Re)ω² (Sader, Chon & Mulvaney 1999, eq. 4) with the hydrodynamic
function from SciPy's Bessel functions and Sader's (1998) rational correction for the
rectangle, on the peak afmdyn fitted; refusals naming the option."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import curve_fit
from scipy.special import kv

import afmdyn

EX = Path(__file__).resolve().parents[3] / "examples"
KT = 1.380649e-23 * 295.0


def sho(f, p, f0, q, b):
    """The oscillator's one-sided PSD on a white floor."""
    return p * f0 ** 4 / ((f ** 2 - f0 ** 2) ** 2 + (f * f0 / q) ** 2) + b


def gamma_i(re: float) -> float:
    """Im Γ_rect(Re): Γ_circ = 1 + 4K₁(z)/(zK₀(z)), z = −i√(iRe), times Sader's (1998) Ω."""
    z = -1j * np.sqrt(1j * re)
    circ = 1 + 4 * kv(1, z) / (z * kv(0, z))
    t = np.log10(re)
    omega_r = np.polyval([0.00069085, -0.0035117, 0.044055, -0.12886, 0.46842, -0.48274,
                          0.91324], t) / np.polyval(
        [0.00069085, -0.0035862, 0.045155, -0.13444, 0.48690, -0.56964, 1.0], t)
    omega_i = np.polyval([-0.000044510, 0.000064577, -0.00010961, 0.016294, -0.029256,
                          -0.024134], t) / np.polyval(
        [0.0028361, -0.014369, 0.079156, -0.18357, 0.55182, -0.59702, 1.0], t)
    return float((complex(omega_r, omega_i) * circ).imag)


@pytest.mark.filterwarnings("ignore::afmdyn.AfmdynWarning")
def test_an_averaged_spectrum_agrees_with_scipys_fit():
    """The point-mass probe (k = 40 N/m, f₀ = 300 kHz, Q = 400): a spectrum averaged over 64
    records (a fixed seed) fitted by afmdyn and by ``curve_fit`` on relative residuals: the
    same k_B T/⟨x²⟩ within 0.2 of afmdyn's standard error, and k within 4 standard errors of
    the 40 N/m written."""
    k, f0, q = 40.0, 300e3, 400.0
    f = np.linspace(280e3, 320e3, 4000)
    p = 2 * KT / (np.pi * k * f0 * q)
    clean = sho(f, p, f0, q, 1e-3 * p)
    rng = np.random.default_rng(5)
    s = clean * rng.gamma(64, 1 / 64, size=f.size)
    ds = afmdyn.calibrate(probe=str(EX / "probe-point-mass-dmt.toml"), frequency=f,
                          spectral_density=s, signal="deflection")
    doc = json.loads(ds.attrs["summary"])
    m = doc["modes"][0]
    first, _ = curve_fit(sho, f, s, p0=[p, f0, q, 1e-3 * p], sigma=s, maxfev=20000)
    best, _ = curve_fit(sho, f, s, p0=first, sigma=sho(f, *first), maxfev=20000)
    k_scipy = KT / (np.pi / 2 * best[0] * best[1] * best[2])
    se = m["spring_constant_thermal_standard_error"]
    assert abs(m["spring_constant_thermal"] - k_scipy) < 0.2 * se, (m, k_scipy)
    assert abs(m["spring_constant_thermal"] - k) < 4 * se
    assert m["spring_constant_sader"] is None
    assert ds["fitted"].notnull().sum() > 100
    assert ds["modes_quality_factor"].values[0] == pytest.approx(m["quality_factor"])


@pytest.mark.filterwarnings("ignore::afmdyn.AfmdynWarning")
def test_saders_method_is_the_published_formula(tmp_path):
    """The soft lever in water (450 × 50 µm, examples/probe-water-beam.toml): its model
    spectrum (``afmdyn.thermal``) written as a CSV and calibrated; the first mode's Sader
    estimate equals 0.1906 ρb²LQΓ_i(Re)ω² of the peak afmdyn fitted (water: ρ = 997.05 kg/m³,
    η = 0.890 mPa s) within 1e-3, and the static k of the thermal method the probe's within
    0.5 %."""
    probe = str(EX / "probe-water-beam.toml")
    th = afmdyn.thermal(probe=probe, to=150e3, points=20000)
    csv = tmp_path / "psd.csv"
    np.savetxt(csv, np.column_stack([th["frequency"], th["apparent_deflection"]]),
               delimiter=",", header="frequency,psd", comments="")
    doc = json.loads(afmdyn.calibrate(probe=probe, psd=str(csv)).attrs["summary"])
    m = doc["modes"][0]
    rho, eta, b, length = 997.05, 8.90e-4, 50e-6, 450e-6
    w = 2 * np.pi * m["frequency"]
    want = 0.1906 * rho * b ** 2 * length * m["quality_factor"] * gamma_i(
        rho * w * b ** 2 / (4 * eta)) * w ** 2
    assert m["static_spring_constant_sader"] == pytest.approx(want, rel=1e-3)
    assert doc["spring_constant"]["thermal"] == pytest.approx(th.attrs["spring_constant"],
                                                              rel=5e-3)


def test_bad_options_are_refused_naming_them():
    probe = str(EX / "probe-point-mass-dmt.toml")
    f = np.linspace(250e3, 350e3, 100)
    with pytest.raises(ValueError, match="psd"):
        afmdyn.calibrate(probe=probe)
    with pytest.raises(ValueError, match="psd"):
        afmdyn.calibrate(probe=probe, frequency=f, spectral_density=-np.ones_like(f))
    with pytest.raises(ValueError, match="volts"):
        afmdyn.calibrate(probe=probe, frequency=f, spectral_density=np.ones_like(f), volts=True)
