"""Turbulent wind fields and a hub-mounted continuous-wave LIDAR with per-blade preview.

This package imports neither ``linearize`` nor ``mpc_wt``; turbine geometry arrives as numbers.
"""
from lidar.coherence import coherence_corner_model, rotor_coherence_model
from lidar.cw import CWLidar, LidarMeasurement, LidarSensor
from lidar.errors import FieldFileError
from lidar.field import WindField
from lidar.points import PointLidar
from lidar.iec import (
           CONDITIONS,
           IEC_REFERENCE_SPEED,
           IEC_TURBULENCE,
           IECSite,
           event_duration,
           iec_field,
)
from lidar.preview import (
           Preview,
           PreviewBuffer,
           blade_effective_wind,
           coherence,
           coherence_bandwidth,
           peak_lag,
           preview,
           preview_series,
           rms_preview_error,
           rotor_effective_wind,
)
from lidar.turbulence import (
           SamplerCache,
           TurbulenceSpec,
           evolution_coherence,
           evolve_field,
           generate_evolved_field,
           generate_field,
           iec_coherence,
           iec_sigma,
           kaimal_spectrum,
           simley_pao_evolution,
)

__all__ = ["IECSite", "iec_field", "event_duration", "CONDITIONS", "IEC_REFERENCE_SPEED",
           "IEC_TURBULENCE", "SamplerCache", "CWLidar", "LidarMeasurement", "LidarSensor", "PointLidar",
           "rotor_coherence_model", "coherence_corner_model", "FieldFileError", "WindField", "Preview",
           "PreviewBuffer", "blade_effective_wind", "coherence", "coherence_bandwidth", "peak_lag", "preview",
           "preview_series", "rms_preview_error", "rotor_effective_wind", "TurbulenceSpec",
           "evolution_coherence", "evolve_field", "generate_evolved_field", "generate_field", "iec_coherence", "iec_sigma",
           "kaimal_spectrum", "simley_pao_evolution"]
