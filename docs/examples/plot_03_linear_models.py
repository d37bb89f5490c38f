"""
Linear models over mean wind
============================

Linearize the plant at operating points from 6 to 24 m/s and look at what a controller
designer needs: the power's sensitivity to pitch, which the baseline's gain schedule follows,
and the poles of the linear models.
"""
import matplotlib.pyplot as plt
import numpy as np

import linearize

turbine = linearize.load_turbine("nrel5mw")
family = linearize.linearize_family(turbine, np.arange(6.0, 24.1, 3.0),
                                    config=linearize.PlantConfig.madsen())
dp_dpitch = [linearize.sensitivities(m)["dP_dpitch_W_per_rad"] / 1e6 for m in family.models]

fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
axes[0].plot(family.wind_mps, dp_dpitch, "o-")
axes[0].set_xlabel("mean wind speed [m/s]")
axes[0].set_ylabel("dP/dpitch [MW/rad]")
for v, m in zip(family.wind_mps, family.models):
    poles = np.linalg.eigvals(m.A)
    axes[1].plot(poles.real, poles.imag / (2 * np.pi), ".", label=f"{v:g} m/s")
axes[1].set_xlabel("real part [1/s]")
axes[1].set_ylabel("damped frequency [Hz]")
axes[1].set_xlim(-3.0, 0.5)
axes[1].legend(fontsize=7)
fig.tight_layout()
