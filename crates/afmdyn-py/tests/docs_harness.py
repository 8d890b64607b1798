"""The book's runnable examples and links (issue 80), as functions the docs test
(``test_docs.py``) calls on every page: the README and every ``docs/**/*.md``.

Conventions (docs/index.md's book, written against them):

* A fenced block with info string ``console`` is run. Its lines beginning ``$ `` are commands (a
  trailing `` \\`` continues a command on the next line); only commands starting ``afmdyn `` are
  allowed, and ``afmdyn`` is replaced by the checkout's binary. The lines after a command, up to
  the next ``$ `` line or the block's end, are its quoted output: every non-blank quoted line must
  occur in one line of the command's stdout+stderr (whitespace runs compared as one space), where
  ``...`` inside a quoted line matches any text. A command whose quoted output starts with
  ``afmdyn: `` must exit 2 (a refusal); every other command must exit 0.
* A fenced block with info string ``python`` is run: the blocks of one page in order, in one
  namespace.
* Each page runs in its own scratch directory (the working directory), holding the symlinks
  ``examples`` and ``docs`` to the repository's; its blocks run in page order.
* Directives, HTML comments on the line(s) right before a fence:
  ``<!-- docs-test: skip: REASON -->`` (not run; the reason is required);
  ``<!-- docs-test: replace "OLD" "NEW" ... -->`` (textual replacements applied to the block's
  commands / Python code / file text before it runs; the quoted output is then not compared,
  only the exit status); ``<!-- docs-test: file NAME -->`` (the block's text is written to NAME
  in the scratch directory, and not run).
* Blocks with any other info string are shown, not run.

Links: every Markdown link and image of a page whose target is a relative path must name an
existing file or directory (relative to the page; ``../crates/...`` included), and a
``#anchor`` to a Markdown page (or ``#anchor`` alone, the page itself) must be a heading's slug
there, computed as MyST's ``myst_heading_anchors = 4`` does (GitHub style: the heading's text
and inline code, lower-cased, spaces to ``-``, every character but word characters, ``-`` and
spaces dropped; duplicates suffixed ``-1``, ``-2``; math and markup not part of the text).
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Set, Tuple
from urllib.parse import unquote, urlsplit

FENCE = re.compile(r"^( {0,3}|\s*)(`{3,}|~{3,})\s*([^`\s]*)(.*)$")
DIRECTIVE = re.compile(r"^\s*<!--\s*docs-test:\s*(.*?)\s*-->\s*$")
# a command's shell syntax the harness does not run (it runs the argument list, without a shell)
SHELL_TOKENS = {"|", "||", "&&", ";", ">", ">>", "<", "2>", "2>&1", "&"}


@dataclass
class Block:
    """A fenced code block: its info string's first word, its text, the 1-based line of its
    opening fence, and the docs-test directives right before it."""

    info: str
    text: str
    line: int
    skip: Optional[str] = None
    replace: List[Tuple[str, str]] = field(default_factory=list)
    file: Optional[str] = None


@dataclass
class Command:
    """One ``$ `` command of a console block: its text (continuations joined), its line and
    its quoted output lines."""

    text: str
    line: int
    quoted: List[str] = field(default_factory=list)

    @property
    def refusal(self) -> bool:
        lines = [q for q in self.quoted if q.strip()]
        return bool(lines) and lines[0].strip().startswith("afmdyn: ")


class DocsError(ValueError):
    """A page that breaks the conventions (a malformed directive, a command that is not
    ``afmdyn``): reported as the page's failure."""


def parse_directive(body: str, where: str) -> Tuple[str, object]:
    """``skip: REASON``, ``replace "OLD" "NEW" ...`` or ``file NAME`` into (kind, value)."""
    if body.startswith("skip"):
        reason = body[len("skip"):].lstrip(":").strip()
        if not body.startswith("skip:") or not reason:
            raise DocsError(f"{where}: a skip directive needs a reason: 'skip: REASON'")
        return "skip", reason
    if body.startswith("replace"):
        rest = body[len("replace"):]
        strings = re.findall(r'"((?:[^"\\]|\\.)*)"', rest)
        if re.sub(r'"((?:[^"\\]|\\.)*)"', "", rest).strip() or not strings or len(strings) % 2:
            raise DocsError(f'{where}: a replace directive is pairs of "OLD" "NEW": {body!r}')
        strings = [s.replace('\\"', '"').replace("\\\\", "\\") for s in strings]
        return "replace", list(zip(strings[::2], strings[1::2]))
    if body.startswith("file "):
        name = body[len("file "):].strip()
        if not name or len(name.split()) != 1 or os.path.isabs(name) or ".." in Path(name).parts:
            raise DocsError(f"{where}: a file directive names one relative file: {body!r}")
        return "file", name
    raise DocsError(f"{where}: unknown docs-test directive {body!r} (skip:, replace, file)")


def blocks(text: str, name: str = "page") -> List[Block]:
    """The fenced code blocks of a Markdown page with their directives. A directive that is not
    right before a fence, or a fence left open, is a DocsError."""
    lines = text.splitlines()
    found: List[Block] = []
    pending: List[Tuple[int, str]] = []  # (line, directive body) right before the next fence
    i = 0
    while i < len(lines):
        line = lines[i]
        d = DIRECTIVE.match(line)
        if d:
            pending.append((i + 1, d.group(1)))
            i += 1
            continue
        m = FENCE.match(line)
        if not m or (m.group(2)[0] == "`" and "`" in m.group(4)):
            if pending:
                raise DocsError(f"{name}:{pending[0][0]}: a docs-test directive not right "
                                "before a fenced block")
            i += 1
            continue
        indent, fence, info = len(m.group(1)), m.group(2), m.group(3)
        body = []
        j = i + 1
        while j < len(lines):
            close = re.match(r"^\s*(`{3,}|~{3,})\s*$", lines[j])
            if close and close.group(1)[0] == fence[0] and len(close.group(1)) >= len(fence):
                break
            # the opening fence's indentation is not part of the text
            body.append(lines[j][indent:] if lines[j][:indent].strip() == "" else lines[j].lstrip())
            j += 1
        else:
            raise DocsError(f"{name}:{i + 1}: a fenced block that is never closed")
        block = Block(info=info, text="\n".join(body) + "\n", line=i + 1)
        for at, directive in pending:
            kind, value = parse_directive(directive, f"{name}:{at}")
            if kind == "replace":
                block.replace.extend(value)  # type: ignore[arg-type]
            else:
                setattr(block, kind, value)
        pending = []
        found.append(block)
        i = j + 1
    if pending:
        raise DocsError(f"{name}:{pending[0][0]}: a docs-test directive not right before a "
                        "fenced block")
    return found


def console_commands(block: Block) -> List[Command]:
    """The ``$ `` commands of a console block with their quoted output."""
    commands: List[Command] = []
    lines = block.text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("$ "):
            text = line[2:]
            start = block.line + 1 + i
            while text.endswith("\\") and i + 1 < len(lines):
                i += 1
                text = text[:-1].rstrip() + " " + lines[i].strip()
            commands.append(Command(text=text.strip(), line=start))
        elif line.strip():
            if not commands:
                raise DocsError(f"line {block.line + 1 + i}: a console block's text before its "
                                f"first '$ ' command: {line!r}")
            commands[-1].quoted.append(line)
        i += 1
    return commands


def apply(text: str, pairs: Sequence[Tuple[str, str]], where: str) -> str:
    """The replace directive's pairs applied in order; an OLD that does not occur is an error
    (the text changed under the directive)."""
    for old, new in pairs:
        if old not in text:
            raise DocsError(f"{where}: replace: {old!r} does not occur in the block")
        text = text.replace(old, new)
    return text


def normalize(s: str) -> str:
    return " ".join(s.split())


def quoted_line_matches(quoted: str, output: str) -> bool:
    """A quoted line occurs in one line of the output, whitespace runs as one space, ``...``
    matching any text."""
    parts = [re.escape(normalize(p)) for p in normalize(quoted).split("...")]
    pattern = re.compile(r"\s*.*?\s*".join(parts) if len(parts) > 1 else parts[0])
    return any(pattern.search(normalize(line)) for line in output.splitlines())


def run_command(command: Command, binary: Path, cwd: Path, pairs: Sequence[Tuple[str, str]],
                where: str, timeout: float = 300) -> Tuple[List[str], float]:
    """Run one console command; its failures (messages) and its wall time."""
    text = command.text
    for old, new in pairs:  # checked against the whole block by run_page
        text = text.replace(old, new)
    try:
        args = shlex.split(text, comments=True)
    except ValueError as e:
        return [f"{where}: cannot split {text!r}: {e}"], 0.0
    if not args or args[0] != "afmdyn":
        return [f"{where}: only 'afmdyn ...' commands are run in a console block: {text!r}"], 0.0
    shell = [a for a in args if a in SHELL_TOKENS]
    if shell:
        return [f"{where}: shell syntax {shell} in a console command (run without a shell): "
                f"{text!r}"], 0.0
    t0 = time.perf_counter()
    try:
        run = subprocess.run([str(binary), *args[1:]], cwd=cwd, capture_output=True, text=True,
                             stdin=subprocess.DEVNULL, timeout=timeout)
    except subprocess.TimeoutExpired:
        return [f"{where}: {text}: ran past {timeout:.0f} s"], timeout
    took = time.perf_counter() - t0
    out = run.stdout + run.stderr
    failures = []
    want = 2 if command.refusal else 0
    if run.returncode != want:
        failures.append(f"{where}: {text}: exit status {run.returncode}, the page shows "
                        f"{'a refusal (2)' if want == 2 else 'a success (0)'}; output:\n"
                        f"{out[-2000:]}")
    elif not pairs:
        missing = [q for q in command.quoted if q.strip() and not quoted_line_matches(q, out)]
        if missing:
            failures.append(f"{where}: {text}: quoted output not in the output: {missing}; "
                            f"output:\n{out[-2000:]}")
    return failures, took


def scratch_dir(root: Path, repo: Path) -> Path:
    """The page's working directory with the ``examples`` and ``docs`` symlinks."""
    root.mkdir(parents=True, exist_ok=True)
    for name in ("examples", "docs"):
        if not (root / name).exists():
            (root / name).symlink_to(repo / name)
    return root


def run_page(page: Path, binary: Path, cwd: Path, name: Optional[str] = None,
             timings: Optional[List[Tuple[str, float]]] = None) -> List[str]:
    """Run a page's console and python blocks in page order in ``cwd`` (the scratch
    directory); the failures, as messages naming the page and line. ``timings`` collects each
    command's and Python block's wall time."""
    name = name or page.name
    try:
        found = blocks(page.read_text(encoding="utf-8"), name)
    except DocsError as e:
        return [str(e)]
    failures: List[str] = []
    namespace: Dict[str, object] = {"__name__": "__docs__"}
    here = os.getcwd()
    os.chdir(cwd)
    try:
        for block in found:
            where = f"{name}:{block.line}"
            try:
                if block.skip is not None:
                    continue
                if block.file is not None:
                    text = apply(block.text, block.replace, where) if block.replace else block.text
                    target = cwd / block.file
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.write_text(text, encoding="utf-8")
                elif block.info == "console":
                    if block.replace:
                        apply(block.text, block.replace, where)  # every OLD occurs in the block
                    for command in console_commands(block):
                        at = f"{name}:{command.line}"
                        f, took = run_command(command, binary, cwd, block.replace, at)
                        failures.extend(f)
                        if timings is not None:
                            timings.append((f"{at} {command.text[:60]}", took))
                elif block.info == "python":
                    code = apply(block.text, block.replace, where) if block.replace else block.text
                    t0 = time.perf_counter()
                    try:
                        exec(compile(code, f"{name}:{block.line}", "exec"), namespace)
                    except Exception as e:  # noqa: BLE001 - any failure of the page's code
                        failures.append(f"{where}: the python block raised "
                                        f"{type(e).__name__}: {e}")
                    if timings is not None:
                        timings.append((f"{where} python", time.perf_counter() - t0))
            except DocsError as e:
                failures.append(str(e))
    finally:
        os.chdir(here)
    return failures


# ---------------------------------------------------------------------------- links and anchors

def _markdown():
    """MyST's own Markdown parser (the book's: dollarmath, colon_fence), for links and
    headings exactly as the book reads them."""
    from markdown_it.renderer import RendererHTML
    from myst_parser.config.main import MdParserConfig
    from myst_parser.parsers.mdit import create_md_parser

    return create_md_parser(
        MdParserConfig(enable_extensions={"dollarmath", "colon_fence"}, heading_anchors=4),
        RendererHTML)


_MD = None


def tokens(text: str):
    global _MD
    if _MD is None:
        _MD = _markdown()
    return _MD.parse(text)


def github_slug(title: str) -> str:
    """MyST's GitHub-style slug (myst_parser.slugs.github_slugify)."""
    return re.sub(r"[^\w\u4e00-\u9fff\- ]", "", title.lower().replace(" ", "-"))


def heading_slugs(text: str, max_level: int = 4) -> Set[str]:
    """The anchors MyST makes for a page's headings of level <= max_level
    (myst_heading_anchors): the title is the heading's text and inline code, the slug made
    unique with -1, -2, ...; an empty slug gives no anchor."""
    toks = tokens(text)
    slugs: Set[str] = set()
    for i, tok in enumerate(toks):
        if tok.type != "heading_open" or int(tok.tag[1:]) > max_level:
            continue
        title = "".join(c.content for c in (toks[i + 1].children or [])
                        if c.type in ("text", "code_inline"))
        slug = github_slug(title)
        if not slug:
            continue
        unique, n = slug, 1
        while unique in slugs:
            unique, n = f"{slug}-{n}", n + 1
        slugs.add(unique)
    return slugs


def links(text: str) -> List[str]:
    """The targets of a page's Markdown links and images (not those inside code)."""
    found = []

    def walk(toks):
        for tok in toks:
            if tok.type == "link_open" and tok.attrGet("href") is not None:
                found.append(str(tok.attrGet("href")))
            elif tok.type == "image" and tok.attrGet("src") is not None:
                found.append(str(tok.attrGet("src")))
            if tok.children:
                walk(tok.children)

    walk(tokens(text))
    return found


def check_links(page: Path, repo: Path, name: Optional[str] = None) -> List[str]:
    """Every relative link of the page names an existing file (relative to the page) inside
    the repository, and every ``#anchor`` into a Markdown page a heading there."""
    name = name or page.name
    text = page.read_text(encoding="utf-8")
    failures = []
    slugs_of: Dict[Path, Set[str]] = {}
    for target in links(text):
        parts = urlsplit(target)
        if parts.scheme or parts.netloc or target.startswith("{"):
            continue  # a URL (https:, mailto:) or a MyST role
        path = unquote(parts.path)
        dest = (page.parent / path).resolve() if path else page.resolve()
        if path:
            if not dest.exists():
                failures.append(f"{name}: link {target!r}: no file {path}")
                continue
            try:
                dest.relative_to(repo.resolve())
            except ValueError:
                failures.append(f"{name}: link {target!r}: outside the repository")
                continue
        if parts.fragment and dest.suffix == ".md" and dest.is_file():
            if dest not in slugs_of:
                slugs_of[dest] = heading_slugs(dest.read_text(encoding="utf-8"))
            if unquote(parts.fragment) not in slugs_of[dest]:
                failures.append(f"{name}: link {target!r}: no heading #{parts.fragment} in "
                                f"{dest.name}")
    return failures
