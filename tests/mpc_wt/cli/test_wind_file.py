"""A case on the user's own wind: ``mpcwt simulate --wind-file`` on a TurbSim .bts runs every
controller kind; the plant starts from the trim at the rotor-disc mean of the file's first 5 s;
bad files and flags are named."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import lidar
import linearize
from mpc_wt.cli import main
from mpc_wt.controllers.discon import rosco_discon, rosco_library
from mpc_wt.registry.registry import kinds
from mpc_wt.simulation.results import ClosedLoopResult
from mpc_wt.simulation.scenario import Scenario, field_spec, start_wind

#: extra flags of the kinds that require an option
REQUIRED = {"apc": ["--apc-frequency", "0.05"],
            "discon": ["--discon-library", str(rosco_library()), "--discon-in",
                       str(rosco_discon())]}


@pytest.fixture(scope="module")
def bts(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """45 s of class B turbulence at 15 m/s written as a TurbSim full-field file."""
    tb = linearize.load_turbine()
    f = lidar.generate_field(field_spec(tb, Scenario(15.0, "B", 77, duration=25.0)), 77)
    path = tmp_path_factory.mktemp("wind") / "turbsim.bts"
    f.save(path)
    return path


def _names() -> list[str]:
    out = []
    for name, k in kinds().items():
        if k.addon_to:
            out.append(f"{k.default_base}+{name}")
        elif k.pattern:
            out.append("derate80")
        else:
            out.append(name)
    return out


@pytest.mark.parametrize("name", _names())
def test_every_kind_runs_on_a_turbsim_file(bts: Path, tmp_path: Path, name: str) -> None:
    kind = name.split("+")[-1].rstrip("0123456789")
    out = tmp_path / "r.nc"
    assert main(["simulate", "--wind-file", str(bts), "--controller", name, "--duration",
                 "4", "--out", str(out), *REQUIRED.get(kind, [])]) == 0
    res = ClosedLoopResult.load(out)
    assert res.meta["wind_file"] == str(bts) and "wind_mps" not in res.meta
    assert res.t[-1] == pytest.approx(4.0)
    assert np.all(np.isfinite(res.channel("rotor_speed")))


def test_the_plant_starts_at_the_files_first_seconds(bts: Path) -> None:
    """The start wind is the rotor-disc mean of u over the first 5 s of the file, computed here
    from the field itself."""
    tb = linearize.load_turbine()
    f = lidar.WindField.load(bts)
    yy, zz = np.meshgrid(f.y, f.z - f.hub_height, indexing="ij")
    disc = yy**2 + zz**2 <= tb.geometry.tip_radius**2
    first = f.t <= f.t[0] + 5.0
    assert start_wind(tb, Scenario(wind_file=str(bts), duration=10.0)) == pytest.approx(
        float(f.u[first][:, disc].mean()), rel=1e-6)


def test_bad_wind_files_are_named(bts: Path, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(ValueError, match="wind_file 'nope.bts': no such file"):
        Scenario(wind_file="nope.bts")
    with pytest.raises(ValueError, match="wind_file must be a TurbSim .bts or an mpc-wt .npz"):
        Scenario(wind_file=str(tmp_path / "w.wnd"))
    with pytest.raises(ValueError, match="wind_mps must be None with a wind_file"):
        Scenario(12.0, wind_file=str(bts))
    with pytest.raises(ValueError, match="wind_mps must be a mean wind > 0 m/s"):
        Scenario()
    broken = tmp_path / "broken.bts"
    broken.write_bytes(bts.read_bytes()[:1000])
    assert main(["simulate", "--wind-file", str(broken), "--out", str(tmp_path / "x.nc")]) == 2
    assert "--wind-file: " in (err := capsys.readouterr().err) and "truncated .bts" in err
    assert main(["simulate", "--wind-file", str(bts), "--duration", "100", "--out",
                 str(tmp_path / "x.nc")]) == 2
    assert ("--duration: the wind file holds 44.95 s of wind; the run's duration is 100 s"
            in capsys.readouterr().err)
    with pytest.raises(SystemExit):
        main(["simulate", "--wind-file", str(bts), "--wind", "12", "--out",
              str(tmp_path / "x.nc")])


def _edited(bts: Path, path: Path, **change) -> Path:
    """A copy of the fixture's field with fields replaced, saved as ``path``."""
    import dataclasses

    f = lidar.WindField.load(bts)
    dataclasses.replace(f, **{k: v(f) for k, v in change.items()}).save(path)
    return path


@pytest.mark.parametrize("suffix", [".bts", ".npz"])
def test_a_wind_file_is_checked_as_the_wind_flag_is(bts: Path, tmp_path: Path, suffix: str,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """A file whose wind blows upwind (-15 m/s under a header of 15), whose header says 1000
    m/s over data of 15, or whose wind is 1000 m/s is refused before anything runs (exit 2),
    naming the file and the values (it simulated silently at 0 MW, was binned at 1000 m/s, or
    diverged at t = 0.49 s); a grid that lies above the rotor is named with the file."""
    upwind = _edited(bts, tmp_path / f"upwind{suffix}", u=lambda f: -f.u)
    header = _edited(bts, tmp_path / f"header{suffix}", mean_speed=lambda f: 1000.0)
    fast = _edited(bts, tmp_path / f"fast{suffix}", u=lambda f: f.u * (1000.0 / 15.0),
                   mean_speed=lambda f: 1000.0)
    high = _edited(bts, tmp_path / f"high{suffix}", z=lambda f: f.z + 400.0,
                   hub_height=lambda f: f.hub_height + 400.0)
    cases = [(upwind, r"upwind\S*: its mean wind at the grid point nearest the hub .* is "
                      r"-1[45]\.\d+ m/s; a wind file must blow downwind"),
             (header, r"header's mean wind 1000 m/s disagrees with its data's 1[45]\.\d+ m/s"),
             (fast, r"its mean wind .* is 9\d\d\.?\d* m/s; .* in \(0, 70\] m/s"),
             (high, r"high\S*: its grid \(y .* m, z 4\d\d.* does not cover the rotor")]
    for path, msg in cases:
        out = tmp_path / "x.nc"
        assert main(["simulate", "--wind-file", str(path), "--duration", "2", "--out",
                     str(out)]) == 2
        assert re.search(msg, capsys.readouterr().err), path.name
        assert not out.exists()
