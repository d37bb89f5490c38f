"""Controllers designed in mpc-wt exported as Bladed-style controller libraries (``DISCON``),
to run in OpenFAST's ServoDyn, in Bladed or in any host of that interface.

An export is a folder with the C sources of the controller (the Bladed entry point, the
reader of its input file and the control law), a ``Makefile``, the input file that holds
every number of the design (a user changes a gain there without recompiling), a ServoDyn
input file for the turbine's packaged OpenFAST deck that points at the library, and the
library itself when a C compiler is found (``cc``, or ``$CC``).

The design is the one mpc-wt runs: :func:`mpc_wt.run.export_discon` builds the controller through
the registry (as every run does) and :func:`export_controller` writes its numbers out, so the
library and the Python controller are the same law (checked step by step in the tests).

The library's interface (``DISCON(avrSWAP, aviFAIL, accINFILE, avcOUTNAME, avcMSG)``), the swap
records it reads and writes, and its behaviour on errors are described in the guide
"Run your mpc-wt controller in OpenFAST".
"""
from __future__ import annotations

import dataclasses
import datetime as _dt
import importlib.resources
import logging
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any, Mapping, Sequence

import linearize
from mpc_wt.errors import ControllerLibraryError

__all__ = ["DisconExport", "EXPORTABLE", "export_controller", "export_design", "controller_input",
           "check_exportable",
           "build_library",
           "find_compiler", "library_name", "servodyn_input", "SWAP_READ", "SWAP_WRITTEN"]

log = logging.getLogger(__name__)

#: The controller kinds that export, and what each becomes.
EXPORTABLE: dict[str, str] = {
    "baseline": "the tuned PI pitch loop and torque law, constant power in region III",
    "baseline-ct": "the baseline with constant torque in region III",
}

#: The swap records the library reads (1-based, as the interface numbers them).
SWAP_READ: dict[int, str] = {
    1: "status (0 first call, 1 running, -1 last call)", 2: "time [s]",
    3: "communication interval [s] (checked against the design's)",
    4: "blade 1 pitch [rad]", 33: "blade 2 pitch [rad]", 34: "blade 3 pitch [rad]",
    20: "generator speed [rad/s]", 49: "length of avcMSG", 50: "length of accINFILE",
    51: "length of avcOUTNAME"}

#: The swap records the library writes.
SWAP_WRITTEN: dict[int, str] = {
    35: "generator contactor (1)", 36: "shaft brake (0: off)",
    41: "yaw actuator torque demand (0)", 42: "blade 1 pitch demand [rad]",
    43: "blade 2 pitch demand [rad]", 44: "blade 3 pitch demand [rad]",
    45: "collective pitch demand (the blades' mean) [rad]",
    47: "generator torque demand [N m]", 48: "yaw rate demand (0)",
    55: "pitch override (0: off)", 56: "torque override (0: off)", 65: "logging channels (0)"}

_SOURCES = ("mpcwt_discon.h", "input.c", "baseline.c", "discon.c")
_CFLAGS = "-O2 -std=c99 -Wall -fPIC -fvisibility=hidden"
_SANITIZE = "-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined " \
            "-fno-sanitize-recover=all"


@dataclasses.dataclass(frozen=True)
class DisconExport:
    """What an export wrote (:func:`export_controller`, :func:`mpc_wt.run.export_discon`).

    Parameters
    ----------
    kind : str
        The controller kind.
    directory : Path
        The export folder.
    input_file : Path
        The controller's input file (``accINFILE``, ServoDyn's ``DLL_InFile``).
    sources : tuple of Path
        The C sources and header.
    makefile : Path
        ``make`` builds the library with the system's C compiler.
    library : Path or None
        The built library (None when it was not built: see ``note``).
    servodyn : Path or None
        A ServoDyn input file of the turbine's packaged OpenFAST deck pointing at the library
        (None when no deck is packaged for the turbine: see ``note``).
    dt : float
        The communication interval the design runs at [s] (ServoDyn's ``DLL_DT``).
    note : str
        What was not done and why (empty when everything was).
    """

    kind: str
    directory: Path
    input_file: Path
    sources: tuple[Path, ...]
    makefile: Path
    library: Path | None
    servodyn: Path | None
    dt: float
    note: str = ""


def library_name(kind: str) -> str:
    """The file name of an exported library on this platform (``libmpcwt_<kind>.so``,
    ``.dylib`` on macOS, ``mpcwt_<kind>.dll`` on Windows).

    Parameters
    ----------
    kind : str
        The controller kind.

    Returns
    -------
    str
    """
    stem = "mpcwt_" + kind.replace("-", "_").replace("+", "_")
    if sys.platform == "win32":
        return stem + ".dll"
    return "lib" + stem + (".dylib" if sys.platform == "darwin" else ".so")


def find_compiler() -> str | None:
    """The C compiler the export builds with: ``$CC`` if set, else the first of ``cc``,
    ``gcc``, ``clang`` on the path.

    Returns
    -------
    str or None
        Its path, or None when there is none.
    """
    env = os.environ.get("CC")
    if env:
        found = shutil.which(env.split()[0])
        return found
    for name in ("cc", "gcc", "clang"):
        found = shutil.which(name)
        if found:
            return found
    return None


def _fmt(v: float) -> str:
    return repr(float(v))


def _baseline_entries(ctl: Any) -> list[tuple[str, float, str]]:
    """The numbers of a :class:`~mpc_wt.controllers.baseline.BaselineController` as input-file
    entries (key, value, unit and meaning)."""
    from mpc_wt.controllers.baseline import BaselineController

    if type(ctl) is not BaselineController:
        raise ValueError(f"the baseline export takes a BaselineController, got "
                         f"{type(ctl).__name__}")
    if ctl.power_reference is not None or ctl._sched_f is not None:
        raise ValueError("a baseline with a power reference or a gain schedule (active power "
                         "control) does not export yet: export the plain design")
    g, tb = ctl.gains, ctl.turbine
    return [
        ("dt", ctl.dt, "communication interval [s] (ServoDyn DLL_DT)"),
        ("speed_filter_corner_hz", ctl.wc / (2 * math.pi),
         "generator-speed low-pass corner [Hz]"),
        ("gen_speed_setpoint", g.rated_gen_speed_rad_s, "PI speed set-point [rad/s]"),
        ("kp", g.kp, "proportional gain at fine pitch [s]"),
        ("ki", g.ki, "integral gain at fine pitch [-]"),
        ("theta_k", g.theta_k_rad, "pitch at which the gain has halved [rad]"),
        ("pitch_min", ctl.pitch_min, "minimum pitch command [rad]"),
        ("pitch_max", ctl.pitch_max, "maximum pitch command [rad]"),
        ("pitch_rate_max", ctl.rate, "pitch-rate limit [rad/s]"),
        ("torque_rate_max", ctl.tq_rate, "generator-torque rate limit [N m/s]"),
        ("torque_max", ctl.tq_max, "maximum generator torque [N m]"),
        ("gen_speed_cutin", ctl.w_cutin, "region 1.5 starts [rad/s]"),
        ("gen_speed_region2", ctl.w_rgn2, "region 2 starts [rad/s]"),
        ("gen_speed_transition", ctl.w_trans, "region 2.5 starts [rad/s]"),
        ("gen_speed_rated", ctl.w_rated, "region 3 speed [rad/s]"),
        ("gen_speed_sync", ctl.w_sync, "region 2.5 line's zero-torque speed [rad/s]"),
        ("slope_region15", ctl.slope15, "region 1.5 torque slope [N m s/rad]"),
        ("slope_region25", ctl.slope25, "region 2.5 torque slope [N m s/rad]"),
        ("k_opt", g.k_opt, "region 2 torque gain [N m s^2/rad^2]"),
        ("torque_cap", ctl.tq_cap, "largest torque below rated [N m]"),
        ("rated_power", g.rated_power, "rated electrical power [W]"),
        ("gen_efficiency", tb.drivetrain.generator_efficiency, "generator efficiency [-]"),
        ("rated_torque", g.rated_torque, "region 3 torque (constant torque) [N m]"),
        ("region3_constant_power", float(ctl.region3 == "constant_power"),
         "1: constant power above rated, 0: constant torque"),
    ]


def controller_input(controller: Any, kind: str, turbine: linearize.Turbine,
                     source: str = "") -> str:
    """The input file of an exported controller: every number of its design.

    Parameters
    ----------
    controller : object
        The designed controller (from :func:`mpc_wt.run.design_controller`).
    kind : str
        Its kind (one of :data:`EXPORTABLE`).
    turbine : Turbine
        Its turbine (named in the header).
    source : str
        How it was designed (written as a comment).

    Returns
    -------
    str
        The file's text.

    Raises
    ------
    ValueError
        A kind that does not export, or a controller of another type.
    """
    if kind not in EXPORTABLE:
        raise ValueError(f"controller kind {kind!r} does not export as a DISCON library; "
                         f"the kinds that do: {sorted(EXPORTABLE)}")
    entries = _baseline_entries(controller)
    from mpc_wt._version import __version__

    head = [f"# mpc-wt {__version__}: controller '{kind}' for {turbine.name}",
            f"# {EXPORTABLE[kind]}",
            f"# exported {_dt.date.today().isoformat()}{'; ' + source if source else ''}",
            "# One entry per line: key value [value ...]; '#' starts a comment. Every number",
            "# here is read at the first call: change one and restart the simulation.",
            "format_version 1",
            f"kind {'baseline'}"]
    width = max(len(k) for k, _, _ in entries)
    body = [f"{k:<{width}} {_fmt(v):<24} # {doc}" for k, v, doc in entries]
    return "\n".join(head + body) + "\n"


def _copy_sources(directory: Path) -> tuple[Path, ...]:
    src = importlib.resources.files("mpc_wt.io") / "discon_c"
    out = []
    for name in _SOURCES:
        target = directory / name
        target.write_text((src / name).read_text())
        out.append(target)
    return tuple(out)


def _makefile(directory: Path, lib: str) -> Path:
    srcs = " ".join(n for n in _SOURCES if n.endswith(".c"))
    text = (f"# Builds {lib} with the system's C compiler (make CC=... to choose another).\n"
            f"CC ?= cc\nCFLAGS ?= {_CFLAGS}\nLDLIBS = -lm -lpthread\n\n"
            f"{lib}: {srcs} mpcwt_discon.h\n"
            f"\t$(CC) $(CFLAGS) -shared -o $@ {srcs} $(LDLIBS)\n\n"
            f"clean:\n\trm -f {lib}\n")
    path = directory / "Makefile"
    path.write_text(text)
    return path


def build_library(directory: str | Path, kind: str, *, compiler: str | None = None,
                  sanitize: bool = False, name: str | None = None) -> Path:
    """Compile an export folder's sources into the shared library.

    Parameters
    ----------
    directory : path
        The export folder (its ``*.c`` and header).
    kind : str
        The controller kind (names the library).
    compiler : str, optional
        The C compiler (default :func:`find_compiler`).
    sanitize : bool
        Build with AddressSanitizer and UndefinedBehaviorSanitizer (the library then runs
        only in a process that loads the sanitizer runtime first).
    name : str, optional
        The library's file name (default :func:`library_name`).

    Returns
    -------
    Path
        The library.

    Raises
    ------
    ControllerLibraryError
        No compiler, or the compiler failed (its output in the message).
    """
    directory = Path(directory).resolve()
    cc = compiler or find_compiler()
    if cc is None:
        raise ControllerLibraryError(
            "no C compiler found (looked for $CC, cc, gcc, clang): install one (e.g. "
            "build-essential, Xcode's command line tools, MSYS2) and run 'make' in "
            f"{directory}")
    lib = directory / (name or library_name(kind))
    flags = (_SANITIZE if sanitize else _CFLAGS).split()
    if sanitize:
        flags += ["-fPIC"]
    cmd = [cc, *flags, "-shared", "-o", str(lib),
           *[str(directory / n) for n in _SOURCES if n.endswith(".c")], "-lm"]
    if sys.platform != "win32":
        cmd.append("-lpthread")
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=directory)
    if proc.returncode != 0 or not lib.is_file():
        raise ControllerLibraryError(
            f"building {lib.name} failed (exit {proc.returncode}): {' '.join(cmd)}\n"
            f"{proc.stderr.strip() or proc.stdout.strip()}")
    return lib


#: ServoDyn inputs of the packaged OpenFAST decks, by turbine name prefix.
def _deck_servodyn(turbine: linearize.Turbine) -> Path | None:
    name = turbine.name
    if name.startswith("IEA-15-240-RWT"):
        root = importlib.resources.files("linearize") / "data" / "iea15mw"
        p = Path(str(root)) / "IEA-15-240-RWT-Monopile" / "IEA-15-240-RWT-Monopile_ServoDyn.dat"
        return p if p.is_file() else None
    if name.startswith("NREL 5-MW"):
        try:
            from mpc_wt.controllers.discon import rosco_discon
            deck = rosco_discon("NREL-5MW").parent
        except Exception:  # noqa: BLE001 - the rosco package is optional
            return None
        p = deck / "NRELOffshrBsline5MW_Onshore_ServoDyn.dat"
        return p if p.is_file() else None
    return None


def servodyn_input(template: str | Path, out: str | Path, library: str | Path,
                   input_file: str | Path, dt: float, *, individual_pitch: bool = True) -> Path:
    """A ServoDyn input file that runs a Bladed-style library: ``template`` with pitch and
    torque control from the library (``PCMode = 5``, ``VSContrl = 5``), ``DLL_FileName``,
    ``DLL_InFile``, ``DLL_ProcName = "DISCON"``, ``DLL_DT`` and ``Ptch_Cntrl`` set; every other
    line as it was.

    Parameters
    ----------
    template : path
        A ServoDyn input file (OpenFAST v3/v4 layout: ``value  Key  - description``).
    out : path
        Where to write it.
    library, input_file : path
        The library and its input file (written as absolute paths).
    dt : float
        ``DLL_DT`` [s].
    individual_pitch : bool
        ``Ptch_Cntrl`` 1 (records 42-44) or 0 (record 45).

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        If the template lacks one of the keys.
    """
    want = {"PCMode": "5", "VSContrl": "5",
            "DLL_FileName": f'"{Path(library).resolve()}"',
            "DLL_InFile": f'"{Path(input_file).resolve()}"', "DLL_ProcName": '"DISCON"',
            "DLL_DT": repr(float(dt)), "Ptch_Cntrl": "1" if individual_pitch else "0"}
    lines = Path(template).read_text().splitlines()
    seen = set()
    for i, line in enumerate(lines):
        parts = line.split()
        if len(parts) >= 2 and parts[1] in want and parts[1] not in seen:
            key = parts[1]
            rest = line[line.index(key):]
            lines[i] = f"{want[key]:<14} {rest}"
            seen.add(key)
    missing = sorted(set(want) - seen)
    if missing:
        raise ValueError(f"ServoDyn template {template}: no line for {missing}")
    out = Path(out)
    out.write_text("\n".join(lines) + "\n")
    return out


def check_exportable(kind: str) -> None:
    """Raise ``ValueError`` (listing the kinds that export) unless ``kind`` exports.

    Parameters
    ----------
    kind : str
        A controller kind.

    Raises
    ------
    ValueError
        If it is not one of :data:`EXPORTABLE`.
    """
    if kind not in EXPORTABLE:
        raise ValueError(f"controller kind {kind!r} does not export as a DISCON library; "
                         f"the kinds that do: {sorted(EXPORTABLE)}")


def export_controller(controller: Any, kind: str, turbine: linearize.Turbine,
                      out: str | Path, *, build: bool = True, compiler: str | None = None,
                      source: str = "") -> DisconExport:
    """Export a designed controller object as a Bladed-style library
    (:func:`mpc_wt.run.export_discon` designs a kind and calls this).

    Parameters
    ----------
    controller : object
        The controller (of the type its kind builds).
    kind : str
        Its kind (one of :data:`EXPORTABLE`).
    turbine : Turbine
        Its turbine.
    out : path
        The export folder (created).
    build : bool
        Compile the library now.
    compiler : str, optional
        The C compiler.
    source : str
        How it was designed (a comment in the input file).

    Returns
    -------
    DisconExport
    """
    check_exportable(kind)
    dt = float(getattr(controller, "dt"))
    directory = Path(out)
    directory.mkdir(parents=True, exist_ok=True)
    text = controller_input(controller, kind, turbine, source)
    input_file = directory / f"mpcwt_{kind.replace('-', '_')}.in"
    input_file.write_text(text)
    sources = _copy_sources(directory)
    lib_name = library_name(kind)
    makefile = _makefile(directory, lib_name)
    notes = []
    library = None
    if build:
        if find_compiler() is None and compiler is None:
            notes.append("no C compiler found ($CC, cc, gcc, clang): the sources and Makefile "
                         "are written; run 'make' where a compiler is installed")
        else:
            library = build_library(directory, kind, compiler=compiler)
    template = _deck_servodyn(turbine)
    servodyn = None
    if template is None:
        notes.append(f"no OpenFAST deck is packaged for {turbine.name}: set DLL_FileName, "
                     f"DLL_InFile, DLL_ProcName and DLL_DT in your ServoDyn file yourself")
    else:
        servodyn = servodyn_input(template, directory / f"ServoDyn_mpcwt_{kind}.dat",
                                  directory / lib_name, input_file, dt)
    for n in notes:
        log.warning("%s", n)
    return DisconExport(kind=kind, directory=directory, input_file=input_file,
                        sources=sources, makefile=makefile, library=library,
                        servodyn=servodyn, dt=dt, note="; ".join(notes))


def export_design(doc: Mapping[str, Any], turbine: linearize.Turbine, out: str | Path, *,
                  build: bool = True, compiler: str | None = None) -> DisconExport:
    """Export a saved design (a gain-table document of ``mpcwt design``) as a library.

    Parameters
    ----------
    doc : mapping
        The design document (:func:`mpc_wt.io.gain_tables.load_design`).
    turbine : Turbine
        Its turbine.
    out : path
        The export folder.
    build : bool
        Compile the library now.
    compiler : str, optional
        The C compiler.

    Returns
    -------
    DisconExport

    Raises
    ------
    ValueError
        A design of a kind that does not export.
    """
    from mpc_wt.controllers.baseline import BaselineController, BaselineGains

    kind = doc.get("kind")
    if kind != "baseline":
        raise ValueError(f"a {kind!r} design does not export as a DISCON library from its "
                         f"gain table; the kinds that do: {sorted(EXPORTABLE)} (mpcwt design "
                         f"baseline, or export_discon for a registered kind)")
    s = doc["settings"]
    gains = BaselineGains(kp=s["kp"], ki=s["ki"], theta_k_rad=s["theta_k_rad"], k_opt=s["k_opt"],
                          rated_gen_speed_rad_s=s["rated_gen_speed_rad_s"],
                          rated_torque=s["rated_torque"], rated_power=s["rated_power"],
                          dpdtheta_0=math.nan, omega_n_rad_s=s.get("omega_n_rad_s", 0.6),
                          zeta=s.get("zeta", 0.7), power_fraction=s.get("power_fraction", 1.0))
    ctl = BaselineController(turbine, gains)
    return export_controller(ctl, "baseline", turbine, out, build=build, compiler=compiler,
                             source=f"from the design of omega_n {gains.omega_n_rad_s:g} rad/s, "
                                    f"zeta {gains.zeta:g}, power fraction "
                                    f"{gains.power_fraction:g}")
