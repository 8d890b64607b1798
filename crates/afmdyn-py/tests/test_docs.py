"""The book and the README cannot drift (issue 80): every page — the README and every
``docs/**/*.md`` — runs its ``console`` and ``python`` blocks by the conventions of
``docs_harness.py`` (one case per page, in its own scratch directory), and its relative links and
``#anchors`` resolve; the README's ``cargo run --release -- …`` lines run; every subcommand and
flag the pages name exists in ``--help``; a refusal shown in a shown-only block (``sh``) is
what the command prints. (The book's build without warnings is scripts/test.sh's, with
scripts/build-book.sh.)"""

from __future__ import annotations

import re
import shlex
from pathlib import Path
from typing import List, Tuple

import pytest

import docs_harness as h
from conftest import REPO, _binary

DOCS = REPO / "docs"
# docs/conf.py's exclude_patterns: the figures' and the build's folders hold no pages
PAGES = sorted(p for p in DOCS.rglob("*.md")
               if not {"_build", "figures"} & set(p.relative_to(DOCS).parts))
ALL = [REPO / "README.md", *PAGES]
IDS = [str(p.relative_to(REPO)) for p in ALL]


# ------------------------------------------------------------------ every page's examples and links

@pytest.mark.parametrize("page", ALL, ids=IDS)
def test_the_page_runs(page: Path, cli, tmp_path, monkeypatch):
    """The page's console and python blocks, in page order, in a scratch directory."""
    monkeypatch.setenv("MPLBACKEND", "Agg")  # a python block's plots go nowhere
    cwd = h.scratch_dir(tmp_path / "page", REPO)
    timings: List[Tuple[str, float]] = []
    failures = h.run_page(page, _binary(), cwd, str(page.relative_to(REPO)), timings)
    slow = [f"{w}: {t:.1f} s" for w, t in timings if t > 10]
    if slow:
        print("slow examples (reduce them with a replace directive):", *slow, sep="\n  ")
    assert not failures, "\n".join(failures)


@pytest.mark.parametrize("page", ALL, ids=IDS)
def test_the_page_links_resolve(page: Path):
    failures = h.check_links(page, REPO, str(page.relative_to(REPO)))
    assert not failures, "\n".join(failures)


def test_the_book_has_its_pages():
    names = {str(p.relative_to(DOCS)) for p in PAGES}
    assert {"index.md", "getting-started.md", "outputs.md", "contact-laws.md"} <= names


# ------------------------------------------------------------------------------ the README's lines

def readme_commands() -> List[List[str]]:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    commands = []
    for block in re.findall(r"```(?:sh|bash)?\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            line = line.strip()
            if line.startswith("cargo run --release -- "):
                commands.append(shlex.split(line[len("cargo run --release -- "):], comments=True))
    return commands


def test_readme_lists_the_commands():
    names = {c[0] for c in readme_commands()}
    # the main job, and one line for every analysis the README shows
    assert {"bifurcation", "simulate", "attractors", "chart", "basins", "approach",
            "resonance", "cantilevers"} <= names


def test_every_readme_command_runs(cli, tmp_path):
    """Every ``cargo run --release -- …`` line of the README's blocks, in order, with the
    binary of this checkout in a scratch directory (``examples/`` linked into it), exits 0 with
    nothing on stderr but warnings and progress."""
    (tmp_path / "examples").symlink_to(REPO / "examples")
    for args in readme_commands():
        run = cli(*args, cwd=tmp_path)
        assert run.returncode == 0, f"{' '.join(args)}: {run.stderr}"
        for line in run.stderr.splitlines():
            assert "error" not in line.lower() or "warning" in line, f"{' '.join(args)}: {line}"


# ------------------------------------------------------------- the subcommands and flags named

def inline_commands() -> List[tuple]:
    """Every ``afmdyn SUBCOMMAND …`` written in backticks in the pages: (page, subcommand,
    its ``--flags``)."""
    found = []
    for path in ALL:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"`afmdyn ([a-z]+)((?: [^`]*)?)`", text):
            found.append((path.name, m.group(1), re.findall(r"--[a-z][a-z0-9-]*", m.group(2))))
    return found


def block_commands() -> List[tuple]:
    """The ``afmdyn …`` commands of the pages' code blocks (``console``, ``sh``, ``bash``, no
    info string; ``$ `` prompts stripped, `` \\`` continuations joined): (page, args, the
    block's info string, the lines after the command up to the next command in its block)."""
    found = []
    for path in ALL:
        for block in h.blocks(path.read_text(encoding="utf-8"), path.name):
            if block.info not in ("", "sh", "bash", "shell", "console"):
                continue
            lines = block.text.splitlines()
            i = 0
            while i < len(lines):
                line = lines[i].strip()
                if line.startswith("$ "):
                    line = line[2:]
                while line.endswith("\\") and i + 1 < len(lines):
                    i += 1
                    line = line[:-1].rstrip() + " " + lines[i].strip()
                i += 1
                if not line.startswith("afmdyn "):
                    continue
                after = []
                while i < len(lines) and not re.match(r"\s*(\$ )?afmdyn ", lines[i]):
                    after.append(lines[i].strip())
                    i += 1
                found.append((path.name, shlex.split(line[len("afmdyn "):], comments=True),
                              block.info, after))
    return found


def test_every_flag_the_docs_name_exists(cli):
    """Issue 28 item 9: a subcommand or flag written in the pages (inline or in a code block)
    that the command line does not have is drift. Checked against ``--help``, without running
    (shown-only commands are examples with placeholders: P, DIR, α5)."""
    top = cli("--help").stdout
    helps: dict = {}
    cases = inline_commands() + [(f, a[0], [t for t in a if t.startswith("--")])
                                 for f, a, _, _ in block_commands() if a]
    assert len(cases) >= 30
    for name, sub, flags in cases:
        assert re.search(rf"^  {sub}\b", top, flags=re.M), f"{name}: no subcommand {sub}"
        if sub not in helps:
            helps[sub] = cli(sub, "--help").stdout
        for flag in flags:
            flag = flag.split("=")[0]
            assert re.search(rf"(^|\s){re.escape(flag)}\b", helps[sub]), \
                f"{name}: afmdyn {sub} has no {flag}"


def test_the_refusals_shown_are_what_the_command_prints(cli, tmp_path):
    """A refusal a shown-only block (``sh``, ``bash``) shows — a command followed by the line
    ``afmdyn: …`` it prints — is the command's: exit status 2 and that stderr. (A console
    block's are run by test_the_page_runs; ``bad.toml``'s is abridged in the text.)"""
    (tmp_path / "examples").symlink_to(REPO / "examples")
    for name, args, info, after in block_commands():
        shown = [a for a in after if a.startswith("afmdyn: ")]
        if info == "console" or not shown or any("bad" in a for a in args):
            continue
        run = cli(*args, cwd=tmp_path)
        assert run.returncode == 2, f"{name}: afmdyn {' '.join(args)}: {run.stderr}"
        assert run.stderr.strip() == shown[0], f"{name}: {run.stderr!r} vs {shown[0]!r}"


# ------------------------------------------------------------------ the harness on a fixture page

FIXTURE = '''# A page

## The `--out` flag: files, *and* Ω α₅ — naïve $x$ here

## A page

Links: [ok](#a-page-1), [flag](#the---out-flag-files-and-ω-α₅--naïve--here),
[broken anchor](#nowhere), [missing](missing.md), [repo file](../../crates/afmdyn-py/tests/conftest.py),
[web](https://example.org/x.md), `[in code](nothere.md)`.

```console
$ afmdyn modes
free (region I)
   i   ω (undamped) ... Q
$ afmdyn simulate \\
    --periods -1
afmdyn: periods = -1: must be ...
```

<!-- docs-test: file probe-copy.toml -->
```toml
# written to the scratch directory
```

<!-- docs-test: replace "--periods 1e9" "--periods 2" -->
```console
$ afmdyn simulate --periods 1e9 --files none
this line is not compared under a replace directive
```

<!-- docs-test: skip: shown only, it would take hours -->
```console
$ afmdyn nonsense
```

```python
import pathlib
n = len(pathlib.Path("probe-copy.toml").read_text())
```

```python
assert n > 0 and pathlib.Path("examples").is_dir() and pathlib.Path("docs").is_dir()
```

```sh
$ afmdyn not run: shown only
```
'''


def fixture(tmp_path: Path, text: str = FIXTURE) -> Path:
    page = tmp_path / "docs" / "sub" / "page.md"
    page.parent.mkdir(parents=True)
    page.write_text(text, encoding="utf-8")
    return page


def test_harness_parses_blocks_and_directives(tmp_path):
    found = h.blocks(FIXTURE)
    assert [b.info for b in found] == ["console", "toml", "console", "console", "python",
                                       "python", "sh"]
    assert found[1].file == "probe-copy.toml"
    assert found[2].replace == [("--periods 1e9", "--periods 2")]
    assert found[3].skip == "shown only, it would take hours"
    commands = h.console_commands(found[0])
    assert [c.text for c in commands] == ["afmdyn modes", "afmdyn simulate --periods -1"]
    assert [c.refusal for c in commands] == [False, True]
    assert commands[0].quoted == ["free (region I)", "   i   ω (undamped) ... Q"]
    with pytest.raises(h.DocsError, match="needs a reason"):
        h.blocks("<!-- docs-test: skip -->\n```console\n$ afmdyn modes\n```\n")
    with pytest.raises(h.DocsError, match="pairs"):
        h.blocks('<!-- docs-test: replace "a" -->\n```console\n$ afmdyn modes\n```\n')
    with pytest.raises(h.DocsError, match="not right before"):
        h.blocks("<!-- docs-test: skip: x -->\n\n```console\n$ afmdyn modes\n```\n")
    with pytest.raises(h.DocsError, match="unknown"):
        h.blocks("<!-- docs-test: run -->\n```console\n$ afmdyn modes\n```\n")


def test_harness_quoted_output():
    out = "free (region I)\n   i   ω (undamped)           Re λ     Q\n"
    assert h.quoted_line_matches("i ω (undamped) ... Q", out)
    assert h.quoted_line_matches("free (region I)", out)
    assert not h.quoted_line_matches("free (region II)", out)
    # `...` stays within one line of the output
    assert not h.quoted_line_matches("free ... Re λ", out)


def test_harness_runs_the_fixture_page(tmp_path, cli):
    page = fixture(tmp_path)
    cwd = h.scratch_dir(tmp_path / "scratch", REPO)
    assert h.run_page(page, _binary(), cwd) == []
    assert (cwd / "probe-copy.toml").exists()


def test_harness_reports_what_drifted(tmp_path, cli):
    page = fixture(tmp_path, FIXTURE
                   .replace("free (region I)", "free (region IX)")
                   .replace("must be ...", "must be positive")
                   .replace('"--periods 2"', '"--periods 0"')
                   .replace("n > 0", "n < 0")
                   .replace("$ afmdyn simulate \\", "$ afmdyn simulate > out.txt \\"))
    cwd = h.scratch_dir(tmp_path / "scratch", REPO)
    failures = h.run_page(page, _binary(), cwd, "page.md")
    text = "\n".join(failures)
    assert "page.md:12: afmdyn modes: quoted output not in the output: ['free (region IX)']" in text
    assert "shell syntax ['>']" in text
    assert "exit status 2, the page shows a success (0)" in text  # --periods 0, replaced
    assert "page.md:41: the python block raised AssertionError" in text
    assert len(failures) == 4, text
    # a refusal's quoted line is compared too
    page.write_text("```console\n$ afmdyn simulate --periods -1\nafmdyn: periods = -1: "
                    "must be positive\n```\n", encoding="utf-8")
    assert "quoted output not in the output" in "\n".join(h.run_page(page, _binary(), cwd))
    # a replace whose OLD the block no longer has
    page.write_text('<!-- docs-test: replace "--steps 400" "--steps 4" -->\n'
                    "```console\n$ afmdyn modes\n```\n", encoding="utf-8")
    assert "does not occur" in "\n".join(h.run_page(page, _binary(), cwd))
    # only afmdyn commands
    page.write_text("```console\n$ rm -rf docs\n```\n", encoding="utf-8")
    assert "only 'afmdyn ...' commands" in "\n".join(h.run_page(page, _binary(), cwd))


def test_harness_checks_links_and_anchors(tmp_path):
    page = fixture(tmp_path)
    # the fixture's repository: tmp_path, with crates/afmdyn-py/tests/conftest.py in it
    (tmp_path / "crates" / "afmdyn-py" / "tests").mkdir(parents=True)
    (tmp_path / "crates" / "afmdyn-py" / "tests" / "conftest.py").write_text("")
    failures = h.check_links(page, tmp_path, "page.md")
    assert failures == ["page.md: link '#nowhere': no heading #nowhere in page.md",
                        "page.md: link 'missing.md': no file missing.md"], failures
    other = page.parent / "other.md"
    other.write_text("[a](page.md#the---out-flag-files-and-ω-α₅--naïve--here) "
                     "[b](page.md#a-page-2) [c](../../crates/none.rs)\n", encoding="utf-8")
    assert h.check_links(other, tmp_path, "other.md") == [
        "other.md: link 'page.md#a-page-2': no heading #a-page-2 in page.md",
        "other.md: link '../../crates/none.rs': no file ../../crates/none.rs"]


def test_harness_slugs_are_myst_s():
    """The slugs of the headings above as MyST 5.2 writes them in the HTML (checked by
    building a page with them: ids the-out-flag… are docutils' own, not linkable by slug)."""
    text = ("# Top\n\n## The `--out` flag: files, and *emphasis* & [a link](x.md)\n\n"
            "## Unicode: Ω and α₅ — μm, naïve\n\n## Math $\\omega$ here\n\n## Top\n\n## Top\n\n"
            "##### Level five\n")
    assert h.heading_slugs(text) == {
        "top", "the---out-flag-files-and-emphasis--a-link", "unicode-ω-and-α₅--μm-naïve",
        "math--here", "top-1", "top-2"}
