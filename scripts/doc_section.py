"""Replace the generated section NAME of a document: the text from `<!-- NAME:begin` to
`<!-- NAME:end -->` becomes the contents of FILE (which carries both markers). When the document
has no such section, it is appended under the heading HEADING.

Usage: python3 scripts/doc_section.py NAME FILE HEADING [DOC]   (DOC: docs/performance.md)
"""
import re
import sys

name, path, heading = sys.argv[1:4]
doc_path = sys.argv[4] if len(sys.argv) > 4 else "docs/performance.md"
doc = open(doc_path).read()
new = open(path).read().strip()
pat = re.compile(r"<!-- %s:begin.*?<!-- %s:end -->" % (name, name), re.S)
if pat.search(doc):
    doc = pat.sub(lambda _: new, doc)
else:
    doc = doc.rstrip() + "\n\n## " + heading + "\n\n" + new + "\n"
open(doc_path, "w").write(doc)
