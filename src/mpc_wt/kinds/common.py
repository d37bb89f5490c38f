"""What the kinds share: the shipped law of a kind that exports, the LIDAR's options, the
wind estimator and schedule checks of the scheduled designs."""
from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from typing import Any, Optional


import linearize
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import Options, option

log = logging.getLogger(__name__)

# -- the shipped laws: a kind that exports runs its compiled C law --------------------------
def shipped_law(kind: str, base: str | None = None) -> Any:
    """The ``shipped`` hook of an exportable kind: the design's numbers written to its input
    file, its compiled library (:func:`mpc_wt.io.discon_export.shipped_library`) called through
    the host in this process, every run of the kind then calls the law users run in OpenFAST.
    ``base``: for an add-on, the base its export is made on (another base keeps the Python
    step). A design with options the library does not take (an MPC on OSQP, the sparse
    formulation) keeps its Python step too; the run's metadata says which law ran."""
    def hook(ctx: BuildContext, sel: Any, opts: Any, built: Built) -> Built:
        from mpc_wt.controllers.discon import DisconController
        from mpc_wt.io.discon_export import log_channels, shipped_input, shipped_library

        if base is not None and sel.base.name != base:
            return built
        try:
            infile = shipped_input(built.controller, kind, ctx.turbine, built.preview)
        except ValueError as err:
            log.info("%s: the design does not export (%s); its Python step runs", kind, err)
            return dataclasses.replace(built, meta={**built.meta, "law": "python"})
        dt = float(built.controller.dt)
        ctl = DisconController(shipped_library(kind), infile, ctx.turbine, dt=dt,
                               lidar=built.sensors[-1] if built.sensors else None,
                               isolate=False, log_names=log_channels(kind))
        return dataclasses.replace(built, controller=ctl, controller_dt=dt, preview=None,
                                   design=built.controller,
                                   meta={**built.meta, "law": "shipped",
                                         "library": ctl.library.name})
    return hook


_CW = "lidar.CWLidar setting (unset: its default)"


@dataclass(frozen=True)
class LidarOptions(Options):
    """Settings of the CW LIDAR (:class:`lidar.CWLidar`); unset ones keep its defaults."""

    focus_distance: Optional[float] = option(None, help=_CW, unit="m", lo=0.0, lo_open=True)
    span_fraction: Optional[float] = option(None, help=_CW, unit="-", lo=0.0, lo_open=True)
    wavelength: Optional[float] = option(None, help=_CW, unit="m", lo=0.0, lo_open=True)
    beam_radius: Optional[float] = option(None, help=_CW, unit="m", lo=0.0, lo_open=True)
    sample_rate: Optional[float] = option(None, help=_CW, unit="Hz", lo=0.0, lo_open=True)
    noise_std: Optional[float] = option(None, help=_CW, unit="m/s", lo=0.0)
    misalignment_rad: Optional[float] = option(None, help=_CW, unit="rad")
    perfect_alignment: Optional[bool] = option(None, help=_CW)
    los_error: Optional[bool] = option(None, help=_CW)
    range_weighting: Optional[bool] = option(None, help=_CW)
    n_range: Optional[int] = option(None, help=_CW, lo=1)
    evolution: bool = option(True, help="wind evolution between the focus and the rotor "
                             "(Simley and Pao's coherence, lidar.evolve_field); false: frozen "
                             "turbulence, Madsen's assumption")

    def given(self) -> dict[str, Any]:
        """The :class:`lidar.CWLidar` settings that were set.

        Returns
        -------
        dict
            Name -> value of the CWLidar options that are not None (``evolution`` is not one:
            it acts on the field the LIDAR sees, :func:`mpc_wt.simulation.scenario.lidar_field`).
        """
        return {k: v for k, v in self.to_dict().items() if v is not None and k != "evolution"}

    def instrument(self, turbine: linearize.Turbine) -> Any:
        """The CW LIDAR of these settings on the turbine's rotor.

        Parameters
        ----------
        turbine : Turbine
            For the rotor radius.

        Returns
        -------
        lidar.CWLidar

        Raises
        ------
        ValueError
            A setting CWLidar refuses, prefixed "lidar options:".
        """
        import lidar

        try:
            return lidar.CWLidar(turbine.geometry.tip_radius, **self.given())
        except (TypeError, ValueError) as err:
            raise ValueError(f"lidar options: {err}") from err


def envelope_family(ctx: BuildContext, config: str, step: float,
                     region3_pitch_deg: float = 0.0) -> Any:
    """The turbine's linear models from cut-in to cut-out (kept in the design cache); with
    ``region3_pitch_deg`` > 0 the first design above rated where the trim's pitch has left fine
    pitch by that much (:func:`~mpc_wt.controllers.scheduling.envelope_winds`)."""
    from mpc_wt.controllers.scheduling import envelope_winds

    conf = {"madsen": linearize.PlantConfig.madsen, "do": linearize.PlantConfig.do}[config]
    r3 = math.radians(region3_pitch_deg) if region3_pitch_deg > 0.0 else None
    grid = ctx.cache.get(ctx.turbine, ("envelope-grid", config, step, r3),
                         lambda: envelope_winds(ctx.turbine, step, region3_pitch=r3,
                                                config=conf()))
    return ctx.cache.get(ctx.turbine, ("family", config, tuple(grid)),
                         lambda: linearize.linearize_family(ctx.turbine, grid, config=conf()))


def wind_estimator(ctx: BuildContext, dt: float) -> Any:
    """A wind estimator at ``dt`` on the turbine's C_P table (which
    :func:`linearize.rotor_performance` keeps for the process)."""
    from mpc_wt.controllers.wind_estimator import WindSpeedEstimator

    return WindSpeedEstimator(ctx.turbine, dt)


def check_design_wind(turbine: linearize.Turbine, v: float) -> float:
    op = turbine.operation
    if not op.cut_in_wind <= v <= op.cut_out_wind:
        raise ValueError(f"design_wind_mps = {v:g} m/s is outside the turbine's operating range "
                         f"{op.cut_in_wind:g}..{op.cut_out_wind:g} m/s")
    return float(v)
