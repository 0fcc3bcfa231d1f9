"""SciPy's solve_ivp on the batch right-hand side against the closed form
of a damped oscillator, m x'' + c x' + k x = 0 (derived by hand, not by
the library): x(t) = e^(-a t) (x0 cos(w t) + (v0 + a x0)/w sin(w t)),
a = c/(2m), w = sqrt(k/m - a^2)."""
import numpy as np
import pytest

import autoeom

scipy_integrate = pytest.importorskip("scipy.integrate")

MODEL = """# damped oscillator
param m = 2   [kg]
param k = 50  [N/m]
param c = 1.5 [N s/m]
coord x = 0.3 [m] rate -0.2
T = 1/2*m*x_dot^2
V = 1/2*k*x^2
R = 1/2*c*x_dot^2
"""


def closed_form(t, m=2.0, k=50.0, c=1.5, x0=0.3, v0=-0.2):
    a = c / (2 * m)
    w = np.sqrt(k / m - a * a)
    return np.exp(-a * t) * (x0 * np.cos(w * t) +
                             (v0 + a * x0) / w * np.sin(w * t))


def test_solve_ivp_on_batch_rhs_reproduces_closed_form():
    s = autoeom.load(MODEL)
    assert np.array_equal(s.x0, [0.3, -0.2])
    calls = []

    def fun(t, y):
        # solve_ivp passes y as (2n, k) when vectorized: the batch is its
        # transpose
        calls.append(y.shape)
        return s.rhs(t, y.T).T

    t = np.linspace(0.0, 3.0, 31)
    sol = scipy_integrate.solve_ivp(fun, (0.0, 3.0), s.x0, method="Radau",
                                    t_eval=t, vectorized=True, rtol=1e-10,
                                    atol=1e-12)
    assert sol.success
    assert any(len(shape) == 2 and shape[1] > 1 for shape in calls)
    assert np.max(np.abs(sol.y[0] - closed_form(t))) < 1e-8
