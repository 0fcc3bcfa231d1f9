"""Evaluation at a state against closed forms of the spring pendulum
(T = m/2 (rd^2 + r^2 thd^2), V = k/2 (r - r0)^2 + m g (r0 - r cos th)),
and the batch right-hand side against single calls."""
import math
import os

import numpy as np

import autoeom

M, K, R0, G = 1.0, 75.0, 1.0, 9.81  # the shipped file's defaults


def closed_form_rhs(x):
    r, th, rd, thd = x
    rdd = r * thd**2 - K / M * (r - R0) + G * math.cos(th)
    thdd = (-2 * rd * thd - G * math.sin(th)) / r
    return np.array([rd, thd, rdd, thdd])


def test_rhs_mass_matrix_energy_match_closed_forms(spring):
    x = np.array([1.2, 0.4, -0.3, 0.7])
    assert np.allclose(spring.rhs(0.0, x), closed_form_rhs(x), rtol=1e-13,
                       atol=1e-13)
    assert np.allclose(spring.mass_matrix(x),
                       [[M, 0.0], [0.0, M * x[0]**2]], rtol=1e-14)
    e = spring.energy(0.0, x)
    T = 0.5 * M * (x[2]**2 + x[0]**2 * x[3]**2)
    V = 0.5 * K * (x[0] - R0)**2 + M * G * (R0 - x[0] * math.cos(x[1]))
    assert math.isclose(e["T"], T, rel_tol=1e-14)
    assert math.isclose(e["V"], V, rel_tol=1e-14)
    assert math.isclose(e["E"], T + V, rel_tol=1e-14)
    assert np.array_equal(spring.accelerations(0.0, x),
                          spring.rhs(0.0, x)[2:])


def test_batch_rhs_equals_single_calls(spring):
    rng = np.random.default_rng(7)
    X = spring.x0 + 0.2 * rng.standard_normal((50, 4))
    batch = spring.rhs(0.0, X)
    single = np.array([spring.rhs(0.0, x) for x in X])
    assert batch.shape == (50, 4)
    assert np.array_equal(batch, single)
    # one time per state
    ts = np.linspace(0.0, 1.0, 50)
    assert np.array_equal(spring.rhs(ts, X), single)
    # a list of lists and a non-contiguous view are batches too
    assert np.array_equal(spring.rhs(0.0, X.tolist()), single)
    assert np.array_equal(spring.rhs(0.0, X.T.copy().T), single)


def test_constrained_model_multipliers_and_jacobians(models_dir):
    s = autoeom.load(os.path.join(models_dir, "four-bar.eom"))
    x = s.project(s.x0, start=True)
    C, phi = s.constraint_jacobian(x)
    assert C.shape == (s.nconstraints, s.ncoords)
    assert np.max(np.abs(phi)) < 1e-10
    # M qdd = dL/dq - ... + C^T lambda: the accelerations satisfy the
    # velocity form's time derivative C qdd + (dC/dt) qd = 0, checked by a
    # difference of C qd along the motion
    xd = s.rhs(0.0, x)
    h = 1e-6
    Cp, _ = s.constraint_jacobian(x + h * xd)
    Cm, _ = s.constraint_jacobian(x - h * xd)
    n = s.ncoords
    dCqd = (Cp @ (x[n:] + h * xd[n:]) - Cm @ (x[n:] - h * xd[n:])) / (2 * h)
    assert np.max(np.abs(dCqd)) < 1e-6
    lam = s.multipliers(0.0, x)
    assert lam.shape == (s.nconstraints,) and np.all(np.isfinite(lam))
    A = s.state_jacobian(0.0, x)
    # against central differences of the right-hand side
    Afd = np.empty_like(A)
    for j in range(2 * n):
        d = np.zeros(2 * n)
        d[j] = 1e-6
        Afd[:, j] = (s.rhs(0.0, x + d) - s.rhs(0.0, x - d)) / 2e-6
    assert np.allclose(A, Afd, rtol=1e-5, atol=1e-5)
