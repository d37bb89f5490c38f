"""The QP backends: each adapter against hand-worked QPs, bad input, and DAQP's C path against
DAQP's own Python interface."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from mpc_wt.controllers.qp import BACKENDS, SOLVED, make_backend
from mpc_wt.errors import QPSetupError

# min (v1 - 1)^2 + 2 (v2 - 2)^2 - 9 = 0.5 v' H v + q' v with H = diag(2, 4), q = (-2, -8):
# unconstrained optimum (1, 2)
H = np.diag([2.0, 4.0])
Q = np.array([-2.0, -8.0])
A = np.vstack([np.eye(2), [[1.0, 1.0]]])          # two box rows, one general row v1 + v2


def _backend(name: str):  # type: ignore[no-untyped-def]
    pytest.importorskip(BACKENDS[name].module)
    b = make_backend(name)
    b.setup(H, Q, A, 2)
    return b


def _tol(name: str) -> float:
    # DAQP is exact to rounding on a 2-variable QP; OSQP stops at its default eps_abs/eps_rel
    # of 1e-3 (relative to the solution's size, about 2 here), polished to ~1e-6
    return 1e-9 if name == "daqp" else 2e-3


#: hand-worked optima: (lower bounds, upper bounds) of (v1, v2, v1 + v2) -> solution
CASES = {
    # nothing binds: the unconstrained optimum
    "free": (([-10.0, -10.0, -10.0], [10.0, 10.0, 10.0]), [1.0, 2.0]),
    # separable objective: v1 <= 0.5 binds, v2 stays at its optimum
    "box": (([0.0, 0.0, -10.0], [0.5, 3.0, 10.0]), [0.5, 2.0]),
    # v1 + v2 <= 2: 2 (v1 - 1) + l = 0, 4 (v2 - 2) + l = 0, v1 + v2 = 2 -> l = 4/3 (KKT)
    "row": (([-10.0, -10.0, -10.0], [10.0, 10.0, 2.0]), [1.0 / 3.0, 5.0 / 3.0]),
}


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("name", sorted(BACKENDS))
def test_backend_finds_the_hand_worked_optimum(name: str, case: str) -> None:
    (lo, hi), expected = CASES[case]
    b = _backend(name)
    b.update_bounds(np.array(lo), np.array(hi))
    x, status = b.solve()
    assert status in SOLVED
    assert_allclose(x, expected, atol=_tol(name), rtol=0)


@pytest.mark.parametrize("name", sorted(BACKENDS))
def test_infeasible_bounds_are_reported_not_solved(name: str) -> None:
    # v1 >= 1.5, v2 >= 1.5 and v1 + v2 <= 2 cannot all hold: no solution is returned
    b = _backend(name)
    b.update_bounds(np.array([1.5, 1.5, -10.0]), np.array([10.0, 10.0, 2.0]))
    x, status = b.solve()
    assert status not in SOLVED
    assert x is None


def test_unknown_backend_names_the_allowed_ones() -> None:
    with pytest.raises((ValueError, QPSetupError), match="backend"):
        make_backend("gurobi")


def test_daqp_bad_interface_option_is_named() -> None:
    pytest.importorskip("daqp")
    b = make_backend("daqp", options={"interface": "fortran"})
    with pytest.raises(QPSetupError, match="interface must be 'c' or 'python'"):
        b.setup(H, Q, A, 2)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), width=st.floats(0.05, 2.0))
def test_daqp_c_interface_gives_daqps_own_iterates(seed: int, width: float) -> None:
    """Our direct path into DAQP's C functions against DAQP's own Python ``Model``
    (the peer) on random strictly convex QPs with box and general rows, warm-started over a
    sequence of bound updates as in the loop: the same exit flags, iteration counts and
    solutions (to 1e-12)."""
    pytest.importorskip("daqp")
    from mpc_wt.controllers.qp import DAQPBackend

    rng = np.random.default_rng(seed)
    n, mg = 12, 20
    m = rng.standard_normal((n, n))
    h = m @ m.T + n * np.eye(n)
    a = np.vstack([np.eye(n), rng.standard_normal((mg, n))])
    q = np.zeros(n) if seed % 2 else rng.standard_normal(n)
    direct, peer = DAQPBackend(), DAQPBackend({"interface": "python"})
    direct.setup(h, q, a, n)
    peer.setup(h, q, a, n)
    assert direct.direct is not None and peer.direct is None
    lo, hi = np.empty(n + mg), np.empty(n + mg)
    for _ in range(6):
        lo[:] = -rng.uniform(0.0, width, n + mg) - 0.01
        hi[:] = rng.uniform(0.0, width, n + mg) + 0.01
        direct.update_bounds(lo, hi)                  # the same arrays, rewritten in place
        peer.update_bounds(lo, hi)
        (xd, sd), (xp, sp) = direct.solve(), peer.solve()
        assert sd == sp
        assert direct.iterations == peer.iterations
        if xp is not None:
            assert_allclose(xd, xp, rtol=0, atol=1e-12)


def test_daqp_c_interface_bad_input() -> None:
    pytest.importorskip("daqp")
    from mpc_wt.controllers.qp import DAQPBackend
    from mpc_wt.errors import QPSetupError

    be = DAQPBackend()
    be.setup(np.eye(2), np.zeros(2), np.eye(2), 2)
    with pytest.raises(ValueError, match=r"bounds have shapes \(3,\), \(2,\); expected \(2,\)"):
        be.update_bounds(np.zeros(3), np.ones(2))
    for interface in ("c", "python"):                # lo > hi: infeasible, not the old QP
        be = DAQPBackend({"interface": interface})
        be.setup(np.eye(2), np.zeros(2), np.eye(2), 2)
        be.update_bounds(-np.ones(2), np.ones(2))
        assert be.solve()[1] == "solved"
        be.update_bounds(np.ones(2), np.zeros(2))
        x, status = be.solve()
        assert x is None and "infeasible" in status
    with pytest.raises(QPSetupError, match="interface must be 'c' or 'python', got 'fortran'"):
        DAQPBackend({"interface": "fortran"}).setup(np.eye(2), np.zeros(2), np.eye(2), 2)
