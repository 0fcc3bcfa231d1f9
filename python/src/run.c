/* run.c - System.run: integrate from t = 0 to t_end with any of libeom's
 * methods and options, as eom-run does (the same sample grid, start
 * projection, integrator calls and CSV columns from the run layer), and
 * return the rows as one NumPy array instead of writing a CSV. The
 * integration runs without the GIL; the GIL is taken back at each row
 * only to check for KeyboardInterrupt and to call the progress callback.
 *
 * Options are read by pyeom_parse_opts, which ensemble.c shares. */
#include "pyeom.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "eom/run.h"

/* eom_opts.linear_solver from its name. */
static int linear_solver_of(const char *s)
{
    if (strcmp(s, "auto") == 0)
        return EOM_LINSOL_AUTO;
    if (strcmp(s, "dense") == 0)
        return EOM_LINSOL_DENSE;
    if (strcmp(s, "sparse") == 0)
        return EOM_LINSOL_SPARSE;
    return -1;
}

/* The input index of a sensitivity name (eom_opts.sens): a parameter,
 * a coordinate (its initial value) or NAME_dot (its initial rate). */
static int sens_input(pyeom_system *self, const char *name)
{
    const size_t len = strlen(name);
    char buf[256];
    int k = eom_param_index(self->s, name);
    if (k >= 0)
        return k;
    k = eom_coord_index(self->s, name);
    if (k >= 0)
        return self->np + k;
    if (len > 4 && len < sizeof buf && strcmp(name + len - 4, "_dot") == 0) {
        memcpy(buf, name, len - 4);
        buf[len - 4] = '\0';
        k = eom_coord_index(self->s, buf);
        if (k >= 0)
            return self->np + self->n + k;
    }
    return -1;
}

static int parse_sens(pyeom_system *self, PyObject *v, eom_opts *o,
                      int **sens_out)
{
    PyObject *seq = PySequence_Fast(v, "sensitivity= is a list of names");
    Py_ssize_t k, count;
    if (!seq)
        return -1;
    count = PySequence_Fast_GET_SIZE(seq);
    *sens_out = PyMem_Malloc(((size_t)count + 1) * sizeof(int));
    if (!*sens_out) {
        Py_DECREF(seq);
        PyErr_NoMemory();
        return -1;
    }
    for (k = 0; k < count; k++) {
        PyObject *item = PySequence_Fast_GET_ITEM(seq, k);
        const char *name = PyUnicode_Check(item) ? PyUnicode_AsUTF8(item)
                                                 : NULL;
        int w = name ? sens_input(self, name) : -1;
        if (w < 0) {
            PyErr_Format(PyExc_ValueError, "sensitivity=: %R is not a "
                         "parameter, coordinate or NAME_dot of the model",
                         item);
            Py_DECREF(seq);
            return -1;
        }
        (*sens_out)[k] = w;
    }
    Py_DECREF(seq);
    o->n_sens = (int)count;
    o->sens = *sens_out;
    return 0;
}

/* One option: returns 1 if key was known, 0 if not, -1 on error. */
static int parse_opt(pyeom_system *self, const char *key, PyObject *v,
                     eom_opts *o, int **sens_out)
{
    if (strcmp(key, "integrator") == 0) {
        const char *s = PyUnicode_Check(v) ? PyUnicode_AsUTF8(v) : NULL;
        int m = s ? eom_method_from_name(s) : -1;
        if (m < 0) {
            PyErr_Format(PyExc_ValueError, "integrator=%R: not one of rk4, "
                         "erk, adams, bdf, ida, esdirk, imex", v);
            return -1;
        }
        o->method = (eom_method)m;
    } else if (strcmp(key, "dt") == 0) {
        o->dt = PyFloat_AsDouble(v);
    } else if (strcmp(key, "rtol") == 0) {
        o->rtol = PyFloat_AsDouble(v);
    } else if (strcmp(key, "atol") == 0) {
        o->atol = PyFloat_AsDouble(v);
    } else if (strcmp(key, "proj_tol") == 0) {
        o->proj_tol = PyFloat_AsDouble(v);
    } else if (strcmp(key, "max_steps") == 0) {
        o->max_steps = PyLong_AsLong(v);
    } else if (strcmp(key, "max_order") == 0) {
        o->max_order = (int)PyLong_AsLong(v);
    } else if (strcmp(key, "project") == 0) {
        o->project = PyObject_IsTrue(v);
    } else if (strcmp(key, "tol_per_step") == 0) {
        o->tol_per_step = PyObject_IsTrue(v);
    } else if (strcmp(key, "dq_jacobian") == 0) {
        o->dq_jacobian = PyObject_IsTrue(v);
    } else if (strcmp(key, "erk_table") == 0) {
        o->erk_table = PyUnicode_AsUTF8(v); /* kept alive by kw */
        if (!o->erk_table)
            return -1;
    } else if (strcmp(key, "linear_solver") == 0) {
        const char *s = PyUnicode_Check(v) ? PyUnicode_AsUTF8(v) : NULL;
        int ls = s ? linear_solver_of(s) : -1;
        if (ls < 0) {
            PyErr_Format(PyExc_ValueError, "linear_solver=%R: not one of "
                         "auto, dense, sparse", v);
            return -1;
        }
        o->linear_solver = ls;
    } else if (strcmp(key, "sensitivity") == 0) {
        if (v != Py_None && parse_sens(self, v, o, sens_out) != 0)
            return -1;
    } else {
        return 0;
    }
    return PyErr_Occurred() ? -1 : 1;
}

int pyeom_parse_opts(pyeom_system *self, PyObject *kw, eom_opts *o,
                     int **sens_out)
{
    PyObject *key, *v;
    Py_ssize_t pos = 0;
    /* eom-run's defaults (docs/cli.md), not libeom's: the same call gives
     * the same run from Python and from the command line */
    eom_opts_default(o);
    o->method = EOM_ERK;
    o->dt = 1e-3;
    o->rtol = 1e-8;
    o->atol = 1e-10;
    o->max_steps = 10000000L;
    o->project = 1;
    *sens_out = NULL;
    while (kw && PyDict_Next(kw, &pos, &key, &v)) {
        const char *k = PyUnicode_AsUTF8(key);
        int rc = k ? parse_opt(self, k, v, o, sens_out) : -1;
        if (rc < 0)
            return -1;
        if (rc == 0) {
            PyErr_Format(PyExc_TypeError, "unknown option %R", key);
            return -1;
        }
    }
    return 0;
}

/* The optional CSV columns (EOM_RUN_* flags) from a list of names. */
static int parse_columns(PyObject *v, unsigned *extra)
{
    static const struct {
        const char *name;
        unsigned flag;
    } groups[] = {{"accelerations", EOM_RUN_ACCELERATIONS},
                  {"multipliers", EOM_RUN_MULTIPLIERS},
                  {"condition", EOM_RUN_CONDITION},
                  {"health", EOM_RUN_HEALTH}};
    PyObject *seq;
    Py_ssize_t k;
    *extra = 0;
    if (!v || v == Py_None)
        return 0;
    seq = PySequence_Fast(v, "columns= is a list of names");
    if (!seq)
        return -1;
    for (k = 0; k < PySequence_Fast_GET_SIZE(seq); k++) {
        PyObject *item = PySequence_Fast_GET_ITEM(seq, k);
        const char *s = PyUnicode_Check(item) ? PyUnicode_AsUTF8(item) : "";
        size_t g;
        for (g = 0; g < sizeof groups / sizeof groups[0]; g++)
            if (s && strcmp(s, groups[g].name) == 0)
                break;
        if (g == sizeof groups / sizeof groups[0]) {
            PyErr_Format(PyExc_ValueError, "columns=: %R is not one of "
                         "accelerations, multipliers, condition, health",
                         item);
            Py_DECREF(seq);
            return -1;
        }
        *extra |= groups[g].flag;
    }
    Py_DECREF(seq);
    return 0;
}

/* What the loop needs, kept together so that the GIL-free part touches
 * no Python object. */
typedef struct run_job {
    eom_system *s;
    eom_opts o;
    eom_run_columns *cols;
    eom_integ *it;
    double *data;     /* rows x width */
    double *x;        /* 2n */
    int width, n2;    /* columns, then 2n x n_sens sensitivities */
    long long rows;   /* rows filled */
    int st;           /* first failing status (< 0), else 0 */
    char msg[1024];
} run_job;

/* Fill row number job->rows at (t, x, W). */
static void fill_row(run_job *j, double t, double W)
{
    double *row = j->data + j->rows * j->width;
    eom_run_row_info info; /* the run layer fills it; not needed here */
    eom_stats st;
    int rc;
    if (j->it && eom_integ_stats(j->it, &st) == EOM_OK) {
        eom_run_columns_set_stats(j->cols, &st);
    } else {
        memset(&st, 0, sizeof st); /* the start row: nothing counted yet */
        eom_run_columns_set_stats(j->cols, &st);
    }
    rc = eom_run_columns_fill(j->cols, j->s, t, j->x, W, row, &info);
    if (rc < 0 && j->st == 0) {
        j->st = rc;
        snprintf(j->msg, sizeof j->msg, "at t = %.17g the outputs could "
                 "not be evaluated: %s", t, j->cols->msg);
    }
    if (j->o.n_sens > 0 && j->it) {
        /* eom_integ_sensitivities is S[i * ns + k]; the row holds them
         * input by input, as eom-run's CSV does */
        const int ns = j->o.n_sens, n2 = j->n2;
        double *S = row + j->cols->count + (size_t)n2 * ns; /* spare tail */
        int i, k;
        rc = eom_integ_sensitivities(j->it, S);
        for (k = 0; k < ns; k++)
            for (i = 0; i < n2; i++)
                row[j->cols->count + k * n2 + i] = S[i * ns + k];
        if (rc < 0 && j->st == 0) {
            j->st = rc;
            snprintf(j->msg, sizeof j->msg, "the sensitivities: %s",
                     eom_integ_errmsg(j->it));
        }
    }
    j->rows++;
}

/* Seconds on a monotonic clock. */
static double monotonic(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Call progress(t) with the GIL; checks for KeyboardInterrupt. */
static int tick(PyObject *progress, double t)
{
    PyObject *r;
    if (PyErr_CheckSignals() != 0)
        return -1;
    if (!progress || progress == Py_None)
        return 0;
    r = PyObject_CallFunction(progress, "d", t);
    Py_XDECREF(r);
    return r ? 0 : -1;
}

/* _run(x0, t_end, sample, columns, progress, **opts) -> (names, data,
 * stats, error): data has one row per sample time (the CSV's rows,
 * sensitivities after the other columns); error is None, or (status,
 * message) for a run that failed part way (its rows so far are kept). */
static PyObject *system_run(pyeom_system *self, PyObject *args, PyObject *kw)
{
    PyObject *x0o, *cols_o, *progress, *names = NULL, *data = NULL;
    PyObject *res = NULL, *stats = NULL;
    PyArrayObject *x0;
    run_job j;
    double t_end, sample, W = 0.0;
    long long K, k;
    int exact, *sens = NULL, c, pyerr = 0;
    int has_progress;
    double last_tick = monotonic(), loop_start, loop_end;
    unsigned extra;
    char err[1024];
    npy_intp dims[2];

    memset(&j, 0, sizeof j);
    if (!PyArg_ParseTuple(args, "OddOO", &x0o, &t_end, &sample, &cols_o,
                          &progress))
        return NULL;
    has_progress = progress != Py_None;
    if (!(t_end >= 0.0) || !(sample > 0.0) || t_end / sample > 1e9) {
        PyErr_Format(PyExc_ValueError, "t_end must be >= 0 and sample > 0, "
                     "with at most 1e9 rows (t_end = %R, sample = %R)",
                     PyTuple_GET_ITEM(args, 1), PyTuple_GET_ITEM(args, 2));
        return NULL;
    }
    if (parse_columns(cols_o, &extra) != 0)
        return NULL;
    if (pyeom_parse_opts(self, kw, &j.o, &sens) != 0)
        return NULL;
    x0 = pyeom_vector(x0o, 2 * self->n, "x0");
    if (!x0)
        goto done;
    j.s = self->s;
    j.n2 = 2 * self->n;
    j.x = self->scratch;
    memcpy(j.x, PyArray_DATA(x0), (size_t)j.n2 * sizeof(double));
    Py_DECREF(x0);
    if (eom_run_columns_new(&j.cols, self->s, extra, err, sizeof err) != 0) {
        pyeom_raise(EOM_ERR_ARG, err);
        goto done;
    }
    j.width = j.cols->count + j.n2 * j.o.n_sens;
    eom_run_grid(t_end, sample, &K, &exact);
    /* one spare row: the sensitivities' scratch of fill_row */
    j.data = PyMem_Malloc(((size_t)(K + 2 + !exact)) * (size_t)j.width *
                          sizeof(double));
    if (!j.data) {
        PyErr_NoMemory();
        goto done;
    }
    /* the start as eom-run takes it: checked, and projected onto the
     * constraints when it is off them */
    if (self->m > 0 && eom_run_prepare_start(self->s, j.x, &j.o, "autoeom",
                                             "model") != 0) {
        pyeom_raise(EOM_ERR_PROJECTION, "the start could not be taken "
                    "onto the constraints (see the message above)");
        goto done;
    }
    /* the span without the GIL, for stats (on time.perf_counter's clock:
     * a test compares it with what other threads did meanwhile) */
    loop_start = monotonic();
    Py_BEGIN_ALLOW_THREADS
    if (j.o.n_sens == 0)
        fill_row(&j, 0.0, 0.0);
    if ((K > 0 || !exact || j.o.n_sens > 0) && j.st == 0) {
        j.st = eom_integ_new(&j.it, self->s, &j.o, 0.0, j.x);
        if (j.st < 0)
            snprintf(j.msg, sizeof j.msg, "cannot start the %s integrator: "
                     "%s", eom_method_name(j.o.method),
                     eom_system_errmsg(self->s));
    }
    if (j.o.n_sens > 0 && j.st == 0)
        fill_row(&j, 0.0, 0.0);
    for (k = 1; j.st == 0 && k <= K + !exact; k++) {
        const double tout = k <= K ? (double)k * sample : t_end;
        int rc = eom_integ_advance(j.it, tout, j.x, &W);
        if (rc < 0) {
            j.st = rc;
            snprintf(j.msg, sizeof j.msg, "integration failed before t = "
                     "%.17g: %s", tout, eom_integ_errmsg(j.it));
            break;
        }
        fill_row(&j, tout, W);
        /* back to Python for the progress callback at each row, else
         * every 0.2 s for Ctrl-C only: taking the GIL at every row would
         * make a run wait on any busy Python thread */
        if (has_progress || monotonic() - last_tick >= 0.2) {
            Py_BLOCK_THREADS
            pyerr = tick(progress, tout);
            Py_UNBLOCK_THREADS
            last_tick = monotonic();
            if (pyerr)
                break;
        }
    }
    Py_END_ALLOW_THREADS
    loop_end = monotonic();
    if (pyerr)
        goto done;
    /* the rows filled (all, or those before a failure) */
    dims[0] = (npy_intp)j.rows;
    dims[1] = j.width;
    data = pyeom_empty(2, dims);
    if (!data)
        goto done;
    memcpy(PyArray_DATA((PyArrayObject *)data), j.data,
           (size_t)j.rows * (size_t)j.width * sizeof(double));
    names = PyList_New(0);
    for (c = 0; names && c < j.cols->count; c++) {
        PyObject *s = PyUnicode_FromString(j.cols->names[c]);
        if (!s || PyList_Append(names, s) != 0)
            Py_CLEAR(names);
        Py_XDECREF(s);
    }
    if (!names)
        goto done;
    {
        eom_stats st;
        memset(&st, 0, sizeof st);
        if (j.it)
            eom_integ_stats(j.it, &st);
        stats = Py_BuildValue(
            "{s:l,s:l,s:l,s:l,s:l,s:d,s:d,s:d,s:l,s:l,s:l,s:d,s:d,s:d,"
            "s:d}",
            "steps", st.steps, "rhs_evals", st.rhs_evals, "failures",
            st.failures, "jac_evals", st.jac_evals, "projections",
            st.projections, "wall_time", st.wall_time, "max_residual",
            st.max_residual, "min_rcond_S", st.min_rcond_S, "svd_solves",
            st.svd_solves, "singular_passes", st.singular_passes,
            "branch_switches", st.branch_switches, "step_tol", st.step_tol,
            "tol_reachable", st.tol_reachable, "loop_start", loop_start,
            "loop_end", loop_end);
    }
    if (!stats)
        goto done;
    res = Py_BuildValue("(NNNN)", names, data, stats,
                        j.st < 0 ? Py_BuildValue("(is)", j.st, j.msg)
                                 : Py_NewRef(Py_None));
    names = data = stats = NULL;
done:
    Py_XDECREF(names);
    Py_XDECREF(data);
    Py_XDECREF(stats);
    eom_integ_free(&j.it);
    eom_run_columns_free(&j.cols);
    PyMem_Free(j.data);
    PyMem_Free(sens);
    return res;
}

PyMethodDef pyeom_run_methods[] = {
    {"_run", (PyCFunction)(void (*)(void))system_run,
     METH_VARARGS | METH_KEYWORDS,
     "_run(x0, t_end, sample, columns, progress, **options) -> (names, "
     "data, stats, error) (use System.run)"},
    {NULL, NULL, 0, NULL},
};
