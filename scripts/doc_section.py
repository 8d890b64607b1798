"""Replace the generated section NAME of a document: the text from `<!-- NAME:begin` to
`<!-- NAME:end -->` becomes the contents of FILE (which carries both markers). When the document
has no such section, it is appended under the heading HEADING.

The document is DOC when given, else the page SECTIONS names for NAME (the performance chapter
is split by topic into docs/performance/*.md; docs/performance.md is its index, with no
generated section). `--where NAME` prints that page, for the scripts that show the section.

Usage: python3 scripts/doc_section.py NAME FILE HEADING [DOC]
       python3 scripts/doc_section.py --where NAME
"""
import re
import sys

# The page that holds each generated section (and the script that generates it).
SECTIONS = {
    "peers": "docs/performance/propagator.md",  # scripts/peers/run.sh
    "thermal": "docs/performance/propagator.md",  # scripts/perf-thermal.sh
    "laws": "docs/performance/laws.md",  # scripts/perf-laws.sh
    "dmt-peer": "docs/performance/laws.md",  # scripts/peers/dmt.sh
    "stability": "docs/performance/analyses.md",  # scripts/perf-stability.sh
    "curves": "docs/performance/analyses.md",  # scripts/perf-curves.sh
    "floor": "docs/performance/recording.md",  # scripts/perf-floor.sh
    "record": "docs/performance/recording.md",  # scripts/perf-floor.sh
    "simulate": "docs/performance/recording.md",  # scripts/perf-simulate.sh
    "study": "docs/performance/commands.md",  # scripts/perf-study.sh
    "basins": "docs/performance/commands.md",  # scripts/perf-basins.sh
    "high-q": "docs/performance/commands.md",  # scripts/perf-high-q.sh
    "fm": "docs/performance/commands.md",  # scripts/perf-fm.sh
    "bimodal": "docs/performance/commands.md",  # scripts/perf-bimodal.sh
    "liquid": "docs/performance/commands.md",  # scripts/perf-liquid.sh
    "image": "docs/performance/commands.md",  # scripts/perf-image.sh
    "image-pi": "docs/performance/commands.md",  # scripts/perf-image-pi.sh
    "wasm": "docs/performance/commands.md",  # scripts/perf-wasm.sh
    "explorer": "docs/performance/commands.md",  # scripts/perf-explorer.sh
    "reconstruct": "docs/performance/commands.md",  # scripts/perf-reconstruct.sh
    "peakforce": "docs/performance/commands.md",  # scripts/perf-peakforce.sh
    "image-pi-large": "docs/performance/commands.md",  # scripts/perf-image-pi-large.sh
    "fit": "docs/performance/commands.md",  # scripts/perf-fit.sh
    "pfimage": "docs/performance/commands.md",  # scripts/perf-image-peakforce.sh
    "fit-dynamic": "docs/performance/commands.md",  # scripts/perf-fit-dynamic.sh
    "fit-coverage": "docs/performance/commands.md",  # scripts/fit-coverage.py
    "fit-map": "docs/performance/maps.md",  # scripts/perf-fit-map.sh
    "peakforce-bias": "docs/tutorials/peakforce.md",  # scripts/peakforce-study.py
}


def page_of(name: str) -> str:
    if name not in SECTIONS:
        sys.exit(f"doc_section.py: no page for the section {name!r}: add it to SECTIONS or give DOC")
    return SECTIONS[name]


if __name__ == "__main__":
    if sys.argv[1:2] == ["--where"]:
        print(page_of(sys.argv[2]))
        sys.exit(0)
    name, path, heading = sys.argv[1:4]
    doc_path = sys.argv[4] if len(sys.argv) > 4 else page_of(name)
    doc = open(doc_path).read()
    new = open(path).read().strip()
    pat = re.compile(r"<!-- %s:begin.*?<!-- %s:end -->" % (name, name), re.S)
    if pat.search(doc):
        doc = pat.sub(lambda _: new, doc)
    else:
        doc = doc.rstrip() + "\n\n## " + heading + "\n\n" + new + "\n"
    open(doc_path, "w").write(doc)
