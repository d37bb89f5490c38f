"""
Turbulent wind and the LIDAR's preview
======================================

Generate a short IEC class-A turbulent field at 18 m/s, let the hub-mounted continuous-wave
LIDAR measure it ahead of the rotor, and compare each beam's estimate with the wind its blade
meets a preview time later.
"""
import matplotlib.pyplot as plt
import numpy as np

import lidar
import linearize

turbine = linearize.load_turbine("nrel5mw")
spec = lidar.TurbulenceSpec(mean_speed=18.0, turbulence="A",
                            hub_height=turbine.geometry.hub_height, duration=120.0,
                            dt=0.1, width=150.0, height=150.0, n_y=16, n_z=16)
field = lidar.generate_field(spec, seed=3)

omega = 12.1 * np.pi / 30                      # rated rotor speed [rad/s]
cw = lidar.CWLidar(turbine.geometry.tip_radius, focus_distance=80.0, sample_rate=10.0)
t = np.arange(0.0, 100.0, 0.1)
meas = cw.measure(field, t, omega * t, omega)
tp = meas.preview_time
met = lidar.blade_effective_wind(field, t + tp, omega * (t + tp), cw.radius)

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(t + tp, meas.u_hat[:, 0], label="LIDAR, beam 1 (shifted by the preview time)")
ax.plot(t + tp, met[:, 0], label="wind blade 1 meets")
ax.set_xlabel("time [s]")
ax.set_ylabel("longitudinal wind [m/s]")
ax.set_title(f"preview time {tp:.2f} s")
ax.legend(fontsize=8)
fig.tight_layout()
