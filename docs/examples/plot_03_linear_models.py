"""
Linear models over mean wind
============================

Linearize the plant (all degrees of freedom) at operating points from 6 to 24 m/s and look at
what a controller designer needs: the power's sensitivity to pitch, which the baseline's gain
schedule follows, and the structural modes of each linear model.
"""
import matplotlib.pyplot as plt
import numpy as np

import linearize

turbine = linearize.load_turbine("nrel5mw")
family = linearize.linearize_family(turbine, np.arange(6.0, 24.1, 3.0))
dp_dpitch = [linearize.sensitivities(m)["dP_dpitch_W_per_rad"] / 1e6 for m in family.models]

fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
axes[0].plot(family.wind_mps, dp_dpitch, "o-")
axes[0].set_xlabel("mean wind speed [m/s]")
axes[0].set_ylabel("dP/dpitch [MW/rad]")
for v, m in zip(family.wind_mps, family.models):
    modes = m.modes()
    axes[1].plot([x["frequency_Hz"] for x in modes], [100 * x["damping_ratio"] for x in modes],
                 "o", label=f"{v:g} m/s")
axes[1].set_xlabel("natural frequency [Hz]")
axes[1].set_ylabel("damping ratio [%]")
axes[1].set_yscale("log")
axes[1].legend(fontsize=7)
print("modes at 18 m/s:", ", ".join(f"{x['name']} {x['frequency_Hz']:.2f} Hz"
                                    for x in family.at(18.0).modes()))
fig.tight_layout()
