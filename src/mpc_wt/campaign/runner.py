"""Run a campaign on Dask (``dask.distributed``), a plain process pool or in this process.

The default engine is Dask: a :class:`distributed.LocalCluster` sized to the machine (one
single-threaded worker process per core), or any running cluster given by its scheduler
address (``tcp://HOST:PORT``; ``dask scheduler`` + ``dask worker``, or dask-jobqueue on SLURM).
Dask schedules; we only submit one pure task per case (:func:`~mpc_wt.campaign.task.run_case`)
and commit each result to the index as it arrives. A worker that dies mid-case has its case
re-run by Dask on another worker; a client that dies loses only the cases in flight, and a
case whose file landed before the client died is picked up without simulating again.

The process-pool engine (``concurrent.futures``) exists to measure Dask's overhead against
(benchmarks/bench_campaign.py) and for machines without the ``dask`` extra; a worker killed
there breaks the pool and the cases in flight are recorded failed (rerun them).
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import logging
import os
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from mpc_wt.campaign.spec import CampaignSpec
from mpc_wt.campaign.store import CampaignStore
from mpc_wt.campaign.task import run_case

__all__ = ["run_campaign", "RunSummary", "ENGINES", "submission_order", "check_designs"]

log = logging.getLogger(__name__)

ENGINES = ("dask", "processes", "serial")


@dataclass
class RunSummary:
    """What one ``run_campaign`` call did.

    Parameters
    ----------
    total, skipped, submitted : int
        Cases in the spec, already finished, handed to the engine.
    done, failed, reused : int
        Finished now, failed, and done from a file already written.
    wall_s : float
        Wall time [s].
    engine : str
        The engine used.
    workers : int
        Worker processes.
    sync : dict
        What :meth:`CampaignStore.sync` did.
    failures : list of (str, str)
        (case id, error) of the failed cases.
    """

    total: int
    skipped: int
    submitted: int
    done: int = 0
    failed: int = 0
    reused: int = 0
    wall_s: float = 0.0
    engine: str = "dask"
    workers: int = 0
    sync: dict[str, int] = field(default_factory=dict)
    failures: list[tuple[str, str]] = field(default_factory=list)

    @property
    def cases_per_min(self) -> float:
        """Simulated cases per minute of wall time (reused files not counted)."""
        n = self.done - self.reused
        return 60.0 * n / self.wall_s if self.wall_s > 0 else 0.0


def worker_count(workers: int | None) -> int:
    if workers is None:
        return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                   else (os.cpu_count() or 1))
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    return workers


def _dask_import() -> Any:
    try:
        import distributed
    except ImportError as err:  # pragma: no cover - depends on the extra
        raise ImportError("the dask engine needs the 'dask' extra: pip install 'mpc-wt[dask]' "
                          "(or use engine='processes')") from err
    return distributed


def run_campaign(spec: CampaignSpec, out: str | Path, *, workers: int | None = None,
                 scheduler: Any = None, engine: str = "dask", progress: bool = True,
                 on_result: Callable[[str, dict[str, Any]], None] | None = None) -> RunSummary:
    """Run every case of ``spec`` that is not finished in the campaign directory ``out``.

    Parameters
    ----------
    spec : CampaignSpec
        The validated campaign.
    out : path
        Campaign directory (created). Must be visible to every worker (shared file system).
    workers : int, optional
        Worker processes of a local cluster or pool (default: the cores of this machine).
    scheduler : str or distributed.LocalCluster, optional
        A running Dask scheduler's address (``tcp://HOST:PORT``) or a :func:`local_cluster`
        (its TLS credentials go to the client); ``workers`` is then ignored.
    engine : {"dask", "processes", "serial"}
        Dask (default), a plain process pool, or this process.
    progress : bool
        A progress bar: cases done, running, failed and the ETA.
    on_result : callable(case_id, outcome), optional
        Called after each case is committed (tests use it to interrupt).

    Returns
    -------
    RunSummary
        Counts, failures and wall time.

    Raises
    ------
    ValueError
        Unknown engine, bad worker count, ``scheduler`` with an engine other than dask.
    CampaignLockedError
        Another client runs the same directory.
    """
    n_workers = _check_engine(engine, scheduler, workers)
    out = Path(out)
    t_start = time.perf_counter()
    with CampaignStore(out, lock=True) as store:
        _write_spec(spec, out, store)
        sync = store.sync(spec)
        sync["redesigned"] = sync.get("redesigned", 0) + check_designs(spec, store)
        todo = submission_order(store.todo())
        total = len(spec.cases())
        summary = RunSummary(total=total, skipped=total - len(todo), submitted=len(todo),
                             engine=engine, workers=n_workers, sync=sync)
        log.info("campaign %s: %d cases, %d finished, %d to run (%s)", spec.name, total,
                 summary.skipped, len(todo), sync)
        if not todo:
            summary.wall_s = time.perf_counter() - t_start    # the check of what is done
            return summary
        _check_memory(todo, 0 if scheduler else n_workers)
        bar = _Bar(len(todo), spec.name, progress)
        spec_hash = spec.spec_hash

        def commit(case_id: str, outcome: dict[str, Any]) -> None:
            store.record(case_id, outcome, spec_hash)
            if outcome["status"] == "done":
                summary.done += 1
                summary.reused += bool(outcome.get("reused"))
            else:
                summary.failed += 1
                summary.failures.append((case_id, outcome.get("error", "")))
                log.warning("case %s failed: %s", case_id, outcome.get("error"))
            bar.step(outcome["status"] == "done")
            if on_result is not None:
                on_result(case_id, outcome)

        store.mark_submitted(c.case_id for c in todo)
        root = str(out.resolve())
        try:
            _dispatch(engine, todo, root, n_workers, scheduler, commit, bar)
        finally:
            bar.close()
            summary.wall_s = time.perf_counter() - t_start
        return summary


def _recorded_design(path: Path) -> dict[str, Any] | None:
    """The design a result file records: its digest and, for a shipped law, the law's build
    key (None if it records none or cannot be read)."""
    from mpc_wt.simulation.results import ClosedLoopResult

    design = (ClosedLoopResult.read_meta(path) or {}).get("design")
    return design if isinstance(design, dict) and design.get("digest") else None


def _differs(recorded: dict[str, Any] | None, now: dict[str, Any]) -> bool:
    """Whether a finished case's recorded design is not the one made now: another digest, or
    another law where both name theirs (a file of a version that recorded no law keeps)."""
    if recorded is None:
        return False
    if recorded["digest"] != now.get("digest"):
        return True
    return bool(recorded.get("law") and now.get("law") and recorded["law"] != now["law"])


def check_designs(spec: CampaignSpec, store: CampaignStore) -> int:
    """Send back the finished cases whose controller the package designs differently today.

    A case's hash covers its controller's options with every default written out, but not a
    default that lives in code (a cost weight of the kind, a candidate list of a design
    check): a new version that changes one would keep the old results. Each controller with
    finished cases is designed once here (as its workers will) and the design's digest
    (:func:`~mpc_wt.registry.context.design_digest`) compared with the one each finished case's
    file records, and a shipped law's build key
    (:func:`~mpc_wt.io.discon_export.shipped_law_key`: its C sources, compiler and flags) with
    the one the file records (a fixed law, the same numbers); a case whose design differs is
    computed again, its file kept as
    ``cases/ID.redesigned.nc`` (logged). A controller that cannot be designed here keeps its
    cases (logged).

    Parameters
    ----------
    spec : CampaignSpec
    store : CampaignStore
        The campaign's index, synced with ``spec``.

    Returns
    -------
    int
        The cases sent back.
    """
    from mpc_wt.campaign.task import load_case_turbine
    from mpc_wt.registry.registry import load_plugins
    from mpc_wt.run import design_controller

    done = {r.case_id: r for r in store.rows() if r.status == "done" and r.file}
    if not done:
        return 0
    by: dict[str, list[Any]] = {}
    for c in spec.cases():
        if c.case_id in done:
            by.setdefault(c.controller, []).append(c)
    redo: list[str] = []
    for name, cases in by.items():
        recorded = {c.case_id: _recorded_design(store.root / done[c.case_id].file)
                    for c in cases}
        if not any(recorded.values()):
            continue
        first = cases[0]
        try:
            load_plugins(first.plugins, first.plugin_folder)
            built, _ = design_controller(load_case_turbine(first.turbine), first.run_name,
                                         first.options, shipped=True)
            now = built.meta["design"]
        except Exception as err:       # a design that fails here fails in its cases too
            log.warning("controller %s could not be designed to check the design of its %d "
                        "finished cases (%s); they are kept", name, len(cases), err)
            continue
        stale = [cid for cid, d in recorded.items() if _differs(d, now)]
        if stale:
            log.warning("controller %s: %d finished cases were computed with another design "
                        "than this version makes from the same options (a default of the kind "
                        "changed); computing them again (their files kept as "
                        "cases/ID.redesigned.nc)", name, len(stale))
            redo += stale
    return store.redo(redo, "redesigned") if redo else 0


def _dispatch(engine: str, todo: list[Any], root: str, n_workers: int, scheduler: Any,
              commit: Callable[..., None], bar: "_Bar") -> None:
    """Run the cases on the engine, committing each as it finishes."""
    if engine == "serial":
        for c in todo:
            bar.running(1)
            commit(c.case_id, run_case(c.to_dict(), root))
    elif engine == "processes":
        _run_pool(todo, root, n_workers, commit, bar)
    else:
        _run_dask(todo, root, n_workers, scheduler, commit, bar)


def submission_order(cases: list[Any]) -> list[Any]:
    """The cases in the order they are handed out: the longest simulations first (the last
    ones to finish are then short), and the controllers of one scenario (wind, turbulence,
    seed, condition) one after another, so that a worker meets a field it has just made
    (:data:`mpc_wt.campaign.task.WORKER_FIELDS`). Otherwise the spec's order.

    Parameters
    ----------
    cases : list of Case
        The cases to run.

    Returns
    -------
    list of Case
        The same cases, reordered.
    """
    def key(ic: tuple[int, Any]) -> tuple[Any, ...]:
        i, c = ic
        sc = c.scenario
        return (-float(sc.duration), str(sc.condition), str(sc.turbulence), str(sc.iec_class),
                -1.0 if sc.wind_mps is None else float(sc.wind_mps), int(sc.seed),
                int(sc.sign), str(sc.wind_file or ""),
                float(sc.shear_exponent), i)
    return [c for _, c in sorted(enumerate(cases), key=key)]


def _check_memory(todo: list[Case], processes: int) -> None:
    """Refuse a campaign whose largest case, once per worker, would not fit in the memory
    available (:mod:`mpc_wt.simulation.memory`; a LIDAR's field counted for every kind whose
    name says LIDAR); nothing is checked for ``processes`` 0 (a cluster elsewhere)."""
    if processes < 1:
        return
    from mpc_wt.campaign.task import load_case_turbine
    from mpc_wt.registry import resolve
    from mpc_wt.simulation.memory import check_run_memory, estimate_run_memory

    worst, name = None, ""
    for turbine in {c.turbine for c in todo}:
        cases = [c for c in todo if c.turbine == turbine]
        big = max(cases, key=lambda c: c.scenario.duration)
        try:
            comps = resolve(big.run_name).field_components
        except ValueError:
            comps = "uvw"
        m = estimate_run_memory(load_case_turbine(turbine), big.scenario,
                                components=len(comps), lidar_fields=int(any(
                                    "lidar" in c.run_name for c in cases)))
        if worst is None or m.total > worst.total:
            worst, name = m, big.case_id
    if worst is not None:
        check_run_memory(worst, what=f"the campaign's largest case ({name})",
                         processes=processes)


def _check_engine(engine: str, scheduler: Any, workers: int | None) -> int:
    """Check the engine settings; the number of worker processes."""
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    if scheduler is not None and engine != "dask":
        raise ValueError(f"scheduler {scheduler!r} needs engine='dask', got {engine!r}")
    if isinstance(scheduler, str) and not scheduler.startswith(("tcp://", "tls://",
                                                                "inproc://", "ws://")):
        raise ValueError(f"scheduler must be an address like tcp://HOST:PORT, got {scheduler!r}")
    return 1 if engine == "serial" else worker_count(workers)


def _write_spec(spec: CampaignSpec, out: Path, store: CampaignStore) -> None:
    """Keep the spec in the directory (its file, or the validated mapping) and in the index."""
    from mpc_wt._version import __version__

    if spec.source and Path(spec.source).is_file():
        (out / "spec.yaml").write_text(Path(spec.source).read_text())
    else:
        import yaml

        (out / "spec.yaml").write_text(yaml.safe_dump(spec.raw, sort_keys=False))
    store.set_meta(name=spec.name, spec_hash=spec.spec_hash, software_version=__version__,
                   spec_raw=spec.resolved_raw(), code=spec_code(spec),
                   reference=spec.reference, last_run=time.strftime("%Y-%m-%dT%H:%M:%S"))


def spec_code(spec: CampaignSpec) -> dict[str, Any]:
    """The code a campaign runs besides mpc-wt, as the index names it: each plugin module's
    file and each controller library's path with its SHA-256.

    Parameters
    ----------
    spec : CampaignSpec

    Returns
    -------
    dict
        ``plugins`` {module: file}, ``libraries`` {path: sha256}.
    """
    import sys

    from mpc_wt.campaign.checksum import file_sha256

    from mpc_wt.controllers.discon import rosco_library
    from mpc_wt.errors import ControllerLibraryError

    plugins = {m: getattr(sys.modules.get(m), "__file__", None) for m in spec.plugins}
    libs = {}
    for c in spec.controllers:
        lib = c.options.get("discon_library")
        if c.controller == "rosco":              # the rosco package's compiled controller
            with contextlib.suppress(ControllerLibraryError):
                lib = str(rosco_library())
        if isinstance(lib, str) and Path(lib).is_file():
            libs[lib] = file_sha256(Path(lib))
    return {"plugins": plugins, "libraries": libs}


def _failed(case_id: str, err: BaseException, tb: str | None = None) -> dict[str, Any]:
    return {"case_id": case_id, "status": "failed", "error": f"{type(err).__name__}: {err}",
            "traceback": tb or "".join(traceback.format_exception(err)), "worker": None}


def _run_pool(todo: list[Any], root: str, n: int, commit: Callable[..., None],
              bar: "_Bar") -> None:
    import multiprocessing as mp

    with cf.ProcessPoolExecutor(max_workers=n, mp_context=mp.get_context("spawn")) as ex:
        futs = {ex.submit(run_case, c.to_dict(), root): c.case_id for c in todo}
        pending = set(futs)
        while pending:
            bar.running(min(n, len(pending)))
            done, pending = cf.wait(pending, timeout=1.0, return_when=cf.FIRST_COMPLETED)
            for f in done:
                try:
                    commit(futs[f], f.result())
                except Exception as err:  # noqa: BLE001 - a broken pool fails its cases
                    commit(futs[f], _failed(futs[f], err))


def local_cluster(n: int) -> Any:
    """A local Dask cluster of ``n`` single-threaded worker processes, one task per worker at
    a time (the campaigns' engine; a tuning keeps one for all its trials).

    Parameters
    ----------
    n : int
        Worker processes.

    Returns
    -------
    distributed.LocalCluster
        Close it when done.

    Notes
    -----
    The cluster is closed to other processes: its scheduler and workers speak TLS with
    certificates made for this cluster alone (``Security.temporary()``; a client without them,
    another user's or another process's, cannot connect), all on the loopback interface, and
    the scheduler serves no dashboard (its HTTP server has no routes, on a port of the
    system's choosing).
    """
    distributed = _dask_import()
    import dask
    from distributed.security import Security

    # cases ran 12-18 % slower in Dask's workers than in a process pool. Dask's nanny
    # sets MALLOC_TRIM_THRESHOLD_=65536 in its workers, which fixes glibc's trim threshold so
    # that freed arrays go back to the OS and come back as page faults (a 300 s case: +4..11 %
    # measured); None unsets it. The worker's statistical profiler samples the task thread's
    # stack every 10 ms and the GIL monitor polls every 1 ms: both off.
    dask.config.set({"distributed.scheduler.worker-saturation": 1.0,
                     "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                     "distributed.worker.profile.enabled": False,
                     "distributed.admin.system-monitor.gil.enabled": False,
                     "distributed.scheduler.http.routes": []})
    return distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                    dashboard_address=None, host="127.0.0.1",
                                    security=Security.temporary(), protocol="tls://",
                                    scheduler_kwargs={"dashboard_address": "127.0.0.1:0"})


def _run_dask(todo: list[Any], root: str, n: int, scheduler: Any,
              commit: Callable[..., None], bar: "_Bar") -> None:
    distributed = _dask_import()
    cluster = None
    if scheduler is None:
        cluster = local_cluster(n)
        client = distributed.Client(cluster)
    elif isinstance(scheduler, str):
        client = distributed.Client(scheduler, timeout="30s")
    else:                                   # a cluster of this process: its credentials
        client = distributed.Client(scheduler)
    try:
        futs = {}
        for i, c in enumerate(todo):
            # the key carries the case and its inputs' hash: a restarted client that finds the
            # same task still on the scheduler attaches to it instead of running it twice
            key = f"mpcwt-{c.case_id}-{c.case_hash[:12]}-{c.assess_hash[:6]}"
            futs[client.submit(run_case, c.to_dict(), root, key=key, pure=False,
                               priority=len(todo) - i)] = c.case_id
        pending = set(futs)
        while pending:
            bar.running(_dask_running(client, pending))
            try:
                res = distributed.wait(list(pending), timeout=1.0,
                                       return_when="FIRST_COMPLETED")
                done = set(res.done)
            except TimeoutError:
                continue
            for f in done:
                pending.discard(f)
                cid = futs[f]
                if f.status == "finished":
                    commit(cid, f.result())
                else:   # the task itself never raises: this is a lost worker (KilledWorker)
                    err = f.exception()
                    tb = f.traceback()
                    commit(cid, _failed(cid, err, "".join(traceback.format_tb(tb))
                                        if tb else None))
                f.release()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _dask_running(client: Any, pending: set[Any]) -> int:
    """Cases executing now: tasks processing on a worker, capped at its thread count."""
    try:
        proc = client.processing()
        threads = client.nthreads()
    except Exception:  # noqa: BLE001 - the bar is informative only
        return 0
    keys = {f.key for f in pending}
    return sum(min(threads.get(w, 1), sum(1 for k in ks if k in keys))
               for w, ks in proc.items())


class _Bar:
    """tqdm bar: done / running / failed and the ETA (silent when ``enabled`` is False)."""

    def __init__(self, total: int, name: str, enabled: bool) -> None:
        self.failed = 0
        self.run = 0
        self.bar = None
        if enabled:
            import sys

            from tqdm import tqdm

            # a terminal redraws twice a second; a log file gets a line every 30 s at most
            self.bar = tqdm(total=total, desc=f"campaign {name}", unit="case", smoothing=0.1,
                            mininterval=0.5 if sys.stderr.isatty() else 30.0)
            self._post()

    def _post(self) -> None:
        if self.bar is not None:
            self.bar.set_postfix_str(f"running {self.run}, failed {self.failed}", refresh=False)
            self.bar.update(0)

    def running(self, n: int) -> None:
        """Called about once a second: the running count, and the elapsed time and ETA."""
        if n != self.run:
            self.run = n
            self._post()
        elif self.bar is not None:
            self.bar.update(0)      # elapsed time and ETA, within tqdm's mininterval

    def step(self, ok: bool) -> None:
        self.failed += not ok
        if self.bar is not None:
            self.bar.update(1)
            self._post()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
