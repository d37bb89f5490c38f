"""
Steady operating schedule
=========================

Trim the NREL 5-MW from cut-in to cut-out: blade pitch, rotor speed and electrical power
against mean wind, the schedule every controller in mpc-wt starts from.
"""
import matplotlib.pyplot as plt
import numpy as np

import linearize

turbine = linearize.load_turbine("nrel5mw")
winds = np.arange(4.0, 25.01, 1.0)
points = linearize.operating_schedule(turbine, winds)

fig, axes = plt.subplots(3, 1, sharex=True, figsize=(6, 6))
axes[0].plot(winds, [np.degrees(p.pitch_rad) for p in points], "o-")
axes[0].set_ylabel("pitch [deg]")
axes[1].plot(winds, [p.rotor_speed_rad_s * 30 / np.pi for p in points], "o-")
axes[1].set_ylabel("rotor speed [rpm]")
axes[2].plot(winds, [p.power / 1e6 for p in points], "o-")
axes[2].set_ylabel("electrical power [MW]")
axes[2].set_xlabel("mean wind speed [m/s]")
print(f"rated wind speed {linearize.rated_wind_speed(turbine):.2f} m/s")
fig.tight_layout()
