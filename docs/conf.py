"""The afmdyn book (issue 80): Sphinx with MyST Markdown over docs/.

Sphinx rather than mdBook: Python's API reference comes from the package's own docstrings
(autodoc, Google-style ``Args:`` sections by napoleon), and Sphinx and myst-parser install from
PyPI into the test venv in seconds (``docs/requirements.txt``), where mdBook would be a
``cargo install`` of a few hundred crates in every clean CI run. Build:
``bash scripts/build-book.sh`` (``-W``: a warning fails the build).
"""

project = "afmdyn"
author = "the afmdyn developers"
copyright = "2026, the afmdyn developers"

extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
source_suffix = {".md": "markdown"}
root_doc = "index"
# the JSON schemas, figures and generated tables are read by pages, not pages themselves
exclude_patterns = ["_build", "schema/**/*.json", "figures"]
# GitHub-style anchors for headings down to ####, so that `page.md#section` links resolve
myst_heading_anchors = 4
myst_enable_extensions = ["dollarmath", "colon_fence"]
html_theme = "alabaster"
html_title = "afmdyn"
autodoc_typehints = "description"
napoleon_google_docstring = True
napoleon_numpy_docstring = False
