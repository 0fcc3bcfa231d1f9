/* analysis.c - System methods for linearization and equilibrium:
 * eom_linearize (about a rest state: M, K, D, reduced matrices, natural
 * frequencies and mode shapes), eom_linearize_state (A, B about any state,
 * reduced to the constraints, eigenvalues), eom_linearize_steady (about a
 * steady motion) and eom_equilibrium. Results come back as dicts of NumPy
 * arrays (copies: the library's results are freed before returning). */
#include "pyeom.h"

#include <string.h>

#include "eom/steady.h"

/* A new array (rows x cols, or a vector when cols is 0) holding a copy of
 * v; NULL v gives an empty array of that shape. */
static PyObject *copy(const double *v, npy_intp rows, npy_intp cols)
{
    npy_intp dims[2] = {rows, cols};
    PyObject *a = pyeom_empty(cols ? 2 : 1, dims);
    if (a && v && rows * (cols ? cols : 1) > 0)
        memcpy(PyArray_DATA((PyArrayObject *)a), v,
               (size_t)(rows * (cols ? cols : 1)) * sizeof(double));
    else if (a)
        memset(PyArray_DATA((PyArrayObject *)a), 0,
               (size_t)(rows * (cols ? cols : 1)) * sizeof(double));
    return a;
}

/* linearize(q) -> dict of M, K, D, N, Mr, Kr, Dr, omega, modes. */
static PyObject *an_linearize(pyeom_system *self, PyObject *qo)
{
    PyArrayObject *q = pyeom_vector(qo, self->n, "q");
    eom_linear lin;
    PyObject *d;
    int st, n, nr;
    if (!q)
        return NULL;
    memset(&lin, 0, sizeof lin);
    Py_BEGIN_ALLOW_THREADS
    st = eom_linearize(self->s, PyArray_DATA(q), &lin);
    Py_END_ALLOW_THREADS
    Py_DECREF(q);
    if (st < 0)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    n = lin.n;
    nr = lin.nr;
    d = Py_BuildValue("{s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N}",
                      "M", copy(lin.M, n, n), "K", copy(lin.K, n, n),
                      "D", copy(lin.D, n, n), "N", copy(lin.N, n, nr),
                      "Mr", copy(lin.Mr, nr, nr), "Kr", copy(lin.Kr, nr, nr),
                      "Dr", copy(lin.Dr, nr, nr),
                      "omega", copy(lin.omega, nr, 0),
                      "modes", copy(lin.modes, n, nr));
    eom_linear_free(&lin);
    return d;
}

/* The eigenvalues re + i im as one complex array. */
static PyObject *complex_of(const double *re, const double *im, npy_intp k)
{
    PyObject *a = PyArray_SimpleNew(1, &k, NPY_CDOUBLE);
    npy_intp i;
    if (!a)
        return NULL;
    for (i = 0; i < k; i++) {
        double *z = (double *)PyArray_GETPTR1((PyArrayObject *)a, i);
        z[0] = re[i];
        z[1] = im[i];
    }
    return a;
}

static PyObject *state_linear_dict(const eom_state_linear *l)
{
    return Py_BuildValue("{s:d,s:N,s:N,s:N,s:N,s:N,s:N,s:N}", "t", l->t,
                         "x", copy(l->x, l->n2, 0),
                         "A", copy(l->A, l->n2, l->n2),
                         "B", copy(l->B, l->n2, l->np),
                         "T", copy(l->T, l->n2, l->nz),
                         "Ar", copy(l->Ar, l->nz, l->nz),
                         "Br", copy(l->Br, l->nz, l->np),
                         "eigenvalues", complex_of(l->eig_re, l->eig_im,
                                                   l->nz));
}

/* linearize_state(t, x) -> dict of t, x, A, B, T, Ar, Br, eigenvalues. */
static PyObject *an_linearize_state(pyeom_system *self, PyObject *args)
{
    PyObject *xo, *d;
    PyArrayObject *x;
    eom_state_linear lin;
    double t;
    int st;
    if (!PyArg_ParseTuple(args, "dO", &t, &xo))
        return NULL;
    x = pyeom_vector(xo, 2 * self->n, "x");
    if (!x)
        return NULL;
    memset(&lin, 0, sizeof lin);
    Py_BEGIN_ALLOW_THREADS
    st = eom_linearize_state(self->s, t, PyArray_DATA(x), &lin);
    Py_END_ALLOW_THREADS
    Py_DECREF(x);
    if (st < 0)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    d = state_linear_dict(&lin);
    eom_state_linear_free(&lin);
    return d;
}

/* linearize_steady(t, x, keep=None) -> dict of kept (state indices), Ar,
 * eigenvalues, dropped (the eigenvalues left out), acc, full (the
 * linearize_state dict). */
static PyObject *an_linearize_steady(pyeom_system *self, PyObject *args)
{
    PyObject *xo, *keep_o = Py_None, *d = NULL, *kept;
    PyArrayObject *x, *keep = NULL;
    eom_steady_linear lin;
    double t;
    int st, nkeep = 0, i;
    if (!PyArg_ParseTuple(args, "dO|O", &t, &xo, &keep_o))
        return NULL;
    x = pyeom_vector(xo, 2 * self->n, "x");
    if (!x)
        return NULL;
    if (keep_o != Py_None) {
        keep = (PyArrayObject *)PyArray_FROMANY(keep_o, NPY_INT, 1, 1,
                                                NPY_ARRAY_IN_ARRAY);
        if (!keep) {
            Py_DECREF(x);
            return NULL;
        }
        nkeep = (int)PyArray_DIM(keep, 0);
    }
    memset(&lin, 0, sizeof lin);
    Py_BEGIN_ALLOW_THREADS
    st = eom_linearize_steady(self->s, t, PyArray_DATA(x),
                              keep ? PyArray_DATA(keep) : NULL, nkeep, &lin);
    Py_END_ALLOW_THREADS
    Py_DECREF(x);
    Py_XDECREF(keep);
    if (st < 0)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    kept = PyList_New(lin.nr);
    for (i = 0; kept && i < lin.nr; i++)
        PyList_SET_ITEM(kept, i, PyLong_FromLong(lin.kept[i]));
    if (kept)
        d = Py_BuildValue("{s:N,s:N,s:N,s:N,s:d,s:N}", "kept", kept,
                          "Ar", copy(lin.Ar, lin.nr, lin.nr),
                          "eigenvalues", complex_of(lin.eig_re, lin.eig_im,
                                                    lin.nr),
                          "dropped", complex_of(lin.drop_re, lin.drop_im,
                                                lin.ndrop),
                          "acc", lin.acc, "full",
                          state_linear_dict(&lin.full));
    eom_steady_linear_free(&lin);
    return d;
}

/* equilibrium(q, tol=1e-10) -> (q, iterations): Newton from the guess. */
static PyObject *an_equilibrium(pyeom_system *self, PyObject *args,
                                PyObject *kw)
{
    /* PyArg_ParseTupleAndKeywords takes char *, not const */
    static char k_q[] = "q", k_tol[] = "tol";
    static char *kwlist[] = {k_q, k_tol, NULL};
    PyObject *qo, *out;
    PyArrayObject *q;
    double tol = 1e-10;
    int st, iters = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|d", kwlist, &qo, &tol))
        return NULL;
    q = pyeom_vector(qo, self->n, "q");
    if (!q)
        return NULL;
    out = copy(PyArray_DATA(q), self->n, 0);
    Py_DECREF(q);
    if (!out)
        return NULL;
    Py_BEGIN_ALLOW_THREADS
    st = eom_equilibrium(self->s, PyArray_DATA((PyArrayObject *)out), tol,
                         &iters);
    Py_END_ALLOW_THREADS
    if (st < 0) {
        Py_DECREF(out);
        return pyeom_raise(st, eom_system_errmsg(self->s));
    }
    return Py_BuildValue("(Ni)", out, iters);
}

PyMethodDef pyeom_analysis_methods[] = {
    {"linearize", (PyCFunction)an_linearize, METH_O,
     "linearize(q) -> {'M','K','D','N','Mr','Kr','Dr','omega','modes'} about "
     "the rest state q (qd = 0)"},
    {"linearize_state", (PyCFunction)an_linearize_state, METH_VARARGS,
     "linearize_state(t, x) -> {'A','B','T','Ar','Br','eigenvalues',...}"},
    {"linearize_steady", (PyCFunction)an_linearize_steady, METH_VARARGS,
     "linearize_steady(t, x, keep=None) -> {'kept','Ar','eigenvalues',"
     "'dropped','acc','full'} about a steady motion"},
    {"equilibrium", (PyCFunction)(void (*)(void))an_equilibrium,
     METH_VARARGS | METH_KEYWORDS,
     "equilibrium(q, tol=1e-10) -> (q at rest, Newton iterations)"},
    {NULL, NULL, 0, NULL},
};
