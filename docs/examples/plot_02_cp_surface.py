"""
Power-coefficient surface
=========================

The BEM plant's power coefficient over tip-speed ratio and blade pitch, and the optimum that
the baseline's torque law tracks below rated.
"""
import matplotlib.pyplot as plt
import numpy as np

import linearize

turbine = linearize.load_turbine("nrel5mw")
tsr = np.linspace(3.0, 12.0, 19)
pitch_deg = np.linspace(-2.0, 10.0, 13)
cp, ct = linearize.steady_coefficients(turbine, tsr[:, None], pitch_deg[None, :])
tsr_opt, cp_max = linearize.optimal_tsr(turbine, 0.0)

fig, ax = plt.subplots(figsize=(6, 4))
levels = np.linspace(0.0, 0.5, 11)
cs = ax.contourf(tsr, pitch_deg, np.clip(cp, 0.0, None).T, levels=levels)
fig.colorbar(cs, label="power coefficient C_P [-]")
ax.plot(tsr_opt, 0.0, "r*", markersize=12, label=f"C_P max {cp_max:.3f}")
ax.set_xlabel("tip-speed ratio [-]")
ax.set_ylabel("blade pitch [deg]")
ax.legend()
fig.tight_layout()
