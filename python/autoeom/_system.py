"""autoeom.System and autoeom.load: a built system and how to make one
from a model file or text.

Evaluation (rhs, mass_matrix, energy, ...) is in C on the base class and
called directly; this layer adds what reads better in Python: keyword
arguments, the start state with its overrides, runs as Run objects,
modes, ensembles and compiled tapes with a warning when they are not in
use.
"""
import os
import warnings

import numpy as np

from . import _core
from ._run import Run


class System(_core.System):
    """A built system: tapes, parameters, solvers. Make one with
    autoeom.load(...) or Model.build(). Names follow the C API (eom.h) and
    eom-run's options (docs/cli.md)."""

    # coordinate overrides of the start, NAME or NAME_dot -> value
    _start = None

    @property
    def params(self):
        """The parameters in use, as a dict name -> value (a copy)."""
        return dict(zip(self.param_names, self.param_values))

    def set_params(self, **values):
        """Set parameters by name: system.set_params(k=100, m=2)."""
        for name, value in values.items():
            self.set_param(name, value)

    def set(self, **values):
        """As eom-run's --set: parameters, and coordinates' initial values
        (NAME) and rates (NAME_dot) of the start (x0)."""
        coords = set(self.coord_names)
        for name, value in values.items():
            base = name[:-4] if name.endswith("_dot") else name
            if name in self.param_names:
                self.set_param(name, float(value))
            elif base in coords:
                if self._start is None:
                    self._start = {}
                self._start[name] = float(value)
            else:
                raise KeyError(
                    "%r is not a parameter or coordinate of the model "
                    "(parameters: %s; coordinates: %s)" % (
                        name, ", ".join(self.param_names) or "none",
                        ", ".join(self.coord_names)))

    @property
    def x0(self):
        """The start of a run: the model's initial state at the parameters
        in use, with the coordinates and rates given to set()."""
        x = self.initial_state()
        n = self.ncoords
        for name, value in (self._start or {}).items():
            if name.endswith("_dot"):
                x[n + self.coord_names.index(name[:-4])] = value
            else:
                x[self.coord_names.index(name)] = value
        return x

    def set_compiled(self, on=True):
        """Run compiled tapes (on=True) or the interpreter. Returns a dict
        of what it took; when compiling fails the system stays on the
        interpreter and a RuntimeWarning says why."""
        status, message, info = self._set_compiled(on)
        if status:
            warnings.warn("compiled tapes are not in use: " + message,
                          RuntimeWarning, stacklevel=2)
        return info

    def run(self, t_end=10.0, sample=0.01, x0=None, columns=None,
            progress=None, baumgarte=None, **options):
        """Integrate from t = 0 to t_end with rows every `sample`, as
        eom-run does, and return a Run.

        options: integrator ("rk4", "erk" (default), "adams", "bdf",
        "ida", "esdirk", "imex"), dt, rtol, atol, max_steps, max_order,
        linear_solver ("auto", "dense", "sparse"), tol_per_step, project,
        proj_tol, erk_table, dq_jacobian, sensitivity (names of
        parameters, coordinates, NAME_dot). columns: optional groups
        ("accelerations", "multipliers", "condition", "health").
        progress(t) is called after each row. The integration releases
        the GIL. A failure part way raises autoeom.Error whose ``run``
        attribute holds the rows before it."""
        if baumgarte is not None:
            self.set_baumgarte(*baumgarte)
        x = self.x0 if x0 is None else x0
        names, data, stats, error = self._run(
            x, float(t_end), float(sample), columns, progress, **options)
        sens = options.get("sensitivity") or []
        sens_names = ["d(%s)/d(%s)" % (state, inp) for inp in sens
                      for state in self.coord_names +
                      [c + "_dot" for c in self.coord_names]]
        run = Run(self, names, data, stats, sens_names, len(sens),
                  groups=columns or ())
        if error is not None:
            status, message = error
            exc = Error(message)
            exc.status = status
            exc.status_name = _status_name(status)
            exc.run = run
            raise exc
        return run

    def modes(self, q=None, tol=1e-10):
        """As eom-run --modes: the static equilibrium from q (default: the
        start's coordinates), then the linearization about it. Returns the
        dict of linearize() with 'q' (the equilibrium) and 'iterations'."""
        q0 = self.x0[:self.ncoords] if q is None else q
        q_eq, iters = self.equilibrium(q0, tol=tol)
        lin = self.linearize(q_eq)
        lin["q"] = q_eq
        lin["iterations"] = iters
        return lin

    def ensemble(self, params, names, t_end=10.0, sample=0.01, x0=None,
                 threads=0, **options):
        """Run the model once per row of params (runs x len(names)
        values of the parameters named), on `threads` threads in C
        (0: one per core), each with its own clone of the system. Returns
        a dict: t (rows), x (runs x rows x 2n), W (runs x rows), status
        (runs; 0 or the libeom status of a failed run, whose rows from
        the failure on are NaN) and messages. options as for run()."""
        params = np.asarray(params, dtype=float)
        if params.ndim == 1:
            params = params[:, None]
        if isinstance(names, str):
            names = [names]
        X, W, status, messages = self._ensemble(
            params, list(names), x0, float(t_end), float(sample),
            int(threads), **options)
        rows = X.shape[1]
        t = np.minimum(np.arange(rows) * float(sample), float(t_end))
        return {"t": t, "x": X, "W": W, "status": status,
                "messages": messages}


Error = _core.Error


def _status_name(status):
    return _core.status_name(status)


def _is_text(source):
    # model text has a line break; a path never does
    return isinstance(source, str) and "\n" in source


def load(source, compiled=False, **sets):
    """A System from a model file (a path) or model text (a str with a
    line break), as eom-run takes it.

    Keyword arguments name the file's structural settings (links=5),
    parameters (k=100) and the start's coordinates and rates (theta=0.3,
    theta_dot=1), as eom-run's --set does. compiled=True runs compiled
    tapes (see System.set_compiled). Errors in the file raise
    autoeom.Error with the library's message (file:line:col)."""
    is_text = _is_text(source)
    if not is_text:
        source = os.fspath(source)
    rest = dict(sets)
    system = System._load(source, is_text, rest)
    # parameters first, so that a start that follows them is taken after
    params = {k: v for k, v in rest.items() if k in system.param_names}
    system.set(**params)
    system.set(**{k: v for k, v in rest.items() if k not in params})
    if compiled:
        system.set_compiled(True)
    return system
