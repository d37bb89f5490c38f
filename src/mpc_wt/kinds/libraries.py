"""Bladed-style libraries in the loop: ROSCO and any DISCON (:mod:`mpc_wt.controllers.discon`)."""
from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional


import linearize
from mpc_wt.controllers.discon import CALL_TIMEOUT_S
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import REQUIRED, Options, option
from mpc_wt.registry.registry import register
from mpc_wt.simulation.scenario import Scenario, start_wind
from mpc_wt.kinds.baseline import derated_trim
from mpc_wt.kinds.common import LidarOptions

log = logging.getLogger(__name__)

# -- Bladed-style libraries: ROSCO and any DISCON ---------------------------------------------
_ISOLATE = ("run the library in a child process of its own, so that a library that exits or "
            "crashes fails the case only (about 0.1 ms per call); false loads it in this "
            "process, uncontained")
_TIMEOUT = ("in a child process: the longest one call or the loading may take before the "
            "library is stopped and the case fails naming it (0: no limit)")


@dataclass(frozen=True)
class DisconOptions(Options):
    """Any Bladed-style controller library (``DISCON``) in the loop (:mod:`mpc_wt.controllers.discon`)."""

    discon_library: str = option(REQUIRED, help="the shared library exporting DISCON")
    discon_in: str = option(REQUIRED, help="its input file (accINFILE, e.g. DISCON.IN)")
    pitch_control: str = option("individual", help="avrSWAP(28): read records 42-44 "
                                "(individual) or 45 (collective)",
                                choices=("individual", "collective"))
    discon_dt: float = option(1.0 / 80.0, help="communication interval, a multiple of the "
                              "plant step", unit="s", lo=0.0, lo_open=True, hi=1.0)
    lidar_records: bool = option(False, help="fill OpenFAST's lidar records (2001-2016) from a "
                                 "hub-mounted CW LIDAR (the lidar options)", flag="")
    lidar: LidarOptions = option(LidarOptions(), help="CW LIDAR settings (focus_distance, "
                                 "noise_std, ...)", flag="")
    isolate: bool = option(True, help=_ISOLATE, flag="")
    call_timeout: float = option(CALL_TIMEOUT_S, help=_TIMEOUT, unit="s", lo=0.0)


@dataclass(frozen=True)
class RoscoOptions(Options):
    """ROSCO, the rosco package's compiled controller, in the loop."""

    discon_in: Optional[str] = option(None, help="ROSCO input file; 'shipped' for the DISCON.IN "
                                      "ROSCO ships for the turbine (nrel5mw, iea15mw); default: "
                                      "one exported from our baseline design")
    power_fraction: float = option(1.0, help="with the exported design: derate to this "
                                   "fraction of rated power", unit="-", lo=0.0, lo_open=True,
                                   hi=1.0, flag="--rosco-power-fraction")
    pitch_control: str = option("individual", help="avrSWAP(28): read records 42-44 "
                                "(individual) or 45 (collective)",
                                choices=("individual", "collective"))
    discon_dt: float = option(1.0 / 80.0, help="communication interval, a multiple of the "
                              "plant step", unit="s", lo=0.0, lo_open=True, hi=1.0)
    isolate: bool = option(True, help=_ISOLATE, flag="")
    call_timeout: float = option(CALL_TIMEOUT_S, help=_TIMEOUT, unit="s", lo=0.0)


def _discon_built(ctx: BuildContext, library: Any, discon_in: Any, opts: Any,
                  kind: str, power_fraction: float = 1.0, **meta: Any) -> Built:
    from mpc_wt.controllers.discon import DisconController

    sensor = None
    if getattr(opts, "lidar_records", False):
        sensor = ctx.lidar(opts.lidar.instrument(ctx.turbine), opts.lidar.evolution)
        meta["lidar"] = {**opts.lidar.given(), "evolution": opts.lidar.evolution}
    ctl = DisconController(library, discon_in, ctx.turbine, dt=opts.discon_dt,
                           pitch_control=opts.pitch_control, lidar=sensor,
                           isolate=opts.isolate,
                           call_timeout=opts.call_timeout)
    return Built(ctl, controller_dt=opts.discon_dt,
                 meta={kind: {"library": str(ctl.library), "discon_in": str(ctl.discon_in),
                              "pitch_control": opts.pitch_control, "dt": opts.discon_dt,
                              **meta}},
                 power_fraction=power_fraction)


def _discon_operating_point(turbine: linearize.Turbine, sc: Scenario, opts: DisconOptions
                            ) -> linearize.OperatingPoint:
    """The trim, or for a ROSCO-style input file with a TSR-tracking law the point where that
    law holds the rotor (:func:`_file_start`)."""
    op = linearize.trim(turbine, start_wind(turbine, sc))
    return _file_start(turbine, op, Path(opts.discon_in))


@register("discon", DisconOptions, field_components="u",
          operating_point=_discon_operating_point,
          summary="any Bladed-style controller library (DISCON) with its input file")
def _build_discon(ctx: BuildContext, opts: DisconOptions) -> Built:
    return _discon_built(ctx, opts.discon_library, opts.discon_in, opts, "discon")


_ROSCO_FILES = {"NREL 5-MW": "NREL-5MW", "IEA-15-240-RWT": "IEA-15-240-RWT"}


def _shipped_name(turbine: linearize.Turbine) -> str | None:
    """The name of the ROSCO deck shipped for this turbine, or None."""
    return next((v for k, v in _ROSCO_FILES.items() if turbine.name.startswith(k)), None)


def _rosco_operating_point(turbine: linearize.Turbine, sc: Scenario, opts: RoscoOptions
                           ) -> linearize.OperatingPoint:
    if opts.discon_in is None:
        if opts.power_fraction < 1.0:
            return derated_trim(turbine, sc, opts)     # type: ignore[arg-type]
        return linearize.trim(turbine, start_wind(turbine, sc))
    op = linearize.trim(turbine, start_wind(turbine, sc))
    if opts.discon_in == "shipped":
        from mpc_wt.controllers.discon import rosco_discon

        name = _shipped_name(turbine)
        if name is None:
            return op
        path = rosco_discon(name)
    else:
        path = Path(opts.discon_in)
    return _file_start(turbine, op, path)


def _file_start(turbine: linearize.Turbine, op: linearize.OperatingPoint, path: Path
                ) -> linearize.OperatingPoint:
    """Where a ROSCO file's own below-rated law holds the rotor, so the run starts in its
    equilibrium rather than in our schedule's.

    A TSR-tracking file (``VS_ControlMode`` 2-4) holds the generator speed at
    ``VS_TSRopt * v / WE_BladeRadius * WE_GearboxRatio`` within ``VS_MinOMSpd..VS_RefSpd``;
    ROSCO's shipped NREL 5-MW file allows 34.6 rad/s (3.4 rpm at the rotor), where our schedule
    (and the turbine's definition) keeps 6.9 rpm. Started at ours, its torque controller brakes
    the rotor at full torque rate (3.9 MN m and 0.23 x rated rotor speed at 3 m/s). Above the
    file's rated speed, or for any other law, or where no equilibrium exists at that speed,
    the trim is kept (it is the file's region-3 point too)."""
    from mpc_wt.io.gain_tables import read_rosco

    try:
        f = read_rosco(path)
        mode = int(f["VS_ControlMode"])
        tsr, lo, hi = (float(f[k]) for k in ("VS_TSRopt", "VS_MinOMSpd", "VS_RefSpd"))
        radius, gear = float(f["WE_BladeRadius"]), float(f["WE_GearboxRatio"])
    except (OSError, KeyError, ValueError, TypeError):
        return op
    if mode not in (2, 3, 4) or min(tsr, lo, hi, radius, gear) <= 0:
        return op
    gen = min(max(tsr * op.wind_mps / radius * gear, lo), hi)
    omega = gen / turbine.drivetrain.gearbox_ratio
    if gen >= hi * (1 - 1e-6) or abs(omega - op.rotor_speed_rad_s) <= 1e-3 * omega:
        return op
    try:
        return linearize.operating_point(turbine, op.wind_mps, omega, op.pitch_rad,
                                         shear_exponent=op.shear_exponent)
    except linearize.TrimError:
        return op


@register("rosco", RoscoOptions, field_components="u", operating_point=_rosco_operating_point,
          summary="ROSCO (the rosco package's libdiscon) with a DISCON.IN exported from our "
                  "baseline, ROSCO's own ('shipped') or any file")
def _build_rosco(ctx: BuildContext, opts: RoscoOptions) -> Built:
    from mpc_wt.controllers.discon import rosco_discon, rosco_library

    discon_in = opts.discon_in
    source = {}
    if discon_in == "shipped":
        name = _shipped_name(ctx.turbine)
        if name is None:
            raise ValueError(f"rosco: no DISCON.IN shipped for turbine {ctx.turbine.name!r}; "
                             f"give discon_in (--discon-in FILE)")
        source = {"shipped_file": str(rosco_discon(name))}
        discon_in = ctx.cache.get(ctx.turbine, ("rosco-shipped", name),
                                  lambda: _quiet_copy(rosco_discon(name)))
    elif discon_in is None:
        discon_in = ctx.cache.get(ctx.turbine, ("rosco-export", opts.power_fraction),
                                  lambda: _export_rosco(ctx.turbine, opts.power_fraction))
    ours = opts.discon_in is None
    if not ours and opts.discon_in != "shipped":
        rosco_file_check(Path(discon_in))
    return _discon_built(ctx, rosco_library(), discon_in, opts, "rosco",
                         power_fraction=opts.power_fraction if ours else 1.0,
                         design=("ours" if ours else
                                 "shipped" if opts.discon_in == "shipped" else "file"),
                         **source)


def _rosco_entries(path: Path) -> list[tuple[int, str, str]]:
    """The ``value ! key - description`` lines of a ROSCO input file: (line number, key,
    value text)."""
    out = []
    for no, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        head, bang, tail = line.partition("!")
        if bang and head.strip() and tail.split():
            out.append((no, tail.split()[0], head.strip()))
    return out


#: ROSCO's modes that need what mpc-wt's plant and host do not give, and what that is: ROSCO
#: reads records no host fills or drives actuators the plant lacks (BAR_10's own file,
#: ``Flp_Mode`` 2, ended the library's process with a segmentation fault at the first call)
ROSCO_MODES_REFUSED = {"Flp_Mode": "trailing-edge flap control; the plant has no flaps",
                       "CC_Mode": "cable control; the plant has no mooring",
                       "StC_Mode": "structural control; the plant has no tuned dampers",
                       "Ext_Mode": "an external controller library called by ROSCO",
                       "ZMQ_Mode": "a ZeroMQ connection to another process"}


def _refused_modes(path: Path, entries: list[tuple[int, str, str]]) -> None:
    """Raise ValueError naming the first of :data:`ROSCO_MODES_REFUSED` that ``path`` (its
    :func:`_rosco_entries`) sets."""
    for no, key, head in entries:
        if key not in ROSCO_MODES_REFUSED:
            continue
        try:
            value = int(float(head.split()[0]))
        except ValueError:
            continue
        if value != 0:
            raise ValueError(f"discon_in: {path.name}:{no} {key} is {value} "
                             f"({ROSCO_MODES_REFUSED[key]}); allowed here: 0; set it to 0 "
                             f"in a copy of {path}")


def rosco_file_check(path: Path) -> list[str]:
    """The keys the installed ROSCO's own NREL 5-MW input file has and ``path`` lacks, logged
    as a warning with the installed version: a file written for another ROSCO release (ROSCO
    stops on the ones it requires: "Missing or default values are not allowed for ...").
    A file that sets a mode of :data:`ROSCO_MODES_REFUSED` is refused.

    Parameters
    ----------
    path : Path
        A ``DISCON.IN``.

    Returns
    -------
    list of str
        The missing keys (empty: none).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        Naming the file, line, key and value of a refused mode.
    """
    from importlib.metadata import PackageNotFoundError, version

    from mpc_wt.controllers.discon import rosco_discon

    if not path.is_file():
        raise FileNotFoundError(f"discon_in: {path} does not exist")
    entries = _rosco_entries(path)
    _refused_modes(path, entries)
    have = {k for _, k, _ in entries}
    ref = rosco_discon("NREL-5MW")
    missing = [k for _, k, _ in _rosco_entries(ref) if k not in have]
    if missing:
        try:
            installed = version("rosco")
        except PackageNotFoundError:  # pragma: no cover - rosco_discon needs the package
            installed = "?"
        log.warning("%s lacks %d keys of the installed ROSCO %s's own input files (%s): it was "
                    "written for another ROSCO release, and ROSCO stops on those it requires "
                    "('Missing or default values are not allowed for ...'); write it again with "
                    "ROSCO %s's toolbox, or add them with the values of %s", path, len(missing),
                    installed, ", ".join(missing[:8]) + (", ..." if len(missing) > 8 else ""),
                    installed, ref)
    return missing


def _process_folder(prefix: str) -> Path:
    """A temporary folder kept for the process (removed when it exits)."""
    import atexit
    import shutil
    import tempfile

    out = Path(tempfile.mkdtemp(prefix=prefix))
    atexit.register(shutil.rmtree, out, ignore_errors=True)
    return out


def _quiet_copy(discon_in: Path) -> str:
    """ROSCO's shipped DISCON.IN with ``LoggingLevel`` 0 (its debug file written every call
    takes about a quarter of a run) and ``PerfFileName`` made absolute, in a folder kept for the
    process; every control parameter as shipped."""
    lines = discon_in.read_text().splitlines()
    for i, line in enumerate(lines):
        words = line.split()
        if len(words) >= 3 and words[2] == "LoggingLevel":
            lines[i] = "0" + line[len(words[0]):]
        elif len(words) >= 3 and words[2] == "PerfFileName":
            perf = words[0].strip('"')
            if not Path(perf).is_absolute():
                lines[i] = f'"{(discon_in.parent / perf).resolve()}"' + line[len(words[0]):]
    out = _process_folder("mpcwt_rosco_shipped_") / discon_in.name
    out.write_text("\n".join(lines) + "\n")
    return str(out)


def _export_rosco(turbine: linearize.Turbine, power_fraction: float) -> str:
    """Our baseline design as a ROSCO DISCON.IN in a folder kept for the process (removed when
    it exits)."""
    from mpc_wt.controllers.baseline import tune_baseline
    from mpc_wt.kinds.baseline import baseline_table
    from mpc_wt.io.rosco import write_rosco_discon

    out = _process_folder("mpcwt_rosco_export_")
    doc = baseline_table(turbine, tune_baseline(turbine, power_fraction=power_fraction))
    return str(write_rosco_discon(turbine, doc, out)[0])
