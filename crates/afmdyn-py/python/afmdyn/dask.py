"""Studies on a Dask cluster (``pip install "afmdyn[dask]"``): the tasks the library plans for
a study, mapped over a ``dask.distributed.Client`` — a ``LocalCluster`` on this machine by
default, or any cluster (``dask_jobqueue.SLURMCluster`` and friends, see ``docs/cluster.md``).

Every task is a pure function of the request and its number (its random starts are keyed by
the seed and the cell, never by the worker or the order), so a chart computed here equals
:func:`afmdyn.chart` on one machine bit for bit, whatever the cluster. A worker that dies has
its tasks rerun elsewhere (Dask's own retry); with ``store=`` each finished task's cells are
written to a Zarr store as they arrive, and a rerun with the same request resumes from it,
computing only the tasks not stored (a finished store computes nothing).

The store ``S`` is a plain Zarr group, the chart's variables as ``xarray.open_zarr(S)``
reads them (dims ``y``, ``x``, ``attractor``; the fingerprint of the request in its
attributes). Beside it, the directory ``S.afmdyn`` is locked while a run writes the store and
holds ``done``, the numbers of the finished tasks, one per line, appended (and flushed) after
the task's region is written: a killed driver loses at most the task it was writing.
"""

from __future__ import annotations

from . import _dask_wrappers
from ._dask import DONE, ledger_dir, run_chart_task, run_plan_task
# chart, bifurcation, basins, image, fit_map: generated
from ._dask_wrappers import *  # noqa: F401,F403

__all__ = ["DONE", "ledger_dir", "run_chart_task", "run_plan_task"]
__all__ += _dask_wrappers.__all__
