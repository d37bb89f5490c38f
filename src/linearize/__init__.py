"""BEM plant of a reference wind turbine: data, aerodynamics, nonlinear plant and trim.

This package never imports ``mpc_wt`` or ``lidar``.
"""
from linearize.bem import AeroOptions, element_induction, element_loads
from linearize.errors import (
    LinearizationError,
    LinFileError,
    SimulationDivergedError,
    TrimError,
    TurbineFileError,
)
from linearize.linear import jacobian_check, linearize, linearize_family
from linearize.load import load_turbine
from linearize.models import (
    LinearModel,
    LinearModelFamily,
    augment_actuator,
    sensitivities,
    with_power_input,
)
from linearize.openfast import load_openfast
from linearize.openfast_lin import read_lin, read_lin_set, write_lin
from linearize.params import (
    DOF_NAMES,
    INPUT_NAMES,
    INPUT_UNITS,
    MADSEN_OUTPUTS,
    OUTPUT_NAMES,
    OUTPUT_UNITS,
    STATE_NAMES,
    STATE_UNITS,
    PlantConfig,
    PlantParams,
    plant_params,
    check_plant_step,
    structural_frequencies,
)
from linearize.performance import (
    RotorPerformance,
    read_rotor_performance,
    rotor_performance,
    write_rotor_performance,
)
from linearize.plant import PlantStepper, SimulationResult, plant_outputs, plant_rhs, rk4_simulate
from linearize.steady import optimal_tsr, rotor_average, steady_coefficients
from linearize.trim import (
    OperatingPoint,
    aero_torque,
    max_torque_pitch,
    operating_point,
    operating_schedule,
    rated_wind_speed,
    region2_pitch,
    trim,
)
from linearize.turbine import LoadReport, MinPitchTable, Turbine, available_turbines
from linearize.wind import GridWind, SteadyWind, element_wind

__all__ = [
    "AeroOptions", "element_induction", "element_loads", "DOF_NAMES", "INPUT_NAMES", "INPUT_UNITS", "MADSEN_OUTPUTS",
    "OUTPUT_NAMES", "OUTPUT_UNITS", "STATE_NAMES", "STATE_UNITS", "GridWind", "PlantConfig",
    "PlantParams", "PlantStepper", "SimulationDivergedError", "SimulationResult", "SteadyWind",
    "element_wind",
    "plant_outputs", "plant_params", "plant_rhs", "rk4_simulate", "structural_frequencies", "check_plant_step",
    "optimal_tsr", "rotor_average", "steady_coefficients", "OperatingPoint", "TrimError",
    "operating_point", "max_torque_pitch", "region2_pitch", "MinPitchTable", "aero_torque",
    "operating_schedule", "rated_wind_speed", "trim", "Turbine", "TurbineFileError",
    "available_turbines",
    "load_turbine", "LinearizationError", "LinearModel", "LinearModelFamily",
    "augment_actuator", "jacobian_check", "linearize", "linearize_family", "sensitivities",
    "with_power_input", "load_openfast", "LoadReport", "RotorPerformance",
    "read_rotor_performance", "rotor_performance", "write_rotor_performance", "LinFileError",
    "read_lin", "read_lin_set", "write_lin",
]
