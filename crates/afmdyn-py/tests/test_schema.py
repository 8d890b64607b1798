"""Every JSON document of the command line (``afmdyn <command> --json``) and of Python
(``to_dict()``, ``summary()``, the dict-returning analyses) conforms to its JSON Schema in
``docs/schema/documents/``, with and without a probe; each schema refuses a document missing a
required key (and, where the keys are fixed, one with a key it does not describe); the request
schemas of ``docs/schema/requests/`` (generated from the Rust types by
``crates/afmdyn/tests/schema.rs``) accept the requests' defaults they carry as ``examples``."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any, Callable, Dict, List, Tuple

import afmdyn
import pytest
from conftest import EXAMPLES, REPO
from jsonschema import Draft202012Validator, ValidationError
from referencing import Registry, Resource

SCHEMA = REPO / "docs" / "schema"
DOCUMENTS = SCHEMA / "documents"
REQUESTS = SCHEMA / "requests"
P1 = str(EXAMPLES / "probe-point-mass-dmt.toml")
P2 = str(EXAMPLES / "probe-geometry-hertz.toml")
EIG = str(EXAMPLES / "probe-eigenmodes-dmt.toml")
BIM = str(EXAMPLES / "probe-bimodal.toml")
STRIPE = str(EXAMPLES / "sample-stripe.toml")
IMAGE = ["--probe", P1, "--sample", STRIPE, "--setpoint", 0.7, "--pixels", 4]
PF = str(EXAMPLES / "probe-peakforce-water.toml")
PF_IMAGE = ["--mode", "peakforce", "--probe", str(EXAMPLES / "probe-peakforce-amo-garcia.toml"),
            "--sample", str(EXAMPLES / "sample-peakforce-blend.toml"), "--setpoint", "2nN",
            "--pixels", 4]
FIT_PROBE = str(EXAMPLES / "probe-fit-hertz.toml")
FIT_DATA = str(EXAMPLES / "force-curve-hertz.csv")
FM_DATA = str(EXAMPLES / "fm-curve-point-mass.csv")
IMPACT = "--contact-law impact --restitution 0.5 --modes 1 --gap 0.05 --omega 3".split()
IMPACT_PY = dict(contact_law="impact", restitution=0.5, modes=1, gap=0.05, omega=3.0)
SHORT = ["--max-periods", 300]

COMMANDS = ["modes", "units", "simulate", "converge", "bifurcation", "attractors", "orbit",
            "continue", "lyapunov", "approach", "resonance", "chart", "basins", "reconstruct",
            "fm", "bimodal", "image", "peakforce", "fit"]
FM = str(EXAMPLES / "fm-vdw.csv")
FM_ARGS = ["--fm", FM, "--spring-constant", 40, "--resonance-frequency", "300kHz",
           "--amplitude", "10nm"]
SHARED = ["params", "si", "converged"]
PYTHON_ONLY = ["observe"]


def _load(path: Path) -> Dict[str, Any]:
    doc: Dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return doc


# the document schemas refer to each other by file name ({"$ref": "si.json"})
REGISTRY: Registry = Registry().with_resources(
    (p.name, Resource.from_contents(_load(p))) for p in DOCUMENTS.glob("*.json")
)


def validator(name: str) -> Draft202012Validator:
    return Draft202012Validator(_load(DOCUMENTS / f"{name}.json"), registry=REGISTRY)


def check(name: str, doc: Dict[str, Any]) -> None:
    errors = sorted(validator(name).iter_errors(doc), key=lambda e: list(e.absolute_path))
    assert not errors, f"{name}: " + "; ".join(
        f"{'/'.join(map(str, e.absolute_path))}: {e.message[:300]}" for e in errors
    )


def plain(doc: Any) -> Any:
    """A Python document as JSON has it (``observe`` returns ``state`` as a NumPy array)."""
    return json.loads(json.dumps(doc, default=lambda o: o.tolist()))


# ------------------------------------------------------------------------ the schema files


def test_one_schema_per_document_and_every_schema_valid() -> None:
    names = sorted(p.stem for p in DOCUMENTS.glob("*.json"))
    assert names == sorted(COMMANDS + SHARED + PYTHON_ONLY)
    for p in [*DOCUMENTS.glob("*.json"), *REQUESTS.glob("*.json")]:
        Draft202012Validator.check_schema(_load(p))


# ------------------------------------------------------------------------ command line

# (schema, arguments); --out is added for the commands that write files
CLI_CASES: List[Tuple[str, List[Any]]] = [
    ("modes", []),
    ("modes", ["--probe", P1]),
    ("modes", ["--probe", P2]),
    ("modes", IMPACT),
    ("modes", ["--sweep", "fig3"]),
    ("units", ["--probe", P1]),
    ("units", ["--config", EXAMPLES / "probe.toml"]),
    # the hysteretic laws' si.contact_hysteresis
    ("units", ["--probe", EXAMPLES / "probe-jkr-polymer.toml"]),
    ("units", ["--probe", EXAMPLES / "probe-capillary-humid.toml"]),
    ("units", ["--probe", EXAMPLES / "probe-water-sls.toml"]),
    ("simulate", ["--periods", 3, "--files", "none"]),
    ("simulate", ["--periods", 3, "--files", "data"]),
    ("simulate", ["--periods", 3, "--files", "none", "--probe", P1]),
    ("simulate", ["--periods", 3, "--files", "none", *IMPACT]),
    ("converge", ["--max-modes", 2]),
    ("converge", ["--max-modes", 2, "--probe", P2]),
    ("bifurcation", ["--steps", 5, *SHORT]),
    ("bifurcation", ["--steps", 5, *SHORT, "--probe", P1]),
    ("attractors", ["--samples", 2, *SHORT]),
    ("attractors", ["--samples", 2, *SHORT, "--probe", P1]),
    ("attractors", ["--samples", 2, *SHORT, *IMPACT]),
    ("attractors", ["--samples", 2, *SHORT, *IMPACT, "--sweep", "omega", "--from", 2.9, "--to", 3, "--steps", 2]),
    ("attractors", ["--samples", 2, *SHORT, "--sweep", "omega", "--from", 2.6, "--to", 2.7, "--steps", 2, "--probe", P1]),
    ("orbit", SHORT),
    ("orbit", [*SHORT, "--probe", P2]),
    ("orbit", [*SHORT, *IMPACT]),
    ("continue", [*SHORT, "--from", 3, "--to", 2.5]),
    ("continue", [*SHORT, "--probe", P1]),
    ("lyapunov", ["--transient", 10, "--periods", 20, "--blocks", 2]),
    ("lyapunov", ["--transient", 10, "--periods", 20, "--blocks", 2, "--probe", P1]),
    ("lyapunov", ["--transient", 10, "--periods", 20, "--blocks", 2, *IMPACT]),
    ("approach", ["--points", 5, "--no-branches", "--files", "none"]),
    ("approach", ["--points", 5, "--files", "none"]),
    ("approach", ["--points", 5, "--no-branches", "--files", "none", "--probe", P1]),
    ("approach", ["--points", 9, "--files", "none", "--setpoint", 0.8, "--probe", P1]),
    ("approach", ["--points", 3, "--no-branches", "--files", "none", "--traces", 8, "--probe", P1]),
    ("approach", ["--points", 9, "--files", "none", "--setpoint", 0.8, "--probe", P1,
                  "--temperature", 295]),
    ("resonance", ["--points", 5, "--no-branches", "--files", "none"]),
    ("resonance", ["--points", 5, "--no-branches", "--files", "none", "--probe", P1]),
    ("chart", ["--x-steps", 2, "--y-steps", 1, "--starts", 1, "--lyapunov-periods", 20, *SHORT]),
    ("basins", ["--x-steps", 3, "--y-steps", 2, *SHORT, *IMPACT]),
    ("basins", ["--x-steps", 2, "--y-steps", 1, *SHORT, "--probe", P1]),
    ("reconstruct", FM_ARGS),
    ("fm", ["--points", 4]),
    ("fm", ["--points", 4, "--probe", P1]),
    ("fm", ["--points", 4, "--mode", 2, "--probe", EIG]),
    # the thermal block and the curve's noise columns
    ("fm", ["--points", 3, "--probe", P1, "--temperature", 295, "--bandwidth", "50Hz"]),
    ("approach", ["--points", 4, "--no-branches", "--files", "none", "--probe", EIG]),
    ("bimodal", ["--points", 4, "--files", "none", "--probe", BIM]),
    ("bimodal", ["--points", 2, "--files", "none", "--average", "--probe", BIM]),
    # each component's lock-in noise, in the sweeps and at the operating points
    ("bimodal", ["--points", 4, "--files", "none", "--probe", BIM, "--temperature", 295,
                 "--setpoint", 0.8]),
    ("image", IMAGE),
    ("image", [*IMAGE, "--setpoint-study", "0.3:0.9:3"]),
    ("image", [*IMAGE, "--feedback", "pi", "--scan-rate", 20]),
    # the noise maps, each material's engaged noise and the thermal block
    ("image", [*PF_IMAGE, "--temperature", 295]),
    ("image", PF_IMAGE),
    ("peakforce", ["--probe", PF]),
    # the thermal block, and the noise channels of a sweep
    ("peakforce", ["--probe", PF, "--temperature", 295, "--from", "90nm", "--to", "89nm",
                   "--step", "1nm", "--thermal-cycles", 100, "--files", "none"]),
    ("fit", ["--probe", FIT_PROBE, "--data", FIT_DATA, "--fit", "sample.youngs_modulus,contact_point",
             "--files", "data"]),
    ("fit", ["--probe", FIT_PROBE, "--data", FIT_DATA, "--fit", "sample.youngs_modulus",
             "--range", "-2e-7,0", "--files", "none"]),
    # the SLS in time: an approach, a dwell and a retract with the rows' times
    ("fit", ["--probe", str(EXAMPLES / "probe-fit-sls.toml"), "--data",
             str(EXAMPLES / "force-curve-sls-dwell.csv"), "--files", "data"]),
    # a dynamic curve's form: the frequency shift of the FM loop against z
    ("fit", ["--probe", P1, "--data", FM_DATA, "--fit", "sample.hamaker,z_offset",
             "--files", "none"]),
    # (a probe refuses the dimensionless omega axis: the drive frequency in Hz, 0.99 f0)
    ("chart", ["--x", "z-c", "--x-from", 6e-9, "--x-to", 8e-9, "--x-steps", 2, "--y",
               "drive-frequency", "--y-from", "297kHz", "--y-to", "297kHz", "--y-steps", 1,
               "--starts", 1, *SHORT, "--probe", P1]),
]
WRITES = {"simulate", "converge", "bifurcation", "attractors", "continue", "chart", "basins",
          "reconstruct", "fm", "image", "peakforce", "fit"}


@pytest.fixture(scope="module")
def cli_docs(
    cli_json: Callable[..., Dict[str, Any]], tmp_path_factory: pytest.TempPathFactory
) -> List[Tuple[str, List[Any], Dict[str, Any]]]:
    """The document of every case, run once (the refusal tests reuse them)."""
    out = []
    for k, (name, args) in enumerate(CLI_CASES):
        writes = name in WRITES or "--sweep" in args
        extra = ["--out", tmp_path_factory.mktemp(f"{name}{k}")] if writes else []
        out.append((name, args, cli_json(name, *args, *extra)))
    return out


def test_every_command_has_a_case() -> None:
    assert {name for name, _ in CLI_CASES} == set(COMMANDS)


@pytest.mark.parametrize("k", range(len(CLI_CASES)), ids=lambda k: " ".join(
    [CLI_CASES[k][0], *(Path(str(a)).name for a in CLI_CASES[k][1])]))
def test_cli_documents_conform(cli_docs: List[Tuple[str, List[Any], Dict[str, Any]]], k: int) -> None:
    name, args, doc = cli_docs[k]
    check(name, doc)
    # (an image is in SI throughout: no si block of scales)
    assert ("si" in doc) == ("--probe" in args and name != "image"), "an si block exactly with a probe"


# ------------------------------------------------------------------------ Python


def _python_docs() -> List[Tuple[str, str, Callable[[], Any]]]:
    sim = dict(periods=3)
    lyap = dict(transient=10, periods=20, blocks=2)
    curve = dict(points=5, branches=False)
    return [
        ("modes", "modes", lambda: afmdyn.modes().to_dict()),
        ("modes", "modes probe", lambda: afmdyn.modes(probe=P2).to_dict()),
        ("units", "probe()", lambda: (lambda p: {"params": p["params"].to_dict(), "si": p["si"]})(
            afmdyn.probe(P1))),
        ("simulate", "simulate", lambda: afmdyn.summary(afmdyn.simulate(**sim))),
        ("simulate", "simulate probe", lambda: afmdyn.summary(afmdyn.simulate(probe=P1, **sim))),
        ("simulate", "simulate probe z_c", lambda: afmdyn.summary(
            afmdyn.simulate(probe=P1, z_c=5e-9, **sim))),
        ("converge", "converge", lambda: afmdyn.summary(afmdyn.converge(max_modes=2))),
        ("converge", "converge probe", lambda: afmdyn.summary(
            afmdyn.converge(max_modes=2, probe=P2))),
        ("attractors", "attractors", lambda: afmdyn.attractors(
            samples=2, max_periods=300).to_dict()),
        ("attractors", "attractors probe", lambda: afmdyn.attractors(
            samples=2, max_periods=300, probe=P1).to_dict()),
        ("attractors", "attractors impact", lambda: afmdyn.attractors(
            samples=2, max_periods=300, **IMPACT_PY).to_dict()),
        ("basins", "basins", lambda: afmdyn.summary(afmdyn.basins(
            x_steps=3, y_steps=2, max_periods=300, **IMPACT_PY))),
        ("attractors", "global continuation", lambda: afmdyn.summary(afmdyn.global_continuation(
            samples=2, max_periods=300, from_=2.9, to=3.0, steps=2, **IMPACT_PY))),
        ("orbit", "orbit", lambda: afmdyn.orbit(max_periods=300).to_dict()),
        ("orbit", "orbit probe", lambda: afmdyn.orbit(max_periods=300, probe=P2).to_dict()),
        ("continue", "continuation", lambda: afmdyn.summary(
            afmdyn.continuation(from_=3.0, to=2.5, max_periods=300))),
        ("lyapunov", "lyapunov", lambda: afmdyn.lyapunov(**lyap).to_dict()),
        ("lyapunov", "lyapunov probe", lambda: afmdyn.lyapunov(probe=P1, **lyap).to_dict()),
        ("approach", "approach", lambda: afmdyn.summary(afmdyn.approach(**curve))),
        ("approach", "approach probe", lambda: afmdyn.summary(afmdyn.approach(probe=P1, **curve))),
        ("resonance", "resonance", lambda: afmdyn.summary(afmdyn.resonance(**curve))),
        ("resonance", "resonance probe z_c", lambda: afmdyn.summary(afmdyn.resonance(
            probe=P1, z_c=7e-9, **curve))),
        ("observe", "observe", lambda: afmdyn.summary(afmdyn.observe())),
        ("observe", "observe probe", lambda: afmdyn.summary(afmdyn.observe(probe=P1))),
        ("observe", "observe impact", lambda: afmdyn.summary(afmdyn.observe(**IMPACT_PY))),
        ("observe", "observe probe bimodal", lambda: afmdyn.summary(
            afmdyn.observe(probe=BIM, z_c=9e-9))),
        ("reconstruct", "reconstruct", lambda: afmdyn.summary(afmdyn.reconstruct(
            **_fm_curve(), spring_constant=40.0, resonance_frequency=3e5, amplitude=1e-8))),
        ("fm", "fm", lambda: afmdyn.summary(afmdyn.fm(points=4))),
        ("fm", "fm probe", lambda: afmdyn.summary(afmdyn.fm(points=4, probe=P1))),
        ("bimodal", "bimodal probe", lambda: afmdyn.summary(afmdyn.bimodal(probe=BIM, **curve))),
        # an image is in SI throughout (its label names no probe: no si block)
        ("image", "image", lambda: _quiet(lambda: afmdyn.summary(
            afmdyn.image(P1, STRIPE, 0.7, pixels=4)))),
        ("image", "image pi", lambda: _quiet(lambda: afmdyn.summary(afmdyn.image(
            P1, STRIPE, 0.7, pixels=4, feedback="pi", scan_rate=20.0, progress=False)))),
        ("peakforce", "peakforce probe", lambda: afmdyn.summary(afmdyn.peakforce(probe=PF))),
        ("fit", "fit probe", lambda: _quiet(lambda: afmdyn.summary(afmdyn.fit(
            probe=FIT_PROBE, data=FIT_DATA, fit=["sample.youngs_modulus", "contact_point"])))),
    ]


def _quiet(run: Callable[[], Any]) -> Any:
    """``run()`` with afmdyn's warnings (an image's regime switches) silenced."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        return run()


def _fm_curve() -> Dict[str, Any]:
    import csv

    with open(FM, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in ("distance", "frequency_shift")}


PY_CASES = _python_docs()


@pytest.mark.parametrize("k", range(len(PY_CASES)), ids=lambda k: PY_CASES[k][1])
def test_python_documents_conform(k: int) -> None:
    name, label, run = PY_CASES[k]
    doc = plain(run())
    check(name, doc)
    assert ("si" in doc) == ("probe" in label or name == "units")


def test_every_python_document_has_a_case() -> None:
    py = {name for name, _, _ in PY_CASES}
    # bifurcation and chart have no document in Python (datasets); observe none on the
    # command line
    assert py == (set(COMMANDS) - {"bifurcation", "chart"}) | set(PYTHON_ONLY)


def test_one_attractor_conforms() -> None:
    """``Attractor.to_dict()`` is one entry of the attractors document."""
    found = afmdyn.attractors(samples=2, max_periods=300)
    schema = {"$ref": "attractors.json#/$defs/attractor"}
    v = Draft202012Validator(schema, registry=REGISTRY)
    for a in found:
        v.validate(a.to_dict())


# ------------------------------------------------------------------------ refusals


def _required_paths(schema: Dict[str, Any], doc: Dict[str, Any]) -> List[str]:
    """The required keys of ``doc`` (of the form it has, for ``modes`` and ``units``)."""
    if "allOf" in schema:  # a document that extends another (bimodal: approach's)
        (ref,) = [s["$ref"] for s in schema["allOf"]]
        return _required_paths(_load(DOCUMENTS / ref), doc) + list(schema["required"])
    forms = schema.get("oneOf", [schema])
    (form,) = [f for f in forms if set(f["required"]) <= set(doc) <= set(f["properties"])]
    return list(form["required"])


def test_each_schema_refuses_a_missing_key_and_an_unknown_one(
    cli_docs: List[Tuple[str, List[Any], Dict[str, Any]]],
) -> None:
    seen = set()
    for name, _, doc in cli_docs:
        schema = _load(DOCUMENTS / f"{name}.json")
        v = validator(name)
        for key in _required_paths(schema, doc):
            broken = copy.deepcopy(doc)
            del broken[key]
            with pytest.raises(ValidationError):
                v.validate(broken)
        if schema.get("additionalProperties") is False or "oneOf" in schema or "allOf" in schema:
            broken = dict(doc, unexpected_key=1)
            with pytest.raises(ValidationError):
                v.validate(broken)
        # the shared parts: params in every document, si with a probe, converged
        for part, key in [("params", "omega"), ("si", "scales"), ("converged", "settled")]:
            if part in doc:
                broken = copy.deepcopy(doc)
                del broken[part][key]
                with pytest.raises(ValidationError):
                    v.validate(broken)
                broken = copy.deepcopy(doc)
                broken[part]["unexpected_key"] = 1
                with pytest.raises(ValidationError):
                    v.validate(broken)
                seen.add(part)
        seen.add(name)
    assert seen == set(COMMANDS + SHARED)


def test_observe_schema_refuses_a_missing_key() -> None:
    doc = afmdyn.summary(afmdyn.observe())
    v = validator("observe")
    for key in ["amplitude", "closed_form", "state", "period"]:
        broken = dict(doc)
        del broken[key]
        with pytest.raises(ValidationError):
            v.validate(broken)
    with pytest.raises(ValidationError):
        v.validate(dict(doc, unexpected_key=1))


def test_fixed_shapes_are_enforced(cli_docs: List[Tuple[str, List[Any], Dict[str, Any]]]) -> None:
    """Multipliers are [re, im] pairs; enums are closed."""
    orbit = next(d for n, _, d in cli_docs if n == "orbit")
    broken = copy.deepcopy(orbit)
    broken["multipliers"][0] = broken["multipliers"][0][:1]
    with pytest.raises(ValidationError):
        validator("orbit").validate(broken)
    broken = dict(orbit, critical="saddle-node")
    with pytest.raises(ValidationError):
        validator("orbit").validate(broken)


# ------------------------------------------------------------------------ requests

REQUEST_NAMES = sorted(p.stem for p in REQUESTS.glob("*.json"))


def test_every_request_has_a_schema() -> None:
    assert REQUEST_NAMES == sorted(
        ["model", "steady", "integrator", "start", "orbit", "continuation", "lyapunov",
         "attractors", "observe", "converge", "simulate", "bifurcation", "curve", "modes",
         "approach", "resonance", "chart", "global_continuation", "basins", "reconstruct",
         "fm", "image", "image_scan", "image_options", "peakforce", "fit", "fit_map",
         "thermal", "calibrate"]
    )


@pytest.mark.parametrize("name", REQUEST_NAMES)
def test_request_schema_accepts_the_default_and_refuses_unknown_keys(name: str) -> None:
    schema = _load(REQUESTS / f"{name}.json")
    v = Draft202012Validator(schema)
    (default,) = schema["examples"]  # serde_json of Default::default(), written by schema.rs
    v.validate(default)
    with pytest.raises(ValidationError):
        v.validate(dict(default, unexpected_key=1))
    # a key of the wrong type: an object for the first property (modes has none)
    if not schema.get("properties"):
        return
    key = next(iter(schema["properties"]))
    with pytest.raises(ValidationError):
        v.validate(dict(default, **{key: {"wrong": "type"}}))


def test_quasiperiodic_bimodal_document_conforms(tmp_path: Path) -> None:
    """A quasi-periodic drive (f2/f1 = 6.25 + √2·1e-2: no fraction with q ≤ 1000 within 1e-6)
    through Python: its ratio [p, q] has p beyond 1e6, its points are time averages with the
    ``time_average`` block, and the document conforms to bimodal.json; the warning names it."""
    f2 = 300e3 * (6.25 + 2 ** 0.5 * 1e-2)
    text = _bim_text().replace("frequency = [300e3, 1.875e6]  ", f"frequency = [300e3, {f2!r}]")
    text = text.replace("quality_factor = [400, 2500]", "quality_factor = [60, 300]")
    probe = tmp_path / "quasi.toml"
    probe.write_text(text, encoding="utf-8")
    with pytest.warns(afmdyn.AfmdynWarning, match="quasi-periodic"):
        ds = afmdyn.bimodal(probe=str(probe), from_=11e-9, to=10e-9, points=2)
    doc = afmdyn.summary(ds)
    assert doc["si"]["drive_components"][0]["ratio"][1] > 1000
    assert len(doc["time_average"]["approach"]["settled"]) == 2
    check("bimodal", plain(doc))


def _bim_text() -> str:
    return Path(BIM).read_text(encoding="utf-8")
