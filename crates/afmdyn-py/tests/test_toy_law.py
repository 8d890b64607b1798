"""The toy contact law from Python (issue 76: a new law with a new group costs its file and one
registry line, Python included). The law (`crates/afmdyn/src/contact/spring_adhesion.rs`, a
linear spring with a constant adhesion force, F_c = α4 δ + α6 δ̇ − F̃_ad in contact) does not
ship: it is compiled only with the feature ``toy-law``. ``scripts/test.sh`` builds a second
wheel of the extension with it and runs this file against that wheel with
``AFMDYN_TOY_LAW=1``; the ordinary run (the shipped extension) skips it. Nothing in the Python
package names the law or its group: the keywords below reach it through the registry."""

from __future__ import annotations

import os

import numpy as np
import pytest

import afmdyn

if os.environ.get("AFMDYN_TOY_LAW") != "1":
    pytest.skip("needs the extension built with the toy law (feature toy-law): scripts/test.sh "
                "runs this file against such a wheel", allow_module_level=True)

LAW = "spring_adhesion"
GROUP = "toy_adhesion"
MODEL = {"modes": 1, "omega": 3.0, "gap": 0.05}


def test_the_law_and_its_group_are_keywords():
    # the group has its registry default and range, and is refused on another law, as every
    # group is
    assert getattr(afmdyn.Params(contact_law=LAW), GROUP) == 0.1
    p = afmdyn.Params(contact_law=LAW, **{GROUP: 0.3})
    assert p.to_dict()["contact_law"] == {"law": LAW, GROUP: 0.3}
    with pytest.raises(ValueError, match=f"{GROUP} is a group of the {LAW} law"):
        afmdyn.Params(contact_law="hertz", **{GROUP: 0.1})
    with pytest.raises(ValueError, match=GROUP):
        afmdyn.Params(contact_law=LAW, **{GROUP: -1.0})


def test_without_adhesion_it_is_the_linear_law():
    # a defining identity: with F̃_ad = 0 the toy law is the paper's spring–damper (eqs. 16–18),
    # which `linear` propagates exactly; the toy law's orbit comes from another integrator
    toy = afmdyn.orbit(contact_law=LAW, **{GROUP: 0.0}, **MODEL)
    linear = afmdyn.orbit(contact_law="linear", **MODEL)
    assert toy.stable and linear.stable
    np.testing.assert_allclose(toy.state, linear.state, rtol=1e-6, atol=1e-8)


def test_the_simulated_contact_force_is_the_law():
    # along a trajectory, in contact (V_T ≤ 0, the indentation δ = −V_T, δ̇ = −V̇_T):
    # F_c = α4 δ + α6 δ̇ − F̃_ad
    p = afmdyn.Params(contact_law=LAW, **{GROUP: 0.5}, **MODEL)
    ds = afmdyn.simulate(p, periods=4, samples_per_period=400)
    a = p.to_dict()
    touch = ds.in_contact.values.astype(bool)
    assert touch.any() and not touch.all()
    delta = -ds.v_t.values[touch]
    rate = -ds.v_t_dot.values[touch]
    law = a["alpha4"] * delta + a["alpha6"] * rate - 0.5
    np.testing.assert_allclose(ds.contact_force.values[touch], law, rtol=1e-9, atol=1e-9)
    assert np.all(ds.contact_force.values[~touch] == 0.0)
