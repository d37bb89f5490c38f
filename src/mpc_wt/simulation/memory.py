"""How much memory a run will take, estimated before it starts, against what the machine has.

A run holds its turbulent wind field (float32 on the grid of :func:`field_grid`, every
``FIELD_DT`` s, one array per velocity component, a second field for a LIDAR's evolved
wind), briefly about twice that while the field is generated, and its result (every plant
state, input and output and the controller's signals in float64 at the plant's rate) on top of
the process's fixed share (libraries, compiled kernels, designs). The estimate is an upper
bound calibrated on measured peaks (``benchmarks/bench_memory.py``; RESULTS.md): a run whose
estimate exceeds the memory available now is refused before any work, naming the estimate,
what is available and what to change.
"""
from __future__ import annotations

import logging
import os
from dataclasses import dataclass

import linearize
from mpc_wt.errors import RunTooLargeError
from mpc_wt.simulation.scenario import Scenario, field_grid

__all__ = ["RunMemory", "estimate_run_memory", "available_memory", "check_run_memory",
           "RunTooLargeError"]

log = logging.getLogger(__name__)

#: Step of the generated turbulence fields [s] (the default grid's).
FIELD_DT = 0.05
#: The process's share before any run: libraries, compiled kernels, designs [B].
BASE_BYTES = 450e6
#: Peak over stored size of a field while it is generated (measured 1.6-1.9).
FIELD_PEAK = 2.0
#: Result columns per plant step: states, inputs, outputs and up to 60 controller signals.
RESULT_COLUMNS = len(linearize.STATE_NAMES) + 4 + len(linearize.OUTPUT_NAMES) + 60


@dataclass(frozen=True)
class RunMemory:
    """An estimate of one run's peak memory [B].

    Parameters
    ----------
    field : float
        Wind fields at their peak while generated.
    result : float
        The recorded arrays.
    base : float
        The process's fixed share.
    """

    field: float
    result: float
    base: float = BASE_BYTES

    @property
    def total(self) -> float:
        """The whole estimate [B]."""
        return self.field + self.result + self.base


def estimate_run_memory(turbine: linearize.Turbine, scenario: Scenario, *,
                        components: int = 1, lidar_fields: int = 0,
                        plant_dt: float = 1.0 / 80.0) -> RunMemory:
    """The peak memory of one run, estimated from its length and grid.

    Parameters
    ----------
    turbine : Turbine
        For the field's grid (:func:`~mpc_wt.simulation.scenario.field_grid`).
    scenario : Scenario
        Its duration; a steady or deterministic case has no turbulent field.
    components : int
        Velocity components the plant's field holds (1-3).
    lidar_fields : int
        Further fields for LIDARs (their evolved wind), each of ``components``.
    plant_dt : float
        The plant's step [s].

    Returns
    -------
    RunMemory
    """
    from mpc_wt.simulation.scenario import is_deterministic

    samples = scenario.duration / plant_dt + 1
    result = samples * RESULT_COLUMNS * 8.0
    if scenario.wind_file is not None \
            or is_deterministic(scenario.condition, (scenario.turbulence,)):
        return RunMemory(0.0, result)
    _, n = field_grid(turbine)
    one = (scenario.duration / FIELD_DT + 1) * n * n * 4.0 * components
    return RunMemory(FIELD_PEAK * one * (1 + lidar_fields), result)


def available_memory() -> float | None:
    """The memory available to new work now.

    Returns
    -------
    float or None
        [B]: Linux's ``MemAvailable``, else the free physical pages; None where neither is
        known.
    """
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def _gb(x: float) -> str:
    return f"{x / 1e9:.2f} GB"


def check_run_memory(need: RunMemory, *, what: str, processes: int = 1,
                     available: float | None = None) -> None:
    """Refuse work whose estimate exceeds the memory available.

    Parameters
    ----------
    need : RunMemory
        One run's estimate (the largest, for a campaign).
    what : str
        What is checked, for the message (``"run at 12 m/s for 3600 s"``).
    processes : int
        Runs held at once (a campaign's workers).
    available : float, optional
        [B]; default :func:`available_memory` (nothing is checked where it is unknown).

    Raises
    ------
    RunTooLargeError
        Naming the estimate, its parts, what is available and what to change.
    """
    have = available_memory() if available is None else available
    total = need.total * processes
    if have is None:
        log.debug("memory available unknown; %s estimated at %s", what, _gb(total))
        return
    if total > have:
        each = f"{processes} x " if processes > 1 else ""
        raise RunTooLargeError(
            f"{what} needs about {each}{_gb(need.total)} of memory (wind fields "
            f"{_gb(need.field)}, result {_gb(need.result)}, process {_gb(need.base)}), more "
            f"than the {_gb(have)} available now: shorten the duration"
            + (", run fewer workers" if processes > 1 else "") + " or free memory")
