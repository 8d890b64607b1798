"""Python's progress bar (issue 60 item 20): by default only where a person watches — a terminal
or Jupyter — and never a line per update in a log file or a pipe; ``progress=True`` forces it."""

import io

import pytest

import afmdyn
from afmdyn import _progress


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_the_default_bar_is_off_outside_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    log = io.StringIO()
    monkeypatch.setattr("sys.stderr", log)
    with _progress.reporter(None, "points") as callback:
        assert callback is None
    assert log.getvalue() == ""


def test_the_default_bar_is_on_in_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("sys.stderr", _Terminal())
    with _progress.reporter(None, "points") as callback:
        assert isinstance(callback, _progress._Bar)
        assert callback.delay == _progress.DELAY


def test_true_forces_the_bar_and_false_none(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("sys.stderr", io.StringIO())
    with _progress.reporter(True, "points") as callback:
        assert isinstance(callback, _progress._Bar) and callback.delay == 0.0
    with _progress.reporter(False, "points") as callback:
        assert callback is None


def test_every_public_function_with_progress_documents_it() -> None:
    import inspect

    checked = 0
    for name in afmdyn.__all__:
        f = getattr(afmdyn, name)
        if not inspect.isfunction(f):
            continue
        if "progress" in inspect.signature(f).parameters:
            assert "progress" in (f.__doc__ or ""), name
            checked += 1
    assert checked >= 15
