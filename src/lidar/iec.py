"""Wind conditions of IEC 61400-1 ed. 3 (2005) for a turbine class, as wind fields.

Section 6.3 of the standard defines, for a wind turbine class (I, II, III: the reference speed
V_ref, table 1) and a turbulence category (A, B, C: I_ref):

* the normal wind profile (NWP, 6.3.1.2): V(z) = V_hub (z / z_hub)^alpha, alpha = 0.2;
* the normal turbulence model (NTM, 6.3.1.3, eq 11): sigma_1 = I_ref (0.75 V_hub + b),
  b = 5.6 m/s;
* the extreme wind model (EWM, 6.3.2.1, eqs 14-15): V_e50(z) = 1.4 V_ref (z / z_hub)^0.11,
  V_e1(z) = 0.8 V_e50(z);
* the extreme turbulence model (ETM, 6.3.2.3, eq 19): sigma_1 = c I_ref (0.072 (V_ave / c + 3)
  (V_hub / c - 4) + 10), c = 2 m/s, V_ave = 0.2 V_ref;
* the extreme operating gust (EOG, 6.3.2.2, eqs 16-17): V_gust = min(1.35 (V_e1 - V_hub),
  3.3 sigma_1 / (1 + 0.1 D / Lambda_1)), V(z, t) = V(z) - 0.37 V_gust sin(3 pi t / T)
  (1 - cos(2 pi t / T)) for 0 <= t <= T = 10.5 s (sigma_1 of the NTM);
* the extreme direction change (EDC, 6.3.2.4, eqs 20-21): theta_e = +-4 arctan(sigma_1 /
  (V_hub (1 + 0.1 D / Lambda_1))), theta(t) = 0.5 theta_e (1 - cos(pi t / T)), T = 6 s;
* the extreme coherent gust with direction change (ECD, 6.3.2.5, eqs 22-24): V_cg = 15 m/s,
  V(z, t) = V(z) + 0.5 V_cg (1 - cos(pi t / T)) and theta(t) = +-0.5 theta_cg (1 - cos(pi t /
  T)) for 0 <= t <= T = 10 s (V_cg and theta_cg after), theta_cg = 180 deg below 4 m/s,
  720 deg m/s / V_hub up to V_ref;
* the extreme wind shear (EWS, 6.3.2.6, eqs 25-26): V(y, z, t) = V(z) +- ((z - z_hub) / D)
  (2.5 m/s + 0.2 beta sigma_1 (D / Lambda_1)^(1/4)) (1 - cos(2 pi t / T)) vertically (y / D
  for the horizontal shear), beta = 6.4, T = 12 s;

with the longitudinal turbulence scale Lambda_1 = 0.7 z_hub up to 60 m, 42 m above (eq 5).

:func:`iec_field` makes any of them a :class:`WindField` on a (y, z) grid (the ETM through
:func:`generate_field` with its sigma_1), so that the plant and a LIDAR in the loop meet the
same event. A direction change turns the wind vector towards +y (to the left looking downwind)
for a positive angle: u = V cos(theta), v = V sin(theta); the field's frame stays the rotor's
(no yaw).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lidar._typing import FloatArray
from lidar.field import WindField

__all__ = ["IEC_REFERENCE_SPEED", "IEC_TURBULENCE", "CONDITIONS", "IECSite", "iec_field",
           "event_duration"]

#: V_ref of the wind turbine classes of IEC 61400-1 ed. 3, table 1 [m/s].
IEC_REFERENCE_SPEED = {"I": 50.0, "II": 42.5, "III": 37.5}
#: I_ref of the turbulence categories, table 1 [-].
IEC_TURBULENCE = {"A": 0.16, "B": 0.14, "C": 0.12}
#: The conditions :func:`iec_field` makes, and their event durations T [s] (0: steady or
#: turbulent, no transient).
CONDITIONS = {"nwp": 0.0, "ntm": 0.0, "etm": 0.0, "eog": 10.5, "edc": 6.0, "ecd": 10.0,
              "ews-v": 12.0, "ews-h": 12.0}
_V_CG = 15.0          # ECD gust amplitude [m/s] (eq 22)
_BETA = 6.4           # EWS (eq 25)


def event_duration(condition: str) -> float:
    """The transient's duration T of a condition (0 for the steady and turbulent ones) [s].

    Parameters
    ----------
    condition : str
        One of :data:`CONDITIONS`.

    Returns
    -------
    float
        T [s].

    Raises
    ------
    ValueError
        An unknown condition, listing the known ones.
    """
    key = str(condition).lower()
    if key not in CONDITIONS:
        raise ValueError(f"condition must be one of {sorted(CONDITIONS)}, got {condition!r}")
    return CONDITIONS[key]


def _finite_positive(name: str, value: Any) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return v


@dataclass(frozen=True)
class IECSite:
    """A turbine's design conditions: its IEC class and category, hub height and rotor.

    Parameters
    ----------
    turbine_class : {"I", "II", "III"}
        Wind turbine class (V_ref 50, 42.5, 37.5 m/s). Class S (site-specific) is not a class
        the standard tabulates; ed. 2's class IV is not in ed. 3.
    turbulence_class : {"A", "B", "C"}
        Turbulence category (I_ref 0.16, 0.14, 0.12).
    hub_height : float
        z_hub [m].
    diameter : float
        Rotor diameter D [m].
    shear_exponent : float
        alpha of the normal wind profile (0.2, 6.3.1.2).
    cut_in, cut_out : float, optional
        The turbine's operating range [m/s]: operating events (EOG, EDC, ECD, EWS, ETM) outside
        it are refused.
    """

    turbine_class: str = "I"
    turbulence_class: str = "A"
    hub_height: float = 90.0
    diameter: float = 126.0
    shear_exponent: float = 0.2
    cut_in: float | None = None
    cut_out: float | None = None

    def __post_init__(self) -> None:
        tc = str(self.turbine_class).upper()
        if tc not in IEC_REFERENCE_SPEED:
            raise ValueError(f"turbine_class must be one of {list(IEC_REFERENCE_SPEED)} "
                             f"(IEC 61400-1 ed. 3, table 1), got {self.turbine_class!r}")
        cat = str(self.turbulence_class).upper()
        if cat not in IEC_TURBULENCE:
            raise ValueError(f"turbulence_class must be one of {list(IEC_TURBULENCE)} "
                             f"(IEC 61400-1 ed. 3, table 1), got {self.turbulence_class!r}")
        object.__setattr__(self, "turbine_class", tc)
        object.__setattr__(self, "turbulence_class", cat)
        _finite_positive("hub_height", self.hub_height)
        _finite_positive("diameter", self.diameter)
        if self.diameter > 2.0 * self.hub_height:
            raise ValueError(f"diameter ({self.diameter!r} m) must be at most twice the hub "
                             f"height ({self.hub_height!r} m): the rotor would hit the ground")
        a = float(self.shear_exponent)
        if not (math.isfinite(a) and 0.0 <= a < 1.0):
            raise ValueError(f"shear_exponent must be in [0, 1), got {self.shear_exponent!r}")
        if self.cut_in is not None and self.cut_out is not None \
                and not 0.0 < float(self.cut_in) < float(self.cut_out):
            raise ValueError(f"need 0 < cut_in < cut_out, got {self.cut_in!r}, "
                             f"{self.cut_out!r} m/s")

    @property
    def v_ref(self) -> float:
        """Reference wind speed V_ref [m/s] (table 1)."""
        return IEC_REFERENCE_SPEED[self.turbine_class]

    @property
    def i_ref(self) -> float:
        """Reference turbulence intensity I_ref [-] (table 1)."""
        return IEC_TURBULENCE[self.turbulence_class]

    @property
    def lambda_1(self) -> float:
        """Longitudinal turbulence scale parameter Lambda_1 [m] (eq 5)."""
        return 0.7 * self.hub_height if self.hub_height <= 60.0 else 42.0

    def extreme_speed(self, z: Any = None, years: int = 50) -> Any:
        """Extreme 10-min speed of the EWM: V_e50(z) = 1.4 V_ref (z / z_hub)^0.11 (eq 14) for
        a 50-year recurrence, V_e1 = 0.8 V_e50 (eq 15) for one year [m/s].

        Parameters
        ----------
        z : float or array, optional
            Height [m] (default the hub).
        years : {50, 1}
            Recurrence period.

        Returns
        -------
        float or ndarray
            [m/s].

        Raises
        ------
        ValueError
            A recurrence the standard does not give.
        """
        if years not in (50, 1):
            raise ValueError(f"years must be 50 or 1 (the EWM's recurrence periods), got "
                             f"{years!r}")
        z = self.hub_height if z is None else np.asarray(z, float)
        v50 = 1.4 * self.v_ref * (z / self.hub_height) ** 0.11
        return v50 if years == 50 else 0.8 * v50

    def magnitudes(self, v_hub: float) -> dict[str, float]:
        """The standard's magnitudes at a hub-height speed.

        Parameters
        ----------
        v_hub : float
            Hub-height speed [m/s].

        Returns
        -------
        dict
            ``sigma_ntm`` (eq 11: I_ref (0.75 V_hub + 5.6 m/s)), ``sigma_etm`` (eq 19: c I_ref
            (0.072 (V_ave / c + 3)(V_hub / c - 4) + 10), c = 2 m/s), ``eog_gust`` (eq 16:
            min(1.35 (V_e1 - V_hub), 3.3 sigma_1 / (1 + 0.1 D / Lambda_1)), sigma_1 of the NTM)
            [m/s]; ``edc_deg`` (eq 20: 4 arctan(sigma_1 / (V_hub (1 + 0.1 D / Lambda_1))), at
            most 180) and ``ecd_deg`` (eq 23: 180 below 4 m/s, else 720 deg m/s / V_hub) [deg];
            ``ews_amplitude`` (eqs 25-26: A = 2.5 m/s + 0.2 beta sigma_1 (D / Lambda_1)^(1/4),
            beta = 6.4; a point at (z - z_hub) / D, or y / D, gets A times that times (1 -
            cos(2 pi t / T)), so the rotor's edges differ by 2 A at the peak) [m/s].
        """
        v = float(v_hub)
        s1 = self.i_ref * (0.75 * v + 5.6)
        c, v_ave = 2.0, 0.2 * self.v_ref
        d_l = self.diameter / self.lambda_1
        return {"sigma_ntm": s1,
                "sigma_etm": c * self.i_ref * (0.072 * (v_ave / c + 3.0) * (v / c - 4.0) + 10.0),
                "eog_gust": min(1.35 * (float(self.extreme_speed(years=1)) - v),
                                3.3 * s1 / (1.0 + 0.1 * d_l)),
                "edc_deg": min(4.0 * math.degrees(math.atan(s1 / (v * (1.0 + 0.1 * d_l)))),
                               180.0),
                "ecd_deg": 180.0 if v < 4.0 else 720.0 / v,
                "ews_amplitude": 2.5 + 0.2 * _BETA * s1 * d_l ** 0.25}

    def check_speed(self, condition: str, v_hub: Any) -> float:
        """The hub speed of a condition, checked against what the standard allows.

        Parameters
        ----------
        condition : str
            One of :data:`CONDITIONS`.
        v_hub : float
            Hub-height speed [m/s].

        Returns
        -------
        float
            The speed.

        Raises
        ------
        ValueError
            A speed that is not finite and positive, an operating event outside the turbine's
            operating range (cut-in to cut-out), an ECD above V_ref, an EOG whose 1-year
            extreme speed is below the mean.
        """
        cond = str(condition).lower()
        event_duration(cond)
        v = _finite_positive("mean_speed", v_hub)
        if cond in ("nwp", "ntm"):
            return v
        lo, hi = self.cut_in, self.cut_out
        if hi is not None and v > float(hi) + 1e-9:
            raise ValueError(f"mean_speed {v:g} m/s is above the turbine's cut-out "
                             f"{float(hi):g} m/s: the standard's {cond.upper()} is an "
                             f"operating condition, V_in <= V_hub <= V_out")
        if lo is not None and v < float(lo) - 1e-9:
            raise ValueError(f"mean_speed {v:g} m/s is below the turbine's cut-in "
                             f"{float(lo):g} m/s: the standard's {cond.upper()} is an "
                             f"operating condition, V_in <= V_hub <= V_out")
        if cond == "ecd" and v > self.v_ref:
            raise ValueError(f"mean_speed {v:g} m/s is above V_ref = {self.v_ref:g} m/s of "
                             f"class {self.turbine_class}: the ECD is defined up to V_ref")
        if cond == "eog" and v >= float(self.extreme_speed(years=1)):
            raise ValueError(f"mean_speed {v:g} m/s is not below V_e1 = "
                             f"{float(self.extreme_speed(years=1)):g} m/s of class {self.turbine_class}")
        return v


def _transient(condition: str, mag: dict[str, float], tau: FloatArray, sign: float
               ) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Per time (relative to the event's start): speed added at every point [m/s], direction
    [rad], and the linear shear amplitude across the rotor A(t) [m/s] (multiplied by
    (z - z_hub) / D or y / D); ``mag``: :meth:`IECSite.magnitudes` at the hub speed."""
    T = CONDITIONS[condition]
    inside = (tau >= 0.0) & (tau <= T)
    x = np.where(inside, tau / T if T else 0.0, 0.0)
    after = tau > T
    gust = np.zeros_like(tau)
    theta = np.zeros_like(tau)
    shear = np.zeros_like(tau)
    if condition == "eog":
        vg = mag["eog_gust"]
        gust = np.where(inside, -0.37 * vg * np.sin(3 * np.pi * x) * (1 - np.cos(2 * np.pi * x)),
                        0.0)
    elif condition == "ecd":
        ramp = np.where(inside, 0.5 * (1 - np.cos(np.pi * x)), after.astype(float))
        gust = _V_CG * ramp
        theta = sign * math.radians(mag["ecd_deg"]) * ramp
    elif condition == "edc":
        ramp = np.where(inside, 0.5 * (1 - np.cos(np.pi * x)), after.astype(float))
        theta = sign * math.radians(mag["edc_deg"]) * ramp
    elif condition in ("ews-v", "ews-h"):
        shear = np.where(inside, sign * mag["ews_amplitude"] * (1 - np.cos(2 * np.pi * x)),
                         0.0)
    return gust, theta, shear


def iec_field(condition: str, mean_speed: float, site: IECSite, *, t_start: float = 30.0,
              duration: float | None = None, dt: float = 0.05, width: float | None = None,
              n: int = 32, sign: int = 1, seed: int | None = None) -> WindField:
    """An IEC 61400-1 ed. 3 wind condition as a wind field (module docstring).

    Parameters
    ----------
    condition : str
        "nwp", "ntm", "etm" (turbulent: the normal or extreme turbulence model's sigma_1 on the
        Kaimal field of :func:`generate_field`), "eog", "edc", "ecd", "ews-v", "ews-h".
    mean_speed : float
        V_hub [m/s].
    site : IECSite
        Class, category, hub height, rotor.
    t_start : float
        When the transient starts [s].
    duration : float, optional
        The field's length (default t_start + T + 30 s; 600 s for the turbulent ones) [s].
    dt : float
        Time step [s].
    width : float, optional
        Side of the square (y, z) grid (default 1.2 D) [m].
    n : int
        Points per side.
    sign : {1, -1}
        Direction of a direction change (EDC, ECD) or a shear (EWS).
    seed : int, optional
        Of a turbulent field.

    Returns
    -------
    WindField
        ``meta`` names the condition, class, the magnitudes and the event's start and T.

    Raises
    ------
    ValueError
        An unknown condition, a speed outside what the standard allows (:meth:`IECSite.
        check_speed`), a bad sign, time step or grid.
    """
    from lidar.turbulence import TurbulenceSpec, generate_field

    cond = str(condition).lower()
    T = event_duration(cond)
    v = site.check_speed(cond, mean_speed)
    if sign not in (1, -1):
        raise ValueError(f"sign must be 1 or -1, got {sign!r}")
    dt = _finite_positive("dt", dt)
    width = 1.2 * site.diameter if width is None else _finite_positive("width", width)
    if width / 2.0 >= site.hub_height:
        raise ValueError(f"width {width:g} m reaches the ground at hub height "
                         f"{site.hub_height:g} m")
    if int(n) != n or n < 2:
        raise ValueError(f"n must be an integer >= 2 points per side, got {n!r}")
    turbulent = cond in ("ntm", "etm")
    if duration is None:
        duration = 600.0 if turbulent else t_start + T + 30.0
    duration = _finite_positive("duration", duration)
    if not (math.isfinite(t_start) and 0.0 <= t_start):
        raise ValueError(f"t_start must be finite and >= 0, got {t_start!r}")
    meta: dict[str, Any] = {"model": "IEC 61400-1 ed. 3", "condition": cond,
                            "turbine_class": site.turbine_class,
                            "turbulence_class": site.turbulence_class,
                            "hub_height": site.hub_height, "diameter": site.diameter,
                            "shear_exponent": site.shear_exponent}
    mag = site.magnitudes(v)
    if turbulent:
        sigma = mag["sigma_ntm" if cond == "ntm" else "sigma_etm"]
        spec = TurbulenceSpec(v, sigma / v, hub_height=site.hub_height, width=width,
                              height=width, n_y=int(n), n_z=int(n), duration=duration, dt=dt,
                              shear_exponent=site.shear_exponent)
        f = generate_field(spec, seed)
        return WindField(t=f.t, y=f.y, z=f.z, u=f.u, v=f.v, w=f.w, mean_speed=v,
                         hub_height=site.hub_height,
                         meta={**f.meta, **meta, "sigma_1": sigma})
    t = np.arange(int(round(duration / dt)) + 1) * dt
    y = np.linspace(-width / 2, width / 2, int(n))
    z = site.hub_height + np.linspace(-width / 2, width / 2, int(n))
    gust, theta, shear = _transient(cond, mag, t - t_start, float(sign))
    profile = v * (z / site.hub_height) ** site.shear_exponent            # (n_z,)
    speed = profile[None, None, :] + gust[:, None, None]
    if cond == "ews-v":
        speed = speed + shear[:, None, None] * ((z - site.hub_height) / site.diameter)[None,
                                                                                        None, :]
    elif cond == "ews-h":
        speed = speed + shear[:, None, None] * (y / site.diameter)[None, :, None]
    speed = np.broadcast_to(speed, (t.size, y.size, z.size))
    c, s = np.cos(theta)[:, None, None], np.sin(theta)[:, None, None]
    u = (speed * c).astype(np.float32)
    vv = (speed * s).astype(np.float32)
    named = {"eog": ("gust_mps", mag["eog_gust"]),
             "ecd": ("direction_change_deg", sign * mag["ecd_deg"]),
             "edc": ("direction_change_deg", sign * mag["edc_deg"]),
             "ews-v": ("shear_amplitude_mps", sign * mag["ews_amplitude"]),
             "ews-h": ("shear_amplitude_mps", sign * mag["ews_amplitude"])}
    if cond in named:
        key, val = named[cond]
        meta[key] = val
    if cond == "ecd":
        meta["gust_mps"] = _V_CG
    meta.update(t_start=float(t_start), event_duration=T, sign=int(sign),
                sigma_1=mag["sigma_ntm"])
    return WindField(t=t, y=y, z=z, u=u, v=vv, w=np.zeros(u.shape, np.float32), mean_speed=v,
                     hub_height=site.hub_height, meta=meta)
