"""``afmdyn.fit_map`` (issue 78) on real instrument maps against nanite 4.2 (Müller et al.,
BMC Bioinformatics 20 (2019) 465), the peer package: every curve of afmformats' JPK
force-volume map (2 × 2) and QI map (4 curves) fitted with the Hertz paraboloid (R = 10 µm),
the cone (half angle 25°) and the three-sided pyramid (face angle 15°) (ν = 0.5; E, contact
point and baseline free; nanite's three preprocessing steps, the whole approach, unweighted)
gives nanite's E within 0.1 %, the exact sphere nanite's ``sneddon_spher_approx`` within the
approximation's error; each curve's spring constant is its file's;
``export_map`` of arrays gives the map of the same curves as a CSV; a map stored and resumed
equals the map in memory; a malformed map is refused naming the file."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import afmdyn
from test_fit import _nanite_fit, _sneddon_sphere

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
PROBE = str(EXAMPLES / "probe-fit-spot3.toml")
MAPS = [EXAMPLES / "fmt-jpk-fd_map2x2_extracted.jpk-force-map",
        EXAMPLES / "fmt-jpk-fd_2020.02.07-16.29.05.036.jpk-qi-data"]


def _fit_map(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        return afmdyn.fit_map(probe=PROBE, **kw)


def _approximation_error(depth, radius=10e-6):
    """The relative error of nanite's ``sneddon_spher_approx`` (Sneddon's sphere as the
    paraboloid times a series truncated at (δ/R)⁴, nanite's model docs) against the exact
    sphere at the indentation ``depth``: computed here from both forms."""
    d = depth / radius
    series = 1 - d / 10 - d ** 2 / 840 + 11 * d ** 3 / 15120 + 1357 * d ** 4 / 6652800
    paraboloid = 4 / 3 * np.sqrt(radius) * depth ** 1.5
    return abs(paraboloid * series / _sneddon_sphere(depth, radius) - 1)


#: nanite's model, its module, the held parameters, and afmdyn's ``[tip]`` for the same indenter
SHAPES = {
    "paraboloid": ("hertz_para", "model_hertz_paraboloidal", {}, "radius = 10e-6"),
    "sphere": ("sneddon_spher_approx", "model_sneddon_spherical_approximation", {},
               'shape = "sphere"\nradius = 10e-6'),
    "cone": ("hertz_cone", "model_conical_indenter", {"alpha": 25.0},
             'shape = "cone"\nhalf_angle = 25'),
    "pyramid-3": ("hertz_pyr3s", "model_hertz_three_sided_pyramid", {"alpha": 15.0},
                  'shape = "pyramid-3"\nface_angle = 15'),
}


@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("path", MAPS, ids=["force-map", "qi"])
def test_every_curve_of_an_instrument_map_fits_as_nanite_fits_it(path, shape):
    """Every curve of the map with each indenter: E within 0.1 % of nanite's, and the contact
    point within 1e-3; the exact sphere against nanite's approximation within that
    approximation's error at the curve's deepest indentation (stated per curve) plus 1e-4."""
    nanite = pytest.importorskip("nanite")
    pytest.importorskip("afmformats")
    model_key, module, held, tip = SHAPES[shape]
    probe = open(PROBE).read().replace("radius = 10e-6", tip)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ds = afmdyn.fit_map(probe=probe, data=path)
    group = nanite.IndentationGroup(path)
    fitted = 0
    for idnt in group:
        ref = _nanite_fit(idnt, model_key, getattr(nanite.model, module), **held)
        m = idnt.metadata
        # the curve's pixel: the map's grid indices, in the order of their positions
        xs = sorted({c.metadata["grid index x"] for c in group})
        ys = sorted({c.metadata["grid index y"] for c in group})
        pixel = dict(y=ys.index(m["grid index y"]), x=xs.index(m["grid index x"]))
        assert ds["flag"].isel(**pixel).item() == "fitted"
        tolerance = 1e-3
        if shape == "sphere":
            approach = np.asarray(idnt["segment"]) == 0
            tips = np.asarray(idnt["tip position"])[approach]
            depth = ref["contact_point"].value - np.min(tips)
            tolerance = _approximation_error(depth) + 1e-4
        e = ds["youngs_modulus"].isel(**pixel).item()
        assert abs(e / ref["E"].value - 1) < tolerance, (pixel, e, ref["E"].value)
        cp = ds["contact_point"].isel(**pixel).item()
        assert abs(cp - ref["contact_point"].value) < 1e-3 * abs(ref["contact_point"].value)
        fitted += 1
    assert fitted == ds.sizes["x"] * ds.sizes["y"] == 4


def _synthetic(n=3, rows=300, k=0.05, r=10e-6, e=5e3, nu=0.5):
    """A 3 × 3 map of noise-free Hertz approaches (Sneddon 1965: F = (4/3) E/(1 − ν²) √R δ^1.5),
    E rising along x, as a list of mappings."""
    curves = []
    t = np.linspace(0, 1, rows)
    for iy in range(n):
        for ix in range(n):
            modulus = e * (1 + ix)
            x = 1e-6 - 2.5e-6 * t
            f = 4 / 3 * modulus / (1 - nu ** 2) * np.sqrt(r) * np.clip(-x, 0, None) ** 1.5
            curves.append({"x": ix * 1e-6, "y": iy * 1e-6, "height": x - f / k, "force": f,
                           "spring_constant": k})
    return curves


def test_export_map_of_arrays_gives_the_map_of_the_same_curves_as_a_csv(tmp_path):
    curves = _synthetic()
    nc = afmdyn.export_map(curves, tmp_path / "map.nc")
    rows = ["x,y,height,force"]
    for c in curves:
        rows += [f"{c['x']!r},{c['y']!r},{float(h)!r},{float(f)!r}"
                 for h, f in zip(c["height"], c["force"])]
    csv = tmp_path / "map.csv"
    csv.write_text("\n".join(rows) + "\n")
    probe = {"model": "point-mass",
             "cantilever": {"spring_constant": 0.05, "resonance_frequency": 10e3,
                            "quality_factor": 50}, "tip": {"radius": 10e-6},
             "sample": {"law": "hertz", "youngs_modulus": 3e3, "poisson_ratio": 0.5},
             "drive": {"free_amplitude": 10e-9}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        from_nc = afmdyn.fit_map(probe=probe, data=nc)
        from_list = afmdyn.fit_map(probe=probe, data=curves)
        from_csv = afmdyn.fit_map(probe=probe, data=csv)
    truth = 5e3 * (1 + np.arange(3))
    for ds in (from_nc, from_list, from_csv):
        assert ds["youngs_modulus"].shape == (3, 3)
        np.testing.assert_allclose(ds["youngs_modulus"].values, np.tile(truth, (3, 1)), rtol=1e-6)
        np.testing.assert_allclose(ds["x"].values, [0, 1e-6, 2e-6])
    np.testing.assert_array_equal(from_nc["youngs_modulus"].values,
                                  from_csv["youngs_modulus"].values)


def test_a_stored_map_resumes_to_the_map_in_memory(tmp_path):
    path = MAPS[1]
    pytest.importorskip("afmformats")
    mem = _fit_map(data=path)
    stored = _fit_map(data=path, store=tmp_path / "run")
    again = _fit_map(data=path, store=tmp_path / "run", resume=True)
    for ds in (stored, again):
        np.testing.assert_array_equal(ds["youngs_modulus"].values, mem["youngs_modulus"].values)
    assert (tmp_path / "run" / ".fit_map.lines.jsonl").exists()


def test_a_malformed_map_is_refused_naming_the_file(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y,height\n0,0,1\n")
    with pytest.raises(ValueError, match="bad.csv.*no column force"):
        _fit_map(data=bad)
    with pytest.raises(ValueError, match="data"):
        _fit_map(data=None)
