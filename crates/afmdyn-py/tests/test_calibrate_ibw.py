"""``afmdyn.calibrate(psd="….ibw")`` (issue 79 item 2): a thermal spectrum stored as an Igor
binary wave, as Asylum Research's software saves one, read through ``igor2``. The waves are
written here by an independent writer of the version-5 format (WaveMetrics Technical Note
TN003: the 64-byte BinHeader5 with its checksum, the 320-byte WaveHeader5 with the x scaling
sfA/sfB, the data, the extended data units): the calibration of a wave equals the calibration
of the same numbers given as arrays, for a PSD in m²/Hz, an amplitude spectral density in m/√Hz
and a detector's V²/Hz with an InvOLS; a wave whose units say neither, a 2-D wave and a file
that is not a wave are refused naming ``psd``."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest

import afmdyn

pytest.importorskip("igor2")

EX = Path(__file__).resolve().parents[3] / "examples"
KT = 1.380649e-23 * 295.0
PROBE = str(EX / "probe-point-mass-dmt.toml")


def write_ibw(path: Path, data: np.ndarray, x0: float, dx: float, data_units: str,
              x_units: str = "Hz") -> None:
    """An Igor binary wave, version 5 (TN003), little-endian, of float64 ``data`` (1-D or 2-D)
    with x = x0 + dx·i; units of more than 3 bytes go in the extended units sections."""
    data = np.asarray(data, dtype="<f8")
    shape = list(data.shape) + [0] * (4 - data.ndim)
    raw = data.tobytes(order="F")  # Igor stores columns first
    long_data = data_units.encode() if len(data_units.encode()) > 3 else b""
    long_x = x_units.encode() if len(x_units.encode()) > 3 else b""
    wave_header = b"".join([
        struct.pack("<iIIi", 0, 0, 0, data.size),          # next, creation, mod, npnts
        struct.pack("<hh", 4, 0),                          # type NT_FP64, dLock
        b"\0" * 6, struct.pack("<h", 1),                   # whpad1, whVersion
        b"thermal".ljust(32, b"\0"),                       # bname
        struct.pack("<ii", 0, 0),                          # whpad2, dFolder
        struct.pack("<4i", *shape),                        # nDim
        struct.pack("<4d", dx, 1, 1, 1),                   # sfA
        struct.pack("<4d", x0, 0, 0, 0),                   # sfB
        (b"" if long_data else data_units.encode()).ljust(4, b"\0"),     # dataUnits
        (b"" if long_x else x_units.encode()).ljust(4, b"\0") + b"\0" * 12,  # dimUnits
        struct.pack("<hh", 0, 0),                          # fsValid, whpad3
        struct.pack("<dd", 0, 0),                          # top/botFullScale
        b"\0" * (4 + 16 + 16 + 4),                         # dataEUnits, dimEUnits, dimLabels, note
        b"\0" * 64,                                        # whUnused
        b"\0" * 6 + b"\0\0",                               # a/w/swModified, useBits, kindBits
        b"\0" * 4 + b"\0" * 4 + b"\0" * 4 + b"\0" * 4 + b"\0" * 4,  # formula … sIndices
    ])
    assert len(wave_header) == 320
    bin_header = struct.pack("<hhiiii4i4iiii", 5, 0, 320 + len(raw), 0, 0, len(long_data),
                             len(long_x), 0, 0, 0, 0, 0, 0, 0, 0, 0, 0)
    assert len(bin_header) == 64
    # the checksum makes the 16-bit sum of both headers zero
    words = struct.unpack("<192h", bin_header + wave_header)
    checksum = (-sum(words)) & 0xFFFF
    bin_header = bin_header[:2] + struct.pack("<H", checksum) + bin_header[4:]
    assert sum(struct.unpack("<192h", bin_header + wave_header)) & 0xFFFF == 0
    path.write_bytes(bin_header + wave_header + raw + long_data + long_x)


def spectrum(start: float = 270e3, points: int = 6000):
    """An oscillator's thermal PSD (k = 40 N/m, f₀ = 300 kHz, Q = 400: the probe's lever) on a
    floor, with the scatter of 64 averaged records (fixed seed), from ``start`` in steps of
    10 Hz."""
    k, f0, q = 40.0, 300e3, 400.0
    f = start + 10.0 * np.arange(points)
    p = 2 * KT / (np.pi * k * f0 * q)
    clean = p * f0 ** 4 / ((f ** 2 - f0 ** 2) ** 2 + (f * f0 / q) ** 2) + 1e-3 * p
    return f, clean * np.random.default_rng(3).gamma(64, 1 / 64, size=f.size)


def modes(ds):
    return json.loads(ds.attrs["summary"])["modes"]


@pytest.mark.filterwarnings("ignore::afmdyn.AfmdynWarning")
@pytest.mark.parametrize("units, power", [("m^2/Hz", 1), ("m²/Hz", 1), ("m/√Hz", 0.5),
                                          ("m/sqrt(Hz)", 0.5)])
def test_a_wave_calibrates_as_its_arrays(tmp_path, units, power):
    """A PSD (m²/Hz) or an ASD (m/√Hz, squared by the reader) written as a wave gives the
    calibration of the same PSD given as arrays: the same frequency, Q and k."""
    f, s = spectrum()
    path = tmp_path / "thermal.ibw"
    write_ibw(path, s ** power, f[0], f[1] - f[0], units)
    from_wave = modes(afmdyn.calibrate(probe=PROBE, psd=str(path), signal="deflection"))
    from_arrays = modes(afmdyn.calibrate(probe=PROBE, frequency=f, spectral_density=s,
                                         signal="deflection"))
    for key in ("frequency", "quality_factor", "spring_constant_thermal"):
        assert from_wave[0][key] == pytest.approx(from_arrays[0][key], rel=1e-9), key
    assert from_wave[0]["spring_constant_thermal"] == pytest.approx(40.0, rel=0.05)


@pytest.mark.filterwarnings("ignore::afmdyn.AfmdynWarning")
def test_a_detector_wave_takes_the_invols(tmp_path):
    """A wave in V²/Hz (the detector's) with an InvOLS of 50 nm/V equals the same PSD in m²/Hz
    given as arrays; ``volts`` with a wave in m²/Hz is refused naming it. The bin at 0 Hz is
    dropped."""
    f, s = spectrum(0.0, 33001)  # from 0 Hz, as an instrument's spectrum: its first bin the mean
    invols = 50e-9
    path = tmp_path / "thermal-volts.ibw"
    write_ibw(path, s / invols ** 2, 0.0, 10.0, "V^2/Hz")
    got = modes(afmdyn.calibrate(probe=PROBE, psd=str(path), invols=invols, signal="deflection"))
    want = modes(afmdyn.calibrate(probe=PROBE, frequency=f[1:], spectral_density=s[1:],
                                  signal="deflection"))
    assert got[0]["spring_constant_thermal"] == pytest.approx(
        want[0]["spring_constant_thermal"], rel=1e-9)
    f, s = spectrum()
    metres = tmp_path / "thermal-m.ibw"
    write_ibw(metres, s, f[0], 10.0, "m^2/Hz")
    with pytest.raises(ValueError, match="^volts: .*m²/Hz"):
        afmdyn.calibrate(probe=PROBE, psd=str(metres), volts=True, invols=invols)


def test_waves_that_are_not_spectra_are_refused(tmp_path):
    """Units neither a PSD's nor an ASD's, a 2-D wave, x units other than Hz, a file that is
    not a wave, and a wave with the arrays besides: each a ValueError naming ``psd``."""
    f, s = spectrum()
    cases = {
        "units.ibw": lambda p: write_ibw(p, s, f[0], 10.0, "N"),
        "two-d.ibw": lambda p: write_ibw(p, np.column_stack([s, s]), f[0], 10.0, "m^2/Hz"),
        "seconds.ibw": lambda p: write_ibw(p, s, f[0], 10.0, "m^2/Hz", x_units="s"),
        "text.ibw": lambda p: p.write_text("frequency,psd\n1,2\n"),
    }
    messages = {"units.ibw": "data units 'N'", "two-d.ibw": "shape", "seconds.ibw": "x units 's'",
                "text.ibw": "not an Igor binary wave"}
    for name, write in cases.items():
        path = tmp_path / name
        write(path)
        with pytest.raises(ValueError, match=f"^psd: .*{messages[name]}"):
            afmdyn.calibrate(probe=PROBE, psd=str(path))
    good = tmp_path / "good.ibw"
    write_ibw(good, s, f[0], 10.0, "m^2/Hz")
    with pytest.raises(ValueError, match="^psd: give the file psd or the arrays"):
        afmdyn.calibrate(probe=PROBE, psd=str(good), frequency=f, spectral_density=s)
