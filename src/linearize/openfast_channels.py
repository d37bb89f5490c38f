"""OpenFAST output channels and their units, mapped to mpc-wt's channel names in SI.

Shared by the ``.lin`` reader (:mod:`linearize.openfast_lin`) and ``mpc_wt``'s time-series
reader: one table, so a channel means the same in a linearization and in a simulation.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["CHANNEL_MAP", "UNIT_SCALE", "DEFAULT_UNITS", "SI_UNIT", "unit_key",
           "blade_frame_moment",
           "resolve_channels"]

_RPM = math.pi / 30.0
_DEG = math.pi / 180.0
#: OpenFAST unit -> factor to SI (lower case, "-" and "·" as OpenFAST writes them).
UNIT_SCALE = {
    "s": 1.0, "sec": 1.0, "-": 1.0, "": 1.0, "m": 1.0, "m/s": 1.0, "m/s^2": 1.0, "rad": 1.0,
    "rad/s": 1.0, "rad/s^2": 1.0, "n": 1.0, "n-m": 1.0, "nm": 1.0, "w": 1.0,
    "kn": 1e3, "kn-m": 1e3, "knm": 1e3, "kn·m": 1e3, "kw": 1e3, "mw": 1e6, "mn": 1e6,
    "mn-m": 1e6, "rpm": _RPM, "deg": _DEG, "deg/s": _DEG, "deg/s^2": _DEG,
}
_MOMENT = ("kn-m", "knm", "kn·m", "n-m", "nm", "mn-m")
_ANGLE = ("deg", "rad")
_SPEED = ("rpm", "rad/s")
#: OpenFAST channel -> (our channel, allowed units). Earlier entries of one of our channels
#: win over later ones. The blade root moments keep their frames: ElastoDyn's c-frame
#: (``RootMyc``, ``RootMxc``: out of and in the rotor plane) is ours ``flap_moment``,
#: ``edge_moment``; its b-frame, which pitches with the blade (``RootMyb``, ``RootMxb``:
#: flapwise and edgewise), is ours ``flapwise_moment``, ``edgewise_moment``.
CHANNEL_MAP: dict[str, tuple[str, tuple[str, ...]]] = {
    **{f"RootMyc{b}": (f"flap_moment_{b}", _MOMENT) for b in (1, 2, 3)},
    **{f"RootMxc{b}": (f"edge_moment_{b}", _MOMENT) for b in (1, 2, 3)},
    **{f"RootMyb{b}": (f"flapwise_moment_{b}", _MOMENT) for b in (1, 2, 3)},
    **{f"RootMxb{b}": (f"edgewise_moment_{b}", _MOMENT) for b in (1, 2, 3)},
    **{f"BldPitch{b}": (f"pitch_{b}", _ANGLE) for b in (1, 2, 3)},
    "TwrBsMyt": ("tower_base_fa_moment", _MOMENT),
    "TwrBsMxt": ("tower_base_ss_moment", _MOMENT),
    "LSShftMxa": ("lss_torque", _MOMENT),
    "RotTorq": ("lss_torque", _MOMENT),
    "YawBrMyp": ("tilt_moment", _MOMENT),
    "YawBrMzp": ("yaw_moment", _MOMENT),
    "LSSGagMya": ("shaft_bending_blade1", _MOMENT),
    "GenPwr": ("gen_power", ("kw", "w", "mw")),
    "GenSpeed": ("gen_speed", _SPEED),
    "RotSpeed": ("rotor_speed", _SPEED),
    "GenTq": ("gen_torque", _MOMENT),
    "RtAeroFxh": ("thrust", ("n", "kn", "mn")),
    "RtAeroMxh": ("aero_torque", _MOMENT),
    "RtAeroPwr": ("aero_power", ("w", "kw", "mw")),
    "RotThrust": ("thrust", ("kn", "n", "mn")),
    "RotPwr": ("aero_power", ("kw", "w", "mw")),
    "Azimuth": ("azimuth", _ANGLE),
    "TTDspFA": ("tower_fa_displacement", ("m",)),
    "TTDspSS": ("tower_ss_displacement", ("m",)),
    "YawBrTAxp": ("tower_fa_acceleration", ("m/s^2",)),
    "YawBrTAyp": ("tower_ss_acceleration", ("m/s^2",)),
    "Wind1VelX": ("hub_wind_speed", ("m/s",)),
}


#: The unit OpenFAST writes for each mapped channel, assumed for a CSV column without one.
DEFAULT_UNITS = {**{k: "kN-m" for k, (_, u) in CHANNEL_MAP.items() if u == _MOMENT},
                 **{k: "deg" for k, (_, u) in CHANNEL_MAP.items() if u == _ANGLE},
                 **{k: "rpm" for k, (_, u) in CHANNEL_MAP.items() if u == _SPEED},
                 "GenPwr": "kW", "RotPwr": "kW", "RotThrust": "kN", "TTDspFA": "m",
                 "TTDspSS": "m", "YawBrTAxp": "m/s^2", "YawBrTAyp": "m/s^2", "Wind1VelX": "m/s",
                 "RtAeroFxh": "N", "RtAeroMxh": "N-m", "RtAeroPwr": "W"}


#: The SI unit a channel has after conversion, by its OpenFAST unit.
SI_UNIT = {"kn-m": "N m", "knm": "N m", "kn·m": "N m", "n-m": "N m", "nm": "N m",
           "mn-m": "N m", "kn": "N", "n": "N", "mn": "N", "kw": "W", "w": "W", "mw": "W",
           "deg": "rad", "rad": "rad", "rpm": "rad/s", "rad/s": "rad/s", "deg/s": "rad/s",
           "deg/s^2": "rad/s^2", "rad/s^2": "rad/s^2", "m": "m", "m/s": "m/s",
           "m/s^2": "m/s^2", "s": "s", "sec": "s", "-": "-", "": "-"}


def unit_key(unit: str) -> str:
    """A unit as the tables key it: lower case, no brackets or spaces.

    Parameters
    ----------
    unit : str
        A unit as written in a file.

    Returns
    -------
    str
        The key.
    """
    return unit.strip().strip("()[]").strip().lower().replace(" ", "")


def resolve_channels(names: list[str] | tuple[str, ...], units: list[str] | tuple[str, ...],
                     source: str = "") -> list[tuple[str, float]]:
    """For each OpenFAST channel, (name, factor to SI): our name for a mapped channel, unless
    another channel of the file maps to the same one of ours with higher priority (earlier in
    :data:`CHANNEL_MAP`) or the channel is not in the map; then its own name. The factor is from
    :data:`UNIT_SCALE`, NaN for a unit it does not know.

    Parameters
    ----------
    names : sequence of str
        The file's channel names.
    units : sequence of str
        Their units, as written.
    source : str
        The file, for messages.

    Returns
    -------
    list of (str, float)
        Name and factor to SI per channel.

    Raises
    ------
    ValueError
        A mapped channel with a unit the map does not allow, naming channel, unit and the
        allowed ones.
    """
    order = {k: i for i, k in enumerate(CHANNEL_MAP)}
    best: dict[str, tuple[int, int]] = {}
    for j, (name, unit) in enumerate(zip(names, units)):
        if name in CHANNEL_MAP:
            ours, allowed = CHANNEL_MAP[name]
            if unit_key(unit) not in allowed:
                raise ValueError(f"{source}: channel {name!r} has unit {unit!r}; allowed "
                                 f"{list(allowed)} (it maps to {ours!r})")
            if ours not in best or order[name] < best[ours][0]:
                best[ours] = (order[name], j)
    winner = {j: ours for ours, (_, j) in best.items()}
    return [(winner.get(j, name), UNIT_SCALE.get(unit_key(unit), math.nan))
            for j, (name, unit) in enumerate(zip(names, units))]


def blade_frame_moment(name: str, pitch: np.ndarray, flap: np.ndarray,
                       edge: np.ndarray) -> np.ndarray:
    """A blade root moment in the frame that pitches with the blade (ElastoDyn's b-frame) from
    the out-of-plane and in-plane ones (its c-frame), turned by the pitch beta (positive to
    feather; Jonkman 2007, NREL/TP-500-41958, the blade coordinate systems):
    flapwise = cos(beta) M_out + sin(beta) M_in, edgewise = cos(beta) M_in - sin(beta) M_out.

    Parameters
    ----------
    name : str
        ``flapwise_moment_i`` or ``edgewise_moment_i``.
    pitch : ndarray
        Blade pitch [rad].
    flap, edge : ndarray
        Out-of-plane and in-plane root moments [N m].

    Returns
    -------
    ndarray
        [N m]
    """
    c, s = np.cos(pitch), np.sin(pitch)
    if name.startswith("flapwise"):
        return c * flap + s * edge
    if name.startswith("edgewise"):
        return c * edge - s * flap
    raise KeyError(f"no blade-frame moment {name!r}; allowed flapwise_moment_i, "
                   f"edgewise_moment_i")
