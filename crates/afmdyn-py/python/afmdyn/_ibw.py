"""A thermal spectrum stored as an Igor binary wave (``.ibw``, as Asylum Research's software saves
one), read by ``igor2`` for :func:`afmdyn.calibrate`.

The wave is one-dimensional, its x scaling the frequency (x = sfB + sfA·i, in Hz; WaveMetrics
Technical Note TN003, "Igor Binary Format") and its data units say what it holds: a power
spectral density (``m^2/Hz``, ``V^2/Hz``) or an amplitude spectral density (``m/√Hz``,
``V/√Hz``, also written ``m/sqrt(Hz)``, ``m/Hz^0.5``, ``m/rtHz``), which is squared. A wave
whose units say neither is refused, naming them: the reader does not guess a unit. A bin at
0 Hz (the mean) is dropped: the fit takes frequencies > 0."""
from __future__ import annotations

import os
import re
from typing import List, Tuple

import numpy as np

#: the largest file read (a thermal wave holds 10⁴–10⁶ points)
MAX_IBW_BYTES = 256 * 1024 * 1024


def _units(raw: object) -> str:
    """The units as text (bytes as UTF-8, else Latin-1; an array of characters joined), spaces
    dropped and the notations of a square and a root unified (``²`` → ``^2``; ``√Hz``,
    ``sqrt(Hz)``, ``Hz^0.5``, ``Hz^(1/2)``, ``Hz^½``, ``rtHz`` → ``Hz^0.5``)."""
    if isinstance(raw, np.ndarray):
        raw = b"".join(bytes(c) for c in raw.ravel())
    if isinstance(raw, bytes):
        head = raw.split(b"\0")[0]
        try:
            raw = head.decode("utf-8")
        except UnicodeDecodeError:
            raw = head.decode("latin-1")
    text = re.sub(r"\s+", "", str(raw))
    text = text.replace("²", "^2")
    return re.sub(r"√Hz|sqrt\(Hz\)|Hz\^\(1/2\)|Hz\^½|Hz\^0\.5|rtHz", "Hz^0.5", text)


def _data_units(wave: dict) -> str:
    """The wave's data units: its extended units where the file has them, else the header's."""
    long = wave.get("data_units") or b""
    return _units(long if long else wave["wave_header"]["dataUnits"])


def _x_units(wave: dict) -> str:
    """The units of the wave's x (its first dimension): the first ``dimEUnitsSize[0]`` bytes
    of the extended dimension units where there are some, else the header's."""
    size = int(wave["bin_header"]["dimEUnitsSize"][0])
    long = (wave.get("dimension_units") or b"")[:size]
    return _units(long if size else wave["wave_header"]["dimUnits"][0])


def read_spectrum(path: str) -> Tuple[List[float], List[float], bool]:
    """The frequencies (Hz), the one-sided power spectral density and whether it is the
    detector's (V²/Hz; else m²/Hz) of the thermal wave ``path`` (module docs).

    Raises:
        ValueError: naming ``psd`` and the file: igor2 missing, the file too large, not an
            Igor binary wave, not one-dimensional, x units other than Hz, data units neither
            a PSD's nor an ASD's, values not finite."""
    try:
        from igor2 import binarywave  # type: ignore[import-untyped]
    except ImportError as e:
        raise ValueError(f"psd: {path} is an Igor binary wave; reading it needs the igor2 "
                         "package (pip install igor2)") from e
    size = os.path.getsize(path)
    if size > MAX_IBW_BYTES:
        raise ValueError(f"psd: {path} has {size} bytes, more than the {MAX_IBW_BYTES} read of "
                         "a thermal wave")
    try:
        wave = binarywave.load(path)["wave"]
    except Exception as e:  # igor2 raises what its parser meets
        raise ValueError(f"psd: {path} is not an Igor binary wave ({e})") from e
    header = wave["wave_header"]
    data = np.asarray(wave["wData"], dtype=float)
    if data.ndim != 1:
        raise ValueError(f"psd: {path} holds a wave of shape {data.shape}; a thermal spectrum "
                         "is one-dimensional")
    x_units = _x_units(wave)
    if x_units not in ("Hz", ""):
        raise ValueError(f"psd: {path} has x units '{x_units}'; a spectrum's x is the "
                         "frequency in Hz")
    data_units = _data_units(wave)
    kinds = {"m^2/Hz": (False, 1), "V^2/Hz": (True, 1), "m/Hz^0.5": (False, 2),
             "V/Hz^0.5": (True, 2)}
    if data_units not in kinds:
        raise ValueError(f"psd: {path} has data units '{data_units}', neither a power "
                         "spectral density (m^2/Hz, V^2/Hz) nor an amplitude spectral density "
                         "(m/√Hz, V/√Hz)")
    volts, power = kinds[data_units]
    frequency = header["sfB"][0] + header["sfA"][0] * np.arange(data.size)
    psd = data ** power
    if not (np.all(np.isfinite(frequency)) and np.all(np.isfinite(psd))):
        raise ValueError(f"psd: {path} holds values that are not finite")
    keep = frequency > 0
    return frequency[keep].tolist(), psd[keep].tolist(), volts
