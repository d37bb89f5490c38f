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
import hashlib
import importlib.resources
import logging
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

import linearize
from mpc_wt.errors import ControllerLibraryError

__all__ = ["DisconExport", "LawExport", "COMMON_SOURCES", "SIGNAL_CODES", "export_controller",
           "export_design", "controller_input", "prepare_sources", "shipped_library",
           "shipped_input", "signal_codes", "build_library",
           "find_compiler", "library_name", "lidar_geometry", "lidar_inflow", "servodyn_input",
           "SWAP_READ",
           "SWAP_WRITTEN"]

log = logging.getLogger(__name__)

@dataclasses.dataclass(frozen=True)
class LawExport:
    """How a controller kind exports as a Bladed-style library: what it becomes, the C law
    it runs and the numbers of its design that law reads. A kind passes one to its
    registration (``register(..., export=...)``); the export, the shipped run and the
    command line then know it.

    Parameters
    ----------
    name : str
        The exported kind's name (``"baseline+lidar-ff"`` for an add-on on its base); the
        library's and the input file's stem.
    summary : str
        What the library is (the input file's header, the command line's list).
    law : str
        The C law (the input file's ``kind``): its constructor is ``mw_<law>_new`` in the C
        sources, ``baseline`` is in every library.
    entries : callable
        ``entries(controller, preview) -> [(key, value, meaning), ...]``: the design's numbers
        as input-file entries; ``ValueError`` for a design the law does not take.
    sources : tuple of str
        The law's C files beside the common ones (:data:`COMMON_SOURCES`): names in
        ``mpc_wt/io/discon_c/``, or absolute paths (a plugin's C file beside its module).
    qp : bool
        The law solves a QP: its library carries DAQP's sources from their published
        distribution (:mod:`mpc_wt.io.solver_sources`).
    log : tuple of str
        The logging channels the law returns (records 65 and 63 on), in order: the signals a
        shipped run records beside the host's.
    base : str or tuple of str, optional
        For an add-on: the bases its export is made on (another base keeps the Python step).
    rebuilt : bool
        A saved design of the kind exports by building it again from its options (False:
        from its gain table).
    check_saved : callable, optional
        ``check_saved(doc)``: ``ValueError`` for a saved design (a gain-table document) the
        kind's export cannot build again from its options.
    """

    name: str
    summary: str
    law: str
    entries: Callable[[Any, Any], list[tuple[str, Any, str]]]
    sources: tuple[str, ...] = ()
    qp: bool = False
    log: tuple[str, ...] = ()
    base: str | tuple[str, ...] | None = None
    rebuilt: bool = True
    check_saved: Callable[[Mapping[str, Any]], None] | None = None

    def __post_init__(self) -> None:
        if not self.law.isidentifier():
            raise ValueError(f"LawExport {self.name!r}: law must be a C identifier (its "
                             f"constructor is mw_<law>_new), got {self.law!r}")


#: The measured signals a law's estimator may read from the swap array, and their codes in the
#: library (an input file's signal lists).
SIGNAL_CODES = {"rotor_speed": 0, "gen_speed": 1, "pitch_1": 2, "pitch_2": 3, "pitch_3": 4,
                 "flap_moment_1": 5, "flap_moment_2": 6, "flap_moment_3": 7,
                 "tower_fa_acceleration": 8, "tower_ss_acceleration": 9}

#: The swap records the library reads (1-based, as the interface numbers them).
SWAP_READ: dict[int, str] = {
    1: "status (0 first call, 1 running, -1 last call)", 2: "time of the first call [s]",
    3: "communication interval [s] (checked against the design's)",
    4: "blade 1 pitch [rad]", 33: "blade 2 pitch [rad]", 34: "blade 3 pitch [rad]",
    20: "generator speed [rad/s]", 21: "rotor speed [rad/s] (MPC, LQR-PIO, TS)",
    23: "measured generator torque [N m] (MPC, LQR-PIO)",
    30: "blade 1 root out-of-plane moment [N m] (MPC, LQR-PIO, IBC; 31, 32 blades 2, 3)",
    15: "measured electrical power [W] (IBC)",
    53: "tower-top fore-aft acceleration [m/s^2] (MPC, LQR-PIO, TS)",
    54: "tower-top side-side acceleration [m/s^2] (TS)", 49: "length of avcMSG",
    50: "length of accINFILE", 51: "length of avcOUTNAME",
    129: "swap array length (the lidar block is read when it reaches record 2007)",
    2002: "lidar beams (3; the LIDAR kinds)", 2003: "lidar pulse gates (1)",
    2005: "beam 1 line-of-sight speed [m/s] (2006, 2007 beams 2, 3)"}

#: The swap records the library writes.
SWAP_WRITTEN: dict[int, str] = {
    35: "generator contactor (1)", 36: "shaft brake (0: off)",
    41: "yaw actuator torque demand (0)", 42: "blade 1 pitch demand [rad]",
    43: "blade 2 pitch demand [rad]", 44: "blade 3 pitch demand [rad]",
    45: "collective pitch demand (the blades' mean) [rad]",
    47: "generator torque demand [N m]", 48: "yaw rate demand (0)",
    55: "pitch override (0: off)", 56: "torque override (0: off)", 65: "logging channels (0)"}

#: The sources every library is built from: the Bladed entry point, the input file's reader,
#: the baseline law (every law's torque schedule) with its filters, the wind estimator.
COMMON_SOURCES = ("mpcwt_discon.h", "input.c", "baseline.c", "ibc.c", "windest.c", "discon.c")
#: The generated header that lists the laws a library holds (``MW_LAWS``).
_LAWS_HEADER = "mw_laws.h"
_DAQP = "daqp"
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
        A ServoDyn input file pointing at the library, from the OpenFAST deck the turbine was
        read from or the turbine's packaged one (None without either: see ``note``).
    dt : float
        The communication interval the design runs at [s] (ServoDyn's ``DLL_DT``).
    note : str
        What was not done and why (empty when everything was).
    inflow : Path or None
        For a LIDAR kind of a turbine read from an OpenFAST deck: a copy of the deck's
        InflowWind file with the single-point lidar the kind reads.
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
    inflow: Path | None = None

    def files(self) -> list[Path]:
        """Every file the export wrote: the input file, the library, the ServoDyn and
        InflowWind files (when made), the Makefile and the sources.

        Returns
        -------
        list of Path
        """
        made = [f for f in (self.library, self.servodyn, self.inflow) if f is not None]
        return [self.input_file, *made, self.makefile, *self.sources]


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
    stem = _stem(kind)
    if sys.platform == "win32":
        return stem + ".dll"
    return "lib" + stem + (".dylib" if sys.platform == "darwin" else ".so")


def _stem(kind: str) -> str:
    """The file stem of a kind's export (``mpcwt_baseline_lidar_ff``)."""
    return "mpcwt_" + kind.replace("-", "_").replace("+", "_")


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
    return "0" if v == 0.0 else repr(float(v))


def controller_input(controller: Any, export: LawExport, turbine: linearize.Turbine,
                     source: str = "", preview: Any = None) -> str:
    """The input file of an exported controller: every number of its design.

    Parameters
    ----------
    controller : object
        The designed controller (``Built.designed`` of :func:`mpc_wt.run.design_controller`).
    export : LawExport
        Its kind's export (:func:`mpc_wt.registry.law_export`).
    turbine : Turbine
        Its turbine (named in the header).
    source : str
        How it was designed (written as a comment).
    preview : LidarPreview, optional
        The design's LIDAR preview (``Built.preview``), for the LIDAR kinds.

    Returns
    -------
    str
        The file's text.

    Raises
    ------
    ValueError
        A controller the kind's law does not take (from its ``entries``), or a design number
        that is not finite (NaN or infinite gains), naming its key.
    """
    entries = export.entries(controller, preview)
    for k, v, doc in entries:
        bad = ~np.isfinite(np.asarray(v, float).ravel())
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(f"{export.name}: the design's '{k}' ({doc}) has "
                             f"{int(bad.sum())} value(s) that are not finite numbers (value "
                             f"{i + 1}: {np.asarray(v, float).ravel()[i]!r}); its library would "
                             f"refuse the file: the design is broken, make it again")
    from mpc_wt._version import __version__

    head = [f"# mpc-wt {__version__}: controller '{export.name}' for {turbine.name}",
            f"# {export.summary}",
            f"# exported {_dt.date.today().isoformat()}{'; ' + source if source else ''}",
            "# One entry per line: key value [value ...]; '#' starts a comment. Every number",
            "# here is read at the first call: change one and restart the simulation.",
            "format_version 1",
            f"kind {export.law}"]
    width = max(len(k) for k, v, _ in entries if np.ndim(v) == 0)
    body = []
    for k, v, doc in entries:
        if np.ndim(v) == 0:
            body.append(f"{k:<{width}} {_fmt(v):<24} # {doc}")
        else:
            body.append(f"# {k}: {doc} ({np.size(v)} values)")
            body.append(k + " " + " ".join(map(_fmt, np.asarray(v, float).ravel().tolist())))
    return "\n".join(head + body) + "\n"


def _source_names(directory: Path) -> list[str]:
    """An export's source files, relative to its folder: the common ones, the generated list
    of laws, the law's own (the other ``*.c`` files there), then the QP solver's (``daqp/``)."""
    own = sorted(p.name for p in directory.glob("*.c") if p.name not in COMMON_SOURCES)
    names = [*COMMON_SOURCES, _LAWS_HEADER, *own]
    qp = directory / _DAQP
    if qp.is_dir():
        names += sorted(f"{_DAQP}/{p.name}" for p in qp.iterdir()
                        if p.name.endswith((".c", ".h")))
    return names


def prepare_sources(export: LawExport) -> None:
    """Make sure the sources a kind's library is built from can be had: for a law that solves
    a QP, DAQP's C sources in the per-user cache (downloaded where they are not yet).

    Parameters
    ----------
    export : LawExport
        The kind's export.

    Raises
    ------
    SolverSourceError
        Neither cached nor downloadable; the message gives the command that fixes it.
    """
    if export.qp:
        from mpc_wt.io.solver_sources import daqp_sources

        daqp_sources()


def _copy_sources(directory: Path, export: LawExport) -> tuple[Path, ...]:
    """Write the kind's C sources into its export folder (the common ones, the law's, the
    list of laws the library holds); a QP law's come with DAQP's sources from its published
    distribution (:func:`mpc_wt.io.solver_sources.daqp_sources`)."""
    src = importlib.resources.files("mpc_wt.io") / "discon_c"
    own = {Path(n).name: Path(n) for n in export.sources}
    for stale in directory.glob("*.c"):         # an earlier export of another law
        if stale.name not in COMMON_SOURCES and stale.name not in own:
            stale.unlink()
    out = []
    for name in COMMON_SOURCES:
        target = directory / name
        target.write_text((src / name).read_text())
        out.append(target)
    for name, path in own.items():
        target = directory / name
        target.write_text(path.read_text() if path.is_absolute() else (src / name).read_text())
        out.append(target)
    laws = ["baseline"] + ([export.law] if export.law != "baseline" else [])
    header = directory / _LAWS_HEADER
    header.write_text("/* The control laws this library holds (written by mpc-wt's export): "
                      "each has its\n * constructor mw_<law>_new (mpcwt_discon.h). */\n"
                      f"#define MW_LAWS(X) {' '.join(f'X({law})' for law in laws)}\n")
    out.append(header)
    qp = directory / _DAQP
    if export.qp:
        from mpc_wt.io.solver_sources import daqp_sources

        out += daqp_sources().write(qp)
    elif qp.is_dir():
        shutil.rmtree(qp)
    return tuple(out)


def _c_files(directory: Path) -> list[str]:
    return [n for n in _source_names(directory) if n.endswith(".c")]


def _defines(directory: Path) -> list[str]:
    """The preprocessor's flags beyond ``-I.``: the QP solver's headers, where the folder has
    them."""
    return [f"-I{_DAQP}"] if any((directory / _DAQP).glob("*.h")) else []


def _makefile(directory: Path, lib: str) -> Path:
    srcs = " ".join(_c_files(directory))
    cppflags = " ".join(["-I.", *_defines(directory)])
    text = (f"# Builds {lib} with the system's C compiler (make CC=... to choose another).\n"
            f"CC ?= cc\nCFLAGS ?= {_CFLAGS}\nCPPFLAGS += {cppflags}\n"
            f"LDLIBS = -lm -lpthread\n\n"
            f"{lib}: {srcs} mpcwt_discon.h {_LAWS_HEADER}\n"
            f"\t$(CC) $(CPPFLAGS) $(CFLAGS) -shared -o $@ {srcs} $(LDLIBS)\n\n"
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
    flags += _defines(directory)            # relative to the folder, the compiler's cwd
    cmd = [cc, f"-I{directory}", *flags, "-shared", "-o", str(lib),
           *[str(directory / n) for n in _c_files(directory)], "-lm"]
    if sys.platform != "win32":
        cmd.append("-lpthread")
    key = _build_key(directory, cc, flags)
    if _reuse_build(key, lib):
        return lib
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=directory)
    if proc.returncode != 0 or not lib.is_file():
        raise ControllerLibraryError(
            f"building {lib.name} failed (exit {proc.returncode}): {' '.join(cmd)}\n"
            f"{proc.stderr.strip() or proc.stdout.strip()}")
    _BUILDS[key] = (lib, _digest(lib.read_bytes()))
    return lib


#: This process's builds: (compiler, flags, the sources' digest) -> (library, its digest)
_BUILDS: dict[tuple[str, ...], tuple[Path, str]] = {}


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _build_key(directory: Path, cc: str, flags: list[str]) -> tuple[str, ...]:
    """What a build depends on: the compiler, its flags and every source file's bytes."""
    src = b"".join(n.encode() + b"\0" + (directory / n).read_bytes() + b"\0"
                   for n in _source_names(directory) if n.endswith((".c", ".h")))
    return (cc, *flags, sys.platform, _digest(src))


def _reuse_build(key: tuple[str, ...], lib: Path) -> bool:
    """Copy an earlier build of the same sources with the same compiler and flags to ``lib``
    (compiling the same sources again gives the same library); False if there is none, or it
    was removed or changed since."""
    hit = _BUILDS.get(key)
    if hit is None or hit[0] == lib:
        return False
    try:
        data = hit[0].read_bytes()
    except OSError:
        data = b""
    if _digest(data) != hit[1]:
        del _BUILDS[key]
        return False
    tmp = lib.with_name(lib.name + ".part")     # a new file: a loaded library is not touched
    tmp.write_bytes(data)
    os.chmod(tmp, 0o755)
    os.replace(tmp, lib)
    log.debug("%s: the same sources were built as %s in this process; copied", lib, hit[0])
    return True


#: ServoDyn inputs of the packaged OpenFAST decks, by turbine name prefix.
#: This process's libraries of the shipped laws: (law, its sources, QP, compiler) -> the library
_SHIPPED: dict[tuple[Any, ...], Path] = {}
_INPUTS: dict[str, Path] = {}
_INPUT_DIR: list[Path] = []


def shipped_library(export: LawExport, *, compiler: str | None = None) -> Path:
    """The library a kind exports as, compiled once per machine and kept in the per-user cache
    (:func:`mpc_wt.io.solver_sources.cache_dir`, ``libraries/``): the law mpc-wt's own runs
    call, the same bytes a user's export builds.

    Parameters
    ----------
    export : LawExport
        The kind's export (the kinds of one law share its library).
    compiler : str, optional
        The C compiler (default :func:`find_compiler`).

    Returns
    -------
    Path
        The library, in a folder named by the build key of its sources, compiler and flags
        (:func:`shipped_law_key`); a new build where any of them changed.

    Raises
    ------
    ControllerLibraryError
        No C compiler, or the build failed.
    SolverSourceError
        A QP law whose solver's sources cannot be had.
    """
    import tempfile

    from mpc_wt.io.solver_sources import cache_dir

    cc = compiler or find_compiler()
    if cc is None:
        raise ControllerLibraryError(
            f"controller kind {export.name!r} runs its exported C law, and no C compiler was "
            f"found (looked for $CC, cc, gcc, clang): install one (e.g. build-essential, "
            f"Xcode's command line tools, MSYS2)")
    memo = (export.law, export.sources, export.qp, cc)
    if memo in _SHIPPED and _SHIPPED[memo].is_file():
        return _SHIPPED[memo]
    name = library_name(export.law)
    with tempfile.TemporaryDirectory(prefix="mpcwt_shipped_") as tmp:
        folder = Path(tmp)
        _copy_sources(folder, export)
        flags = _CFLAGS.split() + _defines(folder)
        key = _digest("\0".join(_build_key(folder, cc, flags)).encode())[:24]
        target = cache_dir() / "libraries" / key / name
        if not target.is_file():
            lib = build_library(folder, export.law, compiler=cc, name=name)
            target.parent.mkdir(parents=True, exist_ok=True)
            part = target.with_name(f"{name}.{os.getpid()}.part")
            shutil.copy2(lib, part)
            os.replace(part, target)      # whole or not at all, also for a parallel worker
            log.info("the %s law's library built and cached at %s", export.law, target)
    _SHIPPED[memo] = target
    return target


def shipped_law_key(export: LawExport, *, compiler: str | None = None) -> str:
    """What the library :func:`shipped_library` builds for ``export`` is made of: the digest of
    its C sources (the solver's too), the compiler and the flags that names its folder in the
    cache. Two runs whose keys are equal ran the same law; a campaign computes again the
    finished cases of a law whose key changed (:func:`mpc_wt.campaign.runner.check_designs`).

    Parameters
    ----------
    export : LawExport
    compiler : str, optional
        The C compiler (default :func:`find_compiler`).

    Returns
    -------
    str
        24 hex digits.

    Raises
    ------
    ControllerLibraryError, SolverSourceError
        As :func:`shipped_library` (the library is built if it is not there).
    """
    return shipped_library(export, compiler=compiler).parent.name


def shipped_input(controller: Any, export: LawExport, turbine: linearize.Turbine,
                  preview: Any = None) -> Path:
    """A designed controller's input file for its library (:func:`controller_input`), written
    once per content into a folder kept for this process.

    Parameters
    ----------
    controller : object
        The design (of the type its kind builds).
    export : LawExport
        Its kind's export.
    turbine : Turbine
        Its turbine.
    preview : LidarPreview, optional
        The design's LIDAR preview (the LIDAR kinds).

    Returns
    -------
    Path
        The input file.
    """
    import atexit
    import tempfile

    text = controller_input(controller, export, turbine, "the design mpc-wt runs", preview)
    key = _digest(text.encode())
    hit = _INPUTS.get(key)
    if hit is not None and hit.is_file():
        return hit
    if not _INPUT_DIR or not _INPUT_DIR[0].is_dir():
        d = Path(tempfile.mkdtemp(prefix="mpcwt_inputs_"))
        atexit.register(shutil.rmtree, d, ignore_errors=True)
        _INPUT_DIR[:] = [d]
    path = _INPUT_DIR[0] / f"{_stem(export.name)}_{key[:16]}.in"
    path.write_text(text)
    _INPUTS[key] = path
    return path


def _user_deck(turbine: linearize.Turbine) -> Path | None:
    """The OpenFAST deck (main file) the turbine was read from, if it was."""
    src = Path(str(getattr(turbine, "source", "") or ""))
    return src if src.suffix.lower() == ".fst" and src.is_file() else None


def _deck_servodyn(turbine: linearize.Turbine) -> Path | None:
    deck = _user_deck(turbine)
    if deck is not None:
        from linearize.openfast import OpenFASTFile

        p = OpenFASTFile(deck).file("ServoFile")
        return p if p is not None and p.is_file() else None
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


def lidar_geometry(input_file: str | Path) -> tuple[float, float] | None:
    """The LIDAR an exported library reads: cos(cone) and the focus distance [m] of its input
    file's ``lidar`` (MPC) or ``ff`` (feedforward) key, where it turns one on; else None.

    Parameters
    ----------
    input_file : str or Path
        The export's input file.

    Returns
    -------
    (float, float) or None
    """
    text = Path(input_file).read_text()
    if re.search(r"^(feedforward|lidar_preview)\s+1\b", text, re.M) is None:
        return None
    m = re.search(r"^(?:lidar|ff)\s+(\S+)\s+(\S+)", text, re.M)
    return None if m is None else (float(m.group(1)), float(m.group(2)))


def lidar_inflow(input_file: str | Path, inflow: str | Path, out: str | Path,
                 dt: float) -> Path | None:
    """A copy of an InflowWind file with the lidar an exported LIDAR kind reads; None for a
    kind that reads no LIDAR.

    Five single points on its design's ring, the focus distance D upwind at r = D tan(cone)
    (:func:`mpc_wt.io.openfast_run.lidar_points`,
    :func:`mpc_wt.io.openfast_run.write_lidar_inflow`).

    Parameters
    ----------
    input_file : str or Path
        The export's input file (:func:`lidar_geometry`).
    inflow : str or Path
        The deck's InflowWind file (not written to).
    out : str or Path
        The copy's path.
    dt : float
        ``MeasurementInterval`` [s] (the library's ``DLL_DT``).

    Returns
    -------
    Path or None
    """
    from mpc_wt.io.openfast_run import lidar_points, write_lidar_inflow

    geo = lidar_geometry(input_file)
    if geo is None:
        return None
    cos_cone, focus = geo
    return write_lidar_inflow(inflow, out, lidar_points(focus, focus * math.tan(
        math.acos(cos_cone))), dt)


def _lidar_inflow(turbine: linearize.Turbine, input_file: Path, out: Path, dt: float,
                  notes: list[str]) -> Path | None:
    """For a LIDAR kind exported for a turbine read from an OpenFAST deck: :func:`lidar_inflow`
    on the deck's InflowWind file (a note where it cannot be made)."""
    if lidar_geometry(input_file) is None:
        return None
    deck = _user_deck(turbine)
    if deck is None:
        notes.append("the LIDAR kind needs a single-point lidar in InflowWind: see the docs' "
                     "'LIDAR kinds in OpenFAST' for the lines")
        return None
    from linearize.openfast import OpenFASTFile

    iw = OpenFASTFile(deck).file("InflowFile")
    if iw is None or not iw.is_file():
        notes.append(f"the deck {deck} names no InflowWind file: write its lidar yourself")
        return None
    return lidar_inflow(input_file, iw, out, dt)


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


def export_controller(controller: Any, export: LawExport, turbine: linearize.Turbine,
                      out: str | Path, *, build: bool = True, compiler: str | None = None,
                      source: str = "", preview: Any = None) -> DisconExport:
    """Export a designed controller object as a Bladed-style library
    (:func:`mpc_wt.run.export_discon` designs a kind and calls this,
    :func:`mpc_wt.run.export_controller` takes a controller and its kind's name).

    Parameters
    ----------
    controller : object
        The controller (of the type its kind builds).
    export : LawExport
        Its kind's export.
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
    preview : LidarPreview, optional
        The design's LIDAR preview (the LIDAR kinds).

    Returns
    -------
    DisconExport
    """
    dt = float(getattr(controller, "dt"))
    directory = Path(out)
    directory.mkdir(parents=True, exist_ok=True)
    text = controller_input(controller, export, turbine, source, preview)
    stem = _stem(export.name)
    input_file = directory / f"{stem}.in"
    input_file.write_text(text)
    sources = _copy_sources(directory, export)
    lib_name = library_name(export.name)
    makefile = _makefile(directory, lib_name)
    notes = []
    library = None
    if build:
        if find_compiler() is None and compiler is None:
            notes.append("no C compiler found ($CC, cc, gcc, clang): the sources and Makefile "
                         "are written; run 'make' where a compiler is installed")
        else:
            library = build_library(directory, export.name, compiler=compiler)
    template = _deck_servodyn(turbine)
    servodyn = None
    if template is None:
        where = (f"the deck {_user_deck(turbine)} names no ServoDyn file" if _user_deck(turbine)
                 else f"no OpenFAST deck is packaged for {turbine.name}")
        notes.append(f"{where}: set DLL_FileName, DLL_InFile, DLL_ProcName and DLL_DT in your "
                     f"ServoDyn file yourself")
    else:
        servodyn = servodyn_input(template, directory / f"ServoDyn_{stem}.dat",
                                  directory / lib_name, input_file, dt)
    inflow = _lidar_inflow(turbine, input_file, directory / f"InflowWind_{stem}.dat", dt, notes)
    for n in notes:
        log.warning("%s", n)
    return DisconExport(kind=export.name, directory=directory, input_file=input_file,
                        sources=sources, makefile=makefile, library=library,
                        servodyn=servodyn, dt=dt, note="; ".join(notes), inflow=inflow)


def export_design(doc: Mapping[str, Any], export: LawExport, turbine: linearize.Turbine,
                  out: str | Path, *, build: bool = True,
                  compiler: str | None = None) -> DisconExport:
    """Export a saved baseline design (a gain-table document of ``mpcwt design baseline``) as
    a library (:func:`mpc_wt.run.export_saved_design` finds the kind's export).

    Parameters
    ----------
    doc : mapping
        The design document (:func:`mpc_wt.io.gain_tables.load_design`).
    export : LawExport
        The baseline kind's export.
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
        A design that is not a baseline's.
    """
    from mpc_wt.controllers.baseline import BaselineController, BaselineGains

    kind = doc.get("kind")
    if kind != "baseline":
        raise ValueError(f"a {kind!r} design does not export as a DISCON library from its "
                         f"gain table (mpcwt design baseline does; mpc_wt.run.export_discon "
                         f"exports a registered kind from its options)")
    s = doc["settings"]
    gains = BaselineGains(kp=s["kp"], ki=s["ki"], theta_k_rad=s["theta_k_rad"], k_opt=s["k_opt"],
                          rated_gen_speed_rad_s=s["rated_gen_speed_rad_s"],
                          rated_torque=s["rated_torque"], rated_power=s["rated_power"],
                          dpdtheta_0=math.nan, omega_n_rad_s=s.get("omega_n_rad_s", 0.6),
                          zeta=s.get("zeta", 0.7), power_fraction=s.get("power_fraction", 1.0),
                          min_pitch_speeds=tuple(s.get("min_pitch_speeds_rad_s", ())),
                          min_pitch_offsets=tuple(s.get("min_pitch_offsets_rad", ())))
    ctl = BaselineController(turbine, gains)
    return export_controller(ctl, export, turbine, out, build=build, compiler=compiler,
                             source=f"from the design of omega_n {gains.omega_n_rad_s:g} rad/s, "
                                    f"zeta {gains.zeta:g}, power fraction "
                                    f"{gains.power_fraction:g}")


def signal_codes(signals: Sequence[str], who: str) -> np.ndarray:
    """The library's codes of an estimator's measured signals (:data:`SIGNAL_CODES`).

    Parameters
    ----------
    signals : sequence of str
        The measured signals, in order.
    who : str
        The estimator (named in the error).

    Returns
    -------
    ndarray
        The codes, as the input file holds them.

    Raises
    ------
    ValueError
        A signal the library does not read.
    """
    unknown = [s for s in signals if s not in SIGNAL_CODES]
    if unknown:
        raise ValueError(f"the {who} measures {unknown}, which the library does not read from "
                         f"the swap array (it reads {sorted(SIGNAL_CODES)})")
    return np.array([SIGNAL_CODES[s] for s in signals], float)

