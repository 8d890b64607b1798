"""``afmdyn.thermal`` (issue 79 item 1): the free lever's thermal spectrum against closed forms —
a point-mass probe's PSD is the simple harmonic oscillator's (Hutter & Bechhoefer 1993,
S(f) = 2k_BT/(πkf₀Q) / ((1 − r²)² + r²/Q²), written here) from Q = 2 (water) to 20 000
(vacuum), its area k_B T/k (equipartition), a uniform beam's first-mode optical-lever factor
0.817 (Butt & Jaschke 1995); a missing probe refused naming it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import afmdyn

EX = Path(__file__).resolve().parents[3] / "examples"
KT = 1.380649e-23 * 295.0


@pytest.mark.filterwarnings("ignore::afmdyn.AfmdynWarning")
@pytest.mark.parametrize("q", [2.0, 400.0, 20000.0])
def test_a_point_mass_is_the_harmonic_oscillator(q):
    text = (EX / "probe-point-mass-dmt.toml").read_text().replace(
        "quality_factor = 400", f"quality_factor = {q}")
    k, f0 = 40.0, 300e3
    ds = afmdyn.thermal(probe=text, to=3 * f0, points=3000)
    f = ds["frequency"].values
    r = f / f0
    want = 2 * KT / (np.pi * k * f0 * q) / ((1 - r ** 2) ** 2 + (r / q) ** 2)
    np.testing.assert_allclose(ds["deflection"].values, want, rtol=1e-9)
    np.testing.assert_allclose(ds["modes_mean_square_deflection"].values, [KT / k], rtol=1e-12)
    assert ds.attrs["spring_constant"] == pytest.approx(k, rel=1e-12)
    if q == 2.0:
        # a broad peak: its area on a fine grid up to 300 f₀ is k_B T/k (the tail beyond, ~1e-7)
        ds = afmdyn.thermal(probe=text, to=300 * f0, points=3_000_000)
        area = np.trapezoid(ds["deflection"].values, ds["frequency"].values)
        assert area == pytest.approx(KT / k, rel=1e-3)


def test_the_optical_levers_factor_of_the_first_mode_is_butt_and_jaschkes():
    ds = afmdyn.thermal(probe=str(EX / "probe-beam-dmt.toml"), points=16)
    assert float(ds["modes_optical_lever_factor"][0]) == pytest.approx(0.817, abs=5e-4)
    assert float(ds["modes_deflection_factor"][0]) == pytest.approx(0.971, abs=5e-4)


def test_a_missing_probe_is_refused_naming_it():
    with pytest.raises(ValueError, match="probe"):
        afmdyn.thermal()
