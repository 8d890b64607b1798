"""The machinery of :mod:`afmdyn.dask` (its public names are re-exported there): the
clusters, the chart's Zarr ledger, the plans' task runners and the finishers of the generated
``afmdyn.dask.chart``, ``bifurcation``, ``basins``, ``image`` and ``fit_map``
(:mod:`._dask_wrappers`)."""

from __future__ import annotations

import contextlib
import functools
import json
import os
import time
from typing import Any, Dict, Iterable, Iterator, List, Optional, Set

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from . import _layout
from ._chart import dataset, study
from ._common import _request
from ._progress import ProgressArg, reporter

try:
    import distributed
except ImportError as e:  # pragma: no cover - depends on the installation
    raise ImportError(
        'afmdyn.dask needs dask.distributed and zarr: pip install "afmdyn[dask]"'
    ) from e

#: The file of finished tasks, in the store's ledger directory ``STORE.afmdyn``.
DONE = "done"


@contextlib.contextmanager
def _cluster(client: Optional["distributed.Client"]) -> Iterator["distributed.Client"]:
    """``client``, or a ``LocalCluster`` of this machine's cores (one thread per worker)
    started for the study and closed at its end."""
    if client is not None:
        yield client
        return
    cluster = distributed.LocalCluster(threads_per_worker=1, dashboard_address=None)
    own = distributed.Client(cluster)
    try:
        yield own
    finally:
        own.close()
        cluster.close()


def ledger_dir(store: str) -> str:
    """The directory beside a store that is locked during a run and lists its finished tasks."""
    return os.path.normpath(store) + ".afmdyn"


@functools.lru_cache(maxsize=8)
def _chart_of(recipe: str) -> "_core.ChartStudy":
    return _core.ChartStudy(recipe)


def run_chart_task(recipe: str, task: int) -> str:
    """Task ``task`` of the chart of ``recipe`` (what a worker runs): its cells, JSON text.
    The chart is built once per worker process and recipe."""
    return _chart_of(recipe).run_task(task)


def _template(s: "_core.ChartStudy") -> xr.Dataset:
    """The store's dataset before any task: every cell empty (as a cell with no attractor)."""
    return dataset(s, s.arrays([]))


#: Largest ledger of finished tasks read back, in bytes: 16 MiB, a line of at most 16 bytes for
#: each of the 10^6 tasks of the largest chart (one cell a task).
MAX_DONE_BYTES = 16 * 1024 * 1024


def _done(store: str) -> Set[int]:
    """The finished tasks: every complete line of the ledger (a cut last line is dropped)."""
    path = os.path.join(ledger_dir(store), DONE)
    try:
        with open(path, "rb") as f:
            # bounded: one short line per task of the largest chart (1e6 cells), never /dev/zero
            # read on or a sparse file held whole
            text = f.read(MAX_DONE_BYTES + 1)
    except FileNotFoundError:
        return set()
    if len(text) > MAX_DONE_BYTES or b"\0" in text:
        raise ValueError(
            f"resume: {path} is not this store's ledger (text of at most {MAX_DONE_BYTES} "
            "bytes); call with resume=False to start over"
        )
    lines = text.split(b"\n")
    return {int(x) for x in lines[:-1] if x.strip()}


def _open_store(s: "_core.ChartStudy", store: str, resume: bool) -> Set[int]:
    """The tasks already in ``store`` (none for a new one, which is written empty first)."""
    import zarr

    try:
        group = zarr.open_group(store, mode="r")
    except Exception:  # no store there yet (zarr raises its own not-found errors)
        group = None
    if group is None and os.path.exists(store) and (
        not os.path.isdir(store) or os.listdir(store)
    ):
        # never overwrite what is not a store (mode "w" would delete the directory's files)
        raise ValueError(f"store: {store} exists and is not a Zarr store; choose another store=")
    if resume and group is not None:
        then = group.attrs.get("fingerprint")
        if then is None:
            raise ValueError(
                f"resume: {store} has no record of the request that made it; "
                "call with resume=False to start over"
            )
        diff = s.compare(then)
        if diff is not None:
            field, a, b = diff
            raise ValueError(
                f"resume: {field} = {a} in the interrupted run, {b} now; call with the same "
                "arguments, or with resume=False to start over"
            )
        return _done(store)
    done = os.path.join(ledger_dir(store), DONE)
    if os.path.exists(done):
        os.remove(done)
    # Zarr format 2: what every xarray and zarr version reads, with consolidated metadata
    _template(s).to_zarr(store, mode="w", consolidated=False, zarr_format=2)
    return set()


class _Writer:
    """Writes finished tasks' regions into the store, in batches (every ``batch`` tasks or
    ``seconds``, and at the end), then records them as done (flushed to disk): a killed
    driver loses at most the unwritten batch, which a rerun computes again. A batch rewrites
    the rows it touches whole; zarr writes each chunk file atomically (a temporary file
    renamed into place), so the tasks already done in those rows keep their values whatever
    chunk a kill interrupts."""

    def __init__(self, store: str, s: "_core.ChartStudy", batch: int = 32, seconds: float = 2.0):
        import zarr

        self.store, self.s = store, s
        self.group = zarr.open_group(store, mode="r+")
        # the per-cell variables of the chart's layout: over (y, x) and (y, x, attractor)
        self.names = _layout.over(s.arrays([]), ("y", "x"))
        self.arrays = {k: self.group[k] for k in self.names}
        self.batch, self.seconds = batch, seconds
        self.pending: list = []
        self.last = time.monotonic()

    def add(self, task: int, cells: str) -> None:
        self.pending.append((task, cells))
        if len(self.pending) >= self.batch or time.monotonic() - self.last >= self.seconds:
            self.flush()

    def flush(self) -> None:
        if not self.pending:
            return
        # one read and one write per variable: the slab of rows the batch touches
        tiles = [(self.s.tile(t), cells) for t, cells in self.pending]
        y0 = min(iy for (iy, _, _), _ in tiles)
        y1 = max(iy for (iy, _, _), _ in tiles) + 1
        slabs = {k: a[y0:y1] for k, a in self.arrays.items()}
        for (iy, lo, hi), cells in tiles:
            region = _layout.variables(self.s.arrays([cells], origin=(lo, iy), size=(hi - lo, 1)))
            for k in self.names:
                slabs[k][iy - y0, lo:hi] = region[k][1][0]
        for k, a in self.arrays.items():
            a[y0:y1] = slabs[k]
        with open(os.path.join(ledger_dir(self.store), DONE), "a", encoding="utf-8") as f:
            f.write("".join(f"{t}\n" for t, _ in self.pending))
            f.flush()
            os.fsync(f.fileno())
        self.pending.clear()
        self.last = time.monotonic()


def _map(
    client: "distributed.Client",
    s: "_core.ChartStudy",
    todo: Iterable[int],
    each: Any,
    cb: Any,
    total: int,
    done0: int,
) -> None:
    todo = list(todo)
    futures = client.map(
        run_chart_task, [s.recipe] * len(todo), todo, pure=False, retries=3
    )
    task_of = {f.key: t for f, t in zip(futures, todo)}
    finished = done0
    for fut in distributed.as_completed(futures):
        each(task_of[fut.key], fut.result())
        finished += 1
        if cb is not None:
            cb(finished, total)


def _finish_chart(a: Dict[str, Any]) -> xr.Dataset:
    """Run the chart of :func:`afmdyn.dask.chart`'s keywords ``a`` (its ``locals()``)."""
    params, model, client, progress = a["params"], a["model"], a["client"], a["progress"]
    store, resume, checkpoint_seconds = a["store"], a["resume"], a["checkpoint_seconds"]
    s = study(params, model, **_request(a))
    n = s.tasks()
    if not (checkpoint_seconds >= 0 and np.isfinite(checkpoint_seconds)):
        raise ValueError(f"checkpoint_seconds = {checkpoint_seconds}: must be finite and >= 0")
    with _cluster(client) as client:
        lock = None
        try:
            with reporter(progress, "chart (dask)") as cb:
                if store is None:
                    results: Dict[int, str] = {}
                    _map(client, s, range(n), results.__setitem__, cb, n, 0)
                    ds = dataset(s, s.arrays([results[t] for t in range(n)]))
                else:
                    import zarr

                    path = os.fspath(store)
                    lock = _core.StoreLock(ledger_dir(path))
                    done = _open_store(s, path, resume)
                    todo = [t for t in range(n) if t not in done]
                    writer = _Writer(path, s, seconds=checkpoint_seconds)
                    _map(client, s, todo, writer.add, cb, n, n - len(todo))
                    writer.flush()
                    zarr.consolidate_metadata(path)
                    ds = xr.open_zarr(path).load()
                    ds.attrs = {
                        **_template(s).attrs,
                        "failed_runs": int(ds["failures"].values.sum()),
                    }
        finally:
            if lock is not None:
                lock.release()
    s.check(ds["attractors"].values.ravel().tolist())
    return ds


@functools.lru_cache(maxsize=8)
def _plan_of(recipe: str) -> "_core.Plan":
    return _core.Plan(recipe)


def run_plan_task(recipe: str, start: str, task: int) -> str:
    """Task ``task`` of the stage beginning at ``start`` of the study of ``recipe`` (what a
    worker runs; the library's ``study::plan``): its result, as text. The study is built once
    per worker process and recipe."""
    return _plan_of(recipe).run(start, task)


def _run_plan(
    client: "distributed.Client",
    plan: "_core.Plan",
    progress: ProgressArg,
    desc: str,
    unit: str = "task",
    store: Any = None,
    resume: bool = True,
) -> Dict[str, Any]:
    """Map the tasks of ``plan``'s stages over ``client``, each stage's start sent to the
    workers once, and return its outcome (as ``_afmdyn.run`` returns it). With ``store`` (the
    plan's store, ``Plan.store``) the last stage runs only the tasks it does not hold, each
    result appended as it arrives."""
    todo = store.open(resume) if store is not None else None
    if store is not None and todo is None:
        return store.outcome()
    results: List[str] = []
    stages = plan.stages() if todo != [] else 0
    last, done = stages - 1, 0
    with reporter(progress, desc, unit=unit) as cb:
        for k in range(stages):
            start, tasks = plan.stage(k, results)
            if k == last and todo is not None:
                tasks = [t for t in tasks if t in set(todo)]
            shared = client.scatter(start, broadcast=True)
            futures = client.map(run_plan_task, [plan.recipe] * len(tasks),
                                 [shared] * len(tasks), tasks, pure=False, retries=3)
            for fut in distributed.as_completed(futures):
                if k == last and store is not None:
                    store.append(fut.result())
                else:
                    results.append(fut.result())
                # a chain's passes (a sweep's coarse stage) are not counted; a map's are
                if cb is not None and (k == last or stages > 2):
                    done += 1
                    cb(done, len(tasks) if stages <= 2 else None)
    if store is None:
        return plan.outcome(results)
    store.finish()
    return store.outcome()


def _finish_bifurcation(a: Dict[str, Any]) -> xr.Dataset:
    """Run the sweep of :func:`afmdyn.dask.bifurcation`'s keywords ``a`` (its ``locals()``)."""
    params, model, client, progress = a["params"], a["model"], a["client"], a["progress"]
    store, resume = a["store"], a["resume"]
    from ._api import _params, _sweep_dataset, _sweep_request

    request = _sweep_request(a)

    p, _probe = _params(params, model)
    plan = _core.Plan.build("bifurcation", request, p)
    with _cluster(client) as client:
        own = None if store is None else plan.store(os.fspath(store))
        try:
            d = _run_plan(client, plan, progress, "bifurcation (dask)", store=own, resume=resume)
        finally:
            if own is not None:
                own.release()
    return _sweep_dataset(p, d, a["starts"], a["seed"])


def _finish_basins(a: Dict[str, Any]) -> xr.Dataset:
    """Run the basins of :func:`afmdyn.dask.basins`'s keywords ``a`` (its ``locals()``)."""
    from ._basins import _dataset
    from ._common import _params

    p, probe = _params(a["params"], a["model"])
    plan = _core.Plan.build("basins", _request(a), p, probe)
    with _cluster(a["client"]) as client:
        d = _run_plan(client, plan, a["progress"], "basins (dask)", unit="row")
    return _dataset(d["datasets"]["basins"], json.loads(d["json"]), p)


def _finish_image(a: Dict[str, Any]) -> xr.Dataset:
    """Run the image of :func:`afmdyn.dask.image`'s keywords ``a`` (its ``locals()``)."""
    from ._image import _dataset, _keywords

    mode = a["mode"]
    if mode not in ("am", "peakforce"):
        raise ValueError(f"mode = {mode!r}: must be 'am' or 'peakforce'")
    text, request = _keywords(a, "pi" if mode == "am" else "ideal")
    plan = _core.Plan.build("image", request, None, text)
    with _cluster(a["client"]) as client:
        d = _run_plan(client, plan, a["progress"], "image (dask)", unit="line")
    return _dataset(d, a["setpoint"])


def _finish_fit_map(a: Dict[str, Any]) -> xr.Dataset:
    """Fit the map of :func:`afmdyn.dask.fit_map`'s keywords ``a`` (its ``locals()``): a line
    of the map per task, each worker reading its curves from the map file (a path it must
    read: this machine's for a ``LocalCluster``, a shared filesystem for a cluster's)."""
    import tempfile

    from ._common import _params, _warn
    from ._fit_map import _map_dataset, _map_dir, _map_file, _map_request

    request = _map_request(a)
    p, probe = _params(a["params"], a["model"], quasi_static=True)
    store = a["store"]
    with tempfile.TemporaryDirectory(prefix="afmdyn-map-") as tmp:
        # curves given as data are written where the workers read them: the store, or a
        # temporary directory of this machine (a LocalCluster's workers share it); the path
        # as afmdyn.fit_map's (the store's fingerprint holds it: either resumes the other's)
        request["data"] = _map_file(a["data"], _map_dir(store, tmp))
        plan = _core.Plan.build("fit_map", request, p, probe)
        with _cluster(a["client"]) as client:
            own = None if store is None else plan.store(os.fspath(store))
            try:
                d = _run_plan(client, plan, a["progress"], "fit_map (dask)", unit="line",
                              store=own, resume=a["resume"])
            finally:
                if own is not None:
                    own.release()
    _warn(d["json"])
    return _map_dataset(d)
