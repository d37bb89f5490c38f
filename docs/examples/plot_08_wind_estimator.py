"""
The wind a controller can know
==============================

Estimate the rotor-effective wind speed from the measured rotor speed, pitch and generator
torque only (an extended Kalman filter, as ROSCO's), on a 120 s turbulent run of the baseline
at 12 m/s, and compare it with the true rotor-effective wind of the field, which only the
simulator knows.
"""
import matplotlib.pyplot as plt
import numpy as np

import lidar
import linearize
import mpc_wt
from mpc_wt.simulation import make_wind

turbine = linearize.load_turbine("nrel5mw")
scenario = mpc_wt.Scenario(12.0, turbulence="A", seed=3, duration=120.0)
res = mpc_wt.run_controller(turbine, "baseline", scenario)

# the shipped laws' estimator replayed on the run's measurements (10 Hz on the 80 Hz plant)
t_est, estimate = mpc_wt.estimate_wind(turbine, res)

_, field = make_wind(turbine, scenario, "u")       # the simulator's field
truth = lidar.rotor_effective_wind(field, turbine.geometry.tip_radius, method="cube")

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(field.t, truth, label="rotor-effective wind of the field (simulator)")
ax.plot(t_est, estimate, label="estimate from rotor speed, pitch, torque")
ax.set_xlim(0, 120)
ax.set_xlabel("time [s]")
ax.set_ylabel("wind speed [m/s]")
ax.legend(fontsize=8)
fig.tight_layout()
late = t_est >= 30
err = estimate[late] - np.interp(t_est[late], field.t, truth)
print(f"bias {err.mean():+.2f} m/s, RMS error {np.sqrt(np.mean(err**2)):.2f} m/s")
