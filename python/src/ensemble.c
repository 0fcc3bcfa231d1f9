/* ensemble.c - System.ensemble: many runs of one system, one per row of
 * a NumPy array of parameter sets, on threads in C. Each thread owns a
 * clone of the system (eom_system_clone: the tapes are shared read-only,
 * the workspaces are its own) and takes the next run from a counter under
 * a mutex, so a slow run does not hold the others back. The whole
 * ensemble runs without the GIL. Every run's state is kept at the sample
 * times of the run's grid (eom_run_grid), as eom-run's rows would be. */
#include "pyeom.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "eom/run.h"

typedef struct ens_job {
    eom_system *base;
    const eom_opts *o;
    const double *P;     /* runs x nset parameter values */
    int *pidx;           /* nset parameter indices */
    const double *x0;    /* 2n start for every run, or NULL: the model's */
    int nset, n2, nrows;
    long long K;
    int exact;
    double t_end, sample;
    double *X;           /* runs x nrows x 2n states */
    double *W;           /* runs x nrows */
    int *status;         /* runs: 0 or a negative libeom status */
    char (*msg)[256];    /* runs: why a run failed */
    pthread_mutex_t lock;
    int next, runs;
} ens_job;

/* One run r on system s (a clone owned by the calling thread). */
static void one_run(ens_job *j, eom_system *s, int r)
{
    double *x = j->X + (size_t)r * j->nrows * j->n2;
    double *W = j->W + (size_t)r * j->nrows;
    eom_integ *it = NULL;
    long long k = 0, i;
    int st = EOM_OK, p;
    for (p = 0; p < j->nset && st == EOM_OK; p++)
        st = eom_set_param(s, j->pidx[p], j->P[(size_t)r * j->nset + p]);
    if (st == EOM_OK && j->x0)
        memcpy(x, j->x0, (size_t)j->n2 * sizeof(double));
    else if (st == EOM_OK)
        st = eom_initial_state(s, x);
    if (st == EOM_OK && j->o->project && eom_system_nconstraints(s) > 0) {
        st = eom_set_time(s, 0.0);
        if (st == EOM_OK)
            st = eom_project_start(s, x, j->o->proj_tol, NULL);
    }
    W[0] = 0.0;
    if (st == EOM_OK && j->nrows > 1)
        st = eom_integ_new(&it, s, j->o, 0.0, x);
    for (k = 1; st == EOM_OK && k < j->nrows; k++) {
        const double tout = k <= j->K ? (double)k * j->sample : j->t_end;
        memcpy(x + k * j->n2, x + (k - 1) * j->n2,
               (size_t)j->n2 * sizeof(double));
        st = eom_integ_advance(it, tout, x + k * j->n2, W + k);
        if (st > 0)
            st = EOM_OK;
    }
    if (st < 0) {
        /* a setup failure spoils every row, an integrator failure the
         * rows from the one it did not reach: NaN, never stale numbers */
        const long long first = it ? k - 1 : 0;
        snprintf(j->msg[r], sizeof j->msg[r], "%s",
                 it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
        for (i = first * j->n2; i < (long long)j->nrows * j->n2; i++)
            x[i] = NAN;
        for (i = first; i < j->nrows; i++)
            W[i] = NAN;
    }
    j->status[r] = st < 0 ? st : 0;
    eom_integ_free(&it);
}

static void *worker(void *arg)
{
    ens_job *j = arg;
    eom_system *s = NULL;
    char err[256];
    int r, st;
    pthread_mutex_lock(&j->lock);
    /* cloning reads the base system: one thread at a time */
    st = eom_system_clone(&s, j->base, err, sizeof err);
    pthread_mutex_unlock(&j->lock);
    for (;;) {
        pthread_mutex_lock(&j->lock);
        r = j->next < j->runs ? j->next++ : -1;
        pthread_mutex_unlock(&j->lock);
        if (r < 0)
            break;
        if (st != EOM_OK) {
            j->status[r] = st;
            snprintf(j->msg[r], sizeof j->msg[r], "%s", err);
            continue;
        }
        one_run(j, s, r);
    }
    eom_system_free(&s);
    return NULL;
}

/* Indices of the parameters named in the sequence names. */
static int param_indices(pyeom_system *self, PyObject *names, int *pidx,
                         int nset)
{
    int p;
    for (p = 0; p < nset; p++) {
        PyObject *item = PySequence_GetItem(names, p);
        const char *s = item && PyUnicode_Check(item)
                            ? PyUnicode_AsUTF8(item) : NULL;
        pidx[p] = s ? eom_param_index(self->s, s) : -1;
        if (pidx[p] < 0) {
            if (!PyErr_Occurred())
                PyErr_Format(PyExc_ValueError, "ensemble: %R is not a "
                             "parameter of the model", item);
            Py_XDECREF(item);
            return -1;
        }
        Py_DECREF(item);
    }
    return 0;
}

/* _ensemble(params, names, x0, t_end, sample, threads, **options) ->
 * (X, W, status, messages): X (runs, rows, 2n), W (runs, rows), status
 * (runs,) with 0 for a run that reached t_end, messages a list of str. */
static PyObject *system_ensemble(pyeom_system *self, PyObject *args,
                                 PyObject *kw)
{
    PyObject *P_o, *names, *x0_o, *X = NULL, *W = NULL, *S = NULL;
    PyObject *msgs = NULL, *res = NULL;
    PyArrayObject *P = NULL, *x0 = NULL;
    pthread_t *tids = NULL;
    ens_job j;
    eom_opts o;
    int *sens = NULL, threads, started = 0, t, r;
    npy_intp dims[3];

    memset(&j, 0, sizeof j);
    if (!PyArg_ParseTuple(args, "OOOddi", &P_o, &names, &x0_o, &j.t_end,
                          &j.sample, &threads))
        return NULL;
    if (!(j.t_end >= 0.0) || !(j.sample > 0.0) || j.t_end / j.sample > 1e9) {
        PyErr_SetString(PyExc_ValueError, "t_end must be >= 0 and sample "
                        "> 0, with at most 1e9 rows");
        return NULL;
    }
    if (pyeom_parse_opts(self, kw, &o, &sens) != 0)
        return NULL;
    if (o.n_sens > 0) {
        PyErr_SetString(PyExc_ValueError, "ensemble: sensitivity= is for "
                        "run()");
        goto done;
    }
    P = (PyArrayObject *)PyArray_FROMANY(P_o, NPY_DOUBLE, 2, 2,
                                         NPY_ARRAY_IN_ARRAY);
    if (!P)
        goto done;
    j.runs = (int)PyArray_DIM(P, 0);
    j.nset = (int)PyArray_DIM(P, 1);
    if (!PySequence_Check(names) || PySequence_Size(names) != j.nset) {
        PyErr_Format(PyExc_ValueError, "ensemble: %d parameter columns "
                     "need %d names", j.nset, j.nset);
        goto done;
    }
    j.pidx = PyMem_Malloc(((size_t)j.nset + 1) * sizeof(int));
    if (!j.pidx || param_indices(self, names, j.pidx, j.nset) != 0)
        goto done;
    if (x0_o != Py_None) {
        x0 = pyeom_vector(x0_o, 2 * self->n, "x0");
        if (!x0)
            goto done;
        j.x0 = PyArray_DATA(x0);
    }
    eom_run_grid(j.t_end, j.sample, &j.K, &j.exact);
    j.nrows = (int)(j.K + 1 + !j.exact);
    j.n2 = 2 * self->n;
    j.base = self->s;
    j.o = &o;
    j.P = PyArray_DATA(P);
    dims[0] = j.runs;
    dims[1] = j.nrows;
    dims[2] = j.n2;
    X = pyeom_empty(3, dims);
    W = pyeom_empty(2, dims);
    S = PyArray_ZEROS(1, dims, NPY_INT, 0);
    j.msg = PyMem_Calloc((size_t)j.runs + 1, sizeof *j.msg);
    if (!X || !W || !S || !j.msg) {
        if (!PyErr_Occurred())
            PyErr_NoMemory();
        goto done;
    }
    j.X = PyArray_DATA((PyArrayObject *)X);
    j.W = PyArray_DATA((PyArrayObject *)W);
    j.status = PyArray_DATA((PyArrayObject *)S);
    if (threads <= 0)
        threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (threads > j.runs)
        threads = j.runs > 0 ? j.runs : 1;
    tids = PyMem_Malloc((size_t)threads * sizeof *tids);
    if (!tids) {
        PyErr_NoMemory();
        goto done;
    }
    pthread_mutex_init(&j.lock, NULL);
    Py_BEGIN_ALLOW_THREADS
    for (t = 0; t < threads; t++) {
        if (pthread_create(&tids[t], NULL, worker, &j) != 0)
            break;
        started++;
    }
    if (started == 0)
        worker(&j); /* no thread could start: this one does the work */
    for (t = 0; t < started; t++)
        pthread_join(tids[t], NULL);
    Py_END_ALLOW_THREADS
    pthread_mutex_destroy(&j.lock);
    msgs = PyList_New(j.runs);
    for (r = 0; msgs && r < j.runs; r++) {
        PyObject *s = PyUnicode_DecodeUTF8(j.msg[r], (Py_ssize_t)strlen(
                                               j.msg[r]), "replace");
        if (!s) {
            Py_CLEAR(msgs);
            break;
        }
        PyList_SET_ITEM(msgs, r, s);
    }
    if (msgs) {
        res = Py_BuildValue("(NNNN)", X, W, S, msgs);
        X = W = S = msgs = NULL;
    }
done:
    Py_XDECREF(X);
    Py_XDECREF(W);
    Py_XDECREF(S);
    Py_XDECREF(msgs);
    Py_XDECREF(P);
    Py_XDECREF(x0);
    PyMem_Free(j.pidx);
    PyMem_Free(j.msg);
    PyMem_Free(tids);
    PyMem_Free(sens);
    return res;
}

PyMethodDef pyeom_ensemble_methods[] = {
    {"_ensemble", (PyCFunction)(void (*)(void))system_ensemble,
     METH_VARARGS | METH_KEYWORDS,
     "_ensemble(params, names, x0, t_end, sample, threads, **options) -> "
     "(X, W, status, messages) (use System.ensemble)"},
    {NULL, NULL, 0, NULL},
};
