"""Write the sign-off's deterministic wind files: a ramp through the region-2/3 transition.

``ramp_8_14_8.npz``: a uniform, sheared (power law 0.2) wind at the NREL 5-MW's hub height,
8 m/s for the campaign's 60 s transient and 10 s more, a linear ramp to 14 m/s over 60 s, back
to 8 m/s over 60 s, then 8 m/s for 20 s (the ramp up and down in 120 s). Run:

    python benchmarks/studies/winds/make_winds.py
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

import lidar

HUB, RADIUS, SHEAR = 90.0, 63.0, 0.2


def ramp_field(v0: float = 8.0, v1: float = 14.0, t_start: float = 70.0, t_ramp: float = 60.0,
               t_end: float = 230.0, dt: float = 0.05) -> lidar.WindField:
    """The ramp v0 -> v1 -> v0 as a frozen-free uniform field (every point sees it at once)."""
    t = np.arange(0.0, t_end + dt / 2, dt)
    hub = np.interp(t, [0.0, t_start, t_start + t_ramp, t_start + 2 * t_ramp, t_end],
                    [v0, v0, v1, v0, v0])
    y = np.linspace(-1.1 * RADIUS, 1.1 * RADIUS, 7)
    z = HUB + np.linspace(-1.1 * RADIUS, 1.1 * RADIUS, 7)
    prof = (z / HUB) ** SHEAR
    u = hub[:, None, None] * prof[None, None, :] * np.ones((1, y.size, 1))
    zero = np.zeros_like(u)
    return lidar.WindField(t=t, y=y, z=z, u=u, v=zero, w=zero, mean_speed=float(np.mean(hub)),
                           hub_height=HUB, meta={"kind": "ramp", "v0": v0, "v1": v1,
                                                 "t_start": t_start, "t_ramp": t_ramp,
                                                 "shear_exponent": SHEAR})


if __name__ == "__main__":
    out = Path(__file__).with_name("ramp_8_14_8.npz")
    ramp_field().save(out)
    print(f"wrote {out} ({out.stat().st_size / 1e3:.0f} kB)")
