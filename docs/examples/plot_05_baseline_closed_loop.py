"""
The baseline controller in the closed loop
==========================================

Run the tuned baseline PI and torque law for 60 s of class-A turbulence at 18 m/s on the
nonlinear plant and plot what it measures and commands.
"""
import matplotlib.pyplot as plt

import linearize
import mpc_wt

turbine = linearize.load_turbine("nrel5mw")
scenario = mpc_wt.Scenario(18.0, turbulence="A", seed=1, duration=60.0)
res = mpc_wt.run_controller(turbine, "baseline", scenario)

fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 6))
axes[0].plot(res.t, res.channel("gen_power") / 1e6)
axes[0].set_ylabel("electrical power [MW]")
axes[1].plot(res.t, res.channel("rotor_speed") * 30 / 3.141592653589793)
axes[1].set_ylabel("rotor speed [rpm]")
axes[2].plot(res.t, res.channel("pitch_1") * 180 / 3.141592653589793)
axes[2].set_ylabel("pitch [deg]")
axes[2].set_xlabel("time [s]")
fig.tight_layout()
