"""OpenFAST .lin files as LinearModels. The parser against openfast-io's
FASTLinearizationFile (a peer), the MBC3 of a set against our own MBC transform (our plant
written in the .lin layout at 8 azimuths), the MBC3 of a public OpenFAST set (the IEA-15
UMaineSemi linearizations in the rosco wheel) against OpenFAST's own collective-pitch input,
and our plant against OpenFAST's derivatives at a file's operating point."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import rosco  # in the test extras: its wheel carries a public set of .lin files
from openfast_io.FAST_linearization_reader import FASTLinearizationFile

import linearize
from linearize import LinFileError, read_lin, read_lin_set, write_lin
from linearize.openfast_lin import compare_with_openfast

DATA = Path(__file__).parents[1] / "data"
IEA_LIN = (Path(rosco.__file__).parents[1] / "Examples" / "Test_Cases" / "IEA-15-240-RWT"
           / "IEA-15-240-RWT-UMaineSemi" / "linearizations")


def test_read_lin_agrees_with_openfast_io() -> None:
    """FASTLin.lin (OpenFAST v2.2, NREL 5-MW, 11 m/s): every matrix and operating point equal
    to openfast-io's, outputs converted to SI (kW -> W, kN-m -> N m, rpm -> rad/s, deg -> rad)
    and InflowWind's inputs split off as disturbances. The operating points agree to float32
    precision (openfast-io stores them as float32; we keep the file's decimals)."""
    m = read_lin(DATA / "FASTLin.lin")
    peer = FASTLinearizationFile(str(DATA / "FASTLin.lin"))
    np.testing.assert_array_equal(m.A, peer["A"])
    np.testing.assert_array_equal(np.hstack([m.B_d, m.B_u]), peer["B"])
    scale = np.array([1, 1e3, 1e3, math.pi / 180, math.pi / 180, math.pi / 30, math.pi / 30, 1,
                      1, 1e3, 1e3, 1e3, 1e3, 1e3, 1, 1])
    np.testing.assert_allclose(m.C_z, peer["C"] * scale[:, None], rtol=1e-15)
    np.testing.assert_allclose(np.hstack([m.D_d, m.D_u]), peer["D"] * scale[:, None],
                               rtol=1e-15)
    # openfast-io keeps the operating points as float32: equal to its 7 digits
    np.testing.assert_allclose(m.x0, peer["x"], rtol=1e-7)
    np.testing.assert_allclose(m.z0, peer["y"] * scale, rtol=1e-7)
    assert m.states == ("tower_fa_displacement", "azimuth", "tower_fa_velocity", "rotor_speed")
    assert m.disturbances == ("wind", "shear_exponent", "wind_direction")
    assert m.inputs[:3] == ("pitch_ref_1", "pitch_ref_2", "pitch_ref_3")
    assert {"aero_torque", "thrust", "gen_power", "tower_base_fa_moment"} <= set(m.outputs)
    assert m.wind_mps == 11.0 and m.info["rotor_speed_rad_s"] == 1.2367


@pytest.fixture(scope="module")
def our_set(tmp_path_factory, turbine):
    """Our NREL 5-MW (all DOFs, shear 0.2, 16 m/s) at 8 azimuths in the .lin layout, and our own
    MBC model averaged over the same 8 azimuths."""
    d = tmp_path_factory.mktemp("lin")
    p = linearize.plant_params(turbine)
    op = linearize.trim(turbine, 16.0, params=p, shear_exponent=0.2)
    paths, first = [], None
    for k in range(8):
        psi = 2 * math.pi * k / 8
        m = linearize.linearize(turbine, 16.0, params=p, operating_point=op, azimuth_rad=psi,
                                shear_exponent=0.2)
        paths.append(write_lin(m, d / f"ours.{k + 1}.lin", azimuth_rad=psi))
        first = first or m
    ref = linearize.linearize(turbine, 16.0, params=p, operating_point=op, coordinates="mbc",
                              n_azimuth=8, shear_exponent=0.2)
    return paths, ref, first


def test_mbc3_of_a_set_equals_our_mbc_transform(our_set) -> None:
    """read_lin_set (Bir's MBC3 on the files, second-order velocity terms included) against
    linearize(coordinates="mbc"): the same names and matrices to the files' 16 digits
    (asserted 1e-12 of each matrix's largest entry; measured below 1e-15), and the same
    eigenvalues."""
    paths, ref, _ = our_set
    m = read_lin_set(paths)
    assert (m.states, m.inputs, m.disturbances, m.outputs) == (
        ref.states, ref.inputs, ref.disturbances, ref.outputs)
    assert m.coordinates == "mbc" and not any(m.info["mbc_untransformed"].values())
    for name in ("A", "B_u", "B_d", "C_z", "D_u", "D_d"):
        a, b = getattr(m, name), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max(), name
    lam, lam_ref = np.linalg.eigvals(m.A), np.linalg.eigvals(ref.A)
    gap = np.abs(lam[:, None] - lam_ref[None, :]).min(axis=1)
    assert gap.max() <= 1e-9 * np.abs(lam_ref).max()


def test_written_lin_is_read_by_openfast_io(our_set) -> None:
    paths, _, _ = our_set
    peer = FASTLinearizationFile(str(paths[0]))
    ours = read_lin(paths[0])
    np.testing.assert_allclose(peer["A"], ours.A, rtol=1e-14)
    assert peer["x_info"]["RotatingFrame"].count("T") == 15   # pitch, flap, edge (+ rates)


def test_our_model_through_lin_drives_mpc_and_lqr(our_set, turbine) -> None:
    """A model read back from .lin files is used where our own are: model.modes(), the LQR
    and the MPC (which needs Madsen's outputs: they are there under our names)."""
    from mpc_wt.controllers.lqr import design_lqr
    from mpc_wt.controllers.mpc import MPC, MPCSettings

    paths, _, original = our_set
    m = read_lin(paths[0])
    for a, b in zip(m.modes(), original.modes(), strict=True):
        assert a["name"] == b["name"]
        assert a["frequency_Hz"] == pytest.approx(b["frequency_Hz"], rel=1e-12)
    d = design_lqr(m, state_weights={"rotor_speed": 1.0})
    assert np.all(np.linalg.eigvals(m.A - m.B_u[:, :3] @ d.K).real < 0)
    MPC(m, turbine, MPCSettings(estimator="full-state"))
    with pytest.raises(ValueError, match=r"no process-noise default for the model's states "
                                         r"\['tower_ss_displacement'.*estimator='full-state'"):
        MPC(m, turbine)                   # the estimator knows the states of Madsen's model
    with pytest.raises(ValueError, match="model lacks Madsen outputs"):
        MPC(read_lin(DATA / "FASTLin.lin"), turbine, MPCSettings(estimator="full-state"))


def test_public_openfast_set_mbc3_against_collective_input() -> None:
    """The IEA-15-240-RWT UMaineSemi set at 17 m/s (12 azimuths, OpenFAST, 106 states): after
    MBC3 the collective-pitch column built from the three blade-pitch inputs equals OpenFAST's
    own 'collective blade-pitch command' input, which ElastoDyn applies to all three blades
    (to the files' 4 significant digits: asserted 2e-3 of the column's size, measured 3e-5
    on its largest entry). Blade 1's outputs
    without blades 2 and 3 stay in the rotating frame and are listed."""
    files = sorted(IEA_LIN.glob("lin_12.*.lin"))
    assert len(files) == 12
    m = read_lin_set(files)
    assert m.wind_mps == 17.0 and m.n_x == 106
    coll = m.B_u[:, m.inputs.index("pitch_ref_coll")]
    ed = m.B_u[:, m.inputs.index("pitch_ref_collective")]
    assert np.abs(coll - ed).max() <= 2e-3 * np.abs(ed).max()
    assert "pitch_1" in m.info["mbc_untransformed"]["outputs"]
    assert len(m.info["azimuths_rad"]) == 12


def test_compare_with_openfast_at_the_files_point(turbine) -> None:
    """Our plant at FASTLin.lin's operating point (11 m/s, 11.81 rpm, pitch 0; tower fore-aft
    and generator DOFs): wind, rotor-speed and tower-velocity derivatives of aerodynamic torque
    and thrust within 5 % (measured 0.1-4.4 %); dQ/dpitch is +50 % (fine pitch near the C_P
    optimum, see test_linear.py). The tower mode differs (0.395 against 0.329 Hz): the file is
    the OC3-Hywind deck's, a different tower than our land-based one."""
    res = compare_with_openfast(turbine, read_lin(DATA / "FASTLin.lin"))
    assert res["operating_point"]["dofs"] == ["generator", "tower_fa"]
    for k, d in res["derivatives"].items():
        if k == "dQ/dpitch":
            assert d["ratio"] == pytest.approx(1.50, abs=0.03)
        else:
            assert abs(d["ratio"] - 1) <= 0.05, k
    assert res["modes"]["openfast"][0]["name"] == "tower fore-aft"


def test_compare_cli(capsys) -> None:
    from mpc_wt.cli import main

    assert main(["linearize", "--compare", str(DATA / "FASTLin.lin")]) == 0
    out = capsys.readouterr().out
    assert "dT/dV" in out and "OpenFAST" in out and "1.0012" in out


@pytest.mark.parametrize("edit, match", [
    (lambda s: s.replace("Rotor Speed:", "Rotor speed?"), r"no header line 'Rotor Speed'"),
    (lambda s: s.replace("A: 4 x 4", "A: 4 x 5"), r"A is 4 x 5; the header gives 4 x 4"),
    (lambda s: s.replace("-6.13652848E+00", "abc"), r"matrix A after line \d+ is short or not"),
    (lambda s: s.replace("Order of inputs:", "Order of the inputs:"),
     r"no section 'Order of inputs:'"),
    (lambda s: s.replace("    1.10000000E+01                                           F ",
                         "    1.10000000E+01                                           X ", 1),
     r"line \d+: .* is not a row"),
])
def test_bad_lin_file_is_named(tmp_path, edit, match) -> None:
    p = tmp_path / "bad.lin"
    p.write_text(edit((DATA / "FASTLin.lin").read_text()))
    with pytest.raises(LinFileError, match=match):
        read_lin(p)


def test_bad_lin_set(tmp_path, our_set) -> None:
    paths, _, _ = our_set
    with pytest.raises(LinFileError, match="MBC3 needs at least 3 azimuths"):
        read_lin_set(paths[:2])
    with pytest.raises(LinFileError, match="its states differ"):
        read_lin_set([paths[0], paths[1], DATA / "FASTLin.lin"])
    with pytest.raises(LinFileError, match="file not found"):
        read_lin(tmp_path / "none.lin")
