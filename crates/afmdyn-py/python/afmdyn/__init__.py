"""afmdyn — multi-modal tapping-mode AFM cantilever dynamics with intermittent contact.

The Rust engine of the ``afmdyn`` command line, called directly (no subprocess): every
analysis runs with the GIL released, can be interrupted with Ctrl-C, shows a progress bar
when it runs long, and returns NumPy float64 arrays in ``xarray.Dataset`` objects (time
series, sweeps, curves) or small result objects whose ``to_dict()`` is the command line's
``--json`` document for the same arguments.

>>> import afmdyn
>>> afmdyn.modes(modes=5, beam_damping=0, contact_damping=0).contact.omega.round(2)[:3]
array([ 7.79, 20.33, 55.81])

Analyses: :func:`modes`, :func:`simulate`, :func:`converge`, :func:`bifurcation`,
:func:`attractors`, :func:`global_continuation` (attractors and basin fractions continued over a
parameter), :func:`basins` (basins of attraction), :func:`chart` (behaviour charts over two parameters; on a Dask cluster
with :func:`afmdyn.dask.chart`), :func:`orbit`, :func:`continuation`, :func:`lyapunov`, :func:`observe`
(amplitude, phase, dissipated energy, virial, forces of a steady state), :func:`approach`
(approach–retract curves) and :func:`resonance` (resonance curves), both with branches and
folds. Physical units: a probe
file in SI (:func:`probe`, ``Params.from_probe``) sets every parameter. Tip–sample laws:
``contact_law="linear" | "hertz" | "dmt" | "electrostatic" | "jkr" | "capillary" | "sls" | "impact"``
with each law's groups, under their own names, among the model keywords (the table
``afmdyn._afmdyn.MODEL_PARAMETERS`` lists them with their laws and ranges).
"""

from . import _wrappers, _wrappers_afm, _wrappers_starts
from ._afmdyn import Params, SimulationError
from ._api import cantilevers, probe
from ._attractors import Attractor, Attractors
from ._common import AfmdynWarning, Model, summary
from ._fit_map import export_map
from ._interrupt import cancel_running
from ._interrupt import install as _install_sigint
from ._results import Lyapunov, Orbit, RegionSpectrum, Spectrum

# the analyses (simulate, orbit, …, approach, image, …): generated, each module's names in its
# __all__
from ._wrappers import *  # noqa: F401,F403
from ._wrappers_afm import *  # noqa: F401,F403
from ._wrappers_starts import *  # noqa: F401,F403

try:
    from importlib.metadata import version as _version

    __version__ = _version("afmdyn")
except Exception:  # pragma: no cover - not installed as a distribution
    __version__ = "0+unknown"

# Ctrl-C cancels the analyses running in every thread (see afmdyn._interrupt)
_install_sigint()

__all__ = [
    "AfmdynWarning",
    "Attractor",
    "Attractors",
    "Lyapunov",
    "Model",
    "Orbit",
    "Params",
    "RegionSpectrum",
    "SimulationError",
    "Spectrum",
    "cancel_running",
    "cantilevers",
    "export_map",
    "probe",
    "summary",
]
__all__ += _wrappers.__all__
__all__ += _wrappers_afm.__all__
__all__ += _wrappers_starts.__all__
