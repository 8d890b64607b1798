"""The paper's Fig. 5 and the Ω = 2.6 attractor analysis from Python.

    pip install ./crates/afmdyn-py matplotlib
    python examples/python/fig5_attractors.py [--quick] [--out afmdyn-out/python]

Writes fig5.png (bifurcation diagram: section points and X_max over Ω, coloured by period),
omega-2.6.png (the attractor at Ω = 2.6: time series, phase plane with its Poincaré section,
Lyapunov spectrum, and the Floquet multipliers of the unstable period-1 orbit it came from) and
prints what it found. ``--quick`` uses fewer sweep values and samples (what the tests run).
An approach curve in SI from a probe file is in the notebook ``afmdyn_tour.ipynb``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; the notebook shows the same figures inline
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import afmdyn  # noqa: E402

PERIOD_COLOURS = {1: "tab:blue", 2: "tab:orange", 3: "tab:green", 4: "tab:red"}


def period_colour(n: int) -> str:
    if n < 0:
        return "black"  # nonperiodic (−1)
    return PERIOD_COLOURS.get(n, "tab:purple")


def fig5(steps: int, out: Path) -> None:
    ds = afmdyn.bifurcation(from_=1.0, to=5.0, steps=steps, starts=1)
    df = ds.to_dataframe()
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    colours = [period_colour(n) for n in df.period]
    ax1.scatter(df.value, df.w_tip, s=1.5, c=colours)
    ax1.set_ylabel("W(1,τ) at τ = 2πk/Ω  [g0]")
    ax1.set_title(
        f"Fig. 5: bifurcation diagram ({steps} values of Ω, forward, backward, 1 random start)"
    )
    ax2.scatter(df.value, df.x_max, s=1.5, c=colours)
    ax2.set_xlabel("Ω")
    ax2.set_ylabel("X_max  [g0]")
    for n, c in [*PERIOD_COLOURS.items(), (5, "tab:purple"), (-1, "black")]:
        label = {5: "period ≥ 5", -1: "nonperiodic"}.get(n, f"period {n}")
        ax2.scatter([], [], s=10, c=c, label=label)
    ax2.legend(markerscale=2, fontsize=8, ncol=3)
    fig.tight_layout()
    fig.savefig(out / "fig5.png", dpi=120)
    plt.close(fig)
    first = df[df.k == 0]
    counts = first.status.value_counts().to_dict()
    print(f"Fig. 5: {ds.sizes['point']} section points; steady states {counts}")
    print(f"  largest X_max {df.x_max.max():.3f} at Ω = {df.value[df.x_max.idxmax()]:.3f}")


def omega_26(samples: int, periods: int, out: Path) -> None:
    p = afmdyn.Params(omega=2.6)
    atts = afmdyn.attractors(p, samples=samples)
    print(atts)
    a = atts[0]
    ts = a.simulate(periods=8)
    section = afmdyn.simulate(p, initial=a, periods=periods, samples_per_period=1)
    lyap = afmdyn.lyapunov(p, initial=a, transient=0, periods=periods)
    orbit = afmdyn.orbit(p, period=1)
    print(lyap)
    print(orbit)

    fig, axes = plt.subplots(2, 2, figsize=(10, 8))
    ax = axes[0, 0]
    ax.plot(ts.tau, ts.w_tip, lw=0.8, label="W(1,τ)")
    ax.plot(ts.tau, ts.v_t, lw=0.8, label="V_T")
    ax.fill_between(
        ts.tau, -0.15, 0.3, where=ts.in_contact, color="grey", alpha=0.2, label="in contact"
    )
    ax.set_xlabel("τ")
    ax.set_title(f"Ω = 2.6: attractor 1 of {len(atts)} (basin {100 * a.basin_fraction:.0f} %)")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ax.plot(ts.w_tip, ts.w_tip_dot, lw=0.6)
    ax.scatter(
        section.section_w_tip,
        section.section_w_tip_dot,
        s=2,
        c="tab:red",
        label=f"{periods} section points",
    )
    ax.set_xlabel("W(1,τ)")
    ax.set_ylabel("∂W/∂τ")
    ax.set_title("phase plane and stroboscopic section")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    k = np.arange(1, len(lyap.exponents) + 1)
    ax.errorbar(k, lyap.exponents, yerr=lyap.uncertainty, fmt="o")
    ax.axhline(0, color="grey", lw=0.8)
    ax.set_xlabel("i")
    ax.set_ylabel("λ_i  [1/t0]")
    ax.set_title(f"Lyapunov spectrum: {lyap.verdict}, 0–1 test K = {lyap.zero_one:.2f}")
    ax = axes[1, 1]
    t = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(t), np.sin(t), color="grey", lw=0.8)
    ax.scatter(orbit.multipliers.real, orbit.multipliers.imag, c="tab:red")
    ax.set_aspect("equal")
    ax.set_xlabel("Re μ")
    ax.set_ylabel("Im μ")
    ax.set_title(
        f"Floquet multipliers of the period-1 orbit ({'stable' if orbit.stable else 'unstable'})"
    )
    fig.tight_layout()
    fig.savefig(out / "omega-2.6.png", dpi=120)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer values and samples (seconds)")
    ap.add_argument("--out", type=Path, default=Path("afmdyn-out/python"))
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    fig5(steps=60 if a.quick else 400, out=a.out)
    omega_26(samples=8 if a.quick else 64, periods=500 if a.quick else 4000, out=a.out)
    print(f"figures in {a.out}")


if __name__ == "__main__":
    main()
