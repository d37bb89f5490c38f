"""Takagi-Sugeno (TS) model, LMI-designed controller and wind observer (Clemens et al.).

TS model (Clemens et al. eqs 1-3): sub-models (A_i, B_i, B_d,i) and equilibria (x_0,i, u_0,i,
v_0,i) from our numerical linearization at the vertices of a rectangular grid of the premise
z = [v, Delta P] (eq 2: rotor-effective wind speed, power reduction), blended by memberships
h_i(z) = h_a(v) h_b(Delta P): products of one-dimensional hat functions, so h_i >= 0 and
sum_i h_i(z) = 1 for every z in the grid (eq 3). The state is Clemens' eq 4 (tower side-side and
fore-aft, rotor and generator speed, drivetrain torsion, ``linearize.PlantConfig.clemens()``),
the inputs eq 5 (collective pitch, generator torque); a vertex with Delta P > 0 is trimmed to
the electrical power (1 - Delta P) P_rated.

Controller (eq 7): parallel distributed compensation u = sum_i h_i (u_0,i - K_i (x_hat - x_0,i)),
gains from LMIs in X = P^-1 and Y_i = K_i X with a common quadratic Lyapunov function
(Tanaka & Wang's relaxed conditions; pairs only between vertices of one grid cell, the only ones
active together)::

    G_ij = A_i X - B_i Y_j,   H_ij = G_ij + G_ij' + 2 alpha X,
    H_ii < 0,   H_ij + H_ji <= 0,                                  (decay rate alpha)
    [[-r X, G_ij + G_ji], [*, -r X]] < 0 ... (for a disk abs(lambda) < r, D-stability)
    [[1, s_k'], [s_k, X]] >= 0   (the ellipsoid x' P x <= 1 holds the typical deviations s_k)
    [[X, Y_i' e_j], [e_j' Y_i, mu_ij^2]] >= 0  (abs(u_j - u_0,j) <= mu_ij on that ellipsoid
                                                at vertex i)

minimising sum_ij mu_ij^2 (each vertex's least effort for the required decay), or with
mu_ij <= mu_j fixed. States the law leaves alone (``uncontrolled``: by default in the registry
the tower's side-side pair, which the inputs barely reach) are left out of these LMIs.

Observer (eqs 8-10): the state augmented by the rotor-effective wind with the inflow model
dv/dt = -(v - v_0,i) / tau_v (eq 9, tau_v = 4 s), xi = [x; v], gains L_i from
A~_i' P + P A~_i - C~' N_i' - N_i C~ + 2 alpha_o P < 0, L_i = P^-1 N_i (C~ common to the
vertices), with an optional disk abs(lambda) < r_o and the gains' norm minimised.

After every solve the certificate is checked with numpy alone (:func:`verify_controller`,
:func:`verify_observer`): every LMI at the returned P and gains holds with the stated margin, and
the closed loop sum_ij h_i h_j (A_i - B_i K_j) on a fine grid of the premise (vertices and
interpolated points) is Hurwitz with the decay rate and decreases x' P x at rate 2 alpha.
The LMIs are solved in scaled coordinates (states, inputs and outputs divided by typical
magnitudes) so that the SDP is well conditioned; the gains are returned in SI units.
"""
from mpc_wt.controllers.takagi_sugeno.controller import TSController
from mpc_wt.controllers.takagi_sugeno.model import (
    CLEMENS_MEASURED,
    SIDE_SIDE_STATES,
    TURBINE_MEASURED,
    TSModel,
    build_ts_model,
)
from mpc_wt.controllers.takagi_sugeno.synthesis import (
                                                        Certificate,
                                                        TSControllerDesign,
                                                        TSObserverDesign,
                                                        design_ts_controller,
                                                        design_ts_observer,
                                                        verify_controller,
                                                        verify_observer,
)

__all__ = ["TSModel", "build_ts_model", "TSControllerDesign", "TSObserverDesign", "Certificate",
           "design_ts_controller", "design_ts_observer", "verify_controller", "verify_observer",
           "TSController", "CLEMENS_MEASURED", "TURBINE_MEASURED", "SIDE_SIDE_STATES"]
