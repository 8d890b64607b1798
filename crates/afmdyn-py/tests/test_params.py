"""Params: keywords with the command line's names and the paper's aliases, validation errors
that name the field and its range, config files."""

from __future__ import annotations

import math
import pickle

import pytest

import afmdyn
from afmdyn import Params

from conftest import EXAMPLES

NAMES = {
    "tip_mass_ratio": "alpha1",
    "drive_amplitude": "alpha2",
    "beam_damping": "alpha3",
    "contact_stiffness": "alpha4",
    "gap": "alpha5",
    "contact_damping": "alpha6",
}


def test_defaults_are_the_command_lines(cli_json):
    # the paper's Figs. 5–14 set, as `afmdyn modes` resolves it without flags
    assert Params().to_dict() == cli_json("modes")["params"]
    paper = {
        "modes": 3,
        "alpha1": 0.1,
        "alpha2": 0.1,
        "alpha3": 0.1,
        "alpha4": 20.0,
        "alpha5": 0.0,
        "alpha6": 0.2,
        "omega": 2.6,
    }
    assert {k: Params().to_dict()[k] for k in paper} == paper


@pytest.mark.parametrize("name,alias", NAMES.items())
def test_descriptive_names_and_aliases_set_the_same_field(name, alias, cli_json):
    a = Params(**{name: 0.37})
    b = Params(**{alias: 0.37})
    assert a == b
    assert getattr(a, name) == getattr(a, alias) == 0.37
    # the command line's flag of the same name sets the same value
    flag = "--" + name.replace("_", "-")
    assert cli_json("modes", flag, "0.37")["params"] == a.to_dict()


def test_replace_returns_a_validated_copy():
    p = Params(omega=3.0)
    q = p.replace(omega=4.0, modes=2)
    assert (p.omega, p.modes) == (3.0, 3)
    assert (q.omega, q.modes) == (4.0, 2)
    assert q.alpha4 == p.alpha4
    with pytest.raises(ValueError, match="omega"):
        p.replace(omega=0.0)


def test_params_are_immutable_hashable_by_value_and_picklable():
    p = Params(omega=3.3, modes=4)
    with pytest.raises(AttributeError):
        p.omega = 1.0  # type: ignore[misc]
    assert p == Params(modes=4, omega=3.3)
    assert p != Params(modes=4, omega=3.4)
    assert pickle.loads(pickle.dumps(p)) == p
    assert "omega=3.3" in repr(p) and "modes=4" in repr(p)
    assert math.isclose(p.period, 2 * math.pi / 3.3, rel_tol=1e-15)


@pytest.mark.parametrize(
    "kwargs,field,allowed",
    [
        ({"modes": 0}, "modes", "1..=20"),
        ({"modes": 21}, "modes", "1..=20"),
        ({"modes": -1}, "modes", "1..=20"),
        ({"tip_mass_ratio": -0.1}, "alpha1", ">= 0"),
        ({"alpha2": float("nan")}, "alpha2", ">= 0"),
        ({"beam_damping": -1}, "alpha3", ">= 0"),
        ({"contact_stiffness": float("inf")}, "alpha4", ">= 0"),
        ({"gap": float("nan")}, "alpha5", "finite"),
        ({"contact_damping": -0.2}, "alpha6", ">= 0"),
        ({"omega": 0.0}, "omega", "> 0"),
        ({"omega": -2.6}, "omega", "> 0"),
    ],
)
def test_out_of_range_values_raise_value_error_naming_field_and_range(kwargs, field, allowed):
    with pytest.raises(ValueError) as e:
        Params(**kwargs)
    assert field in str(e.value) and allowed in str(e.value)
    # the same through every analysis' keywords
    with pytest.raises(ValueError, match=field):
        afmdyn.modes(**kwargs)


def test_unknown_keyword_and_wrong_types_raise_type_error():
    with pytest.raises(
        TypeError, match="unknown model parameter 'omegaa'.*tip_mass_ratio \\(alpha1\\)"
    ):
        Params(omegaa=2.0)
    with pytest.raises(TypeError, match="unknown model parameter"):
        afmdyn.simulate(periods=1, stiffness=3.0)
    # 'from' is a Python keyword: the message names from_ (issue 28)
    with pytest.raises(TypeError, match="Python keyword: the start of a range is from_"):
        afmdyn.approach(**{"from": 20e-9}, to=2e-9, points=3)
    with pytest.raises(TypeError, match="omega: expected a number"):
        Params(omega="2.6")
    with pytest.raises(TypeError, match="modes: expected an integer"):
        Params(modes=3.0)
    with pytest.raises(TypeError, match="modes: expected an integer, got bool"):
        Params(modes=True)
    with pytest.raises(TypeError, match="gap: expected a number"):
        Params(gap=None)


def test_a_field_given_twice_is_rejected():
    with pytest.raises(ValueError, match="both given"):
        Params(alpha4=1.0, contact_stiffness=2.0)


def test_integers_are_accepted_for_floats():
    assert Params(omega=3, alpha5=-1).omega == 3.0


def test_keywords_override_a_params_object_in_every_analysis():
    p = Params(modes=2, omega=3.0)
    s = afmdyn.modes(p, modes=4)
    assert s.params == Params(modes=4, omega=3.0)
    assert len(s.free.omega) == 4
    with pytest.raises(TypeError, match="params"):
        afmdyn.modes({"omega": 3.0})  # type: ignore[arg-type]


def test_config_files_read_as_the_command_line_reads_them(cli_json, tmp_path):
    for name in ["fig5.toml", "eq25.toml", "fig15-17-text.toml"]:
        path = EXAMPLES / name
        assert Params.from_toml(path).to_dict() == cli_json("modes", "--config", path)["params"]
    # keywords override the file, as flags do
    p = Params.from_toml(EXAMPLES / "fig5.toml", omega=3.1)
    assert (
        p.to_dict()
        == cli_json("modes", "--config", EXAMPLES / "fig5.toml", "--omega", "3.1")["params"]
    )
    bad = tmp_path / "bad.toml"
    bad.write_text("omega = 2.0\nstiffness = 3.0\n")
    with pytest.raises(TypeError, match=r"bad\.toml.*unknown model parameter 'stiffness'"):
        Params.from_toml(bad)
    bad.write_text("omega = -2.0\n")
    with pytest.raises(ValueError, match=r"bad\.toml.*omega"):
        Params.from_toml(bad)
    with pytest.raises(FileNotFoundError):
        Params.from_toml(tmp_path / "missing.toml")


def test_contact_law_keywords_resolve_as_on_the_command_line(cli_json):
    p = Params(contact_law="impact", restitution=0.5, modes=1, gap=0.05, omega=3.0)
    assert (p.contact_law, p.restitution, p.hamaker) == ("impact", 0.5, None)
    doc = cli_json(
        "modes", "--contact-law", "impact", "--restitution", 0.5, "--modes", 1, "--gap", 0.05,
        "--omega", 3.0,
    )
    assert p.to_dict() == doc["params"]
    # DMT: the groups not given take the library's defaults, as on the command line
    d = Params(contact_law="dmt", hamaker=2e-5)
    assert d.to_dict() == cli_json("modes", "--contact-law", "dmt", "--hamaker", 2e-5)["params"]
    assert d.intermolecular_distance == 0.01
    # a group of the law in force may be changed alone; others are refused, naming both
    assert p.replace(restitution=0.9).restitution == 0.9
    with pytest.raises(ValueError, match="restitution is a group of the impact law"):
        Params(contact_law="hertz", restitution=0.5)
    with pytest.raises(ValueError, match="restitution"):
        Params(contact_law="impact", restitution=1.5)
    with pytest.raises(ValueError, match="contact law 'elastic'"):
        Params(contact_law="elastic")
    with pytest.raises(TypeError, match="contact_law"):
        Params(contact_law=1)
    # the tip-force drive of the beam, as --excitation
    t = Params(excitation="magnetic")
    assert t.excitation == "tip" and Params().excitation == "base"
    assert t.to_dict() == cli_json("modes", "--excitation", "tip")["params"]
    with pytest.raises(ValueError, match="excitation 'laser'"):
        Params(excitation="laser")
    # the electrostatic law: DMT's groups and its own, with their defaults
    e = Params(contact_law="electrostatic")
    assert (e.electrostatic, e.tip_radius, e.hamaker) == (1e-3, 1.0, 1e-5)
    assert e.to_dict() == cli_json("modes", "--contact-law", "electrostatic")["params"]
    with pytest.raises(ValueError, match="electrostatic is a group of the electrostatic law"):
        Params(contact_law="dmt", electrostatic=1e-3)
    with pytest.raises(ValueError, match="tip_radius"):
        Params(contact_law="electrostatic", tip_radius=-1.0)
    # the JKR law: its adhesion group P̃ with its default, as --contact-law jkr --adhesion
    j = Params(contact_law="jkr")
    assert j.adhesion == 0.05 and j.hamaker is None and Params().adhesion is None
    assert j.to_dict() == cli_json("modes", "--contact-law", "jkr")["params"]
    assert (
        Params(contact_law="jkr", adhesion=0.2).to_dict()
        == cli_json("modes", "--contact-law", "jkr", "--adhesion", "0.2")["params"]
    )
    with pytest.raises(ValueError, match="adhesion is a group of the jkr law"):
        Params(contact_law="hertz", adhesion=0.1)
    with pytest.raises(ValueError, match="adhesion"):
        Params(contact_law="jkr", adhesion=0.0)
    # the capillary meniscus: its three groups with their defaults, as on the command line
    c = Params(contact_law="capillary", rupture=0.04)
    assert (c.capillary, c.meniscus, c.rupture) == (0.1, 0.01, 0.04)
    assert c.to_dict() == cli_json("modes", "--contact-law", "capillary", "--rupture", "0.04")[
        "params"
    ]
    with pytest.raises(ValueError, match="meniscus is a group of the capillary law"):
        Params(contact_law="dmt", meniscus=0.01)
    # the standard linear solid: its Maxwell arm κ with its default, the dashpot α6
    s = Params(contact_law="sls")
    assert s.maxwell_stiffness == 20.0 and Params().maxwell_stiffness is None
    assert s.to_dict() == cli_json("modes", "--contact-law", "sls")["params"]
    with pytest.raises(ValueError, match="maxwell_stiffness is a group of the sls law"):
        Params(contact_law="linear", maxwell_stiffness=1.0)
    with pytest.raises(ValueError, match="maxwell_stiffness"):
        Params(contact_law="sls", maxwell_stiffness=0.0)
    with pytest.raises(ValueError, match="alpha6"):
        Params(contact_law="sls", contact_damping=0.0)


def test_every_law_runs_from_python_as_on_the_command_line(cli_json):
    # the orbit document of each law equals the command line's for the same keywords
    for law, extra in [
        ("hertz", {}),
        ("dmt", {}),
        ("electrostatic", {"electrostatic": 2e-3, "tip_radius": 0.5}),
        ("jkr", {"adhesion": 0.02}),
        ("capillary", {"capillary": 0.05, "rupture": 0.04}),
        ("sls", {"maxwell_stiffness": 5.0}),
        ("impact", {"restitution": 0.5}),
    ]:
        model = {"contact_law": law, "modes": 1, "omega": 3.0, "gap": 0.05, **extra}
        args = ["orbit"]
        for k, v in model.items():
            args += ["--" + k.replace("_", "-"), v]
        o = afmdyn.orbit(**model)
        assert o.to_dict() == cli_json(*args), law
        assert o.stable, law


def test_a_misspelt_keyword_gets_the_near_name():
    with pytest.raises(TypeError, match="unknown model parameter 'omgea': did you mean omega?"):
        afmdyn.orbit(omgea=2.0)
    with pytest.raises(TypeError, match="did you mean beam_damping"):
        afmdyn.orbit(beam_dampnig=0.1)
    with pytest.raises(TypeError, match="unknown model parameter 'zzz': expected"):
        afmdyn.orbit(zzz=1.0)
