"""The C sources of the QP solver an exported MPC library is built with, taken from the
solver's published distribution: DAQP's source distribution on the package index
(``daqp-<version>.tar.gz``, whose ``csrc/`` holds DAQP's C library), checked against the
SHA-256 digest recorded here and kept in a per-user cache.

The first MPC export downloads the archive with pip (``pip download --no-deps --no-binary
:all: daqp==<version>``, so the user's index, proxy and certificates apply); later exports,
offline ones included, read it from the cache. Every use checks the archive's digest again, so
a cache that was changed or truncated is refused, not built. Where there is neither a network
nor a cached archive, :func:`daqp_sources` raises a :class:`~mpc_wt.errors.SolverSourceError`
whose one line gives the command that fixes it (``mpcwt solver fetch``, or ``mpcwt solver
fetch --from FILE`` for an archive carried over by hand).

The cache is ``$MPCWT_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/mpc-wt`` (Linux's default
``~/.cache/mpc-wt``), ``~/Library/Caches/mpc-wt`` on macOS, ``%LOCALAPPDATA%\\mpc-wt`` on
Windows.
"""
from __future__ import annotations

import dataclasses
import hashlib
import logging
import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

from mpc_wt.errors import SolverSourceError

__all__ = ["DAQP_VERSION", "DAQP_SDIST_SHA256", "SolverSources", "cache_dir", "daqp_sources",
           "fetch_daqp", "install_daqp_archive"]

log = logging.getLogger(__name__)

#: The DAQP release whose C sources the exported MPC is built with: the release of the
#: ``daqp`` wheel the Python design solves its QP with (``pyproject.toml`` pins it), so the
#: library and the design run the same solver.
DAQP_VERSION = "0.11.0"

#: SHA-256 of DAQP's source distributions on the package index (the digest PyPI lists for
#: ``daqp-0.11.0.tar.gz``). An archive with another digest is refused.
DAQP_SDIST_SHA256: dict[str, str] = {
    "0.11.0": "2f27baf18d2acca14186498e651b34e0bed455627e777d3fd8ba655e7e40f920",
}

_FIX = "run 'mpcwt solver fetch' where the package index can be reached, or 'mpcwt solver " \
       "fetch --from daqp-{v}.tar.gz' with the archive copied from a machine that has it"


@dataclasses.dataclass(frozen=True)
class SolverSources:
    """A QP solver's C sources, read from its verified archive.

    Parameters
    ----------
    name : str
        The solver (``daqp``).
    version : str
        Its release.
    archive : Path
        The verified source distribution in the cache.
    files : dict of str to bytes
        The sources by their name in an export's solver folder (``api.c``, ``types.h``, ...,
        ``LICENSE``): every ``csrc/src/*.c``, ``csrc/include/*.h`` and the licence.
    """
    name: str
    version: str
    archive: Path
    files: dict[str, bytes]

    @property
    def c_files(self) -> list[str]:
        """The sources to compile, sorted."""
        return sorted(n for n in self.files if n.endswith(".c"))

    def write(self, directory: str | Path) -> tuple[Path, ...]:
        """Write the sources into ``directory`` (created).

        Parameters
        ----------
        directory : path
            The export's solver folder.

        Returns
        -------
        tuple of Path
            The files written.
        """
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        out = []
        for name in sorted(self.files):
            (d / name).write_bytes(self.files[name])
            out.append(d / name)
        return tuple(out)


def cache_dir() -> Path:
    """The per-user cache of mpc-wt (created on first use).

    Returns
    -------
    Path
        ``$MPCWT_CACHE_DIR``, else the platform's per-user cache folder with ``mpc-wt``.
    """
    env = os.environ.get("MPCWT_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "mpc-wt"


def _archive_path(version: str) -> Path:
    return cache_dir() / "solvers" / f"daqp-{version}.tar.gz"


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _check_version(version: str) -> str:
    if version not in DAQP_SDIST_SHA256:
        raise SolverSourceError(f"DAQP version {version!r} has no recorded digest; the "
                                f"releases mpc-wt builds with: {sorted(DAQP_SDIST_SHA256)}")
    return DAQP_SDIST_SHA256[version]


def install_daqp_archive(archive: str | Path, version: str = DAQP_VERSION) -> Path:
    """Check a DAQP source distribution against its recorded digest and put it in the cache.

    Parameters
    ----------
    archive : path
        ``daqp-<version>.tar.gz`` as the package index serves it.
    version : str
        Its release.

    Returns
    -------
    Path
        The archive in the cache.

    Raises
    ------
    SolverSourceError
        The file is missing, or its digest is not the recorded one.
    """
    want = _check_version(version)
    src = Path(archive)
    if not src.is_file():
        raise SolverSourceError(f"archive {str(src)!r} is not a file; expected DAQP's source "
                                f"distribution daqp-{version}.tar.gz")
    got = _sha256(src)
    if got != want:
        raise SolverSourceError(f"archive {str(src)!r} has SHA-256 {got}, not the {want} of "
                                f"daqp-{version}.tar.gz on the package index: refused")
    target = _archive_path(version)
    target.parent.mkdir(parents=True, exist_ok=True)
    if src.resolve() != target.resolve():
        # a new file renamed into place: an export reading the cache meanwhile sees the old
        # archive or the new one, never half of one
        fd, tmp = tempfile.mkstemp(dir=target.parent, suffix=".part")
        with os.fdopen(fd, "wb") as f:
            f.write(src.read_bytes())
        os.replace(tmp, target)
    log.info("DAQP %s's source distribution checked (sha256 %s) and cached at %s", version, want,
             target)
    return target


def fetch_daqp(version: str = DAQP_VERSION, *, timeout: float = 300.0) -> Path:
    """Download DAQP's source distribution with pip into the cache (checked by its digest).

    Parameters
    ----------
    version : str
        The release.
    timeout : float
        How long pip may take [s].

    Returns
    -------
    Path
        The archive in the cache.

    Raises
    ------
    SolverSourceError
        pip could not download it (offline, no index), or it is not the recorded archive.
    """
    _check_version(version)
    with tempfile.TemporaryDirectory(prefix="mpcwt-daqp-") as tmp:
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", ":all:",
               "--disable-pip-version-check", "--quiet", "-d", tmp, f"daqp=={version}"]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except (OSError, subprocess.TimeoutExpired) as err:
            raise SolverSourceError(f"downloading daqp-{version}.tar.gz failed ({err}): "
                                    + _FIX.format(v=version)) from err
        found = list(Path(tmp).glob(f"daqp-{version}.tar.gz"))
        if proc.returncode != 0 or not found:
            why = (proc.stderr or proc.stdout).strip().splitlines()
            raise SolverSourceError(f"downloading daqp-{version}.tar.gz with pip failed "
                                    f"({why[-1] if why else f'exit {proc.returncode}'}): "
                                    + _FIX.format(v=version))
        return install_daqp_archive(found[0], version)


def _read_archive(path: Path, version: str) -> dict[str, bytes]:
    """The C library's sources and the licence from a verified archive."""
    top = f"daqp-{version}/"
    files: dict[str, bytes] = {}
    with tarfile.open(path, "r:gz") as tar:
        for m in tar.getmembers():
            if not m.isfile() or not m.name.startswith(top):
                continue
            rel = m.name[len(top):]
            parent, _, name = rel.rpartition("/")
            keep = (parent == "csrc/src" and name.endswith(".c")) or \
                   (parent == "csrc/include" and name.endswith(".h")) or rel == "LICENSE"
            if keep:
                f = tar.extractfile(m)
                if f is not None:
                    files[name] = f.read()
    if not any(n.endswith(".c") for n in files) or "api.h" not in files:
        raise SolverSourceError(f"archive {str(path)!r} holds no DAQP C library (csrc/src, "
                                f"csrc/include): not DAQP's source distribution")
    return files


def daqp_sources(version: str = DAQP_VERSION, *, download: bool = True) -> SolverSources:
    """DAQP's C sources for an export: from the cache, downloaded first where it has none.

    Parameters
    ----------
    version : str
        The release (:data:`DAQP_VERSION`).
    download : bool
        Download the archive with pip when the cache has none (:func:`fetch_daqp`).

    Returns
    -------
    SolverSources

    Raises
    ------
    SolverSourceError
        No archive in the cache and none could be downloaded, or the cached archive's digest
        is not the recorded one; the message gives the command that fixes it.
    """
    want = _check_version(version)
    path = _archive_path(version)
    if not path.is_file():
        if not download:
            raise SolverSourceError(f"DAQP {version}'s C sources are not in the cache ({path}): "
                                    + _FIX.format(v=version))
        path = fetch_daqp(version)
    got = _sha256(path)
    if got != want:
        raise SolverSourceError(f"the cached {path} has SHA-256 {got}, not the recorded {want}: "
                                f"delete it and " + _FIX.format(v=version))
    return SolverSources("daqp", version, path, _read_archive(path, version))
