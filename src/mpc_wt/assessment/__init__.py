"""Assessment of closed-loop series: fatigue, performance, run summaries, ultimate loads.

Pure functions on arrays: rainflow counting and damage-equivalent loads (:mod:`.fatigue`),
covariance ellipses, spectra, pitch duty and energy (:mod:`.performance`), the run-level
summary of a result's channels (:mod:`.series`), extremes and their statistical extrapolation
(:mod:`.ultimate`), and the LIDAR's preview quality (:mod:`.lidar`).
"""
from mpc_wt.assessment.fatigue import (
                                       DEL_CONVENTIONS,
                                       WOEHLER_EXPONENTS,
                                       CycleCount,
                                       DELConvention,
                                       cycle_count,
                                       damage_equivalent_load,
                                       del_convention,
                                       lifetime_del,
                                       lifetime_extension,
                                       miner_damage,
                                       rainflow,
                                       wind_bin_probabilities,
)
from mpc_wt.assessment.performance import (
                                       CSMeasures,
                                       aep_Wh,
                                       cs_measures,
                                       energy_Wh,
                                       harmonic_psd,
                                       pct_change,
                                       pitch_duty,
                                       psd,
                                       tracking_response,
)
from mpc_wt.assessment.series import (
                                       DEFAULT_CHANNELS,
                                       assess_series,
                                       lifetime_comparison,
                                       reductions,
)

__all__ = ["DEL_CONVENTIONS", "WOEHLER_EXPONENTS", "CycleCount", "DELConvention", "cycle_count",
           "damage_equivalent_load", "del_convention", "lifetime_del", "lifetime_extension",
           "miner_damage", "rainflow", "wind_bin_probabilities", "CSMeasures", "aep_Wh",
           "cs_measures", "energy_Wh", "harmonic_psd", "pct_change", "pitch_duty", "psd",
           "tracking_response", "DEFAULT_CHANNELS", "assess_series", "lifetime_comparison",
           "reductions"]
