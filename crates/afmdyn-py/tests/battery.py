"""The reliability battery of issue 27: inputs generated over the classes users hit (command-line
flags at the edges of their ranges and beyond, mutated probe files, Python keywords of the wrong
type or value), each run in its own process with a time and a memory cap, and each outcome
classified:

* ``ok`` — exit 0 (Python: returned), or a refusal that names the input in one line: exit 2 /
  ``ValueError`` / ``TypeError``, or a failure with its cause: exit 1 / ``SimulationError``;
* ``hang`` — over the time cap; ``memory`` — over the memory cap; ``crash`` — a panic, a signal,
  or an exit code without a meaning; ``unclear`` — a message that is not one line starting with
  ``afmdyn:``, that leaks a crate's internals or prints a number of 17 or more digits, an exit
  code other than the one its class means, or (Python) an exception of another type, or a
  ``TypeError``/``ValueError`` that does not name the keyword.

The classes: model flags at and beyond their ranges on every command and law (``cli``); probe
files with a key mutated (``probe``); Python keywords of the wrong type or value (``python``);
and the faults of issue 42's outside battery (``fault``, each with the exit code it must give):
non-finite model values of ``chart``; integrator tolerances NaN, 0, negative, ≥ 1e-3 or below
1e-16 for every law; input files without end or not text (``--probe /dev/zero``,
``--config /dev/urandom``, ``continue --overlay /dev/zero``, a binary probe file, Python
``probe="/dev/zero"``); budgets checked up front (``approach --traces`` memory, a chart's
integrator budget, exit 2 as in ``attractors``); a missing ``--overlay`` (exit 2); writes to a full
device (``> /dev/full``: exit 1 naming standard output); the contact law's name in capitals in a
config file (exit 0); Python numbers beyond a double (``cluster_tol=10**400``: ``ValueError``
naming it); a quality factor of 1e308 (exit 2 naming ``quality_factor``); and issue 60's
classes: an image beyond its memory budget refused before any work (``--pixels 2048``),
``reconstruct --fm/--am /dev/zero``, an SI amplitude beyond its physical range, ``--modes``
against an eigenmode probe's own modes, and off-resonance tapping's exclusive ``--z-c`` and
``--setpoint`` and a modulation frequency beyond 1 MHz (each exit 2 naming the input); and
issue 62's force-curve fit: ``fit --data /dev/zero``, a parameter the law does not have, a
reversed ``--range``, and in Python too few rows and an unknown parameter; and issue 77's: a
PeakForce image no material reaches (exit 1), a filter cut-off and a peak-force setpoint out of
reach, a tapping request on an off-resonance probe, a column named twice, a sub-atomic tip
radius (exit 2 naming each), and Python keywords of the wrong type (``data=5``,
``spring_constant='40'``).

The cases are a pure function of the seed, so a run is reproducible. ``test_battery.py`` runs a
bounded slice in the test command; ``scripts/battery.sh`` runs the whole battery and rewrites
``docs/reliability.md`` with the counts.
"""

from __future__ import annotations

import json
import os
import random
import re
import resource
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence, Tuple

REPO = Path(__file__).resolve().parents[3]
PROBES = [REPO / "examples" / "probe-point-mass-dmt.toml", REPO / "examples" / "probe-beam-dmt.toml"]
PEAKFORCE = REPO / "examples" / "probe-peakforce-air.toml"
FIT_PROBE = REPO / "examples" / "probe-fit-hertz.toml"
FIT_DATA = REPO / "examples" / "force-curve-hertz.csv"

#: values at and beyond the edges of every range (as a user would type them)
EXTREMES = [
    "0", "-0", "1e-300", "1e-12", "0.5", "1", "3", "1e6", "1e12", "1e300",
    "-1", "-1e6", "-5e-1", "nan", "inf", "-inf", "abc", "5e",
]
FLAGS = [
    "--gap", "--contact-stiffness", "--hamaker", "--intermolecular-distance", "--restitution",
    "--omega", "--tip-mass-ratio", "--drive-amplitude", "--beam-damping", "--contact-damping",
    "--modes", "--z-c", "--drive-frequency",
]
LAWS = ["linear", "hertz", "dmt", "impact"]
#: cheap versions of every command (the caps bound them anyway)
COMMANDS = [
    ["orbit", "--max-periods", "200"],
    ["attractors", "--samples", "2", "--max-periods", "200", "--out", "{out}"],
    ["lyapunov", "--periods", "100", "--transient", "20"],
    ["continue", "--from", "2.8", "--to", "2.7", "--max-periods", "200", "--out", "{out}"],
    ["simulate", "--periods", "3", "--files", "none"],
    ["modes"],
    ["bifurcation", "--steps", "2", "--max-periods", "200", "--out", "{out}"],
]
CURVES = [
    ["approach", "--points", "3", "--no-branches", "--files", "none"],
    ["resonance", "--points", "3", "--no-branches", "--files", "none"],
]
#: a probe key, its section, and the values tried for it
PROBE_KEYS = [
    ("free_amplitude", ["1e-30", "1.0", "0", "-1e-9", '"ten"']),
    ("quality_factor", ["1e-6", "1e9", "0", "-400"]),
    ("resonance_frequency", ["1e15", "1", "0", "nan"]),
    ("spring_constant", ["1e-12", "1e12", "-40"]),
    ("z_c", ["-1e-6", "1e3", "0", "inf"]),
    ("hamaker", ["1e-10", "1e10", "-1"]),
    ("intermolecular_distance", ["1e-300", "1e3", "0"]),
    ("youngs_modulus", ["1e30", "1", "0"]),
    ("law", ['"DMT"', '"hooke"', "3"]),
    ("modes", ["0", "21", "2.5", '"3"']),
]
PY_CALLS = [
    ("simulate", {"periods": ["'10'", "None", "1e300", "-1", "float('nan')", "2**64", "True"]}),
    ("attractors", {"samples": ["10**9", "'4'", "None", "-3", "2**64"]}),
    ("orbit", {"period": ["0", "65", "'1'", "2**64"], "tol": ["'x'", "float('nan')", "-1.0"]}),
    ("lyapunov", {"periods": ["10**8", "0", "'5'"], "blocks": ["0", "10**6"]}),
    ("approach", {"points": ["2**64", "1", "None"], "from_": ["float('nan')", "'20nm'"]}),
    ("bifurcation", {"steps": ["'10'", "0", "10**9"], "threads": ["0", "10**6"]}),
    ("resonance", {"mode": ["None", "0", "99"]}),
]

_CHART = ["chart", "--x", "omega", "--x-from", "2.6", "--x-to", "3.0", "--x-steps", "2",
          "--y", "drive-amplitude", "--y-from", "0.1", "--y-to", "0.12", "--y-steps", "2",
          "--starts", "2", "--max-periods", "200", "--out", "{out}"]
#: issue 42's faults: (argv, the exit code it must give, the keyword its message names, stdout
#: file, probe text); "{zero}" is /dev/zero, "{binary}" a file of invalid UTF-8
FAULTS: List[Tuple[List[str], int, Optional[str], Optional[str], Optional[str]]] = [
    *[(_CHART + [flag, v], 2, flag[2:], None, None)
      for flag in ("--contact-stiffness", "--hamaker", "--gap", "--omega")
      for v in ("nan", "inf", "-inf")],
    *[(["attractors", "--samples", "2", "--max-periods", "200", "--out", "{out}",
        "--contact-law", law, "--tolerance", t], 2, "tolerance", None, None)
      for law in LAWS for t in ("nan", "0", "-1", "1", "1e300", "1e-300")],
    (["modes", "--probe", "/dev/zero"], 2, "/dev/zero", None, None),
    (["units", "--probe", "/dev/zero"], 2, "/dev/zero", None, None),
    (["modes", "--config", "/dev/urandom"], 2, "/dev/urandom", None, None),
    (["modes", "--config", "/dev/zero"], 2, "/dev/zero", None, None),
    (["continue", "--from", "2.8", "--to", "2.7", "--overlay", "/dev/zero", "--out", "{out}"],
     2, "/dev/zero", None, None),
    (["continue", "--from", "2.8", "--to", "2.7", "--overlay", "missing.csv", "--out", "{out}"],
     2, "missing.csv", None, None),
    (["modes", "--probe", "{binary}"], 2, "UTF-8", None, None),
    (["approach", "--points", "1000", "--traces", "10000", "--files", "none"], 2, "traces",
     None, None),
    (_CHART + ["--contact-law", "hertz", "--contact-stiffness", "1e8"], 2, "budget", None, None),
    (["modes"], 1, "standard output", "/dev/full", None),
    (["modes", "--json"], 1, "standard output", "/dev/full", None),
    (["cantilevers"], 1, "standard output", "/dev/full", None),
    (["units", "--probe", str(PROBES[0])], 1, "standard output", "/dev/full", None),
    (["modes", "--config", "{config}"], 0, None, None, 'contact_law = "HERTZ"\n'),
    (["simulate", "--periods", "1e300", "--files", "none"], 2, "periods", None, None),
    (["modes", "--probe", "{probe}"], 2, "quality_factor", None,
     PROBES[0].read_text().replace("quality_factor = 400 ", "quality_factor = 1e308 ")),
    # issue 60's classes: a request's budget checked before any work (B6), unbounded input
    # files (B7), an SI amplitude beyond its physical range (A2), one meaning of --modes (A1),
    # exclusive options and a modulation frequency out of range (off-resonance tapping)
    (["image", "--probe", str(PROBES[0]), "--sample", str(REPO / "examples" / "sample-blend.toml"),
      "--setpoint", "0.8", "--pixels", "2048", "--files", "none"], 2, "budget", None, None),
    (["reconstruct", "--fm", "/dev/zero"], 2, "/dev/zero", None, None),
    (["reconstruct", "--am", "/dev/zero"], 2, "/dev/zero", None, None),
    (["fm", "--probe", str(PROBES[0]), "--amplitude", "5e-4", "--files", "none"], 2, "amplitude",
     None, None),
    (["modes", "--probe", str(REPO / "examples" / "probe-eigenmodes-dmt.toml"), "--modes", "3"],
     2, "modes", None, None),
    (["peakforce", "--probe", str(PEAKFORCE), "--z-c", "95nm", "--setpoint", "2nN"], 2,
     "setpoint", None, None),
    (["peakforce", "--probe", "{probe}", "--z-c", "95nm", "--out", "{out}"], 2,
     "modulation_frequency", None,
     PEAKFORCE.read_text().replace("modulation_frequency = 2e3 ", "modulation_frequency = 1e9 ")),
    # issue 62's force-curve fit: an unbounded data file, a parameter the law does not have,
    # a reversed range (each exit 2 naming the input)
    (["fit", "--probe", str(FIT_PROBE), "--data", "/dev/zero", "--out", "{out}"], 2, "/dev/zero",
     None, None),
    (["fit", "--probe", str(FIT_PROBE), "--data", str(FIT_DATA), "--fit", "sample.hamaker",
      "--files", "none"], 2, "fit", None, None),
    (["fit", "--probe", str(FIT_PROBE), "--data", str(FIT_DATA), "--range", "0,-1e-7",
      "--files", "none"], 2, "range", None, None),
    # issue 77's classes: a PeakForce image no material reaches (exit 1, not a map of no
    # finite pixel), a filter cut-off far below f_m and a setpoint no z_c gives (exit 2 naming
    # them), a tapping request on an off-resonance probe, a data file naming a column twice,
    # a tip radius below an atom's
    (["image", "--mode", "peakforce", "--probe", str(PEAKFORCE), "--sample",
      str(REPO / "examples" / "sample-peakforce-blend.toml"), "--setpoint", "0.7", "--pixels",
      "2", "--files", "none"], 1, "setpoint", None, None),
    (["peakforce", "--probe", str(PEAKFORCE), "--filter-cutoff", "1e-308", "--files", "none"],
     2, "filter-cutoff", None, None),
    (["peakforce", "--probe", str(PEAKFORCE), "--setpoint", "1e-30", "--files", "none"], 2,
     "setpoint", None, None),
    (["approach", "--probe", str(PEAKFORCE), "--points", "3", "--files", "none"], 2,
     "drive.mode", None, None),
    (["fit", "--probe", str(FIT_PROBE), "--data", "{probe}", "--files", "none"], 2, "twice",
     None, "height,force,height\n1e-9,1e-9,2e-9\n"),
    (["fit", "--probe", "{probe}", "--data", str(FIT_DATA), "--files", "none"], 2, "radius",
     None, re.sub(r"(?m)^radius = \S+", "radius = 1e-308", FIT_PROBE.read_text())),
]
#: issue 42's Python faults: (call, the keyword its ValueError must name)
PY_FAULTS = [
    ("afmdyn.attractors(cluster_tol=10**400, samples=2, progress=False)", "cluster_tol"),
    ("afmdyn.chart(x='omega', x_from=2.6, x_to=3.0, x_steps=2, y='drive_amplitude', "
     "y_from=0.1, y_to=0.12, y_steps=2, cluster_tol=10**400, progress=False)", "cluster_tol"),
    ("afmdyn.modes(contact_stiffness=10**400)", "contact_stiffness"),
    ("afmdyn.chart(x='omega', x_from=2.6, x_to=3.0, x_steps=2, y='drive_amplitude', "
     "y_from=0.1, y_to=0.12, y_steps=2, contact_stiffness=float('inf'), progress=False)",
     "contact_stiffness"),
    ("afmdyn.modes(probe='/dev/zero')", "/dev/zero"),
    ("afmdyn.simulate(periods=1, tolerance=float('nan'), progress=False)", "tolerance"),
    (f"afmdyn.fit(probe={str(FIT_PROBE)!r}, data={{'height': [1, 0, -1], 'force': [0, 1, 2]}})",
     "data"),
    (f"afmdyn.fit(probe={str(FIT_PROBE)!r}, data={str(FIT_DATA)!r}, fit=['tip.nonsense'])", "fit"),
    # issue 77: keywords convert one way (a string is never read as its characters)
    (f"afmdyn.fit(probe={str(FIT_PROBE)!r}, data=5)", "data"),
    ("afmdyn.reconstruct(distance=[1e-9, 2e-9, 3e-9], frequency_shift=[-1.0, -2.0, -3.0], "
     "spring_constant='40', resonance_frequency=3e5, amplitude=1e-8)", "spring_constant"),
    ("afmdyn.approach(points='5', progress=False)", "points"),
]
#: a message that prints a double with all its digits (1e300 as 301 digits, 16 of round-off)
LONG_NUMBER = re.compile(r"\d{17,}")

INTERNALS = re.compile(
    r"panicked|RUST_BACKTRACE|called `(Option|Result)::unwrap|Initial step size|"
    r"Check your problem definition|memory allocation of"
)


@dataclass
class Case:
    """One generated input: a command line, or a Python snippet."""

    kind: str  # "cli" | "probe" | "python"
    argv: List[str]
    label: str
    keyword: Optional[str] = None
    probe_text: Optional[str] = None
    #: the exit code the case must give (issue 42's faults), else any code with a meaning
    expect: Optional[int] = None
    #: a file standard output goes to (``/dev/full``)
    stdout: Optional[str] = None


@dataclass
class Outcome:
    case: Case
    verdict: str  # ok | hang | memory | crash | unclear
    code: Optional[int]
    seconds: float
    detail: str


def cases(seed: int, n: int) -> List[Case]:
    """``n`` cases drawn over the classes, a pure function of ``seed``."""
    rng = random.Random(seed)
    out: List[Case] = []
    for i in range(n):
        kind = ("cli", "cli", "probe", "python", "fault")[i % 5]
        if kind == "fault" and rng.random() < 0.8:
            argv, expect, keyword, stdout, text = rng.choice(FAULTS)
            label = " ".join(argv) + (f" > {stdout}" if stdout else "")
            out.append(Case("fault", list(argv), label, keyword=keyword, probe_text=text,
                            expect=expect, stdout=stdout))
        elif kind == "fault":
            call, keyword = rng.choice(PY_FAULTS)
            out.append(Case("python", [sys.executable, "-c", f"import afmdyn; {call}"], call,
                            keyword=keyword))
        elif kind == "cli":
            cmd = list(rng.choice(COMMANDS))
            law = rng.choice(LAWS)
            flag, value = rng.choice(FLAGS), rng.choice(EXTREMES)
            argv = cmd + ["--contact-law", law, flag, value]
            out.append(Case("cli", argv, " ".join(argv), keyword=flag))
        elif kind == "probe":
            key, values = rng.choice(PROBE_KEYS)
            value = rng.choice(values)
            probe = rng.choice(PROBES)
            cmd = list(rng.choice(CURVES + [["orbit", "--max-periods", "200"]]))
            text = _mutate(probe.read_text(), key, value)
            out.append(
                Case("probe", cmd, f"{probe.name}: {key} = {value}; {' '.join(cmd)}",
                     keyword=key, probe_text=text)
            )
        else:
            fn, kws = rng.choice(PY_CALLS)
            kw = rng.choice(sorted(kws))
            value = rng.choice(kws[kw])
            snippet = f"import afmdyn; afmdyn.{fn}({kw}={value}, progress=False)"
            out.append(Case("python", [sys.executable, "-c", snippet], f"{fn}({kw}={value})",
                            keyword=kw.rstrip("_")))
    return out


def _mutate(text: str, key: str, value: str) -> str:
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if re.match(rf"^{re.escape(key)}\s*=", line):
            lines[i] = f"{key} = {value}"
            return "\n".join(lines) + "\n"
    # not in this file: add it under the first table that takes it
    return text + f"\n[sample]\n{key} = {value}\n" if key not in ("modes", "law") else text


def _limits(memory_bytes: int) -> Callable[[], None]:
    def apply() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))

    return apply


def run(case: Case, binary: Path, workdir: Path, seconds: float, memory_bytes: int) -> Outcome:
    """Run one case under the caps and classify its outcome."""
    workdir.mkdir(parents=True, exist_ok=True)
    if case.kind == "python":
        argv = case.argv
    else:
        binfile = workdir / "binary.toml"
        binfile.write_bytes(b"a = \xff\xfe\n")
        subst = {"{out}": str(workdir / "out"), "{binary}": str(binfile),
                 "{config}": str(workdir / "config.toml"), "{probe}": str(workdir / "probe.toml")}
        argv = [str(binary.resolve())] + [subst.get(a, a) for a in case.argv]
        if case.kind == "fault" and case.probe_text is not None:
            (workdir / "config.toml").write_text(case.probe_text)
            (workdir / "probe.toml").write_text(case.probe_text)
        if case.kind == "probe":
            probe = workdir / "probe.toml"
            probe.write_text(case.probe_text or "")
            argv += ["--probe", str(probe)]
    t0 = time.monotonic()
    try:
        if case.stdout is not None:
            with open(case.stdout, "w") as sink:
                p = subprocess.run(
                    argv, stdout=sink, stderr=subprocess.PIPE, text=True, timeout=seconds,
                    cwd=workdir, preexec_fn=_limits(memory_bytes),
                )
        else:
            p = subprocess.run(
                argv, capture_output=True, text=True, timeout=seconds, cwd=workdir,
                preexec_fn=_limits(memory_bytes),
            )
    except subprocess.TimeoutExpired:
        return Outcome(case, "hang", None, seconds, f"no answer in {seconds:.0f} s")
    dt = time.monotonic() - t0
    err = p.stderr.strip()
    code = p.returncode
    if case.kind == "python":
        verdict, detail = _python_verdict(case, code, err)
        return Outcome(case, verdict, code, dt, detail)
    if "memory allocation" in err or code in (-6, 134) and "alloc" in err:
        return Outcome(case, "memory", code, dt, err[-300:])
    if code < 0 or code not in (0, 1, 2) or INTERNALS.search(err):
        return Outcome(case, "crash", code, dt, err[-300:])
    if code != 0:
        lines = [l for l in err.splitlines() if l.strip()]
        last = lines[-1] if lines else ""
        if not last.startswith("afmdyn: ") or any(
            not l.startswith("afmdyn: ") for l in lines
        ):
            return Outcome(case, "unclear", code, dt, err[-300:])
        if LONG_NUMBER.search(err):
            return Outcome(case, "unclear", code, dt, f"a long number: {err[-300:]}")
    if case.expect is not None and (
        code != case.expect or (code != 0 and case.keyword and case.keyword not in err)
    ):
        return Outcome(case, "unclear", code, dt,
                       f"expected exit {case.expect} naming {case.keyword}: {err[-300:]}")
    return Outcome(case, "ok", code, dt, err.splitlines()[-1] if err else "")


def _python_verdict(case: Case, code: int, err: str) -> Tuple[str, str]:
    if code == 0:
        return "ok", ""
    if "MemoryError" in err or "memory allocation" in err:
        return "memory", err[-300:]
    if code < 0 or INTERNALS.search(err):
        return "crash", err[-300:]
    last = err.splitlines()[-1] if err else ""
    m = re.match(r"^(?:afmdyn\.)?(\w+): (.*)$", last)
    if not m:
        return "unclear", last
    kind, msg = m.group(1), m.group(2)
    if kind not in ("ValueError", "TypeError", "SimulationError"):
        return "unclear", last
    if kind in ("ValueError", "TypeError") and case.keyword and case.keyword not in msg:
        return "unclear", last
    return "ok", last


def battery(
    seed: int, n: int, binary: Path, workdir: Path, seconds: float, memory_bytes: int,
    progress: Optional[Callable[[Outcome], None]] = None,
) -> List[Outcome]:
    out = []
    for i, case in enumerate(cases(seed, n)):
        o = run(case, binary, workdir / f"case-{i}", seconds, memory_bytes)
        out.append(o)
        if progress:
            progress(o)
    return out


def counts(outcomes: Sequence[Outcome]) -> Dict[str, int]:
    c = {k: 0 for k in ("ok", "hang", "memory", "crash", "unclear")}
    for o in outcomes:
        c[o.verdict] += 1
    return c


def main() -> None:  # pragma: no cover - run by scripts/battery.sh
    import argparse
    import tempfile

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=27)
    ap.add_argument("--cases", type=int, default=400)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--memory-gib", type=float, default=4.0)
    ap.add_argument("--binary", type=Path, default=REPO / "target" / "release" / "afmdyn")
    ap.add_argument("--report", type=Path, default=None)
    a = ap.parse_args()
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory() as tmp:
        outcomes = battery(
            a.seed, a.cases, a.binary, Path(tmp), a.seconds, int(a.memory_gib * 2**30),
            progress=lambda o: print(f"{o.verdict:8} {o.seconds:6.1f} s  {o.case.label}", flush=True),
        )
    total = time.monotonic() - t0
    c = counts(outcomes)
    by_kind = {
        k: counts([o for o in outcomes if o.case.kind == k])
        for k in ("cli", "probe", "python", "fault")
    }
    slowest = sorted(outcomes, key=lambda o: -o.seconds)[:5]
    bad = [o for o in outcomes if o.verdict != "ok"]
    print(json.dumps({"counts": c, "by_kind": by_kind, "seconds": round(total, 1)}))
    if a.report:
        rows = "\n".join(
            f"| {k} | {v['ok']} | {v['hang']} | {v['memory']} | {v['crash']} | {v['unclear']} |"
            for k, v in by_kind.items()
        )
        lines = [
            "# Reliability battery",
            "",
            "Generated by `bash scripts/battery.sh` (do not edit by hand): "
            f"{a.cases} cases from seed {a.seed}, each in its own process capped at "
            f"{a.seconds:.0f} s and {a.memory_gib:g} GiB; {total:.0f} s in all. The classes, the "
            "verdicts and the generator are in `crates/afmdyn-py/tests/battery.py`; a slice of the "
            "same generator runs in the test command (`test_battery.py`). Classes: `cli` (model "
            "flags at and beyond their ranges), `probe` (mutated probe files), `python` (keywords "
            "of the wrong type or value, and issue 42's Python faults), `fault` (issue 42's "
            "outside battery: non-finite chart values, tolerances, input files without end or not "
            "text, up-front budgets, writes to a full device, capitalised law names, a quality "
            "factor of 1e308 — each with the exit code it must give).",
            "",
            "| class | ok | hang | memory | crash | unclear |",
            "|---|---|---|---|---|---|",
            rows,
            f"| **all** | {c['ok']} | {c['hang']} | {c['memory']} | {c['crash']} | {c['unclear']} |",
            "",
            "Exit codes among the command-line cases: "
            + ", ".join(
                f"{code}: {sum(1 for o in outcomes if o.case.kind != 'python' and o.code == code)}"
                for code in (0, 1, 2)
            )
            + ".",
            "",
            "Slowest cases:",
            "",
            *[f"- {o.seconds:.1f} s ({o.verdict}): `{o.case.label}`" for o in slowest],
            "",
            "Cases not ok:" if bad else "Every case ok.",
            *([""] if bad else []),
            *[f"- {o.verdict}: `{o.case.label}` — {o.detail}" for o in bad],
            "",
        ]
        a.report.write_text("\n".join(lines))


if __name__ == "__main__":  # pragma: no cover
    main()
