"""Active power control: the power reference of Clemens et al. (eq 11) and the power weight.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from linearize.validate import check_number

__all__ = ["check_weight_range", "apc_reference", "power_weight", "PowerReduction",
           "PowerReference"]


@dataclass(frozen=True)
class PowerReduction:
    """Delta P(t) = offset + amplitude sin(2 pi f_r t) (Clemens eq 11) [-]; call with t [s].

    Parameters
    ----------
    frequency_hz : float
        f_r [Hz].
    amplitude : float
        [-]
    offset : float
        [-]
    """

    frequency_hz: float
    amplitude: float
    offset: float

    def __call__(self, t: float) -> float:
        return self.offset + self.amplitude * math.sin(2.0 * math.pi * self.frequency_hz * t)


@dataclass(frozen=True)
class PowerReference:
    """The power reference P_r (1 - Delta P(t)) [W]; call with t [s].

    Parameters
    ----------
    rated_power_W : float
        P_r [W].
    reduction : PowerReduction
        Delta P.
    """

    rated_power_W: float
    reduction: PowerReduction

    def __call__(self, t: float) -> float:
        return self.rated_power_W * (1.0 - self.reduction(t))


# --------------------------------------------------------------------------------------------
# Active power control reference
# --------------------------------------------------------------------------------------------
def apc_reference(frequency_hz: float, *, amplitude: float = 0.375, offset: float = 0.375
                  ) -> PowerReduction:
    """Power reduction Delta P(t) = offset + amplitude sin(2 pi f_r t) (Clemens eq 11); the
    power reference is P_r (1 - Delta P).

    Eq 11 as printed, Delta P = 3/4 sin(2 pi f_r t), asks for up to 175 % of rated power when
    the sine is negative, which no generator at rated can give; the default keeps the printed
    peak reduction 3/4 and shifts the sine into [0, 3/4].


    Parameters
    ----------
    frequency_hz : float
        f_r [Hz], >= 0 (0: a constant reduction at the offset).
    amplitude : float
        Amplitude of Delta P (fraction of rated) [-].
    offset : float
        Mean of Delta P [-].

    Returns
    -------
    PowerReduction
        t [s] -> Delta P(t) [-].

    Raises
    ------
    ValueError
        If the frequency is negative or not finite, or Delta P leaves [0, 1): a reduction below
        0 asks for more than rated power, one of 1 or more for no power at all.
    """
    f = check_number("frequency_hz", frequency_hz, lo=0.0)
    a, o = float(amplitude), float(offset)
    if not (math.isfinite(a) and math.isfinite(o) and a >= 0):
        raise ValueError(f"amplitude must be finite and >= 0 and offset finite, got {amplitude!r}"
                         f", {offset!r}")
    if o - a < -1e-12:
        raise ValueError(f"offset - amplitude = {o - a:g}: the power reference would rise to "
                         f"{100 * (1 - o + a):.0f} % of rated, above the power available at rated; "
                         f"need offset >= amplitude")
    if o + a >= 1.0:
        raise ValueError(f"offset + amplitude = {o + a:g}: the power reference would fall to "
                         f"{100 * (1 - o - a):.0f} % of rated; need offset + amplitude < 1")
    return PowerReduction(f, a, o)


def power_weight(power_W: float, rated_power_W: float, weight_range: tuple[float, float]) -> float:
    """Activation weight rising linearly from 0 at ``weight_range[0]`` P_r to 1 at
    ``weight_range[1]`` P_r (Pettas and Cheng sec. 3.1) [-].

    Parameters
    ----------
    power_W : float
        Power [W].
    rated_power_W : float
        Rated (or derated) power [W].
    weight_range : (float, float)
        Power fractions where the weight starts and reaches 1 [-].

    Returns
    -------
    float
        The weight in [0, 1].
    """
    lo, hi = weight_range
    return float(min(max((power_W / rated_power_W - lo) / (hi - lo), 0.0), 1.0))


def check_weight_range(weight_range: tuple[float, float]) -> tuple[float, float]:
    """The power fractions between which a power-dependent weight ramps, checked.

    Parameters
    ----------
    weight_range : (float, float)
        Lower and upper power fraction, 0 <= lo < hi <= 1 [-].

    Returns
    -------
    (float, float)
        The two fractions as floats.

    Raises
    ------
    ValueError
        If they are not ordered within [0, 1].
    """
    lo, hi = (float(v) for v in weight_range)
    if not (0.0 <= lo < hi <= 1.0):
        raise ValueError(f"weight_range must be two power fractions 0 <= lo < hi <= 1, got "
                         f"{weight_range!r}")
    return lo, hi
