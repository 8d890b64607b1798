"""The cantilever library (``afmdyn cantilevers``), as a ``pandas.DataFrame``."""

from __future__ import annotations

import json

import pandas as pd

from . import _afmdyn as _core


def cantilevers() -> pd.DataFrame:
    """The cantilever library (``afmdyn cantilevers``): nominal datasheet values of common
    tapping-mode, soft-tapping and biological-imaging cantilevers, one row per cantilever,
    indexed by name: ``maker``, ``spring_constant`` (N/m), ``resonance_frequency`` (Hz),
    ``quality_factor`` (in air; ``q_typical`` True where it is the lever class's typical value,
    not the datasheet's), ``radius`` (tip radius, m), ``source``. A probe file names one with
    ``[cantilever] name = "RTESPA-300"``; its own keys override the library's."""
    doc = json.loads(_core.cantilevers())
    return pd.DataFrame(doc["cantilevers"]).set_index("name")
