"""Split the instructions of one stepped-curve run (`afmdyn approach` / `resonance` under
callgrind) by phase, from the inclusive costs of `callgrind_annotate --tree=caller`:

- orbits: Newton following the orbit from value to value (`stepped::continue_orbit` as the
  sweep calls it, its halved sub-steps included), and the first point's solve;
- transients: `stepped::settle` (integration after a jump or at a nonperiodic point, with its
  Newton attempts and the classification by `steady::steady_state`);
- observables: `observables::observe` (every sweep and branch point);
- branches: `continuation::continue_branch` (corrector flows, ∂F/∂p, event location);
- rest: everything else (set-up, branch starts, outputs).

Usage: python3 scripts/callgrind_phases.py CALLGRIND_OUT NAME
Prints one Markdown table row: | NAME | total | orbits | transients | observables | branches | rest |
with each figure in 1e9 instructions.
"""
import re
import subprocess
import sys

path, name = sys.argv[1:3]
text = subprocess.run(
    ["callgrind_annotate", "--inclusive=yes", "--tree=caller", path],
    capture_output=True,
    text=True,
    check=True,
).stdout
total = int(re.search(r"^([\d,]+) \(100\.0%\)\s+PROGRAM TOTALS", text, re.M).group(1).replace(",", ""))


def inclusive(func):
    """The inclusive cost of the function entry `* ...func [` (first match)."""
    m = re.search(r"^\s*([\d,]+) \([^)]*\)\s+\*\s+\S*" + re.escape(func) + r" \[", text, re.M)
    return int(m.group(1).replace(",", "")) if m else 0


def from_caller(func, caller):
    """The cost of `func` as called from `caller`: the `< caller` line of `func`'s entry."""
    block = re.search(
        r"((?:^\s*[\d,]+ \([^)]*\)\s+<[^\n]*\n)*)^\s*[\d,]+ \([^)]*\)\s+\*\s+\S*"
        + re.escape(func)
        + r" \[",
        text,
        re.M,
    )
    if not block:
        return 0
    for line in block.group(1).splitlines():
        if re.search(re.escape(caller) + r"(?:'\d+)? \(", line):
            return int(line.split()[0].replace(",", ""))
    return 0


orbits = from_caller("analysis::stepped::continue_orbit", "analysis::stepped::sweep")
orbits += from_caller("analysis::shooting::map::shoot", "analysis::stepped::sweep")
transients = inclusive("analysis::stepped::settle")
observables = inclusive("analysis::observables::observe")
branches = inclusive("analysis::continuation::continue_branch")
rest = total - orbits - transients - observables - branches
g = lambda v: "%.2f" % (v / 1e9)
print(
    "| %s | %s | %s | %s | %s | %s | %s |"
    % (name, g(total), g(orbits), g(transients), g(observables), g(branches), g(rest))
)
