"""modes(): the spectra of eqs. 19–23 against closed forms and the command line."""

from __future__ import annotations

import numpy as np
import pytest

import afmdyn

# clamped–free beam: β_i L roots of 1 + cos β cosh β = 0
BETA = np.array([1.875104068711961, 4.694091132974175, 7.854757438237613])


def test_to_dict_is_the_command_lines_document(cli_json):
    assert afmdyn.modes().to_dict() == cli_json("modes")
    args = {"modes": 5, "alpha3": 0, "alpha6": 0}
    assert afmdyn.modes(**args).to_dict() == cli_json(
        "modes", "--modes", 5, "--alpha3", 0, "--alpha6", 0
    )


def test_paper_eq25_contact_frequencies():
    s = afmdyn.modes(modes=5, beam_damping=0, contact_damping=0)
    assert s.contact.omega[:3].round(2).tolist() == [7.79, 20.33, 55.81]


def test_closed_forms_without_tip_mass():
    # α1 = 0: the Galerkin modes are the beam's own, ω_i = β_i² exactly
    s = afmdyn.modes(modes=3, alpha1=0, alpha3=0, alpha6=0)
    np.testing.assert_allclose(s.free.omega, BETA**2, rtol=1e-12)
    # one mode in contact: ω² = β₁⁴ + α4 φ₁(1)² with φ₁(1)² = 4
    s = afmdyn.modes(modes=1, alpha1=0, alpha3=0.1, alpha6=0, alpha4=20)
    np.testing.assert_allclose(s.contact.omega, [np.sqrt(BETA[0] ** 4 + 4 * 20)], rtol=1e-12)
    # damping α3 on one mode: λ = −α3/2 ± i √(ω² − α3²/4)
    lam = s.free.eigenvalues[0]
    assert lam.real == pytest.approx(-0.05, rel=1e-12)
    assert lam.imag == pytest.approx(np.sqrt(BETA[0] ** 4 - 0.0025), rel=1e-12)
    assert s.free.zeta[0] == pytest.approx(0.05 / abs(lam), rel=1e-12)


def test_dtypes_and_shapes():
    s = afmdyn.modes(modes=4)
    for r in (s.free, s.contact):
        assert r.omega.dtype == np.float64 and r.omega.shape == (4,)
        assert r.eigenvalues.dtype == np.complex128 and r.eigenvalues.shape == (4,)
        assert r.zeta.dtype == np.float64 and r.zeta.shape == (4,)
        assert np.all(np.diff(r.omega) > 0)
        assert np.all(r.eigenvalues.imag >= 0)
    assert s.params.modes == 4
    assert "Spectrum(free" in repr(s)
    d = s.to_dict()
    d["free"]["omega"] = []  # to_dict returns a fresh copy each time
    assert len(s.to_dict()["free"]["omega"]) == 4
