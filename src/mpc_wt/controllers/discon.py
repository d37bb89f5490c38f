"""A host for Bladed-style controller libraries (``DISCON``), ROSCO's included, through ctypes.

The interface is the one OpenFAST's ServoDyn and Bladed call: ``DISCON(avrSWAP, aviFAIL,
accINFILE, avcOUTNAME, avcMSG)`` with a float32 swap array whose records the host fills with
measurements and settings before each call and from which it reads the demands after it
(Bladed User Manual, appendix A; the records as ServoDyn fills them, :data:`SWAP_RECORDS`).
``avrSWAP(1)`` is the status: 0 on the first call, 1 on every later one, -1 on the last.

Each :class:`DisconController` runs the library in a child process of its own, started anew
for every run (:mod:`mpc_wt.controllers.discon_child`): a library that calls ``exit()``, aborts
or crashes ends that process, and the run fails with the library's last output as its reason
while the simulation's process goes on. Libraries keep their state in globals (ROSCO refuses a
second initialization, "This ROSCO dynamic library has already been loaded"), which a fresh
process also gives. With ``isolate=False`` the library is loaded in the simulation's process
instead (a private copy of the file per controller): faster per call, but nothing contains it.
"""
from __future__ import annotations

import contextlib
import ctypes
import logging
import math
import mmap
import os
import select
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from lidar import PointLidar
from mpc_wt.controllers.base import ControllerBase
from mpc_wt.controllers.discon_kernel import library_call
from mpc_wt.errors import ControllerLibraryError

__all__ = ["DisconController", "SWAP_RECORDS", "SWAP_SIZE", "LIDAR_RECORDS", "LOG_ROOM",
           "LOG_START", "rosco_library", "rosco_discon"]

log = logging.getLogger(__name__)

#: Length of the swap array: the Bladed records, ROSCO's extended block from 1001, and room for
#: the logging channels a library may return.
SWAP_SIZE = 3300

#: The longest a library in a child process may take for one call, or to load [s]: ROSCO's
#: calls take microseconds and its first call, which reads its input file, milliseconds.
CALL_TIMEOUT_S = 30.0
_MSG_LEN = 1025
_OUT_LEN = 4097
#: Records the host writes (1-based, as the interface numbers them) -> what they hold.
SWAP_RECORDS = {
    1: "status: 0 first call, 1 running, -1 last call",
    2: "current time [s]", 3: "communication interval [s]",
    4: "blade 1 pitch angle [rad]", 5: "below-rated pitch set-point (fine pitch) [rad]",
    6: "minimum pitch [rad]", 7: "maximum pitch [rad]", 8: "minimum pitch rate [rad/s]",
    9: "maximum pitch rate [rad/s]", 10: "0 = pitch position actuator",
    11: "current demanded pitch [rad]", 13: "demanded power [W]",
    14: "measured shaft power [W]", 15: "measured electrical power [W]",
    17: "minimum generator speed [rad/s]", 18: "optimal-mode maximum speed [rad/s]",
    19: "demanded generator speed above rated [rad/s]",
    20: "measured generator speed [rad/s]", 21: "measured rotor speed [rad/s]",
    22: "demanded generator torque above rated [N m]",
    23: "measured generator torque [N m]", 24: "measured yaw error [rad]",
    27: "hub wind speed [m/s]", 28: "pitch control: 0 collective, 1 individual",
    29: "yaw control: 0 rate", 30: "blade 1 root out-of-plane moment [N m]",
    31: "blade 2 root out-of-plane moment [N m]", 32: "blade 3 root out-of-plane moment [N m]",
    33: "blade 2 pitch angle [rad]", 34: "blade 3 pitch angle [rad]",
    35: "generator contactor (the library's last value, first 1)",
    37: "nacelle yaw from North [rad]", 49: "length of the message buffer",
    50: "length of INFILE incl. NUL", 51: "length of OUTNAME incl. NUL",
    53: "tower-top fore-aft acceleration [m/s^2]",
    54: "tower-top side-side acceleration [m/s^2]", 60: "rotor azimuth [rad]",
    61: "number of blades", 62: "maximum logging channels", 63: "start of logging records",
    64: "length of the OUTNAME buffer", 66: "start of the platform-motion block (1001)",
    69: "blade 1 root in-plane moment [N m]", 70: "blade 2 root in-plane moment [N m]",
    71: "blade 3 root in-plane moment [N m]", 75: "fixed-frame hub tilt moment [N m]",
    76: "fixed-frame hub yaw moment [N m]", 95: "air density [kg/m^3]",
    109: "low-speed-shaft torque [N m]", 110: "rotor thrust [N]", 129: "swap array length",
}
#: The logging channels the host offers a library (record 62) and where they start (63).
LOG_ROOM, LOG_START = 12, 165
#: OpenFAST's lidar block of the extended swap array (ServoDyn's BladedInterface_EX: records
#: 2001-2500), as :class:`DisconController` fills it from a CW LIDAR with three beams.
LIDAR_RECORDS = {
    2001: "sensor type (2: continuous-wave)", 2002: "number of beams (3)",
    2003: "number of pulse gates (1)", 2004: "reference mean wind (0, unset as in OpenFAST)",
    2005: "beam 1 line-of-sight speed, positive toward the LIDAR [m/s]",
    2006: "beam 2 line-of-sight speed [m/s]", 2007: "beam 3 line-of-sight speed [m/s]",
    2008: "beams 1-3 focus point x, upwind of the hub [m] (2008-2010)",
    2011: "beams 1-3 focus point y from the hub [m] (2011-2013)",
    2014: "beams 1-3 focus point z from the hub [m] (2014-2016)"}


def rosco_library() -> Path:
    """The compiled ROSCO controller of the ``rosco`` package (``pip install mpc-wt[rosco]``).

    Returns
    -------
    Path

    Raises
    ------
    ControllerLibraryError
        If the package or its library is not installed.
    """
    try:
        import rosco
    except ImportError:
        raise ControllerLibraryError("the rosco package is not installed; pip install "
                                     "'mpc-wt[rosco]' (it ships ROSCO's libdiscon)") from None
    lib_dir = Path(rosco.__file__).parent / "lib"
    names = {"linux": "libdiscon.so", "darwin": "libdiscon.dylib", "win32": "libdiscon.dll"}
    path = lib_dir / names.get(sys.platform, "libdiscon.so")
    if not path.is_file():
        raise ControllerLibraryError(f"{path}: ROSCO's library is not in the rosco package "
                                     f"(found {sorted(p.name for p in lib_dir.glob('*'))})")
    return path


def rosco_discon(turbine_name: str = "NREL-5MW") -> Path:
    """A ``DISCON.IN`` shipped with the ``rosco`` package's examples.

    Parameters
    ----------
    turbine_name : str
        ``"NREL-5MW"`` (default) or ``"IEA-15-240-RWT"``.

    Returns
    -------
    Path
    """
    cases = rosco_library().parents[2] / "Examples" / "Test_Cases"
    files = {"NREL-5MW": cases / "NREL-5MW" / "DISCON.IN",
             "IEA-15-240-RWT": cases / "IEA-15-240-RWT" / "IEA-15-240-RWT-Monopile"
             / "IEA-15-240-RWT-Monopile_DISCON.IN"}
    if turbine_name not in files:
        raise ValueError(f"turbine_name must be one of {sorted(files)}, got {turbine_name!r}")
    return files[turbine_name]


def _check_library(path: Path) -> None:
    if not path.is_file():
        raise ControllerLibraryError(f"controller library {path}: file not found")
    with path.open("rb") as fh:
        head = fh.read(20)
    magic = {"linux": b"\x7fELF", "darwin": (b"\xcf\xfa\xed\xfe", b"\xca\xfe\xba\xbe"),
             "win32": b"MZ"}.get(sys.platform, b"\x7fELF")
    magics = magic if isinstance(magic, tuple) else (magic,)
    if not any(head.startswith(m) for m in magics):
        raise ControllerLibraryError(
            f"controller library {path}: not a shared library for this platform "
            f"({sys.platform}); its first bytes are {head[:4]!r}, expected {magics[0]!r}")
    if sys.platform == "linux" and len(head) >= 20:
        machine = int.from_bytes(head[18:20], "little")
        want = {"x86_64": 62, "aarch64": 183, "i686": 3, "i386": 3}.get(os.uname().machine)
        if want is not None and machine != want:
            raise ControllerLibraryError(
                f"controller library {path}: built for ELF machine {machine}, this machine is "
                f"{os.uname().machine} (ELF machine {want})")


_PRELOADED: set[str] = set()


def _dependency_libs(original: Path) -> list[Path]:
    """The libraries a wheel bundles beside ``original`` ($ORIGIN-relative RPATH, e.g. ROSCO's
    ``rosco.libs/libgfortran-*.so``), which a copy of ``original`` elsewhere (or a child
    process) must load first to find them by their sonames."""
    import re

    data = original.read_bytes()
    dirs = []
    for m in re.finditer(rb"\$(?:ORIGIN|\{ORIGIN\})([^\x00:]*)", data):
        rest = m.group(1).decode(errors="ignore").lstrip("/")
        d = (original.parent / rest).resolve()
        if d.is_dir() and d != original.parent.resolve():
            dirs.append(d)
    return [f for d in dirs for f in sorted(d.iterdir()) if ".so" in f.name]


def _preload_dependencies(original: Path) -> None:
    """Load :func:`_dependency_libs` of ``original`` once, globally, in this process. Only
    these runtime dependencies are shared between copies; the controller's own globals are
    not."""
    # unbuffered Fortran units, so that a quiet controller's redirect catches what is printed
    os.environ.setdefault("GFORTRAN_UNBUFFERED_PRECONNECTED", "y")
    libs = [f for f in _dependency_libs(original) if str(f) not in _PRELOADED]
    for _ in range(3):                       # dependencies among them: retry in passes
        left = []
        for f in libs:
            try:
                ctypes.CDLL(str(f), mode=getattr(ctypes, "RTLD_GLOBAL", 0))
                _PRELOADED.add(str(f))
            except OSError:
                left.append(f)
        if not left or len(left) == len(libs):
            break
        libs = left


_CHILD = Path(__file__).with_name("discon_child.py")


def _read_exact(fd: int, n: int) -> bytes | None:
    """``n`` bytes from ``fd``, or None when the other end closed first."""
    parts, got = [], 0
    while got < n:
        chunk = os.read(fd, n - got)
        if not chunk:
            return None
        parts.append(chunk)
        got += len(chunk)
    return b"".join(parts)


class _ChildLibrary:
    """A controller library loaded in a child process (:mod:`.discon_child`); what it prints
    goes to a log whose last lines become the reason when it ends its process."""

    def __init__(self, library: Path, infile: str, outname: str,
                 timeout: float = 0.0) -> None:
        self.library = library
        self.timeout = float(timeout)
        self.alive = True
        fd, self.log = tempfile.mkstemp(prefix="mpcwt_discon_", suffix=".log")
        os.close(fd)
        fd, shared = tempfile.mkstemp(prefix="mpcwt_discon_", suffix=".swap")
        try:
            os.ftruncate(fd, SWAP_SIZE * 4)
            self._mem = mmap.mmap(fd, SWAP_SIZE * 4)
        finally:
            os.close(fd)
        self._swap = np.frombuffer(self._mem, dtype=np.float32)
        env = {**os.environ, "GFORTRAN_UNBUFFERED_PRECONNECTED": "y"}
        self.proc = subprocess.Popen(
            [sys.executable, "-I", str(_CHILD), str(library), self.log, shared, infile, outname,
             str(SWAP_SIZE), str(_MSG_LEN), str(_OUT_LEN),
             *(str(f) for f in _dependency_libs(library))],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env)
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self._w, self._r = self.proc.stdin.fileno(), self.proc.stdout.fileno()
        self._wait("to load")
        head = _read_exact(self._r, 2)
        with contextlib.suppress(OSError):       # both have it mapped (or the child failed)
            os.unlink(shared)
        if head == b"NO":
            n = struct.unpack("<i", _read_exact(self._r, 4) or b"\0\0\0\0")[0]
            why = (_read_exact(self._r, n) or b"").decode(errors="replace")
            self.close()
            if "DISCON" in why and "undefined symbol" in why:
                raise ControllerLibraryError(f"controller library {library}: no symbol "
                                             f"'DISCON' (not a Bladed-style controller)")
            raise ControllerLibraryError(f"controller library {library}: cannot be loaded: "
                                         f"{why}")
        if head != b"OK":
            raise self.died("while it was loaded")

    def call(self, view: np.ndarray, t: float) -> tuple[int, str]:
        """One call: the swap array into the shared map, a byte to the child, its
        ``aviFAIL`` and message back, the swap array out of the map."""
        self._swap[:] = view
        try:
            os.write(self._w, b"c")
        except OSError:                               # a broken pipe: the child has gone
            raise self.died(f"at t = {t:g} s") from None
        self._wait(f"its call at t = {t:g} s")
        head = _read_exact(self._r, 8)
        if head is None:
            raise self.died(f"at t = {t:g} s")
        fail, n = struct.unpack("<ii", head)
        text = _read_exact(self._r, n) if n else b""
        if text is None:
            raise self.died(f"at t = {t:g} s")
        view[:] = self._swap
        return fail, text.decode(errors="replace").strip()

    def _wait(self, what: str) -> None:
        """Wait for the child's answer at most ``timeout`` s (0: forever); a library that
        blocks or loops is stopped and named."""
        if self.timeout <= 0:
            return
        ready, _, _ = select.select([self._r], [], [], self.timeout)
        if ready:
            return
        self.proc.kill()
        self.proc.wait()
        self.close()
        raise ControllerLibraryError(
            f"controller library {self.library.name} did not answer {what} within "
            f"{self.timeout:g} s (call_timeout): it blocks or loops; it was stopped")

    def died(self, when: str) -> ControllerLibraryError:
        """The error for a child that ended: its exit status or signal and its last output."""
        try:
            code = self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
        how = (f"killed by signal {-code} ({_signal_name(-code)})" if code < 0
               else f"exit status {code}")
        try:
            tail = Path(self.log).read_text(errors="replace").strip().splitlines()[-5:]
        except OSError:
            tail = []
        last = " | ".join(tail)[-600:] or "(nothing printed)"
        self.close()
        return ControllerLibraryError(f"controller library {self.library.name} ended its "
                                      f"process {when} ({how}); its last output: {last}")

    def close(self) -> None:
        """End the child (its standard input closed; killed if it does not stop) and remove
        its log."""
        self.alive = False
        if self.proc.poll() is None:
            try:
                self.proc.stdin.close()          # type: ignore[union-attr]
                self.proc.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait()
        for f in (self.proc.stdin, self.proc.stdout):
            try:
                f.close()                         # type: ignore[union-attr]
            except OSError:
                pass
        with contextlib.suppress(OSError):
            os.unlink(self.log)
        self._swap = np.empty(0, np.float32)      # release the map's buffer, then close it
        with contextlib.suppress(BufferError, ValueError):
            self._mem.close()


def _output_records() -> tuple[np.ndarray, np.ndarray]:
    """The swap records (0-based) :meth:`DisconController._fill` takes from the plant's
    outputs, and those outputs' indices (:data:`linearize.OUTPUT_NAMES`): the rest of its
    records (status, time, last pitch demand, hub wind) the compiled loop writes itself."""
    import linearize

    z = {n: i for i, n in enumerate(linearize.OUTPUT_NAMES)}
    pairs = [(3, 1), (32, 2), (33, 3), (13, z["aero_power"]), (14, z["gen_power"]),
             (19, z["gen_speed"]), (20, z["rotor_speed"]), (22, z["gen_torque"]),
             (29, 10), (30, 11), (31, 12), (68, 13), (69, 14), (70, 15),
             (52, z["tower_fa_acceleration"]), (53, z["tower_ss_acceleration"]),
             (59, z["azimuth"]), (74, z["tilt_moment"]), (75, z["yaw_moment"]),
             (108, z["lss_torque"]), (109, z["thrust"])]
    return (np.array([r for r, _ in pairs], np.int64), np.array([i for _, i in pairs], np.int64))


def _signal_name(num: int) -> str:
    import signal

    try:
        return signal.Signals(num).name
    except ValueError:
        return "unknown"


class DisconController(ControllerBase):
    """Run a Bladed-style controller library in mpc-wt's closed loop.

    Parameters
    ----------
    library : str or Path
        The shared library exporting ``DISCON``.
    discon_in : str or Path
        Its input file (passed as ``accINFILE``; ROSCO's ``DISCON.IN``).
    turbine : Turbine
        For the settings records (pitch and speed limits, rated values, air density).
    dt : float
        Communication interval [s] (``avrSWAP(3)``); the harness must call at this period.
    pitch_control : {"individual", "collective"}
        ``avrSWAP(28)``: individual (read records 42-44; ROSCO needs it for IPC) or collective
        (record 45 for all blades).
    workdir : str or Path, optional
        Where the library may write its own files (``.dbg``, ...); its ``OUTNAME`` is
        ``workdir/root_name.SrvD``, as OpenFAST's ServoDyn names it (ROSCO strips the extension
        and writes ``root_name.RO.dbg``, ``.RO.dbg2``, ...; without one the C string's NUL
        stays in its root and every debug file opens the same path). Default: a temporary
        folder removed by :meth:`finalize`.
    root_name : str
        The simulation root name given to the library.
    quiet : bool
        In this process (``isolate=False``): send what the library prints on the process's
        standard output (ROSCO's banner and status lines) to the null device during its calls
        (default). In a child process what it prints goes to a temporary log, whose last
        lines become the reason if it ends its process. Its ``aviFAIL`` messages are kept
        either way.
    lidar : lidar.LidarSensor or lidar.PointLidar, optional
        A hub-mounted CW LIDAR (bound to the case's wind by the simulator) whose measurement
        fills OpenFAST's lidar records (:data:`LIDAR_RECORDS`): taken at the instrument's sample
        rate and held between samples, as a LIDAR delivers them. Or InflowWind's single-point
        lidar, bound to the case's wind (:class:`lidar.PointLidar`): the records as OpenFAST v5
        fills them (its type 1, the points' ``|V|`` and positions), taken where the time is an
        exact multiple of its interval.
    isolate : bool
        Run the library in a child process, a new one per run (default): a library that ends
        its process fails the run with its exit status and last output instead of ending the
        simulation's process. False loads it in this process (a private copy per controller;
        faster per call, uncontained).
    log_names : tuple of str
        The names of the logging channels the library returns (record 65 counts them, their
        values from record :data:`LOG_START` on), recorded as signals; a channel without a
        name is ``log_<i>``. The host offers :data:`LOG_ROOM` of them (record 62).
    call_timeout : float
        In a child process: the longest a call (and the loading) may take [s] before the
        library is stopped and the run fails naming it (default :data:`CALL_TIMEOUT_S`; 0:
        no limit). In this process a call cannot be stopped.

    Raises
    ------
    ControllerLibraryError
        If the library or input file does not exist, is not a library for this machine, or has
        no ``DISCON`` symbol.
    """

    def __init__(self, library: str | Path, discon_in: str | Path, turbine: Any, *,
                 dt: float = 1.0 / 80.0, pitch_control: str = "individual",
                 workdir: str | Path | None = None, root_name: str = "mpcwt_discon",
                 quiet: bool = True, lidar: Any = None, isolate: bool = True,
                 log_names: tuple[str, ...] = (),
                 call_timeout: float = CALL_TIMEOUT_S) -> None:
        self.library = Path(library).resolve()
        self.discon_in = Path(discon_in).resolve()
        _check_library(self.library)
        if not self.discon_in.is_file():
            raise ControllerLibraryError(f"controller input file {self.discon_in}: file not "
                                         f"found")
        if pitch_control not in ("individual", "collective"):
            raise ValueError(f"pitch_control must be 'individual' or 'collective', got "
                             f"{pitch_control!r}")
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be finite and > 0 s, got {dt!r}")
        self.turbine, self.dt, self.pitch_control = turbine, float(dt), pitch_control
        self._tq_hi = float(turbine.generator.max_torque)
        self._p_lo = float(turbine.pitch_actuator.min_pitch_rad)
        self._p_hi = float(turbine.pitch_actuator.max_pitch_rad)
        self._own_workdir = workdir is None
        self.workdir = Path(workdir) if workdir is not None else None
        self.root_name = root_name
        self.quiet = quiet
        self.lidar = lidar
        self.isolate = bool(isolate)
        self.log_names = tuple(log_names)
        if not (math.isfinite(call_timeout) and call_timeout >= 0):
            raise ValueError(f"call_timeout must be a finite number of seconds >= 0 (0: no "
                             f"limit), got {call_timeout!r}")
        self.call_timeout = float(call_timeout)
        self._fds: tuple[int, int] | None = None
        self._lib: Any = None
        self._fast: tuple[Any, ...] | None = None
        self._copy_dir: str | None = None
        self._swap = (ctypes.c_float * SWAP_SIZE)()
        self._view = np.frombuffer(self._swap, dtype=np.float32)
        self.signals: dict[str, float] = {}
        self.messages: list[str] = []
        self._status = 0
        self._warned = False
        if self.isolate:                     # fail early on a bad library, in a child
            _ChildLibrary(self.library, str(self.discon_in), "mpcwt_check",
                          self.call_timeout).close()
        else:
            self._load()

    def design_identity(self) -> tuple[Any, ...]:
        """What the library runs, for a design's digest
        (:func:`mpc_wt.registry.context.design_digest`): the library's bytes and its input
        file's text (not the folders they sit in), the interval, the pitch control and the
        logging channels' names.

        Returns
        -------
        tuple
            SHA-256 of the library, the input file's text, dt, pitch control, channel names.
        """
        import hashlib

        lib = hashlib.sha256(self.library.read_bytes()).hexdigest()
        return (lib, self.discon_in.read_text(errors="replace"), self.dt, self.pitch_control,
                self.log_names)

    # -- library lifetime --------------------------------------------------------------------
    def _load(self) -> None:
        self._unload()
        self._copy_dir = tempfile.mkdtemp(prefix="mpcwt_discon_")
        copy = Path(self._copy_dir) / self.library.name
        shutil.copy2(self.library, copy)
        _preload_dependencies(self.library)
        try:
            lib = ctypes.CDLL(str(copy), mode=getattr(ctypes, "RTLD_LOCAL", 0))
        except OSError as err:
            self._unload()
            raise ControllerLibraryError(f"controller library {self.library}: cannot be "
                                         f"loaded: {err}") from err
        try:
            fn = lib.DISCON
        except AttributeError:
            self._unload()
            raise ControllerLibraryError(f"controller library {self.library}: no symbol "
                                         f"'DISCON' (not a Bladed-style controller)") from None
        fn.restype = None
        fn.argtypes = [ctypes.POINTER(ctypes.c_float), ctypes.POINTER(ctypes.c_int),
                       ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p]
        self._lib, self._fn = lib, fn

    def _unload(self) -> None:
        self._fast = None                    # its DISCON goes with the library
        if isinstance(self._lib, _ChildLibrary):
            self._lib.close()
            self._lib = None
        if self._lib is not None:
            handle = self._lib._handle
            self._lib = None
            try:
                import _ctypes
                (getattr(_ctypes, "dlclose", None) or getattr(_ctypes, "FreeLibrary"))(handle)
            except (OSError, AttributeError):
                pass
        if self._copy_dir is not None:
            shutil.rmtree(self._copy_dir, ignore_errors=True)
            self._copy_dir = None

    def reset(self) -> None:
        """A fresh copy of the library (its globals start over) and the first-call status."""
        if not self.isolate and (self._lib is None or self._status != 0):
            self._load()
        if self._own_workdir:
            if self.workdir is not None:        # a run that was never finalized
                shutil.rmtree(self.workdir, ignore_errors=True)
            self.workdir = Path(tempfile.mkdtemp(prefix="mpcwt_discon_run_"))
        assert self.workdir is not None
        self.workdir.mkdir(parents=True, exist_ok=True)
        self._view[:] = 0.0
        self._view[34] = 1.0                 # record 35: generator contactor on
        self._status = 0
        self._last_pitch = np.full(3, self.turbine.operation.fine_pitch_rad)
        self._last_torque = 0.0
        self._lidar_next = -math.inf
        self._lidar_pending: Any = None
        self._settings()
        if self.isolate:                     # a new process: the library's globals start over
            self._unload()
            self._lib = _ChildLibrary(self.library, self._infile.decode(),
                                      self._outname.decode(), self.call_timeout)
        self.messages = []
        self.signals = {}
        # the step's compiled call (the closed loop's own): a library in this process
        self._fast = None
        self._fast = self.compiled_library()     # built anew: this copy's DISCON
        self._cmd, self._hub = np.zeros(5 + LOG_ROOM), np.zeros(1)

    def finalize(self) -> None:
        """The library's last call (status -1), then unload it; its files stay in
        ``workdir`` when one was given."""
        if self._lib is not None and self._status == 1 and getattr(self._lib, "alive", True):
            self._view[0] = -1.0
            try:
                self._call(float(self._view[1]))
            except ControllerLibraryError as err:    # the run is over: report, do not raise
                self.messages.append(str(err))
                log.warning("%s", err)
        self._status = -1
        self._unload()
        if self._fds is not None:
            for fd in self._fds:
                os.close(fd)
            self._fds = None
        if self._own_workdir and self.workdir is not None:
            shutil.rmtree(self.workdir, ignore_errors=True)
            self.workdir = None

    def __del__(self) -> None:  # pragma: no cover - interpreter shutdown order varies
        try:
            self._unload()
            if self._own_workdir and self.workdir is not None:
                shutil.rmtree(self.workdir, ignore_errors=True)
        except Exception:  # noqa: BLE001
            pass

    # -- one call ----------------------------------------------------------------------------
    def _settings(self) -> None:
        """The records that do not change during a run, and the string buffers."""
        tb = self.turbine
        op, pa, dr = tb.operation, tb.pitch_actuator, tb.drivetrain
        n = dr.gearbox_ratio
        assert self.workdir is not None
        self._infile = str(self.discon_in).encode()
        self._outname = str(self.workdir / (self.root_name + ".SrvD")).encode()
        fixed = {3: self.dt, 5: op.fine_pitch_rad, 6: pa.min_pitch_rad, 7: pa.max_pitch_rad,
                 8: -pa.max_rate_rad_s, 9: pa.max_rate_rad_s, 10: 0.0, 13: op.rated_power,
                 17: op.min_rotor_speed_rad_s * n, 18: op.rated_rotor_speed_rad_s * n,
                 19: op.rated_rotor_speed_rad_s * n, 22: tb.rated_generator_torque, 24: 0.0,
                 28: 1.0 if self.pitch_control == "individual" else 0.0, 29: 0.0, 37: 0.0,
                 49: float(_MSG_LEN), 50: float(len(self._infile) + 1),
                 51: float(len(self._outname) + 1), 61: 3.0, 62: float(LOG_ROOM),
                 63: float(LOG_START), 64: float(_OUT_LEN), 66: 1001.0,
                 95: tb.environment.air_density, 129: float(SWAP_SIZE)}
        self._view[np.array(list(fixed)) - 1] = np.array(list(fixed.values()), np.float32)
        self._msg = ctypes.create_string_buffer(_MSG_LEN)
        self._out = ctypes.create_string_buffer(_OUT_LEN)

    #: records filled from the measurements at each call, in the order of ``_fill``'s list
    _DYNAMIC = np.array([1, 2, 4, 33, 34, 11, 14, 15, 20, 21, 23, 27, 30, 31, 32, 69, 70, 71,
                         53, 54, 60, 75, 76, 109, 110]) - 1

    def _fill_lidar(self, t: float, meas: dict[str, Any]) -> None:
        """The lidar records from the LIDAR's measurement at the rotor's azimuth and speed, when
        a sample is due (held in between)."""
        if t < self._lidar_next - 1e-9:
            return
        self.sample_lidar(t, float(meas["azimuth"]), float(meas["rotor_speed"]))

    def sample_lidar(self, t: float, azimuth: float, rotor_speed: float) -> float:
        """Write the LIDAR's sample at time ``t`` to the lidar records (the compiled loop asks
        for it when one is due).

        Parameters
        ----------
        t : float
            The sample's time [s].
        azimuth : float
            The rotor's azimuth [rad, 0-2 pi].
        rotor_speed : float
            The rotor's speed [rad/s].

        Returns
        -------
        float
            When the next sample is due [s].
        """
        if isinstance(self.lidar, PointLidar):
            return self._sample_points(t)
        self._lidar_next = t + 1.0 / self.lidar.instrument.sample_rate
        m = self.lidar.measure(np.array([t]), np.array([azimuth]), rotor_speed)
        ang = m.beam_azimuth_rad[0]
        r = m.radius
        v = self._view
        v[2000:2004] = (2.0, 3.0, 1.0, 0.0)
        v[2004:2007] = m.los[0]
        v[2007:2010] = self.lidar.focus_distance
        v[2010:2013] = -r * np.sin(ang)
        v[2013:2016] = r * np.cos(ang)
        return self._lidar_next

    def _sample_points(self, t: float) -> float:
        """InflowWind's single points as ServoDyn hands them to a library: measured where the
        time is an exact multiple of the interval (:meth:`lidar.PointLidar.due`), the last
        values held in between, and a call sees the measurement of the call before it (the
        first call its own): in OpenFAST v5.0.0's regression case with a 0.1 s interval and
        DLL_DT, a logging library's records at t equal InflowWind's sample at t - 0.1 s."""
        pl = self.lidar
        pending = self._lidar_pending
        now = pl.records(t) if pl.due(t) or pending is None else None
        rec = now if pending is None else pending
        self._view[2000:2000 + rec.size] = rec
        self._lidar_pending = now if now is not None else rec
        self._lidar_next = t + 0.5 * self.dt  # at every call
        return self._lidar_next

    def _fill(self, t: float, meas: dict[str, Any]) -> None:
        if self.lidar is not None:
            self._fill_lidar(t, meas)
        g = meas.get
        p, f, e = meas["pitch"], meas["flap_moment"], meas["edge_moment"]
        self._view[self._DYNAMIC] = (
            self._status, t, p[0], p[1], p[2], self._last_pitch[0], g("aero_power", 0.0),
            g("gen_power", 0.0), meas["gen_speed"], meas["rotor_speed"],
            g("gen_torque", self._last_torque), g("hub_wind_speed", 0.0), f[0], f[1], f[2],
            e[0], e[1], e[2], g("tower_fa_acceleration", 0.0), g("tower_ss_acceleration", 0.0),
            g("azimuth", 0.0), g("tilt_moment", 0.0), g("yaw_moment", 0.0),
            g("lss_torque", 0.0), g("thrust", 0.0))
        if self._status == 0:                # ServoDyn's first call (library_call's)
            self._view[[10, 14, 22]] = (p[0], 0.0, 0.0)

    def _call(self, t: float) -> None:
        if isinstance(self._lib, _ChildLibrary):
            fail_value, text = self._lib.call(self._view, t)
            self._report(t, fail_value, text)
            return
        fail = ctypes.c_int(0)
        self._msg[0] = b"\0"
        ctypes.memmove(self._out, self._outname + b"\0", len(self._outname) + 1)
        with self.quiet_calls():
            self._fn(self._swap, ctypes.byref(fail), self._infile, self._out, self._msg)
        self._report(t, fail.value, self._msg.value.decode(errors="replace").strip())

    def _report(self, t: float, fail: int, text: str) -> None:
        """The library's ``aviFAIL``: < 0 stops the run with its message, > 0 is a warning."""
        self._warned = fail > 0
        if fail == 0:
            return
        if fail < 0:
            raise ControllerLibraryError(
                f"controller library {self.library.name} stopped the run at t = {t:g} s "
                f"(aviFAIL = {fail}): {text or '(no message)'}")
        if text:
            self.messages.append(f"t = {t:g} s: {text}")
            log.warning("%s at t = %g s: %s", self.library.name, t, text)

    # -- the closed loop compiled with the plant ----------------------------------------------
    def compiled_library(self) -> tuple[Any, ...] | None:
        """What the closed loop compiled with the plant needs to call the library itself
        (:func:`mpc_wt.simulation.compiled.run_library_steps`), after :meth:`reset`: ``DISCON``,
        the swap array, ``aviFAIL``, the string buffers (input file, OUTNAME, message, OUTNAME's
        text), the records filled from the plant's outputs and those outputs' indices, and the
        host's state (status, last pitch demand, individual pitch, pitch limits, largest
        torque). None where the loop cannot: a library in a child process. A LIDAR's records
        the loop leaves to :meth:`sample_lidar`.

        Returns
        -------
        tuple or None
            The same arrays as :meth:`step` calls through until the next :meth:`reset`, with
            the host's status and last pitch demand as they stand.
        """
        if self.isolate or self._lib is None:
            return None
        if self._fast is not None:
            self._fast[6][0], self._fast[6][1] = float(self._status), float(self._last_pitch[0])
            return self._fast
        bufs = np.zeros((4, _OUT_LEN), np.uint8)
        bufs[0, :len(self._infile)] = np.frombuffer(self._infile, np.uint8)
        bufs[3, :len(self._outname)] = np.frombuffer(self._outname, np.uint8)
        lib = np.array([float(self._status), float(self._last_pitch[0]),
                        1.0 if self.pitch_control == "individual" else 0.0, self._p_lo,
                        self._p_hi, self._tq_hi, 0.0, 0.0])
        rec, zi = _output_records()
        fn = self._lib["DISCON"]                  # its own function object, pointer arguments
        fn.restype, fn.argtypes = None, [ctypes.c_void_p] * 5
        return (fn, self._view, np.zeros(1, np.int32), bufs, rec, zi, lib)

    def compiled_report(self, t: float, call: tuple[Any, ...], finite: bool = True) -> None:
        """The compiled call's word from the library at time ``t``: its ``aviFAIL`` and message
        (as :meth:`step` reports them: a warning logged and kept, a stop raised), or demands
        that are not finite.

        Parameters
        ----------
        t : float
            The call's time [s].
        call : tuple
            :meth:`compiled_library`'s arrays, as the call left them.
        finite : bool
            False: the call's demands were not finite (the call's flag 2).

        Raises
        ------
        ControllerLibraryError
            If the library stopped the run (``aviFAIL < 0``) or its demands are not finite.
        """
        if not finite:
            v = call[1]
            raise ControllerLibraryError(
                f"controller library {self.library.name} returned pitch {v[41:44].tolist()} "
                f"rad, torque {float(v[46])} N m at t = {t:g} s")
        if call[2][0] == 0:
            self._warned = False
            return
        msg = bytes(call[3][2]).split(b"\0", 1)[0].decode(errors="replace").strip()
        self._report(t, int(call[2][0]), msg)

    def adopt_compiled_state(self, call: tuple[Any, ...], signals: np.ndarray) -> None:
        """Take the state a compiled run left, so the host reads as if :meth:`step` had run
        (the last call, :meth:`finalize`, then follows as usual).

        Parameters
        ----------
        call : tuple
            :meth:`compiled_library`'s arrays, as the loop left them.
        signals : (4 + n,) ndarray
            The last call's signals (pitch command, torque command, contactor, warning, the
            ``n`` logging channels).
        """
        lib = call[6]
        self._status = int(lib[0])
        if self._status == 0:
            return
        v = self._view
        p = v[41:44].tolist() if lib[2] else [float(v[44])] * 3
        self._last_pitch = np.array([lib[1], *p[1:]])
        self._last_torque = float(signals[1])
        self.signals = {"pitch_command": float(signals[0]), "torque_command": float(signals[1]),
                        "generator_contactor": float(signals[2]),
                        "library_warning": float(signals[3])}
        self.signals.update(zip(self.compiled_signals(call)[4:], map(float, signals[4:])))

    def compiled_signals(self, call: tuple[Any, ...]) -> list[str]:
        """The names of the compiled loop's signal columns: the host's four, then the logging
        channels the library returned.

        Parameters
        ----------
        call : tuple
            :meth:`compiled_library`'s arrays, as the loop left them.

        Returns
        -------
        list of str
        """
        return ["pitch_command", "torque_command", "generator_contactor", "library_warning",
                *self._log_keys(int(call[6][6]))]

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        """Fill the swap array, call the library, read its demands.

        Parameters
        ----------
        t : float
            Time of the call, written to record 2 [s].
        meas : dict
            The harness's measurements, written to the records of :data:`SWAP_RECORDS`.

        Returns
        -------
        pitch_ref : (3,) ndarray
            Records 42-44 (individual) or 45 (collective) [rad].
        gen_torque_ref : float
            Record 47 [N m]; zero while the library opens the generator contactor (record 35).

        Raises
        ------
        ControllerLibraryError
            If the library sets ``aviFAIL < 0``; the message is the library's. A warning
            (``aviFAIL > 0``) is logged, kept in :attr:`messages` and marked in the signal
            ``library_warning`` (1 at that step), and its demands apply.
        """
        if self._lib is None:
            raise ControllerLibraryError(f"controller library {self.library.name}: step() "
                                         f"before reset() or after finalize()")
        if self._fast is not None and "outputs" in meas:
            return self._step_compiled(t, meas)
        self._fill(t, meas)
        self._call(t)
        self._status = 1
        v = self._view
        # scalar arithmetic: numpy calls on three values cost more than the library's step
        if self.pitch_control == "individual":
            p = v[41:44].tolist()
        else:
            p = [float(v[44])] * 3
        contactor = float(v[34])
        torque = float(v[46]) if contactor != 0.0 else 0.0
        # the swap array is float32: a demand at a limit may sit one rounding step beyond it
        hi = self._tq_hi
        if hi < torque <= hi * (1 + 1e-6):
            torque = hi
        lo_p, hi_p = self._p_lo, self._p_hi
        for i in range(3):
            if lo_p - 1e-6 <= p[i] < lo_p:
                p[i] = lo_p
            elif hi_p < p[i] <= hi_p + 1e-6:
                p[i] = hi_p
        if not (math.isfinite(p[0] + p[1] + p[2]) and math.isfinite(torque)):
            raise ControllerLibraryError(
                f"controller library {self.library.name} returned pitch {p} rad, torque "
                f"{torque} N m at t = {t:g} s")
        pitch = np.array(p)
        self._last_pitch, self._last_torque = pitch, torque
        n = max(min(int(v[64]), LOG_ROOM), 0)
        self._set_signals(p, torque, contactor, v[LOG_START - 1:LOG_START - 1 + n].tolist())
        return pitch, torque

    def _step_compiled(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        """:meth:`step` through the compiled call (:func:`~mpc_wt.controllers.discon_kernel.library_call`)
        on the plant's output row ``meas["outputs"]``: the same records, demands and signals."""
        call, cmd = self._fast, self._cmd
        lib = call[6]
        lib[0], lib[1] = float(self._status), float(self._last_pitch[0])
        self._hub[0] = meas.get("hub_wind_speed", 0.0)
        if self.lidar is not None:
            self._fill_lidar(t, meas)
        with self.quiet_calls():
            flag = library_call(0, t, meas["outputs"], *call[:6], self._hub, lib, cmd)
        self.compiled_report(t, call, flag != 2)     # raises for aviFAIL < 0
        self._status = 1
        p = cmd[:3].tolist()
        torque = float(cmd[3])
        self._last_pitch, self._last_torque = np.array(p), torque
        self._set_signals(p, torque, float(cmd[4]), cmd[5:5 + int(lib[7])].tolist())
        return np.array(p), torque

    def _set_signals(self, p: list[float], torque: float, contactor: float,
                     logs: list[float]) -> None:
        """The host's signals of a call: the demands, the contactor, a warning, the library's
        logging channels."""
        self.signals = {"pitch_command": (p[0] + p[1] + p[2]) / 3.0,
                        "torque_command": torque, "generator_contactor": contactor,
                        "library_warning": float(self._warned)}
        if logs:
            self.signals.update(zip(self._log_keys(len(logs)), logs))

    @contextlib.contextmanager
    def quiet_calls(self) -> Any:
        """The library's standard output to the null device while in this block, when the
        host is ``quiet`` (its calls, or a compiled loop's block of them).

        Returns
        -------
        context manager
            Restores standard output on leaving.
        """
        if not self.quiet:
            yield
            return
        if self._fds is None:
            sys.stdout.flush()
            self._fds = (os.open(os.devnull, os.O_WRONLY), os.dup(1))
        os.dup2(self._fds[0], 1)
        try:
            yield
        finally:
            os.dup2(self._fds[1], 1)

    def _log_keys(self, n: int) -> list[str]:
        """The signal names of ``n`` logging channels."""
        return [self.log_names[i] if i < len(self.log_names) else f"log_{i + 1}"
                for i in range(n)]
