"""Models recorded from Python functions: the spring pendulum written
with operators equals the shipped file to 1e-14, and misuse is a clear
exception."""
import os

import numpy as np
import pytest

import autoeom
from autoeom import cos


def spring_model():
    m = autoeom.Model()
    m.add_param("m", 1.0, unit="kg")
    m.add_param("k", 75.0, unit="N/m")
    m.add_param("r0", 1.0, unit="m")
    m.add_param("g", 9.81, unit="m/s^2")
    m.add_coord("r", q0=1.1, unit="m")
    m.add_coord("theta", q0=0.5, unit="rad")
    m.set_kinetic(lambda c: 0.5 * c.m * (c.r.dot**2 +
                                         c.r**2 * c.theta.dot**2))
    m.set_potential(lambda c: 0.5 * c.k * (c.r - c.r0)**2 +
                    c.m * c.g * (c.r0 - c.r * cos(c.theta)))
    m.add_probe("height", lambda c: -c.r * cos(c.theta), unit="m")
    return m


def test_python_spring_pendulum_equals_file(models_dir):
    py = spring_model().build()
    f = autoeom.load(os.path.join(models_dir, "spring-pendulum.eom"))
    assert py.coord_names == f.coord_names
    assert np.array_equal(py.x0, f.x0)
    rng = np.random.default_rng(3)
    X = f.x0 + 0.3 * rng.standard_normal((20, 4))
    a, b = py.rhs(0.0, X), f.rhs(0.0, X)
    assert np.all(np.abs(a - b) <= 1e-14 * np.maximum(np.abs(b), 1.0))
    ra = py.run(t_end=2.0, sample=0.1)
    rb = f.run(t_end=2.0, sample=0.1)
    cols = [rb.names.index(c) for c in ra.names if c in rb.names]
    assert np.all(np.abs(ra.x - rb.x) <= 1e-14 * np.maximum(np.abs(rb.x),
                                                            1.0))
    assert len(cols) >= 9
    # the probe: the height of the bob
    assert np.allclose(ra.probes[:, 0], -ra.q[:, 0] * np.cos(ra.q[:, 1]),
                       rtol=1e-14, atol=1e-14)


def test_constraints_forces_and_operators():
    # a bead on a circle of radius 2 in Cartesian coordinates, with a
    # force along x and the operators' every form
    m = autoeom.Model()
    m.add_param("mass", 1.5)
    m.add_coord("x", q0=2.0)
    m.add_coord("y", q0=0.0, qd0=1.0)
    m.set_kinetic(lambda c: c.mass / 2 * (c.x.dot**2 + c.y.dot**2))
    m.set_potential(lambda c: 0.0 * c.x)
    m.set_constraints(1, lambda c: [c.x**2 + c.y**2 - 4.0])
    m.set_forces(lambda c: [1 - (c.x - c.x) + 0 * c.y, 0.0])
    s = m.build()
    x = s.x0
    lam = s.multipliers(0.0, x)
    # radial balance: m v^2 / R = -2 R lambda - F_x at (2, 0), so
    # lambda = -(m v^2 / R + F_x) / (2 R) with C = (2x, 2y) = (4, 0)
    assert np.isclose(lam[0], -(1.5 * 1.0 / 2.0 + 1.0) / 4.0, rtol=1e-14)


def test_misuse_raises():
    kept = []
    m = autoeom.Model()
    m.add_coord("x", q0=1.0)

    def T(c):
        kept.append(c.x)
        return 0.5 * c.x.dot**2

    m.set_kinetic(T)
    m.set_potential(lambda c: c.x**2)
    m.build()
    with pytest.raises(RuntimeError):
        kept[0] + 1.0

    bad = autoeom.Model()
    bad.add_coord("x")

    def branching(c):
        if c.x > 0:
            return c.x
        return -c.x

    bad.set_kinetic(lambda c: c.x.dot**2)
    bad.set_potential(branching)
    with pytest.raises(TypeError):
        bad.build()

    raising = autoeom.Model()
    raising.add_coord("x")
    raising.set_kinetic(lambda c: c.x.dot**2)

    def fails(c):
        raise ZeroDivisionError("inside V")

    raising.set_potential(fails)
    with pytest.raises(ZeroDivisionError):
        raising.build()

    unknown = autoeom.Model()
    unknown.add_coord("x")
    unknown.set_kinetic(lambda c: c.x.dot**2 * c.param("nope"))
    with pytest.raises(autoeom.Error) as e:
        unknown.build()
    assert "nope" in str(e.value)
