"""Ctrl-C cancels every running analysis, in whatever thread it runs.

Python runs signal handlers in the main thread only, so an analysis called from a worker thread
(``ThreadPoolExecutor(...).submit(afmdyn.lyapunov, ...)``) would never see Ctrl-C and would keep
the process alive after it. On import, afmdyn wraps the main thread's SIGINT handler: the
wrapper first cancels every running analysis (:func:`cancel_running`; each raises
``KeyboardInterrupt`` in its own thread within 50 ms, or at the end of the point or start it
is computing), then calls the handler it wrapped (Python's default raises
``KeyboardInterrupt`` in the main thread). It wraps only a Python-level handler (not SIG_IGN or
SIG_DFL), and is wrapped again by the next analysis called from the main thread if other code
replaced it; code that installs its own handler later can call :func:`cancel_running` itself.
"""

from __future__ import annotations

import signal
import threading
from typing import Any, Callable, Optional

from ._afmdyn import cancel_running

_wrapped: Optional[Callable[[int, Any], Any]] = None


def _on_sigint(signum: int, frame: Any) -> Any:
    cancel_running()
    if _wrapped is not None:
        return _wrapped(signum, frame)
    raise KeyboardInterrupt


def install() -> None:
    """Wrap the SIGINT handler (from the main thread; at most once per handler)."""
    global _wrapped
    if threading.current_thread() is not threading.main_thread():
        return
    try:
        current = signal.getsignal(signal.SIGINT)
    except (ValueError, OSError):  # pragma: no cover - no signals here
        return
    if current is _on_sigint or not callable(current):
        return
    _wrapped = current
    signal.signal(signal.SIGINT, _on_sigint)
