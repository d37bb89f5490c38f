"""
MPC with LIDAR preview against the baseline
===========================================

Madsen's Coleman-weighted MPC with per-blade LIDAR preview and the baseline on the same 60 s
turbulent field, with the blade-root flap moment's damage-equivalent load of each.
"""
import matplotlib.pyplot as plt

import linearize
import mpc_wt

turbine = linearize.load_turbine("nrel5mw")
scenario = mpc_wt.Scenario(18.0, turbulence="A", seed=2, duration=60.0)
runs = {name: mpc_wt.run_controller(turbine, name, scenario) for name in ("baseline", "mpc-lidar")}

fig, ax = plt.subplots(figsize=(7, 3.5))
for name, res in runs.items():
    flap = res.channel("flap_moment_1")
    d = mpc_wt.damage_equivalent_load(flap, 10.0, duration=60.0)
    ax.plot(res.t, flap / 1e6, label=f"{name}: DEL {d / 1e6:.2f} MN m (m = 10)")
ax.set_xlabel("time [s]")
ax.set_ylabel("blade-1 flap moment [MN m]")
ax.legend(fontsize=8)
fig.tight_layout()
