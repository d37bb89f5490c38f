"""The controller registry: every kind with typed options, one place per rule, a
user-defined kind added by one registration and used by ``mpcwt simulate`` and a campaign."""
from __future__ import annotations

import dataclasses
import math
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import linearize
from mpc_wt import registry as controllers
from mpc_wt.cli import main
from mpc_wt.kinds import IBCOptions, MPCOptions
from mpc_wt.registry import DesignCache, Options, option, resolve, turbine_key
from mpc_wt.errors import OptionsError
from mpc_wt.registry.registry import _KINDS
from mpc_wt.run import build_controller
from mpc_wt.simulation.scenario import Scenario, make_wind

BUILTIN = ["baseline", "baseline-ct", "derate", "ibc", "coleman-ipc", "mpc", "mpc-collective",
           "mpc-lidar", "torque-law", "lqr-pio", "ts", "apc"]

# The README's example of a user-defined kind, verbatim (ten lines of code).
PLUGIN = textwrap.dedent('''
    from dataclasses import dataclass
    import numpy as np
    from mpc_wt.registry import Built, Options, option, register

    @dataclass(frozen=True)
    class HoldOptions(Options):
        extra_pitch_deg: float = option(0.0, help="pitch added to the trim pitch", unit="deg")

    class Hold:
        """Holds the first measured pitch (plus extra) and torque."""
        def __init__(self, extra): self.extra = extra; self.reset()
        def reset(self): self.cmd = None
        def step(self, t, meas):
            if self.cmd is None:
                self.cmd = (np.asarray(meas["pitch"], float) + self.extra,
                            float(meas["gen_torque"]))
            return self.cmd[0].copy(), self.cmd[1]

    @register("hold-trim", HoldOptions, summary="first measured pitch and torque, held")
    def build(ctx, opts):
        return Built(Hold(np.radians(opts.extra_pitch_deg)), controller_dt=0.1)
''')


def test_registry_lists_every_kind_with_its_options() -> None:
    rows = {r["name"]: r for r in controllers.describe()}
    assert list(rows)[:len(BUILTIN)] == BUILTIN
    assert {o["name"] for o in rows["mpc"]["options"]} == {
        "horizon", "design_wind_mps", "schedule_step",
        "schedule_time_constant", "speed_limit", "kalman_wind_std", "kalman_flap_std",
        "weights", "time_budget_ms", "torque_limit", "power_limit", "below_rated_speed_limit",
        "below_rated_weights", "torque_notch_hz", "torque_notch_q", "tower_notch",
        "region_floor", "region3_pitch_deg"}
    assert rows["ibc"]["addon_to"] == ["baseline", "derate"]
    assert rows["derate"]["pattern"].startswith("derateNN")
    horizon = next(o for o in rows["mpc"]["options"] if o["name"] == "horizon")
    assert horizon["default"] == 15 and horizon["type"] == "int"
    # the options classes document themselves (numpydoc Parameters from the metadata)
    assert "min_gain_margin : float, default 2.0" in IBCOptions.__doc__
    assert "loop_gain_1p : Optional[float], default None" in IBCOptions.__doc__


@pytest.mark.parametrize("name, base, preset, addons", [
    ("derate80+ibc", "derate", {"power_fraction": 0.8}, ["ibc"]),
    ("derate72.5", "derate", {"power_fraction": 0.725}, []),
    ("ibc", "baseline", {}, ["ibc"]),
    ("coleman-ipc", "baseline", {}, ["coleman-ipc"]),
    ("mpc-lidar", "mpc-lidar", {}, []),
])
def test_names_resolve_to_base_preset_and_addons(name, base, preset, addons) -> None:
    s = resolve(name)
    assert (s.base.name, s.preset, [a.name for a in s.addons]) == (base, preset, addons)


@pytest.mark.parametrize("name, options, match", [
    ("baseline", {"gian": 1}, r"gian: unknown option of controller 'baseline'; allowed: "
                              r"\['omega_n_rad_s', 'zeta'\]"),
    ("apc", {}, "controller 'apc' needs apc_frequency"),
    ("mpc", {"horizon": 0}, "horizon must be >= 1 and <= 200, got 0"),
    ("mpc", {"horizon": 2.5}, "horizon must be an integer, got 2.5"),
    ("mpc", {"backend": "osqp"}, r"backend: unknown option of controller 'mpc'"),
    ("ts", {"horizon": 5}, "apply to the MPC controllers only, not to controller 'ts'"),
    ("lqr-pio", {"apc_frequency": 0.1}, "apc_frequency applies to controllers ts and apc only"),
    ("derate80", {"power_fraction": 0.5}, "power_fraction is set by the name 'derate80'"),
    ("mpc-lidar", {"lidar": {"focus": 3}}, "lidar.focus: unknown option"),
    ("mpc-lidar", {"lidar": {"focus_distance": -3}}, "lidar.focus_distance must be > 0 m"),
    ("ibc+mpc", {}, "controller must be one of"),
    ("mpc+ibc", {}, "add-on 'ibc' goes on \\['baseline', 'derate'\\], not on 'mpc'"),
])
def test_option_errors_name_the_option_and_what_is_allowed(name, options, match) -> None:
    with pytest.raises(ValueError, match=match):
        resolve(name).options(options)


def test_options_error_carries_the_key() -> None:
    with pytest.raises(OptionsError) as e:
        resolve("mpc-lidar").options({"lidar": {"n_range": 0}})
    assert e.value.key == "lidar.n_range"


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 60), st.one_of(st.none(), st.floats(3.0, 25.0)),
       st.one_of(st.none(), st.floats(0.5, 2.0)))
def test_options_round_trip(horizon, design_wind, power_limit) -> None:
    """Invariant: from_dict(to_dict(o)) == o, and every field keeps its type."""
    o = MPCOptions.from_dict({"horizon": horizon, "design_wind_mps": design_wind,
                              "power_limit": power_limit})
    assert MPCOptions.from_dict(o.to_dict()) == o
    assert isinstance(o.horizon, int) and o.horizon == horizon


def test_design_cache_is_keyed_on_content_not_identity() -> None:
    a, b = linearize.load_turbine(), linearize.load_turbine()
    assert a is not b and turbine_key(a) == turbine_key(b)
    heavier = dataclasses.replace(a, nacelle=dataclasses.replace(a.nacelle,
                                                                  mass=a.nacelle.mass * 1.01))
    assert turbine_key(heavier) != turbine_key(a)
    cache, made = DesignCache(), []
    for t in (a, b, heavier):
        cache.get(t, ("x",), lambda: made.append(1) or len(made))
    assert len(made) == 2 and cache.hits == 1


def test_register_rejects_a_taken_name_and_a_bad_name() -> None:
    with pytest.raises(ValueError, match="'baseline' is registered already"):
        controllers.register("baseline")(lambda ctx, o: None)
    with pytest.raises(ValueError, match="must be letters"):
        controllers.register("2 fast")(lambda ctx, o: None)


@pytest.fixture()
def plugin(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    (tmp_path / "my_controllers.py").write_text(PLUGIN)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    yield "my_controllers"
    _KINDS.pop("hold-trim", None)
    sys.modules.pop("my_controllers", None)
    from mpc_wt.registry import registry

    registry._PLUGINS_LOADED.discard("my_controllers")


def test_user_kind_runs_in_mpcwt_simulate(plugin: str, tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "hold.nc"
    assert main(["--plugin", plugin, "simulate", "--controller", "hold-trim",
                 "--extra-pitch-deg", "1", "--wind", "18", "--turbulence", "steady",
                 "--duration", "5", "--out", str(out)]) == 0
    from mpc_wt import ClosedLoopResult

    r = ClosedLoopResult.load(out)
    assert r.meta["controller"] == "hold-trim"
    trim_pitch = linearize.trim(linearize.load_turbine(), 18.0).u[0]
    # the command is the trim pitch + 1 deg exactly (the plant's actuator follows it)
    np.testing.assert_allclose(r.u[5:, 0], trim_pitch + math.radians(1.0), rtol=0, atol=1e-12)
    # the option is checked by the registry: a kind that does not take it names the taker
    assert main(["--plugin", plugin, "simulate", "--controller", "baseline",
                 "--extra-pitch-deg", "1", "--wind", "18", "--out", str(out)]) == 2
    assert ("--extra-pitch-deg applies to --controller hold-trim only, not to --controller "
            "baseline") in capsys.readouterr().err


def test_user_kind_runs_in_a_campaign(plugin: str, tmp_path: Path) -> None:
    from mpc_wt.campaign import run_campaign, spec_from_dict

    spec = spec_from_dict({"name": "plug", "duration": 10, "transient": 0, "winds": [18],
                           "seeds": 1, "turbulence": "steady", "plugins": [plugin],
                           "controllers": [{"name": "hold", "controller": "hold-trim",
                                            "extra_pitch_deg": 2.0}],
                           "channels": {"tower_base_fa_moment": 4}})
    s = run_campaign(spec, tmp_path / "c", engine="processes", workers=1, progress=False)
    assert (s.done, s.failed) == (1, 0), s.failures
    with pytest.raises(Exception, match=r"controllers\[0\]\.extra_pitch_deg"):
        spec_from_dict({"name": "p", "winds": [18], "plugins": [plugin],
                        "controllers": [{"name": "h", "controller": "hold-trim",
                                         "extra_pitch_deg": "a"}]})


def test_bad_plugin_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--plugin", "no_such_module_xyz", "controllers"]) == 2
    assert "controller plugin 'no_such_module_xyz' does not import" in capsys.readouterr().err


def test_option_class_for_users_validates_its_fields() -> None:
    @dataclasses.dataclass(frozen=True)
    class Mine(Options):
        gain: float = option(1.0, lo=0.0, lo_open=True, unit="rad/s")

    assert Mine.from_dict({"gain": 2}).gain == 2.0
    with pytest.raises(OptionsError, match=r"gain must be > 0 rad/s, got -1"):
        Mine.from_dict({"gain": -1})
    with pytest.raises(OptionsError, match="gain must be > 0 rad/s, got nan"):
        Mine.from_dict({"gain": float("nan")})


def test_a_number_yaml_reads_as_a_string_is_taken_as_the_number() -> None:
    """PyYAML (YAML 1.1) reads ``4.49e6`` (no dot in the mantissa) as a string: the option is
    that number, as ``4.49e+6`` would be; a string that is no number is named as such."""
    import yaml

    raw = yaml.safe_load("{kalman_flap_std: 4.49e6, horizon: '12'}")
    assert raw["kalman_flap_std"] == "4.49e6"              # what the spec file hands over
    opts = resolve("mpc").options(raw)[0]
    assert (opts.kalman_flap_std, opts.horizon) == (4.49e6, 12)
    with pytest.raises(OptionsError, match="kalman_flap_std must be a number, got 'big'"):
        resolve("mpc").options({"kalman_flap_std": "big"})
    with pytest.raises(OptionsError, match="horizon must be a number, got '2.5'"):
        resolve("mpc").options({"horizon": "2.5"})


@pytest.mark.parametrize("argv, match", [
    (["linearize", "--wind", "12", "--out", "models.lin"], "--out must end in .mat, .npz, .json"),
    (["design", "ts", "--decay-rate=-1"], "--decay-rate must be > 0, got -1.0"),
    (["design", "lqr", "--observer-q=-5"], "--observer-q must be >= 0, got -5.0"),
    (["wind", "generate", "--mean", "18", "--out", "field.txt"], "--out must end in .bts, .npz"),
    (["simulate", "--controller", "mpc", "--horizon", "0", "--wind", "18"],
     "horizon must be >= 1 and <= 200, got 0"),
])
def test_commands_check_their_arguments_before_working(argv, match, tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str],
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    """The argument error comes first: nothing is computed or written (the commands would
    otherwise linearize, solve LMIs or generate a field before failing)."""
    import linearize as lz

    def boom(*a, **k):  # any plant work before the check fails the test
        raise AssertionError("work done before the arguments were checked")

    monkeypatch.setattr(lz, "linearize_family", boom)
    monkeypatch.setattr(lz, "load_turbine", boom)
    out = tmp_path / "d"
    assert main([*argv, "--out", str(out)] if "--out" not in argv else
                [a if a not in ("models.lin", "field.txt") else str(tmp_path / a)
                 for a in argv]) == 2
    assert match in capsys.readouterr().err
    assert not out.exists()


def test_design_weights_reach_the_designs() -> None:
    """The tunable options: the MPC's cost weights (unset ones keep MPCWeights'
    defaults) and the LQR's weights (unset ones keep the region's) are the ones designed with;
    a larger pitch weight gives a smaller LQR gain."""
    from mpc_wt.controllers.mpc import MPCWeights

    t = linearize.load_turbine()
    sc = Scenario(18.0, "A", 1, 30.0)
    built, _, _ = build_controller(t, "mpc", sc, {"weights": {"flap_moment": 2.0,
                                                              "pitch_ref": 0.05}})
    w = built.designed.settings.weights
    assert w.outputs["flap_moment"] == 2.0 and w.inputs["pitch_ref"] == 0.05
    assert w.outputs["rotor_speed"] == MPCWeights().outputs["rotor_speed"]
    gains = {}
    for wp in (1.0, 10.0):
        b, _, _ = build_controller(t, "lqr-pio", sc, {"w_pitch": wp, "w_rotor_speed": 2.0})
        lq = b.meta["lqr"]["weights"]["III"]
        assert lq["state"] == {"rotor_speed": 2.0, "tower_fa_velocity": 1.0}
        assert lq["input"] == {f"pitch_ref_{i}": wp for i in (1, 2, 3)}
        assert lq["output"] == {f"pitch_rate_{i}": 0.4 for i in (1, 2, 3)}
        gains[wp] = np.linalg.norm(b.designed.controllers[-1].lqr.K)
    assert gains[10.0] < gains[1.0]
    with pytest.raises(OptionsError, match="weights.flap_moment must be >= 0"):
        resolve("mpc").options({"weights": {"flap_moment": -1}})


def test_lqr_pio_region2_shares_the_baselines_torque_law() -> None:
    """Do et al. sec. 4.2 compare PI and FSF under one torque law, only the pitch loop differs:
    with the FSF's pitch weighted out (w_pitch 1e6) our region-II lqr-pio must run as the
    baseline (rotor speed within 0.1 %, torque within 0.5 % of rated, 8 m/s TI 12 %, 60 s).
    Do's bare K_opt Omega_g^2 on the raw speed (``region2_torque: k_opt``) lacks region 2.5 and
    does not: its largest torque difference is several per cent of rated."""
    from mpc_wt import run_controller

    t = linearize.load_turbine()
    base = run_controller(t, "baseline", Scenario(8.0, 0.12, 1, 60.0))
    q_rated = t.generator.max_torque / 1.1
    runs = {law: run_controller(t, "lqr-pio", Scenario(8.0, 0.12, 1, 60.0), options={"w_pitch": 1e6, "region2_torque": law})
            for law in ("baseline", "k_opt")}
    assert np.allclose(runs["baseline"].channel("rotor_speed"), base.channel("rotor_speed"),
                       rtol=1e-3)
    diffs = {law: np.max(np.abs(r.channel("gen_torque") - base.channel("gen_torque")))
             for law, r in runs.items()}
    assert diffs["baseline"] < 0.005 * q_rated
    assert diffs["k_opt"] > 0.02 * q_rated


def test_lidar_field_is_made_from_the_seed_not_beside_the_case_field() -> None:
    """The built-in kinds have the case's field made with the plant's u
    only; a LIDAR's field is made from the case's spec and seed. Evolved, it is
    lidar.evolve_field of the whole case field with the context's evolution stream (the
    path before) to single-precision rounding, 2e-5 m/s; frozen (distance 0), the whole
    field, whose u is the case's. A u-only field whose u runs backwards holds the plant's
    clipped u itself, not a second copy."""
    import lidar
    from mpc_wt.simulation.scenario import _EVOLUTION_STREAM, field_spec, lidar_field

    tb = linearize.load_turbine()
    for name in ("mpc-lidar", "baseline+lidar-ff"):
        sel = controllers.resolve(name)
        assert set().union(*(k.field_components for k in (sel.base, *sel.addons))) == {"u"}
    sc = Scenario(18.0, "A", 4, 20.0, 0.2)
    wind, field = make_wind(tb, sc, "u")
    assert not field.v.any() and not field.w.any()
    whole = lidar.generate_field(field_spec(tb, sc), 4)
    assert np.array_equal(field.u, whole.u)
    seen = lidar_field(tb, sc, field, 54.0)
    ref = lidar.evolve_field(whole, 54.0, seed=np.random.default_rng([4, _EVOLUTION_STREAM]))
    for comp in "uvw":
        np.testing.assert_allclose(getattr(seen, comp), getattr(ref, comp), rtol=0, atol=2e-5)
    frozen = lidar_field(tb, sc, field, 0.0)
    assert np.array_equal(frozen.u, whole.u) and np.array_equal(frozen.w, whole.w)
    low = Scenario(4.0, 0.9, 1, 20.0, 0.2)           # 90 % intensity at 4 m/s: u < 0 somewhere
    wind, field = make_wind(tb, low, "u")
    assert lidar.generate_field(field_spec(tb, low), 1).u.min() < 0.0
    assert wind.u is field.u and field.u.min() == 0.0 and field.meta["u_clipped_at_zero"]
    with pytest.raises(ValueError, match="scenario 'eog' with turbulence 'A' has no "
                                         "turbulent field"):
        field_spec(tb, Scenario(18.0, "A", 1, 20.0, 0.2, condition="eog"))


def test_checked_options_pass_through_unchanged(turbine):
    """The options a selection checked once are taken as they are (the command line checks
    them before it runs); another selection's are refused with both named."""
    sel = resolve("derate80+ibc")
    checked = sel.options({"loop_gain_1p": 0.5})
    assert sel.options(checked) is checked
    with pytest.raises(OptionsError, match=r"DerateOptions', 'IBCOptions'\] each, got "
                                           r"\['MPCOptions'\]"):
        sel.options((MPCOptions(),))
    a = build_controller(turbine, "derate80+ibc", Scenario(14.0, "A", 3, 2.0), checked)[0]
    b = build_controller(turbine, "derate80+ibc", Scenario(14.0, "A", 3, 2.0),
                         {"loop_gain_1p": 0.5})[0]
    assert a.controller is b.controller         # the same design from the cache
    assert not b.meta["design"]["new"]
