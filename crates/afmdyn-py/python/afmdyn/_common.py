"""What every analysis shares: the model keywords (:class:`Model`), the parameter set and probe
of a call, the type check of the keywords, the request of the library an analysis' keywords
become, the call of the compiled function
with a progress reporter, and the warnings of its document. It imports no analysis and no
result type, so that every module of the package can import it."""

from __future__ import annotations

import collections.abc
import functools
import inspect
import json
import numbers
import os
import sys
import warnings
from typing import (Any, Callable, Dict, Optional, Protocol, Sequence, Tuple, TypeVar, Union, cast,
                    overload)

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from ._afmdyn import Params
from ._model import Model  # noqa: F401 (afmdyn.Model: generated from the model schema)
from ._progress import ProgressArg, reporter


class HasState(Protocol):
    """A start given by its state at drive phase 0: an :class:`Attractor` or an
    :class:`Orbit` (structurally, so that this module imports neither)."""

    @property
    def state(self) -> np.ndarray: ...


#: An initial state: 2N values, or an :class:`Attractor` / :class:`Orbit` (its ``state``).
StateLike = Union[None, Sequence[float], np.ndarray, HasState]


#: Global attributes of every dataset: the scales of the dimensionless units.
UNITS_NOTE = (
    "dimensionless (paper eq. 5): time in t0 = sqrt(m L^4/(E I)), displacements in the beam "
    "gap g0, forces in EI g0/L³, energies in EI g0²/L³"
)


def _real_array(name: str, v: Any, ndim: int) -> np.ndarray:
    """``v`` as a float64 array of ``ndim`` dimensions, or a ``ValueError`` naming ``name``: a
    complex array (whose imaginary part NumPy would drop with a mere warning) or one of other
    dimensions is refused, not flattened."""
    a = np.asarray(v)
    if np.iscomplexobj(a):
        raise ValueError(f"{name}: must be real numbers, got a complex array")
    if a.ndim != ndim:
        raise ValueError(f"{name}: must be a {ndim}D array, got {a.ndim}D (shape {a.shape})")
    try:
        return a.astype(np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: must be numbers ({e})") from None


def _params(
    params: Optional[Params],
    model: Any,
    default: Optional[Params] = None,
    quasi_static: bool = False,
) -> Tuple[Params, Optional[str]]:
    """The parameter set of an analysis call and its probe file (or ``None``), resolved by the
    library as the command line resolves ``--probe``/``--config`` and the model flags:
    ``params`` (or the probe's set, or ``default``, or the paper's set) with the ``model``
    keywords applied; ``quasi_static`` for a call that uses only the probe's spring constant,
    tip and sample (a force curve's fit: the library's ``ProbeNeeds::Static``)."""
    params, probe, model = _inputs(params, model, quasi_static)
    return _core.resolve(params, default, probe, model, quasi_static), probe


def _inputs(
    params: Optional[Params], model: Any, quasi_static: bool = False
) -> Tuple[Optional[Params], Optional[str], Any]:
    """``params`` checked, the probe's text and the other ``model`` keywords (a new dict)."""
    if params is not None and not isinstance(params, Params):
        raise TypeError(f"params: expected afmdyn.Params or None, got {type(params).__name__}")
    model = dict(model)
    return params, _probe_text(model, quasi_static), model


def _probe_text(model: Dict[str, Any], quasi_static: bool = False) -> Optional[str]:
    """Pop ``probe``, ``cantilever`` and ``medium`` from the model keywords: the probe's TOML
    text with the cantilever's name and the fluid (``"water"``, ``"air"`` or ``"none"``) set
    (the library's ``Probe::source_text``), checked (for a quasi-static call with
    ``quasi_static``), or ``None``."""
    probe = model.pop("probe", None)
    cantilever = model.pop("cantilever", None)
    medium = model.pop("medium", None)
    for key, value in (("cantilever", cantilever), ("medium", medium)):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{key}: expected a name (str), got {type(value).__name__}")
    if probe is None:
        for key, value in (("cantilever", cantilever), ("medium", medium)):
            if value is not None:
                raise ValueError(f"{key} needs probe= (as --{key} needs --probe)")
        return None
    if not isinstance(probe, (str, dict)):
        probe = os.fspath(probe)
    return _core.probe_source(probe, cantilever, medium, quasi_static)


def _state(initial: StateLike) -> Optional[list]:
    if initial is None:
        return None
    # an Attractor or an Orbit: its state at drive phase 0
    initial = getattr(initial, "state", initial)
    z = np.asarray(initial, dtype=np.float64)
    if z.ndim != 1:
        raise ValueError(
            f"initial: expected a 1-D state (a1..aN, adot1..adotN), got shape {z.shape}"
        )
    return z.tolist()


def _start_period(initial: StateLike) -> Optional[int]:
    """The period an :class:`Attractor` start gives an orbit (its own, 1 when nonperiodic);
    ``None`` for another start."""
    if hasattr(initial, "basin_fraction"):
        return getattr(initial, "period", None) or 1
    return None


def _param_attrs(p: Params) -> Dict[str, Any]:
    return {k: v for k, v in p.to_dict().items() if isinstance(v, (int, float, str))}


def _attrs(p: Params, **extra: Any) -> Dict[str, Any]:
    a = _param_attrs(p)
    a["units_note"] = UNITS_NOTE
    a.update(extra)
    return a


_KINDS: Dict[str, Tuple[Any, str]] = {
    "int": (numbers.Integral, "an integer"),
    "float": (numbers.Real, "a number"),
    "bool": ((bool, np.bool_), "True or False"),
    "str": (str, "a string"),
}


_F = TypeVar("_F", bound=Callable[..., Any])

#: the annotations of the sequence keywords ``_typed`` checks: (element kind, optional, a
#: single number taken too)
_SEQUENCES: Dict[str, Tuple[str, bool, bool]] = {
    "Sequence[float]": ("float", False, False),
    "Optional[Sequence[float]]": ("float", True, False),
    "Optional[Tuple[float, float]]": ("float", True, False),
    "Sequence[str]": ("str", False, False),
    "Optional[Sequence[str]]": ("str", True, False),
    "Union[float, Sequence[float], None]": ("float", True, True),
}


@overload
def _typed(f: _F) -> _F: ...


@overload
def _typed(f: None = None, *, si: Dict[str, str]) -> Callable[[_F], _F]: ...


def _typed(f: Optional[_F] = None, *, si: Optional[Dict[str, str]] = None) -> Any:
    """Check the keywords of the public function ``f`` against its annotations before any
    work: ``int``/``float``/``bool``/``str``, their ``Optional[...]`` and the sequences of
    :data:`_SEQUENCES`. A wrong type is a ``TypeError`` naming the keyword and what it takes
    (a string is never read as a sequence of characters); an integer beyond 64 bits (or, for
    a ``float`` keyword, beyond a double's range) a ``ValueError`` naming it (the core's
    conversions would say neither). ``si`` names the keywords that take an SI value with a
    probe and their dimension (the request schema's ``x-dim``: ``"length"``, ``"force"``,
    ``"frequency"``): they take text with a unit too (``z_c="95nm"``), read by the library
    (``_afmdyn.si_value``: a unit of another dimension, or a unit without ``probe=``, is a
    ``ValueError`` naming the keyword). Used as ``@_typed`` or ``@_typed(si={...})``."""
    if f is None:
        return functools.partial(_typed, si=si)
    dims = dict(si or {})
    sig = inspect.signature(f)
    checks: Dict[str, Tuple[str, bool]] = {}
    sequences: Dict[str, Tuple[str, bool, bool]] = {}
    for name, prm in sig.parameters.items():
        ann = prm.annotation if isinstance(prm.annotation, str) else ""
        optional = ann.startswith("Optional[") and ann.endswith("]")
        base = ann[len("Optional["):-1] if optional else ann
        if base in _KINDS:
            checks[name] = (base, optional)
        elif ann in _SEQUENCES:
            sequences[name] = _SEQUENCES[ann]
    # a function without model keywords takes SI values (a fit, a reconstruction, an image)
    model = next((p.name for p in sig.parameters.values() if p.kind is p.VAR_KEYWORD), None)

    @functools.wraps(f)
    def checked(*args: Any, **kwargs: Any) -> Any:
        bound = sig.bind_partial(*args, **kwargs)
        given = bound.arguments
        with_probe = model is None or (given.get(model) or {}).get("probe") is not None
        for name in list(given):
            dim = dims.get(name)
            if name in checks:
                given[name] = _checked_scalar(f.__name__, name, given[name], checks[name],
                                              dim, with_probe)
            elif name in sequences:
                given[name] = _checked_sequence(f.__name__, name, given[name], sequences[name],
                                                dim, with_probe)
        return f(*bound.args, **bound.kwargs)

    return cast(_F, checked)


def _si(name: str, value: Any, dim: Optional[str], with_probe: bool) -> Any:
    """``value``, or its SI value where it is text with a unit for a keyword of dimension
    ``dim`` (``_afmdyn.si_value``)."""
    if dim is not None and isinstance(value, str):
        return _core.si_value(value, name, dim, with_probe)
    return value


def _checked_scalar(fn: str, name: str, value: Any, kind: Tuple[str, bool],
                    dim: Optional[str], with_probe: bool) -> Any:
    """``value`` of keyword ``name`` of ``fn`` checked against its kind (:func:`_typed`)."""
    base, optional = kind
    if value is None and optional:
        return value
    value = _si(name, value, dim, with_probe)
    cls, what = _KINDS[base]
    numeric_bool = base in ("int", "float") and isinstance(value, (bool, np.bool_))
    if numeric_bool or not isinstance(value, cls):
        if dim is not None:
            what += " or text with a unit such as '95nm'"
        takes = what + (" or None" if optional else "")
        raise TypeError(f"{fn}(): {name} must be {takes}, got {type(value).__name__} {value!r}")
    if base == "int" and not -(2**63) <= int(value) < 2**63:
        raise ValueError(f"{name} = {value}: out of range (far beyond every limit)")
    if base == "float" and isinstance(value, numbers.Integral):
        # float(10**400) raises OverflowError: a number out of range is a ValueError
        try:
            float(value)
        except OverflowError:
            digits = len(str(abs(int(value))))
            raise ValueError(
                f"{name} = an integer of {digits} digits: must be a finite number "
                "(far beyond every limit)"
            ) from None
    return value


def _checked_sequence(fn: str, name: str, value: Any, kind: Tuple[str, bool, bool],
                      dim: Optional[str], with_probe: bool) -> Any:
    """``value`` of the sequence keyword ``name`` of ``fn`` checked (:func:`_typed`): a
    sequence (or NumPy array) of numbers (text with a unit where ``dim`` says) or of names,
    never a string read as its characters; a single number where ``kind`` takes one."""
    element, optional, single = kind
    if value is None and optional:
        return value
    numbers_ = element == "float"
    what = ("a sequence of numbers" if numbers_ else "a sequence of names such as ['E']") + (
        ", or a number" if single else "") + (" or None" if optional else "")
    if single and (isinstance(value, str) or isinstance(value, numbers.Real)):
        return _checked_scalar(fn, name, value, ("float", optional), dim, with_probe)
    if isinstance(value, np.ndarray) and numbers_:
        # an array of numbers goes on as it is: its dimensions, and a complex array, are the
        # finisher's to refuse (``_real_array``: a ValueError naming them)
        if value.dtype.kind not in "iufc":
            raise TypeError(f"{fn}(): {name} must be {what}, got an array of {value.dtype}")
        return value
    if isinstance(value, (str, bytes, collections.abc.Mapping)) or \
            not isinstance(value, collections.abc.Iterable):
        raise TypeError(f"{fn}(): {name} must be {what}, got {type(value).__name__} {value!r}")
    items = [_si(name, v, dim, with_probe) for v in value]
    for v in items:
        ok = (isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))) \
            if numbers_ else isinstance(v, str)
        if not ok:
            raise TypeError(f"{fn}(): {name} must be {what}, got an item "
                            f"{type(v).__name__} {v!r}")
    return items


class AfmdynWarning(UserWarning):
    """A computed answer with a caveat the command line prints as ``afmdyn: warning: …`` on
    stderr (a branch that ended before the end of its range, points of a sweep that failed,
    an energy balance that did not close); the same lines are in the summary's ``warnings``."""


def _warn(doc: Any) -> None:
    """Issue every line of a JSON document's ``warnings`` list as an :class:`AfmdynWarning`."""
    if isinstance(doc, str):
        try:
            doc = json.loads(doc)
        except ValueError:
            return
    if isinstance(doc, dict):
        for w in doc.get("warnings") or []:
            warnings.warn(str(w), AfmdynWarning, stacklevel=_user_level())


def _user_level() -> int:
    """The ``stacklevel`` (for a ``warnings.warn`` in the caller) of the first frame outside
    this package: a warning points at the user's line, however deep the package's calls."""
    f, level = sys._getframe(1), 1
    while f.f_back is not None and os.path.dirname(f.f_code.co_filename) == _HERE:
        f, level = f.f_back, level + 1
    return level


_HERE = os.path.dirname(os.path.abspath(__file__))


#: Python's own keywords (a Dask version's ``client`` and ``checkpoint_seconds`` too)
_NOT_REQUEST = frozenset(("params", "progress", "model", "store", "resume", "client",
                          "checkpoint_seconds"))


def _request(names: Dict[str, Any], **given: Any) -> Dict[str, Any]:
    """The request of an analysis: its keywords (``names``, the function's ``locals()``), but
    the model's, ``params``, ``progress``, a store's and a cluster's, with ``given`` ones
    replaced."""
    r = {k: v for k, v in names.items() if k not in _NOT_REQUEST}
    r.update(given)
    return r


def _start(request: Dict[str, Any]) -> Dict[str, Any]:
    """The request of an orbit analysis (the library's ``StartRequest``): the steady-state
    keywords ``tol``, ``max_periods``, ``max_period`` nested under ``steady``."""
    request["steady"] = {k: request.pop(k) for k in ("tol", "max_periods", "max_period")}
    return request


def _door(
    name: str,
    desc: str,
    progress: ProgressArg,
    p: Optional[Params] = None,
    si: Optional[str] = None,
    request: Optional[Dict[str, Any]] = None,
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    stored: bool = False,
) -> Dict[str, Any]:
    """Run analysis ``name`` through the one door of the core (``_afmdyn.run``: the library
    parses the request by name, runs it and lays out its arrays) with a progress reporter:
    ``{"json": document, "datasets": {name: layout}, "facts": dict}``; the document's
    warnings are issued. With ``store`` (or
    ``resume``, or ``stored``: a study of no other door) a study runs through
    ``_afmdyn.run_stored``, into the command line's resumable store there."""
    with reporter(progress, desc) as cb:
        if store is None and not resume and not stored:
            d: Dict[str, Any] = _core.run(name, request, p, si, cb)
        else:
            where = None if store is None else os.fspath(store)
            d = _core.run_stored(name, request, p, si, cb, where, resume)
    _warn(d["json"])
    return d


def summary(ds: xr.Dataset) -> Dict[str, Any]:
    """The command line's ``--json`` document stored with a dataset afmdyn returned
    (``simulate``, ``converge``, ``continuation``, ``approach``, ``resonance``, ``observe``,
    ``basins``, ``global_continuation``, ``reconstruct``); the same as
    ``ds.afmdyn.to_dict()``."""
    return json.loads(ds.attrs["summary"])
