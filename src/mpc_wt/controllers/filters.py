"""Discrete filters of the controllers: Butterworth high- and low-pass and notches as
second-order sections (scipy.signal), and a bank that filters several signals sample by
sample."""
from __future__ import annotations

import math
from typing import Any, Sequence

import numba as nb
import numpy as np
from scipy import signal

from linearize.validate import check_number

__all__ = ["check_corner", "filter_sos", "SOSFilterBank", "MeanTracker"]


def check_corner(name: str, freq_hz: float, fs: float) -> float:
    """A filter corner frequency: finite and strictly between 0 and the Nyquist frequency.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    freq_hz : float
        The corner [Hz].
    fs : float
        Sample rate [Hz].

    Returns
    -------
    float
        The corner [Hz].

    Raises
    ------
    ValueError
        If it is not in (0, fs / 2).
    """
    f = float(freq_hz)
    if not (math.isfinite(f) and 0.0 < f < 0.5 * fs):
        raise ValueError(f"{name} = {freq_hz!r} Hz must be in (0, Nyquist = {0.5 * fs:g} Hz) at "
                         f"the controller rate {fs:g} Hz")
    return f


def filter_sos(fs: float, *, highpass_hz: float | None = None, highpass_order: int = 1,
               notch_hz: Sequence[float] = (), notch_q: float = 1.0,
               lowpass_hz: float | None = None, lowpass_order: int = 2) -> np.ndarray:
    """Second-order sections of a discrete filter chain at sample rate ``fs`` [Hz]: Butterworth
    high-pass, notches (band-stop, quality ``notch_q``: bandwidth f0 / Q) and Butterworth
    low-pass (scipy.signal). An empty chain is the identity.


    Parameters
    ----------
    fs : float
        Sample rate [Hz].
    highpass_hz : float, optional
        High-pass corner [Hz].
    highpass_order : int
        Its order.
    notch_hz : sequence of float
        Notch centres [Hz].
    notch_q : float
        Notch quality factor [-].
    lowpass_hz : float, optional
        Low-pass corner [Hz].
    lowpass_order : int
        Its order.

    Returns
    -------
    (n_sections, 6) ndarray
        Second-order sections.

    Raises
    ------
    ValueError
        If a corner is not in (0, fs / 2) (names the parameter) or an order or Q is not positive.
    """
    check_number("fs", fs, lo=0.0, lo_open=True, unit="Hz")
    sos = [np.array([[1.0, 0.0, 0.0, 1.0, 0.0, 0.0]])]
    if highpass_hz is not None:
        if int(highpass_order) < 1:
            raise ValueError(f"highpass_order must be >= 1, got {highpass_order!r}")
        sos.append(signal.butter(int(highpass_order), check_corner("highpass_hz", highpass_hz, fs),
                                 "highpass", fs=fs, output="sos"))
    if notch_hz is not None and len(notch_hz):
        if not notch_q > 0:
            raise ValueError(f"notch_q must be > 0, got {notch_q!r}")
        for f0 in notch_hz:
            b, a = signal.iirnotch(check_corner("notch_hz", f0, fs), notch_q, fs=fs)
            sos.append(signal.tf2sos(b, a))
    if lowpass_hz is not None:
        if int(lowpass_order) < 1:
            raise ValueError(f"lowpass_order must be >= 1, got {lowpass_order!r}")
        sos.append(signal.butter(int(lowpass_order), check_corner("lowpass_hz", lowpass_hz, fs),
                                 "lowpass", fs=fs, output="sos"))
    return np.vstack(sos)


@nb.njit(cache=True, nogil=True)
def _sos_step(sos: np.ndarray, zi: np.ndarray, x: np.ndarray, y: np.ndarray) -> None:
    """One sample of each channel through the cascade, transposed direct form II; ``zi``
    (n_sections, 2, n_channels) is updated in place."""
    for c in range(x.size):
        v = x[c]
        for k in range(sos.shape[0]):
            b0, b1, b2, a1, a2 = sos[k, 0], sos[k, 1], sos[k, 2], sos[k, 4], sos[k, 5]
            out = b0 * v + zi[k, 0, c]
            zi[k, 0, c] = b1 * v - a1 * out + zi[k, 1, c]
            zi[k, 1, c] = b2 * v - a2 * out
            v = out
        y[c] = v


class SOSFilterBank:
    """The same discrete filter on ``n_channels`` signals, one sample at a time.

    ``step(x)`` filters one sample of each channel ((n_channels,) in and out) in transposed
    direct form II, as :func:`scipy.signal.sosfilt` does, with its carried state (compiled: a
    call of ``sosfilt`` per sample costs more than the whole plant's step); the first sample
    initialises the state to the steady state of that input (no start-up transient).

    Parameters
    ----------
    sos : (n_sections, 6) ndarray
        The filter.
    n_channels : int
        Number of signals.
    """

    def __init__(self, sos: np.ndarray, n_channels: int) -> None:
        self.sos = np.ascontiguousarray(np.atleast_2d(np.asarray(sos, float)))
        if self.sos.ndim != 2 or self.sos.shape[1] != 6:
            raise ValueError(f"sos has shape {self.sos.shape}; expected (n_sections, 6)")
        if not np.allclose(self.sos[:, 3], 1.0):
            raise ValueError(f"sos[:, 3] (each section's a0) must be 1, got {self.sos[:, 3]}")
        self.n = int(n_channels)
        self._zi1 = signal.sosfilt_zi(self.sos)            # (n_sections, 2) for a unit step
        self.reset()

    def reset(self) -> None:
        """Forget the filter state."""
        self.zi: np.ndarray | None = None

    def step(self, x: Any) -> np.ndarray:
        """Filter one sample per channel.

        Parameters
        ----------
        x : (n_channels,) array_like
            One sample of each signal.

        Returns
        -------
        (n_channels,) ndarray
            The filtered sample.
        """
        x = np.asarray(x, float).reshape(self.n)
        if self.zi is None:
            self.zi = np.ascontiguousarray(self._zi1[:, :, None] * x[None, None, :])
        y = np.empty(self.n)
        _sos_step(self.sos, self.zi, x, y)
        return y

    def response(self, freq_hz: Any, fs: float) -> np.ndarray:
        """Complex frequency response at ``freq_hz``.

        Parameters
        ----------
        freq_hz : array_like
            Frequencies [Hz].
        fs : float
            Sample rate [Hz].

        Returns
        -------
        ndarray
            Complex response at each frequency [-].
        """
        return signal.sosfreqz(self.sos, worN=np.atleast_1d(np.asarray(freq_hz, float)),
                               fs=fs)[1]


class MeanTracker:
    """The mean of a measured signal over about the last ``time_constant``: the average of
    every sample while fewer than ``time_constant / dt`` have come (so the start is not one
    sample's), then a first-order low-pass with that time constant.

    Parameters
    ----------
    time_constant : float
        [s], > 0.
    dt : float
        Sample period [s], > 0.
    """

    def __init__(self, time_constant: float, dt: float) -> None:
        if not (math.isfinite(time_constant) and time_constant > 0):
            raise ValueError(f"time_constant must be > 0 s, got {time_constant!r}")
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be > 0 s, got {dt!r}")
        self.alpha = min(1.0, dt / time_constant)
        self.reset()

    def reset(self) -> None:
        """Forget every sample."""
        self.n = 0
        self.value: float | None = None

    def update(self, x: float) -> float:
        """Take one sample; the mean.

        Parameters
        ----------
        x : float
            The sample.

        Returns
        -------
        float
            The mean so far.
        """
        self.n += 1
        if self.value is None:
            self.value = float(x)
        else:
            self.value += max(1.0 / self.n, self.alpha) * (float(x) - self.value)
        return self.value
