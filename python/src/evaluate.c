/* evaluate.c - System methods that evaluate the equations at a state:
 * the right-hand side (one state, or a batch of k states as a (k, 2n)
 * array, looped over in C with the GIL released), the mass matrix, the
 * accelerations and multipliers, energies, probes, constraint residuals
 * and Jacobians. Arguments follow the C API's order: (t, x) where the
 * call takes a time, (x) where it does not. */
#include "pyeom.h"

#include <string.h>

/* Take (t, x) from a fastcall argument vector: t a float, x any array.
 * Returns 0, or -1 with an exception. */
static int t_and_x(PyObject *const *args, Py_ssize_t nargs,
                   const char *fn, double *t, PyObject **x)
{
    if (nargs != 2) {
        PyErr_Format(PyExc_TypeError, "%s(t, x) takes 2 arguments (%zd "
                     "given)", fn, nargs);
        return -1;
    }
    *t = PyFloat_AsDouble(args[0]);
    if (*t == -1.0 && PyErr_Occurred())
        return -1;
    *x = args[1];
    return 0;
}

/* rhs on a (k, 2n) batch: one eom_rhs per row, in C, without the GIL.
 * t is one time for every row or k times. */
static PyObject *rhs_batch(pyeom_system *self, PyObject *tobj, PyObject *xo)
{
    const npy_intp n2 = 2 * self->n;
    PyArrayObject *x, *tv = NULL;
    PyObject *out;
    const double *xs, *ts = NULL;
    double *xd, t0 = 0.0;
    npy_intp k, i, bad = -1;
    int st = EOM_OK;

    x = (PyArrayObject *)PyArray_FROMANY(xo, NPY_DOUBLE, 2, 2,
                                         NPY_ARRAY_IN_ARRAY);
    if (!x)
        return NULL;
    if (PyArray_DIM(x, 1) != n2) {
        PyErr_Format(PyExc_ValueError, "a batch of states has shape (k, "
                     "%zd), not (%zd, %zd)", (Py_ssize_t)n2,
                     (Py_ssize_t)PyArray_DIM(x, 0),
                     (Py_ssize_t)PyArray_DIM(x, 1));
        Py_DECREF(x);
        return NULL;
    }
    k = PyArray_DIM(x, 0);
    if (PyFloat_Check(tobj) || PyLong_Check(tobj)) {
        t0 = PyFloat_AsDouble(tobj);
        if (t0 == -1.0 && PyErr_Occurred())
            goto fail;
    } else {
        tv = pyeom_vector(tobj, k, "t (one time per state of the batch)");
        if (!tv)
            goto fail;
        ts = PyArray_DATA(tv);
    }
    out = PyArray_SimpleNew(2, PyArray_DIMS(x), NPY_DOUBLE);
    if (!out)
        goto fail;
    xs = PyArray_DATA(x);
    xd = PyArray_DATA((PyArrayObject *)out);
    Py_BEGIN_ALLOW_THREADS
    for (i = 0; i < k; i++) {
        st = eom_rhs(self->s, ts ? ts[i] : t0, xs + i * n2, xd + i * n2);
        if (st < 0) {
            bad = i;
            break;
        }
    }
    Py_END_ALLOW_THREADS
    Py_DECREF(x);
    Py_XDECREF(tv);
    if (bad >= 0) {
        PyObject *msg = PyUnicode_FromFormat("state %zd of the batch: %s",
                                             (Py_ssize_t)bad,
                                             eom_system_errmsg(self->s));
        Py_DECREF(out);
        if (msg) {
            pyeom_raise(st, PyUnicode_AsUTF8(msg));
            Py_DECREF(msg);
        }
        return NULL;
    }
    return out;
fail:
    Py_DECREF(x);
    Py_XDECREF(tv);
    return NULL;
}

/* rhs(t, x) -> xd = (qd, qdd): x of shape (2n,), or (k, 2n) for a batch
 * (then t may also be k times). Kept lean: this is the call an ODE solver
 * makes thousands of times. */
static PyObject *eval_rhs(pyeom_system *self, PyObject *const *args,
                          Py_ssize_t nargs)
{
    npy_intp n2 = 2 * self->n;
    PyArrayObject *x;
    PyObject *out, *xo;
    double t;
    int st;
    if (nargs == 2 && PyArray_Check(args[1]) &&
        PyArray_NDIM((PyArrayObject *)args[1]) == 2)
        return rhs_batch(self, args[0], args[1]);
    if (t_and_x(args, nargs, "rhs", &t, &xo) != 0)
        return NULL;
    if (!PyArray_Check(xo) && PySequence_Check(xo) &&
        PySequence_Size(xo) > 0) {
        /* a nested list is a batch too */
        PyObject *first = PySequence_GetItem(xo, 0);
        int nested = first && PySequence_Check(first);
        Py_XDECREF(first);
        if (nested)
            return rhs_batch(self, args[0], xo);
        PyErr_Clear();
    }
    x = pyeom_vector(xo, n2, "x");
    if (!x)
        return NULL;
    out = PyArray_SimpleNew(1, &n2, NPY_DOUBLE);
    if (!out) {
        Py_DECREF(x);
        return NULL;
    }
    st = eom_rhs(self->s, t, PyArray_DATA(x),
                 PyArray_DATA((PyArrayObject *)out));
    Py_DECREF(x);
    if (st < 0) {
        Py_DECREF(out);
        return pyeom_raise(st, eom_system_errmsg(self->s));
    }
    return out;
}

/* accelerations(t, x) -> qdd (n). */
static PyObject *eval_accelerations(pyeom_system *self,
                                    PyObject *const *args, Py_ssize_t nargs)
{
    npy_intp n = self->n;
    PyArrayObject *x;
    PyObject *out, *xo;
    double t;
    int st;
    if (t_and_x(args, nargs, "accelerations", &t, &xo) != 0)
        return NULL;
    x = pyeom_vector(xo, 2 * n, "x");
    if (!x)
        return NULL;
    st = eom_rhs(self->s, t, PyArray_DATA(x), self->scratch);
    Py_DECREF(x);
    if (st < 0)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    out = PyArray_SimpleNew(1, &n, NPY_DOUBLE);
    if (out)
        memcpy(PyArray_DATA((PyArrayObject *)out), self->scratch + n,
               (size_t)n * sizeof(double));
    return out;
}

/* A call of the form f(s, t, x, out) or f(s, x, out) with an output of
 * the given shape. */
typedef int (*tx_fn)(eom_system *, double, const double *, double *);
typedef int (*x_fn)(eom_system *, const double *, double *);

static PyObject *tx_call(pyeom_system *self, PyObject *const *args,
                         Py_ssize_t nargs, const char *name, tx_fn f,
                         int nd, npy_intp d0, npy_intp d1)
{
    npy_intp dims[2] = {d0, d1};
    PyArrayObject *x;
    PyObject *out, *xo;
    double t;
    int st;
    if (t_and_x(args, nargs, name, &t, &xo) != 0)
        return NULL;
    x = pyeom_vector(xo, 2 * self->n, "x");
    if (!x)
        return NULL;
    out = pyeom_empty(nd, dims);
    if (!out) {
        Py_DECREF(x);
        return NULL;
    }
    Py_BEGIN_ALLOW_THREADS
    st = f(self->s, t, PyArray_DATA(x), PyArray_DATA((PyArrayObject *)out));
    Py_END_ALLOW_THREADS
    Py_DECREF(x);
    if (st < 0) {
        Py_DECREF(out);
        return pyeom_raise(st, eom_system_errmsg(self->s));
    }
    return out;
}

static PyObject *x_call(pyeom_system *self, PyObject *xo, x_fn f, int nd,
                        npy_intp d0, npy_intp d1)
{
    npy_intp dims[2] = {d0, d1};
    PyArrayObject *x = pyeom_vector(xo, 2 * self->n, "x");
    PyObject *out;
    int st;
    if (!x)
        return NULL;
    out = pyeom_empty(nd, dims);
    if (!out) {
        Py_DECREF(x);
        return NULL;
    }
    st = f(self->s, PyArray_DATA(x), PyArray_DATA((PyArrayObject *)out));
    Py_DECREF(x);
    if (st < 0) {
        Py_DECREF(out);
        return pyeom_raise(st, eom_system_errmsg(self->s));
    }
    return out;
}

static PyObject *eval_multipliers(pyeom_system *self, PyObject *const *args,
                                  Py_ssize_t nargs)
{
    return tx_call(self, args, nargs, "multipliers", eom_multipliers, 1,
                   self->m, 0);
}

static PyObject *eval_state_jacobian(pyeom_system *self,
                                     PyObject *const *args, Py_ssize_t nargs)
{
    return tx_call(self, args, nargs, "state_jacobian", eom_state_jacobian,
                   2, 2 * self->n, 2 * self->n);
}

static PyObject *eval_param_jacobian(pyeom_system *self,
                                     PyObject *const *args, Py_ssize_t nargs)
{
    return tx_call(self, args, nargs, "param_jacobian", eom_param_jacobian,
                   2, 2 * self->n, self->np);
}

static PyObject *eval_mass_matrix(pyeom_system *self, PyObject *x)
{
    return x_call(self, x, eom_mass_matrix, 2, self->n, self->n);
}

static PyObject *eval_probes(pyeom_system *self, PyObject *x)
{
    return x_call(self, x, eom_probes_at, 1, self->nprobes, 0);
}

/* energy(t, x) -> dict of T, V, L, E, P, Pt (T and V NaN for a model
 * given as a whole Lagrangian). */
static PyObject *eval_energy(pyeom_system *self, PyObject *const *args,
                             Py_ssize_t nargs)
{
    PyArrayObject *x;
    PyObject *xo;
    eom_energy e;
    double t;
    int st;
    if (t_and_x(args, nargs, "energy", &t, &xo) != 0)
        return NULL;
    x = pyeom_vector(xo, 2 * self->n, "x");
    if (!x)
        return NULL;
    st = eom_energy_at(self->s, t, PyArray_DATA(x), &e);
    Py_DECREF(x);
    if (st < 0)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    return Py_BuildValue("{s:d,s:d,s:d,s:d,s:d,s:d}", "T", e.T, "V", e.V,
                         "L", e.L, "E", e.E, "P", e.P, "Pt", e.Pt);
}

/* Two outputs of one call on x: (C, phi), (phi, phidot). */
static PyObject *x_pair(pyeom_system *self, PyObject *xo, int jac)
{
    const npy_intp m = self->m, n = self->n;
    npy_intp dc[2] = {m, n};
    PyArrayObject *x = pyeom_vector(xo, 2 * n, "x");
    PyObject *a, *b;
    int st;
    if (!x)
        return NULL;
    a = jac ? pyeom_empty(2, dc) : pyeom_empty(1, &dc[0]);
    b = pyeom_empty(1, &dc[0]);
    if (!a || !b) {
        Py_DECREF(x);
        Py_XDECREF(a);
        Py_XDECREF(b);
        return NULL;
    }
    if (jac)
        st = eom_constraint_jacobian(self->s, PyArray_DATA(x),
                                     PyArray_DATA((PyArrayObject *)a),
                                     PyArray_DATA((PyArrayObject *)b));
    else
        st = eom_residuals(self->s, PyArray_DATA(x),
                           PyArray_DATA((PyArrayObject *)a),
                           PyArray_DATA((PyArrayObject *)b));
    Py_DECREF(x);
    if (st < 0) {
        Py_DECREF(a);
        Py_DECREF(b);
        return pyeom_raise(st, eom_system_errmsg(self->s));
    }
    return Py_BuildValue("(NN)", a, b);
}

static PyObject *eval_constraint_jacobian(pyeom_system *self, PyObject *x)
{
    return x_pair(self, x, 1);
}

static PyObject *eval_residuals(pyeom_system *self, PyObject *x)
{
    return x_pair(self, x, 0);
}

/* condition(x) -> (rcond_M, rcond_S). */
static PyObject *eval_condition(pyeom_system *self, PyObject *xo)
{
    PyArrayObject *x = pyeom_vector(xo, 2 * self->n, "x");
    double a, b;
    int st;
    if (!x)
        return NULL;
    st = eom_condition(self->s, PyArray_DATA(x), &a, &b);
    Py_DECREF(x);
    if (st < 0)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    return Py_BuildValue("(dd)", a, b);
}

/* project(x, tol=1e-12, start=False) -> projected copy of x. */
static PyObject *eval_project(pyeom_system *self, PyObject *args,
                              PyObject *kw)
{
    /* PyArg_ParseTupleAndKeywords takes char *, not const */
    static char k_x[] = "x", k_tol[] = "tol", k_start[] = "start";
    static char *kwlist[] = {k_x, k_tol, k_start, NULL};
    PyObject *xo;
    PyArrayObject *x;
    double tol = 1e-12;
    int start = 0, st, iters = 0;
    npy_intp n2 = 2 * self->n;
    PyObject *out;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|dp", kwlist, &xo, &tol,
                                     &start))
        return NULL;
    x = pyeom_vector(xo, n2, "x");
    if (!x)
        return NULL;
    out = pyeom_empty(1, &n2);
    if (!out) {
        Py_DECREF(x);
        return NULL;
    }
    memcpy(PyArray_DATA((PyArrayObject *)out), PyArray_DATA(x),
           (size_t)n2 * sizeof(double));
    Py_DECREF(x);
    st = (start ? eom_project_start : eom_project)(
        self->s, PyArray_DATA((PyArrayObject *)out), tol, &iters);
    if (st < 0) {
        Py_DECREF(out);
        return pyeom_raise(st, eom_system_errmsg(self->s));
    }
    return out;
}

#define FAST(f) (PyCFunction)(void (*)(void))(f), METH_FASTCALL

PyMethodDef pyeom_eval_methods[] = {
    {"rhs", FAST(eval_rhs),
     "rhs(t, x) -> xd = (qd, qdd); x of shape (2n,), or (k, 2n) for a batch "
     "evaluated in C (t: one time or k times)"},
    {"accelerations", FAST(eval_accelerations),
     "accelerations(t, x) -> qdd"},
    {"multipliers", FAST(eval_multipliers),
     "multipliers(t, x) -> lambda (m); the constraint force is C^T lambda"},
    {"energy", FAST(eval_energy),
     "energy(t, x) -> {'T', 'V', 'L', 'E', 'P', 'Pt'}"},
    {"state_jacobian", FAST(eval_state_jacobian),
     "state_jacobian(t, x) -> A = d(xd)/dx (2n x 2n)"},
    {"param_jacobian", FAST(eval_param_jacobian),
     "param_jacobian(t, x) -> B = d(xd)/dp (2n x nparams)"},
    {"mass_matrix", (PyCFunction)eval_mass_matrix, METH_O,
     "mass_matrix(x) -> M (n x n)"},
    {"probes", (PyCFunction)eval_probes, METH_O,
     "probes(x) -> the probes' values"},
    {"constraint_jacobian", (PyCFunction)eval_constraint_jacobian, METH_O,
     "constraint_jacobian(x) -> (C (m x n), phi (m))"},
    {"residuals", (PyCFunction)eval_residuals, METH_O,
     "residuals(x) -> (phi, C qd + dphi/dt)"},
    {"condition", (PyCFunction)eval_condition, METH_O,
     "condition(x) -> (rcond_M, rcond_S)"},
    {"project", (PyCFunction)(void (*)(void))eval_project,
     METH_VARARGS | METH_KEYWORDS,
     "project(x, tol=1e-12, start=False) -> x projected onto the "
     "constraints (start=True: least change of the coordinates)"},
    {NULL, NULL, 0, NULL},
};
