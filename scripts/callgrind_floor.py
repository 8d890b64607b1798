"""The exact propagator's cost per forcing period split against its floor, from two callgrind
profiles of `period_cost linear N P advance` at two run lengths P1 < P2 (their difference is
P2 − P1 periods on the attractor, free of build and transient).

Floor (issue 11): the grid steps actually needed, one propagation each, plus the event work.
- one propagation: the mean instructions of one call of `ModalExp::advance_into` (e^{Λh} ⊙ q and
  the tip deflection and rate), times m, the grid sub-steps of a period (a grid interval that
  holds a switching counts as one propagation, and its two partial propagations as event work);
- event work: the functions that serve a switching — the tip series (`build_last_series`, which
  now holds the inlined `build_poly`, and `TipPoly`),
  the leftmost-root search and Newton polish (`Search`, `safeguarded_newton`), the state at the
  switching and the partial steps around it (`state_in_last_at`, `ModalExp::expand*`,
  `apply_rows`, libm's exp and sincos), the stint entry (`enter_stint`);
- above the floor: everything else — the step loop with the certified switching test,
  `step_impl`'s bookkeeping, grid steps tried and refused, copies.

Usage: python3 scripts/callgrind_floor.py OUT1 OUT2 PERIODS M N EVENTS
prints one markdown table row.
"""
import re
import subprocess
import sys

PROPAGATION = "ModalExp::advance_into"
EVENT = (
    "build_last_series",
    "build_poly",
    "TipPoly::",
    "Search::",
    "safeguarded_newton",
    "state_in_last_at",
    "ModalExp::expand",
    "ModalExp::apply_rows",
    "enter_stint",
    "sincos",
    "exp_fma",
    "exp@@",
)


def self_costs(path):
    """Self instructions per function (callgrind_annotate, no inclusive costs)."""
    out = subprocess.run(
        ["callgrind_annotate", "--auto=no", "--threshold=100", path], capture_output=True, text=True, check=True
    ).stdout
    costs = {}
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+)\s+\([^)]*\)\s+[^:]*:(.*?)(\s+\[.*\])?$", line)
        if m:
            name = m.group(2).strip()
            costs[name] = costs.get(name, 0) + int(m.group(1).replace(",", ""))
    return costs


def calls_to(path, needle):
    """Calls of the functions whose name contains `needle`, from the profile's call records."""
    names, callee, total = {}, None, 0
    for line in open(path, errors="replace"):
        m = re.match(r"c?fn=\((\d+)\)(?: (.*))?$", line.rstrip("\n"))
        if m:
            if m.group(2):
                names[m.group(1)] = m.group(2)
            if line.startswith("cfn"):
                callee = m.group(1)
            continue
        m = re.match(r"calls=(\d+)", line)
        if m and callee is not None and needle in names.get(callee, ""):
            total += int(m.group(1))
    return total


def main():
    out1, out2, periods, m, n, events = sys.argv[1:7]
    periods, m, events = float(periods), int(m), float(events)
    a, b = self_costs(out1), self_costs(out2)
    per = {k: (b.get(k, 0) - a.get(k, 0)) / periods for k in set(a) | set(b)}
    total = sum(per.values())
    prop = sum(v for k, v in per.items() if PROPAGATION in k)
    calls = (calls_to(out2, PROPAGATION) - calls_to(out1, PROPAGATION)) / periods
    if calls < m:
        sys.exit(f"N = {n}: {calls:.1f} propagations per period, fewer than the {m} grid steps: "
                 f"is `{PROPAGATION}` inlined or the dense path taken?")
    one = prop / calls
    event = sum(v for k, v in per.items() if any(e in k for e in EVENT))
    floor = m * one + event
    def num(x):
        return f"{x:,.0f}".replace(",", " ")

    print(f"| {n} | {num(total)} | {m} | {num(one)} | {num(m * one)} | {events:.2f} | "
          f"{num(event)} | {num(floor)} | {num(total - floor)} | **{total / floor:.2f}×** |")


main()
