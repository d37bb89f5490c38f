"""The exported MPC's QP solver comes from DAQP's published source distribution: checked
against the digest the package index lists, cached per user, refused when changed, and a
clear one-line error with the fixing command where it cannot be had. The peer for the sources
is the ``daqp`` wheel the Python design solves with: the archive's release is the wheel's."""
from __future__ import annotations

import importlib.metadata
import io
import tarfile
from pathlib import Path

import pytest

from mpc_wt.cli import main
from mpc_wt.errors import SolverSourceError
from mpc_wt.io import solver_sources as ss


@pytest.fixture(scope="module")
def archive() -> Path:
    """The real archive, fetched into the suite's cache once (by pip, from the index)."""
    return ss.daqp_sources().archive


@pytest.fixture()
def empty_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("MPCWT_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _fake_archive(path: Path, members: dict[str, bytes]) -> Path:
    with tarfile.open(path, "w:gz") as tar:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    return path


def test_the_sources_are_the_wheels_release_and_the_index_digest(archive: Path) -> None:
    """The recorded digest is the one PyPI lists for daqp-0.11.0.tar.gz (copied from the
    index's page, https://pypi.org/project/daqp/0.11.0/#files), and the release is the
    installed wheel's, so the library's QP is the design's."""
    assert ss.DAQP_SDIST_SHA256["0.11.0"] == \
        "2f27baf18d2acca14186498e651b34e0bed455627e777d3fd8ba655e7e40f920"
    assert importlib.metadata.version("daqp") == ss.DAQP_VERSION
    src = ss.daqp_sources(download=False)
    assert {"api.c", "daqp.c", "api.h", "types.h", "LICENSE"} <= set(src.files)
    assert b"MIT License" in src.files["LICENSE"]
    assert src.c_files == sorted(n for n in src.files if n.endswith(".c"))


def test_an_archive_carried_over_by_hand_is_checked_and_cached(archive: Path,
                                                               empty_cache: Path) -> None:
    with pytest.raises(SolverSourceError, match=r"not in the cache .*mpcwt solver fetch"):
        ss.daqp_sources(download=False)
    assert main(["solver", "fetch", "--from", str(archive)]) == 0
    got = ss.daqp_sources(download=False)
    assert got.archive.parent == empty_cache / "solvers" and got.archive.is_file()


def test_an_archive_of_another_digest_is_refused(tmp_path: Path, empty_cache: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """An archive that looks like DAQP's but is not the published one: refused with both
    digests named, nothing cached; the command exits 2 with one line."""
    fake = _fake_archive(tmp_path / "daqp-0.11.0.tar.gz",
                         {"daqp-0.11.0/csrc/src/api.c": b"int x;\n",
                          "daqp-0.11.0/csrc/include/api.h": b"\n"})
    with pytest.raises(SolverSourceError, match=r"SHA-256 [0-9a-f]{64}, not the 2f27baf1"):
        ss.install_daqp_archive(fake)
    assert main(["solver", "fetch", "--from", str(fake)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "refused" in err
    assert not (empty_cache / "solvers" / "daqp-0.11.0.tar.gz").exists()
    with pytest.raises(SolverSourceError, match="is not a file"):
        ss.install_daqp_archive(tmp_path / "missing.tar.gz")
    with pytest.raises(SolverSourceError, match=r"version '0\.1' has no recorded digest"):
        ss.daqp_sources("0.1")


def test_a_cache_changed_since_is_refused(archive: Path, empty_cache: Path) -> None:
    cached = ss.install_daqp_archive(archive)
    cached.write_bytes(cached.read_bytes()[:-100])          # truncated
    with pytest.raises(SolverSourceError, match="delete it and run 'mpcwt solver fetch'"):
        ss.daqp_sources(download=False)


def test_offline_without_a_cache_the_export_stops_before_designing(
        empty_cache: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """No index (pip told to use none) and an empty cache: the MPC's export stops at once with
    pip's reason and the command that fixes it; the baseline's export needs no solver."""
    import linearize
    from mpc_wt.run import export_discon

    monkeypatch.setenv("PIP_NO_INDEX", "1")
    monkeypatch.setenv("PIP_FIND_LINKS", str(tmp_path / "no-links"))
    turbine = linearize.load_turbine("nrel5mw")
    with pytest.raises(SolverSourceError, match=r"with pip failed \(.*daqp==0\.11\.0.*\): run "
                                                r"'mpcwt solver fetch'"):
        export_discon(turbine, "mpc", tmp_path / "mpc", build=False)
    assert not (tmp_path / "mpc").exists()                  # nothing designed or written
    ex = export_discon(turbine, "baseline", tmp_path / "baseline", build=False)
    assert not (ex.directory / "mpc.c").exists() and not (ex.directory / "daqp").exists()


def test_status_names_the_cache_and_the_state(archive: Path, empty_cache: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["solver", "status"]) == 0
    assert "missing" in capsys.readouterr().out
    ss.install_daqp_archive(archive)
    assert main(["solver", "status", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"state": "cached"' in out and str(empty_cache) in out
