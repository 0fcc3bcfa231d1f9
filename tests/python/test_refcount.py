"""No reference leaks: the core calls in a loop leave the reference counts
of their arguments and results, and the number of live objects, where
they were (a leaked reference in the C code shows as a count that grows
with the loop)."""
import gc
import sys

import numpy as np
import pytest

import autoeom


def core(s, x, X, t_obj):
    s.rhs(t_obj, x)
    s.rhs(t_obj, X)
    s.accelerations(t_obj, x)
    s.mass_matrix(x)
    s.energy(t_obj, x)
    s.probes(x)
    s.state_jacobian(t_obj, x)
    s.param_jacobian(t_obj, x)
    s.get_param("k")
    s.set_param("k", 75.0)
    s.initial_state()
    s.coord_names
    s.run(t_end=0.02, sample=0.01, columns=["accelerations"])
    s.run(t_end=0.02, sample=0.01, integrator="bdf", sensitivity=["k"])
    s.modes()
    s.linearize_state(t_obj, x)
    s.ensemble([[70.0], [80.0]], ["k"], t_end=0.02, sample=0.01, threads=2)
    bad = x.copy()
    bad[0] = np.nan
    for call in (lambda: s.rhs(t_obj, bad), lambda: s.run(t_end=0.01,
                                                          x0=bad)):
        try:
            call()
        except autoeom.Error:
            pass
    try:
        s.rhs(t_obj, x[:3])
    except ValueError:
        pass


def counts(*objs):
    gc.collect()
    return [sys.getrefcount(o) for o in objs] + [len(gc.get_objects())]


def test_core_calls_leak_no_references(spring):
    x = spring.x0
    X = np.tile(x, (5, 1))
    t_obj = 0.5
    core(spring, x, X, t_obj)  # warm up caches (imports, interned names)
    before = counts(spring, x, X, t_obj)
    for _ in range(50):
        core(spring, x, X, t_obj)
    after = counts(spring, x, X, t_obj)
    assert after[:-1] == before[:-1]
    # a few objects may come and go with the interpreter's own caches;
    # one leaked per call would be hundreds
    assert abs(after[-1] - before[-1]) < 20, (before[-1], after[-1])


def test_model_recording_leaks_no_references():
    def build():
        m = autoeom.Model()
        m.add_param("k", 2.0)
        m.add_coord("x", q0=1.0)
        m.set_kinetic(lambda c: 0.5 * c.x.dot**2)
        m.set_potential(lambda c: 0.5 * c.k * autoeom.sin(c.x)**2)
        s = m.build()
        s.rhs(0.0, s.x0)

    build()
    before = counts()
    for _ in range(30):
        build()
    after = counts()
    assert abs(after[-1] - before[-1]) < 20, (before[-1], after[-1])
