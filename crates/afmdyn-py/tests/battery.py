"""The reliability battery of issue 27: inputs generated over the classes users hit (command-line
flags at the edges of their ranges and beyond, mutated probe files, Python keywords of the wrong
type or value), each run in its own process with a time and a memory cap, and each outcome
classified:

* ``ok`` — exit 0 (Python: returned), or a refusal that names the input in one line: exit 2 /
  ``ValueError`` / ``TypeError``, or a failure with its cause: exit 1 / ``SimulationError``;
* ``hang`` — over the time cap; ``memory`` — over the memory cap; ``crash`` — a panic, a signal,
  or an exit code without a meaning; ``unclear`` — a message that is not one line starting with
  ``afmdyn:``, that leaks a crate's internals, or (Python) an exception of another type, or a
  ``TypeError``/``ValueError`` that does not name the keyword.

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
        kind = ("cli", "cli", "probe", "python")[i % 4]
        if kind == "cli":
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
        argv = [str(binary.resolve())] + [a.replace("{out}", str(workdir / "out")) for a in case.argv]
        if case.kind == "probe":
            probe = workdir / "probe.toml"
            probe.write_text(case.probe_text or "")
            argv += ["--probe", str(probe)]
    t0 = time.monotonic()
    try:
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
    by_kind = {k: counts([o for o in outcomes if o.case.kind == k]) for k in ("cli", "probe", "python")}
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
            "same generator runs in the test command (`test_battery.py`).",
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
