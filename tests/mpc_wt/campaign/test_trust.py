"""Reading a campaign runs none of its code: ``mpcwt campaign report`` and ``status`` of a
campaign whose spec names a plugin do not import the plugin (a module that leaves a marker file
when imported), where ``mpcwt campaign run`` does."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

PLUGIN = textwrap.dedent('''
    """A plugin that leaves a marker when it is imported."""
    import os
    from pathlib import Path

    Path(os.environ["MPCWT_TEST_MARKER"]).write_text("imported")
''')


def _cli(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    code = f"from mpc_wt.cli import main; raise SystemExit(main({args!r}))"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=300)


def test_report_and_status_do_not_import_the_specs_plugins(tmp_path: Path) -> None:
    (tmp_path / "plug").mkdir()
    (tmp_path / "plug" / "trust_plugin.py").write_text(PLUGIN)
    marker = tmp_path / "imported.txt"
    spec = tmp_path / "spec.yaml"
    spec.write_text(textwrap.dedent("""
        name: trust
        duration: 10
        transient: 0
        winds: [18]
        seeds: 1
        turbulence: steady
        plugins: [trust_plugin]
        controllers: [baseline]
        channels: {tower_base_fa_moment: 4}
    """))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(tmp_path / "plug"), os.environ.get("PYTHONPATH", "")]),
        "MPCWT_TEST_MARKER": str(marker)}
    camp = tmp_path / "camp"
    run = _cli(["campaign", "run", str(spec), "--out", str(camp), "--engine", "serial"], env)
    assert run.returncode == 0, run.stderr[-2000:]
    assert marker.read_text() == "imported"           # running a spec runs its plugins
    marker.unlink()
    for args in (["campaign", "report", str(camp)], ["campaign", "status", str(camp)]):
        done = _cli(args, env)
        assert done.returncode == 0, done.stderr[-2000:]
        assert not marker.exists(), f"{args[1]} imported the spec's plugin"
    assert "baseline" in (camp / "report" / "report.md").read_text()


@pytest.mark.parametrize("opts", [{"extra_pitch_deg": "a"}])
def test_a_stored_specs_unknown_kind_is_read_as_given(opts) -> None:
    """Without importing plugins, a kind the registry does not know is a plugin's: its
    options are kept as given, not checked; with the import asked for, the plugin must be
    importable."""
    from mpc_wt.campaign import SpecError, spec_from_dict

    raw = {"name": "p", "winds": [18], "seeds": 1, "plugins": ["not_imported_here"],
           "controllers": [{"name": "h", "controller": "some-plugin-kind", **opts}]}
    spec = spec_from_dict(raw, import_plugins=False)
    assert spec.controllers[0].options == opts
    with pytest.raises(SpecError, match="plugins"):
        spec_from_dict(raw)


def _inc(x: int) -> int:
    return x + 1


def test_the_local_cluster_is_closed_to_other_clients() -> None:
    """The campaigns' local Dask cluster speaks TLS with certificates of its own: its client
    runs a task; a client without them (another process attaching to the address, over TLS or
    plain TCP) is refused; the scheduler serves no dashboard page on the loopback interface."""
    import gc
    import urllib.error
    import urllib.request

    distributed = pytest.importorskip("distributed")
    import dask

    from mpc_wt.campaign.runner import local_cluster

    cluster = local_cluster(1)
    try:
        addr = cluster.scheduler_address
        assert addr.startswith("tls://127.0.0.1:")
        with distributed.Client(cluster) as client:
            assert client.submit(_inc, 1).result(timeout=60) == 2
        for other in (addr, addr.replace("tls://", "tcp://")):
            # a client that fails to connect leaves Dask's config naming its scheduler: the
            # outer setting restores this process's
            with dask.config.set(scheduler="sync"), pytest.raises(Exception):
                distributed.Client(other, timeout="5s")
            # the failed client is collected here: collected while the next one starts its
            # event loop, its __del__ stops that loop under the loop's own lock (the suite
            # hung once in that deadlock inside distributed 2026.8)
            gc.collect()
        ports = [s.getsockname()[1] for s in cluster.scheduler.http_server._sockets.values()]
        assert ports and 8787 not in ports
        for port in ports:
            with pytest.raises(urllib.error.HTTPError) as err:
                urllib.request.urlopen(f"http://127.0.0.1:{port}/status", timeout=5)
            assert err.value.code == 404
    finally:
        cluster.close()


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0,
                    reason="making a file of another user needs root")
def test_a_spec_another_user_wrote_runs_only_with_trust(tmp_path: Path, capsys) -> None:
    """A spec file owned by another user (uid 65534) is refused before any of it runs, naming
    the file and its owner; ``--trust`` runs it; a plugin beside the spec that another user
    wrote is named too."""
    from mpc_wt.cli import main

    spec = tmp_path / "spec.yaml"
    spec.write_text("name: foreign\nduration: 10\ntransient: 0\nwinds: [12]\nseeds: 1\n"
                    "turbulence: steady\ncontrollers: [baseline]\n")
    os.chown(spec, 65534, 65534)
    argv = ["campaign", "run", str(spec), "--out", str(tmp_path / "c"), "--engine", "serial",
            "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{spec}: written by another user: {spec} (owner uid 65534)" in err
    assert "--trust" in err and not (tmp_path / "c").exists()
    assert main(argv + ["--trust"]) == 0
    os.chown(spec, 0, 0)
    (tmp_path / "their_plugin.py").write_text("x = 1\n")
    os.chown(tmp_path / "their_plugin.py", 65534, 65534)
    spec.write_text(spec.read_text() + "plugins: [their_plugin]\n")
    assert main(argv) == 2
    assert "their_plugin.py (owner uid 65534)" in capsys.readouterr().err


def test_plugins_and_libraries_are_resolved_beside_the_spec_and_named(tmp_path: Path,
                                                                      monkeypatch) -> None:
    """A spec whose plugin module sits beside it and whose library path is relative to it runs
    from another folder (neither on Python's path nor the working folder), and the index names
    the plugin's file and the library with its SHA-256."""
    import hashlib
    import shutil as sh

    from mpc_wt.campaign import CampaignStore, load_spec, run_campaign

    cc = sh.which("gcc") or sh.which("cc")
    if cc is None:
        pytest.skip("no C compiler")
    home = tmp_path / "study"
    (home / "lib").mkdir(parents=True)
    subprocess.run([cc, "-shared", "-fPIC", "-O1", "-o", str(home / "lib" / "libprobe.so"),
                    str(Path(__file__).parents[2] / "data" / "discon_probe.c")], check=True)
    (home / "PROBE.IN").write_text("x\n")
    (home / "beside_plugin.py").write_text('"""registers nothing"""\nVALUE = 42\n')
    (home / "spec.yaml").write_text(textwrap.dedent("""
        name: beside
        duration: 10
        transient: 0
        winds: [12]
        seeds: 1
        turbulence: steady
        plugins: [beside_plugin]
        controllers:
          - {name: probe, controller: discon, discon_library: lib/libprobe.so,
             discon_in: PROBE.IN}
    """))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    spec = load_spec(home / "spec.yaml")
    assert spec.controllers[0].options["discon_library"] == str(home / "lib" / "libprobe.so")
    s = run_campaign(spec, elsewhere / "camp", engine="serial", progress=False)
    assert s.done == 1, s.failures
    with CampaignStore(elsewhere / "camp") as st_:
        code = st_.meta()["code"]
    assert code["plugins"] == {"beside_plugin": str(home / "beside_plugin.py")}
    lib = home / "lib" / "libprobe.so"
    assert code["libraries"] == {str(lib): hashlib.sha256(lib.read_bytes()).hexdigest()}


def test_the_index_names_roscos_library_with_its_checksum() -> None:
    """The ``rosco`` kind runs the rosco package's library: the code the index names."""
    import hashlib

    from mpc_wt.campaign import spec_from_dict
    from mpc_wt.campaign.runner import spec_code
    from mpc_wt.controllers.discon import rosco_library

    spec = spec_from_dict({"name": "r", "winds": [12], "seeds": 1,
                           "controllers": [{"name": "r", "controller": "rosco"}, "baseline"]})
    lib = rosco_library()
    assert spec_code(spec) == {"plugins": {}, "libraries": {
        str(lib): hashlib.sha256(lib.read_bytes()).hexdigest()}}
