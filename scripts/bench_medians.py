"""The medians of a farm-bench report (its lines `A|B|A/B cpu|wall ... MEDIAN UNIT`), keyed by
(side, measure): ``medians(path)[("A", "wall")]``. Shared by the perf scripts' tables."""


def medians(path):
    med = {}
    for line in open(path).read().splitlines():
        parts = line.split()
        if len(parts) >= 5 and parts[0] in ("A", "B", "A/B") and parts[1] in ("cpu", "wall"):
            med[(parts[0], parts[1])] = float(parts[-2])
    return med
