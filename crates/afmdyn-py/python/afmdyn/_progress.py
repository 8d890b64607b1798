"""Progress bars for long computations: tqdm in a terminal, tqdm's widget in Jupyter.

The compiled core calls ``callback(done, total)`` from the calling thread about every 50 ms
while a computation runs (``total`` is ``None`` when the work cannot be counted); the bar shows
up only once a run has lasted ``DELAY`` seconds, so quick calls print nothing.
"""

from __future__ import annotations

import contextlib
import sys
from typing import Callable, Iterator, Optional, Union

ProgressArg = Union[None, bool, Callable[[int, Optional[int]], object]]

#: Seconds a computation runs before its bar appears (with ``progress=None``).
DELAY = 1.0


def _in_jupyter() -> bool:
    # a Jupyter kernel has IPython imported already; do not import it otherwise (slow)
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
        return shell is not None and "IPKernelApp" in shell.config
    except Exception:
        return False


def _interactive() -> bool:
    """Whether a default bar (``progress=None``) is shown: in Jupyter, or when stderr is a
    terminal. In a log file or a pipe tqdm would write a line per update."""
    if _in_jupyter():
        return True
    try:
        return sys.stderr is not None and sys.stderr.isatty()
    except (AttributeError, ValueError):  # a replaced or closed stderr
        return False


def _tqdm_class():
    if _in_jupyter():
        try:
            import ipywidgets  # noqa: F401  (the widget bar needs it)
            from tqdm.notebook import tqdm as notebook_tqdm

            return notebook_tqdm
        except Exception:  # no widgets: the text bar works everywhere
            pass
    from tqdm import tqdm as text_tqdm

    return text_tqdm


class _Bar:
    def __init__(self, desc: str, unit: str, delay: float) -> None:
        self.desc, self.unit, self.delay = desc, unit, delay
        self.bar = None

    def __call__(self, done: int, total: Optional[int]) -> None:
        if self.bar is None:
            # work that cannot be counted: the time it has run, the bar gone at its end
            kind = (dict(bar_format="{desc}: running {elapsed}", leave=False) if total is None
                    else dict(unit=self.unit, leave=True))
            self.bar = _tqdm_class()(total=total, desc=self.desc, delay=self.delay, **kind)
        self.bar.update(done - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


@contextlib.contextmanager
def reporter(
    progress: ProgressArg, desc: str, unit: str = "point"
) -> Iterator[Optional[Callable[[int, Optional[int]], object]]]:
    """The callback to hand to the core for ``progress``: ``None`` a tqdm bar after
    ``DELAY`` seconds when stderr is a terminal or in Jupyter (nothing in a log or a pipe),
    ``True`` a bar at once wherever stderr goes, ``False`` nothing, a callable is called as
    is."""
    if progress is False or (progress is None and not _interactive()):
        yield None
    elif progress is None or progress is True:
        bar = _Bar(desc, unit, 0.0 if progress is True else DELAY)
        try:
            yield bar
        finally:
            bar.close()
    elif callable(progress):
        yield progress
    else:
        raise TypeError(
            f"progress: expected None, True, False or a callable(done, total), got {progress!r}"
        )
