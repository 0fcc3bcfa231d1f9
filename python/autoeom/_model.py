"""Models recorded from Python functions (autoeom.Model).

The C type does the recording; this layer keeps the table of names that
lets a callback say ``c.r`` for a coordinate and ``c.m`` for a parameter,
and builds the Python System class.
"""
from . import _core


class Model(_core.Model):
    """A model whose energies are Python functions of a recording context.

    Example (a spring pendulum)::

        m = autoeom.Model()
        m.add_param("m", 1.0, unit="kg")
        m.add_param("k", 75.0, unit="N/m")
        m.add_coord("r", q0=1.1, unit="m")
        m.set_kinetic(lambda c: 0.5*c.m*c.r.dot**2)
        m.set_potential(lambda c: 0.5*c.k*(c.r - 1)**2)
        system = m.build()

    Each function receives a Context ``c`` and returns a recorded value
    (autoeom.Var) or, for vector parts, a sequence of them. The functions
    run once, in build(); the system then replays the tapes.
    """

    def __init__(self):
        super().__init__()
        # name -> (0, coordinate index) or (1, parameter index), read by
        # the C Context's attribute lookup
        self._names = {}

    def build(self, compiled=False):
        """Record every callback once and return the System."""
        from ._system import System
        system = self._build(System)
        if compiled:
            system.set_compiled(True)
        return system
