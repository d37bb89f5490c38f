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

est = mpc_wt.WindSpeedEstimator(turbine, dt=0.1)
k = slice(None, None, 8)                          # the plant runs at 80 Hz, the estimator at 10
pitch = (res.channel("pitch_1") + res.channel("pitch_2") + res.channel("pitch_3")) / 3.0
estimate = [est.step(w, p, q) for w, p, q in zip(res.channel("rotor_speed")[k], pitch[k],
                                                 res.channel("gen_torque")[k])]

_, field = make_wind(turbine, scenario, "u")       # the simulator's field
truth = lidar.rotor_effective_wind(field, turbine.geometry.tip_radius, method="cube")

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(field.t, truth, label="rotor-effective wind of the field (simulator)")
ax.plot(res.t[k], estimate, label="estimate from rotor speed, pitch, torque")
ax.set_xlim(0, 120)
ax.set_xlabel("time [s]")
ax.set_ylabel("wind speed [m/s]")
ax.legend(fontsize=8)
fig.tight_layout()
err = np.array(estimate)[res.t[k] >= 30] - np.interp(res.t[k][res.t[k] >= 30], field.t, truth)
print(f"bias {err.mean():+.2f} m/s, RMS error {np.sqrt(np.mean(err**2)):.2f} m/s")
