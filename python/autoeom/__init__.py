"""autoeom: equations of motion from a recorded Lagrangian, from Python.

The package is a thin layer over the C library (libeom, libtape): models
from a model file or text (``load``) or from Python functions (``Model``),
evaluation at a state, integration with every method of eom-run, batches
of states, linearization and ensembles, with NumPy arrays in and out.
See docs/python.md.
"""
from ._core import Error, Var, Context, strerror, methods, erk_tables
from ._core import (sqr, sqrt, exp, log, sin, cos, tan, asin, acos, atan,
                    sinh, cosh, tanh, atan2, hypot)
from ._system import System, load
from ._model import Model
from ._run import Run

__all__ = [
    "Error", "Var", "Context", "System", "Model", "Run", "load", "strerror",
    "methods", "erk_tables", "sqr", "sqrt", "exp", "log", "sin", "cos",
    "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "atan2", "hypot",
]
