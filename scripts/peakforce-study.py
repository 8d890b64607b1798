#!/usr/bin/env python3
"""Off-resonance (PeakForce) tapping studies of issue 61, generated from `afmdyn peakforce`:

1. The force distortion of Amo & Garcia, ACS Nano 10, 7117 (2016): their parameter set
   (examples/probe-peakforce-amo-garcia.toml: k 5 N/m, f0 150 kHz, R 5 nm, E* 1 GPa,
   a0 0.2 nm, H 8e-20 J) at Q = 100 and Q = 2, f0/f_m = 5, 10, 20, 100, against the
   quasi-static limit (f0/f_m = 3 000). Figure docs/figures/peakforce/distortion.png: the
   force the instrument measures (k x deflection) against the tip-sample distance over one
   cycle at each f0/f_m, and the peak tip-sample force against f0/f_m; the numbers in
   docs/figures/peakforce/distortion.json.
2. The bias of `modulus_dmt` (the PF-QNM DMT fit of the retract curve, on the force the
   instrument measures, k x deflection) at f0/f_m = 100 and 10 on the same lever (Q = 100)
   over DMT, JKR and SLS samples: a table between the markers `peakforce-bias` in
   docs/tutorials/peakforce.md, and docs/figures/peakforce/bias.json.

Every number comes from the command line's JSON document (`afmdyn peakforce --json`).
Usage: cargo build --release -p afmdyn-cli && target/venv-test/bin/python scripts/peakforce-study.py
(matplotlib: the Python package's `plot` extra). AFMDYN_BIN overrides the binary.
"""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = os.environ.get("AFMDYN_BIN", str(ROOT / "target/release/afmdyn"))
PROBE = (ROOT / "examples/probe-peakforce-amo-garcia.toml").read_text()
OUT = ROOT / "docs/figures/peakforce"
F0 = 150e3
RADIUS = 5e-9  # the probe's tip radius (m)
K = 5.0  # the probe's spring constant (N/m)
RATIOS = [5, 10, 20, 100]
QUASI_STATIC = 3000

# the samples of the bias table: [sample] sections replacing the probe's DMT one
SAMPLES = {
    "DMT (E* 1 GPa, H 8e-20 J)": None,
    "JKR (E* 1 GPa, W 0.053 J/m², DMT's H/(12π a0²))": """[sample]
law = "jkr"
youngs_modulus = 1e9
poisson_ratio = 0
adhesion_energy = 0.053
z_c = 18e-9
""",
    "SLS (k1 5 N/m, k2 5 N/m, τ_r 2 µs)": """[sample]
law = "sls"
stiffness = 5
maxwell_stiffness = 5
relaxation_time = 2e-6
z_c = 18e-9
""",
}


def probe(ratio: float, q: float, sample: str | None = None) -> str:
    text = PROBE.replace("modulation_frequency = 15e3", f"modulation_frequency = {F0 / ratio:e}")
    text = text.replace("quality_factor = 100", f"quality_factor = {q:g}")
    if sample is not None:
        head, rest = text.split("[sample]", 1)
        tail = rest[rest.index("[drive]"):]
        text = head + sample + tail
    return text


def run(text: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "probe.toml"
        path.write_text(text)
        out = subprocess.run(
            [BIN, "peakforce", "--probe", str(path), "--json", "--out", str(Path(tmp) / "out")],
            check=True, capture_output=True, text=True,
        )
    return json.loads(out.stdout)


def distortion() -> dict:
    rows = {}
    for q in [100.0, 2.0]:
        qs = run(probe(QUASI_STATIC, q))
        runs = {r: run(probe(r, q)) for r in RATIOS}
        rows[q] = {"quasi_static": qs, "runs": runs}
    return rows


def figure(rows: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    # the force the instrument measures, k × deflection (the point mass: k is the probe's
    # spring constant), against the tip–sample distance over one cycle
    def measured(doc: dict) -> tuple:
        c = doc["cycle"]
        return [x * 1e9 for x in c["distance"]], [K * w * 1e9 for w in c["deflection"]]

    for ax, q in zip(axes[:2], [100.0, 2.0]):
        for r, doc in rows[q]["runs"].items():
            ax.plot(*measured(doc), lw=1, label=f"f0/fm = {r}")
        ax.plot(*measured(rows[q]["quasi_static"]), "k--", lw=1,
                label=f"quasi-static (f0/fm = {QUASI_STATIC})")
        ax.set_xlim(-3, 12)
        ax.set_xlabel("tip–sample distance (nm)")
        ax.set_ylabel("measured force k × deflection (nN)")
        ax.set_title(f"Q = {q:g}")
        ax.legend(fontsize=7)
    ax = axes[2]
    for q, m in [(100.0, "o-"), (2.0, "s-")]:
        qs = rows[q]["quasi_static"]["channels"]["peak_force"]
        ys = [rows[q]["runs"][r]["channels"]["peak_force"] / qs for r in RATIOS]
        ax.plot(RATIOS, ys, m, label=f"Q = {q:g}")
    ax.axhline(1.0, color="k", ls="--", lw=1)
    ax.set_xscale("log")
    ax.set_xlabel("f0/fm")
    ax.set_ylabel("peak force / quasi-static peak force")
    ax.legend()
    fig.suptitle("Amo & Garcia 2016 parameters (k 5 N/m, f0 150 kHz, R 5 nm, E* 1 GPa, A_m 20 nm)")
    fig.tight_layout()
    fig.savefig(OUT / "distortion.png", dpi=110)


def bias() -> list:
    table = []
    for name, sample in SAMPLES.items():
        for ratio in [100, 10]:
            doc = run(probe(ratio, 100.0, sample))
            m = doc["modulus"]
            # a law without a tip radius (SLS) reports the fitted Hertz group in model units:
            # its apparent E* = K F_s / ((4/3) √R g0^{3/2}) with the probe's R
            scale = 1.0
            if m["true"] is None:
                s = doc["si"]["scales"]
                scale = s["force_n"] / (4.0 / 3.0 * RADIUS ** 0.5 * s["length_m"] ** 1.5)
            table.append({
                "sample": name,
                "f0_over_fm": ratio,
                "modulus_dmt": m["modulus_dmt"] * scale,
                "tip_sample_modulus": m["tip_sample_modulus"] * scale,
                "true": m["true"],
                "ratio": m["ratio"],
                "taps_per_cycle": doc["channels"]["taps_per_cycle"],
                "peak_force": doc["channels"]["peak_force"],
            })
    return table


def fmt(x) -> str:
    return "—" if x is None else f"{x / 1e9:.3f} GPa"


def section(table: list) -> str:
    lines = [
        "<!-- peakforce-bias:begin (generated by scripts/peakforce-study.py; do not edit) -->",
        "| sample | f0/f_m | taps per cycle | peak force | modulus_dmt (k × deflection) | the fit on the true force | true E* | modulus_dmt / E* |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in table:
        ratio = "—" if r["ratio"] is None else f"{r['ratio']:.3f}"
        lines.append(
            f"| {r['sample']} | {r['f0_over_fm']} | {r['taps_per_cycle']:g} | "
            f"{r['peak_force'] * 1e9:.2f} nN | {fmt(r['modulus_dmt'])} | "
            f"{fmt(r['tip_sample_modulus'])} | {fmt(r['true'])} | {ratio} |"
        )
    lines += [
        "",
        "The lever of Amo & Garcia 2016 (examples/probe-peakforce-amo-garcia.toml, point mass, "
        "Q = 100, A_m = 20 nm, z_c = 18 nm). The SLS sample has no Hertz modulus: its row is the "
        "apparent E* of the same fit (with R = 5 nm). The fit on the true tip–sample force "
        "recovers DMT's E*; the instrument's, on k × deflection, carries the lever's inertia "
        "and ringing. `target/venv-test/bin/python scripts/peakforce-study.py` "
        "regenerates this table and docs/figures/peakforce/.",
        "<!-- peakforce-bias:end -->",
    ]
    return "\n".join(lines) + "\n"


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    rows = distortion()
    summary = {
        f"Q={q:g}": {
            "quasi_static_peak_force": rows[q]["quasi_static"]["channels"]["peak_force"],
            "peak_force": {str(r): rows[q]["runs"][r]["channels"]["peak_force"] for r in RATIOS},
            "taps_per_cycle": {str(r): rows[q]["runs"][r]["channels"]["taps_per_cycle"] for r in RATIOS},
        }
        for q in rows
    }
    (OUT / "distortion.json").write_text(json.dumps(summary, indent=1) + "\n")
    figure(rows)
    table = bias()
    (OUT / "bias.json").write_text(json.dumps(table, indent=1) + "\n")
    with tempfile.NamedTemporaryFile("w", suffix=".md", delete=False) as f:
        f.write(section(table))
    subprocess.run(
        [sys.executable, str(ROOT / "scripts/doc_section.py"), "peakforce-bias", f.name,
         "PeakForce: the bias of modulus_dmt", str(ROOT / "docs/tutorials/peakforce.md")],
        check=True,
    )
    os.unlink(f.name)
    print(json.dumps(summary, indent=1))
    print(section(table))


if __name__ == "__main__":
    main()
