"""Turbine data: the packaged NREL 5-MW against published values, and broken files."""
from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import linearize
from linearize import TurbineFileError, load_turbine

PKG = Path(linearize.__file__).parent / "data" / "nrel5mw"


def test_packaged_turbine_loads_in_si(turbine: linearize.Turbine) -> None:
    g = turbine.geometry
    # published: Jonkman et al. (2009) Table 1-1 -- exact data entries
    assert_allclose([g.tip_radius, g.hub_height, turbine.operation.rated_power],
                    [63.0, 90.0, 5e6], rtol=0, atol=1e-9)
    assert_allclose(g.precone_rad, math.radians(2.5), rtol=1e-12, atol=0)
    assert_allclose(turbine.operation.rated_rotor_speed_rad_s, 12.1 * math.pi / 30, rtol=1e-12,
                    atol=0)
    assert turbine.blade.r.shape == (17,)
    assert len(turbine.polars) == 8
    assert "nrel5mw" in linearize.available_turbines()


def test_rated_generator_torque_matches_discon(turbine: linearize.Turbine) -> None:
    # published: DISCON.F90 comment "VS_RtTq = 43.09355 kNm" (Jonkman et al. 2009, sec. 7.3)
    assert_allclose(turbine.rated_generator_torque, 43093.55, rtol=2e-6, atol=0)


def test_rotor_mass_properties_match_elastodyn(params: linearize.PlantParams) -> None:
    # published: OpenFAST r-test 5MW_Land_DLL_WTurb.ED.sum (@2668c76): blade mass 17,536.614 kg,
    # rotor inertia 38,677,040.613 kg m^2. Tolerance 1 %: we integrate the 49-station table on a
    # fine grid, ElastoDyn on its 17 blade nodes (its blade mass is 0.4 % lower).
    assert_allclose(params.blade_mass, 17536.614, rtol=0.01, atol=0)
    assert_allclose(params.rotor_inertia, 38677040.613, rtol=0.01, atol=0)


def test_user_turbine_from_a_directory(tmp_path: Path) -> None:
    dst = tmp_path / "mine"
    shutil.copytree(PKG, dst)
    t = load_turbine(dst)
    assert t.source.endswith("turbine.yaml")
    t2 = load_turbine(dst / "turbine.yaml")
    assert_allclose(t2.blade.chord, t.blade.chord, rtol=0, atol=0)


def test_unknown_name_is_clear() -> None:
    with pytest.raises(FileNotFoundError, match="neither a packaged turbine"):
        load_turbine("no_such_turbine")


def _broken(tmp_path: Path, edit_yaml=None, edit_file=None) -> Path:
    dst = tmp_path / "t"
    shutil.copytree(PKG, dst)
    if edit_yaml:
        p = dst / "turbine.yaml"
        p.write_text(edit_yaml(p.read_text()))
    if edit_file:
        name, fn = edit_file
        p = dst / name
        p.write_text(fn(p.read_text()))
    return dst


@pytest.mark.parametrize("edit, match", [
    (lambda s: s.replace("  hub_height_m: 90.0", "  hub_heigth_m: 90.0"),
     r"geometry.*unknown keys \['hub_heigth_m'\].*missing keys \['hub_height_m'\]"),
    (lambda s: s.replace("  tip_radius_m: 63.0             # [ED] TipRad\n", ""),
     r"missing keys \['tip_radius_m'\]"),
    (lambda s: s.replace("  mass_kg: 240000.0", "  mass_kg: -240000.0"),
     r"nacelle.*mass_kg.*\(0, 1e\+08\].*-240000"),
    (lambda s: s.replace("shaft_stiffness_Nm_per_rad: 8.67637e+8", "shaft_stiffness_Nm_per_rad: 0"),
     r"shaft_stiffness_Nm_per_rad"),
    (lambda s: s.replace("tip_radius_m: 63.0", "tip_radius_m: 400.0"),
     r"tip_radius_m.*\(0, 300\]"),
    (lambda s: s.replace("schema_version: 1", "schema_version: 7"), r"schema_version must be 1"),
    (lambda s: s.replace("gravity_mps2: 9.80665", "gravity_mps2: .nan"), r"gravity"),
    (lambda s: s.replace("air_density_kgpm3: 1.225", "air_density_kgpm3: fast"),
     r"air_density_kgpm3 must be a number"),
    (lambda s: s + "extra_section: 1\n", r"unknown keys \['extra_section'\]"),
])
def test_bad_yaml_names_file_field_and_range(tmp_path: Path, edit, match: str) -> None:
    d = _broken(tmp_path, edit_yaml=edit)
    with pytest.raises(TurbineFileError, match=match) as exc:
        load_turbine(d)
    assert "turbine.yaml" in str(exc.value)


def _swap_rows(text: str, i: int, j: int) -> str:
    lines = text.splitlines()
    lines[i], lines[j] = lines[j], lines[i]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("file, edit, match", [
    ("blade_aero_elements_17.csv", lambda s: _swap_rows(s, 5, 6), r"non-monotonic span"),
    ("blade_aero_elements_17.csv", lambda s: s.replace(",3.542,1,", ",-3.542,1,"),
     r"Chord_m.*> 0 m"),
    ("blade_aero_elements_17.csv", lambda s: s.replace(",1.419,8,", ",40.0,8,"),
     r"chord must be below half the tip radius"),
    ("blade_aero_elements_17.csv", lambda s: s.replace("61.6333,60.1333,2.7333", "62.9,60.1333,2.7333"),
     r"must lie within hub_radius..tip_radius"),
    ("blade_aero_elements_17.csv", lambda s: s.replace(",3.542,1,", ",nan,1,"), r"not finite"),
    ("blade_aero_elements_17.csv", lambda s: s.replace(",3.542,1,", ",abc,1,"),
     r"line 2, column 'Chord_m': 'abc' is not a number"),
    ("airfoils/DU21_A17.csv", lambda s: "\n".join(s.splitlines()[:-3]) + "\n",
     r"must cover -180..180 deg"),
    ("structure/blade_structure_elastodyn.csv",
     lambda s: s.replace("6.7893500E+02,1.8110000E+10", "-6.7893500E+02,1.8110000E+10", 1),
     r"BMassDen_kg_per_m.*> 0"),
    ("structure/tower_structure_elastodyn.csv",
     lambda s: s.replace("6.1434300E+11,6.1434300E+11", "0,6.1434300E+11"), r"TwFAStif_Nm2.*> 0"),
    ("structure/mode_shapes_elastodyn.csv", lambda s: s.replace("0.7004,", "0.9004,"),
     r"tower_fa1: phi\(1\)"),
])
def test_bad_tables_name_the_file_and_value(tmp_path: Path, file: str, edit, match: str) -> None:
    d = _broken(tmp_path, edit_file=(file, edit))
    with pytest.raises(TurbineFileError, match=match) as exc:
        load_turbine(d)
    assert Path(file).name in str(exc.value) or "turbine.yaml" in str(exc.value)


def test_missing_table_file(tmp_path: Path) -> None:
    d = _broken(tmp_path)
    (d / "airfoils" / "DU30_A17.csv").unlink()
    with pytest.raises(TurbineFileError, match=r"DU30_A17.csv: file not found"):
        load_turbine(d)


def test_frozen_arrays(turbine: linearize.Turbine) -> None:
    with pytest.raises(ValueError):
        turbine.blade.chord[0] = 1.0
    assert not np.shares_memory(turbine.blade.chord, turbine.blade.r)
