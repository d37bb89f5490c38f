"""
Damage-equivalent loads over a lifetime
=======================================

Rainflow-count a load series (ASTM E1049-85), then combine short-term damage-equivalent loads
of several wind bins into a lifetime DEL with the Rayleigh wind distribution of IEC class II.
"""
import matplotlib.pyplot as plt
import numpy as np

from mpc_wt.assessment import damage_equivalent_load, lifetime_del, wind_bin_probabilities

rng = np.random.default_rng(0)
winds = np.arange(4.0, 25.0, 2.0)
t = np.arange(0.0, 600.0, 0.05)
dels = []
for v in winds:          # a synthetic load: 1P cycles growing with the wind, plus noise
    load = v * 0.1e6 * np.sin(2 * np.pi * 0.2 * t) + 0.05e6 * v * rng.standard_normal(t.size)
    dels.append(damage_equivalent_load(load, 10.0, duration=600.0))
p = wind_bin_probabilities(winds, "rayleigh", mean=8.5)
life = lifetime_del(dels, 10.0, p)

fig, ax1 = plt.subplots(figsize=(6, 3.5))
ax1.bar(winds, p, width=1.5, alpha=0.4, label="probability")
ax1.set_xlabel("mean wind speed [m/s]")
ax1.set_ylabel("bin probability [-]")
ax2 = ax1.twinx()
ax2.plot(winds, np.array(dels) / 1e6, "ko-", label="short-term DEL")
ax2.axhline(life / 1e6, color="r", label=f"lifetime DEL {life / 1e6:.2f} MN m")
ax2.set_ylabel("DEL, m = 10 [MN m]")
ax2.legend(loc="upper left", fontsize=8)
fig.tight_layout()
