/* system.c - the System type of autoeom._core: a built eom_system, made
 * from a model file or text (load) or from a recorded Model, with its
 * names, parameters, initial state, time, Baumgarte settings, clones and
 * compiled tapes. Evaluation, runs and analysis live in their own files
 * (evaluate.c, run.c, analysis.c, ensemble.c). */
#include "pyeom.h"

#include <stdlib.h>
#include <string.h>

#include "eom/model_file.h"

PyObject *pyeom_system_wrap(PyTypeObject *cls, eom_system *s)
{
    pyeom_system *self = (pyeom_system *)cls->tp_alloc(cls, 0);
    if (!self) {
        eom_system_free(&s);
        return NULL;
    }
    self->s = s;
    self->n = eom_system_ncoords(s);
    self->m = eom_system_nconstraints(s);
    self->np = eom_system_nparams(s);
    self->nprobes = eom_system_nprobes(s);
    self->scratch = PyMem_Malloc((2 * (size_t)self->n + 1) * sizeof(double));
    if (!self->scratch) {
        Py_DECREF(self);
        return PyErr_NoMemory();
    }
    return (PyObject *)self;
}

static void system_dealloc(pyeom_system *self)
{
    PyObject_GC_UnTrack(self);
    if (self->weakrefs)
        PyObject_ClearWeakRefs((PyObject *)self);
    Py_CLEAR(self->dict);
    eom_system_free(&self->s);
    PyMem_Free(self->scratch);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int system_traverse(pyeom_system *self, visitproc visit, void *arg)
{
    Py_VISIT(self->dict);
    Py_VISIT(Py_TYPE(self));
    return 0;
}

static int system_clear(pyeom_system *self)
{
    Py_CLEAR(self->dict);
    return 0;
}

/* Apply the structural settings found in sets (a dict) to f, removing
 * them from sets. -1 with an exception. */
static int apply_settings(eom_file *f, PyObject *sets)
{
    const int ns = eom_file_nsettings(f);
    char err[1024];
    int k;
    for (k = 0; k < ns; k++) {
        const char *name = eom_file_setting_name(f, k);
        PyObject *v = PyDict_GetItemString(sets, name); /* borrowed */
        long value;
        int st;
        if (!v)
            continue;
        if (!PyLong_Check(v) && !(PyFloat_Check(v) &&
                                  PyFloat_AsDouble(v) ==
                                      (double)(long)PyFloat_AsDouble(v))) {
            PyErr_Format(PyExc_TypeError, "setting %s must be a whole "
                         "number, not %R", name, v);
            return -1;
        }
        value = PyLong_Check(v) ? PyLong_AsLong(v)
                                : (long)PyFloat_AsDouble(v);
        if (value == -1 && PyErr_Occurred())
            return -1;
        st = eom_file_set_setting(f, name, value, err, sizeof err);
        if (st != EOM_OK) {
            pyeom_raise(st, err);
            return -1;
        }
        if (PyDict_DelItemString(sets, name) != 0)
            return -1;
    }
    return 0;
}

/* _core.load(cls, source, is_text, sets) -> System: read (is_text false:
 * a path) or parse a model file, apply the structural settings named in
 * the dict sets (removed from it: the caller applies the rest), build
 * the model and record the system. */
static PyObject *system_load(PyObject *type, PyObject *args)
{
    PyObject *src, *sets, *res = NULL, *bytes = NULL;
    PyTypeObject *cls = (PyTypeObject *)type;
    int is_text, st;
    eom_file *f = NULL;
    eom_model *model = NULL;
    eom_system *s = NULL;
    char err[4096];

    if (!PyArg_ParseTuple(args, "OpO!", &src, &is_text, &PyDict_Type, &sets))
        return NULL;
    err[0] = '\0';
    if (is_text) {
        const char *text = PyUnicode_AsUTF8(src);
        if (!text)
            return NULL;
        Py_BEGIN_ALLOW_THREADS
        st = eom_file_parse(&f, text, "<string>", err, sizeof err);
        Py_END_ALLOW_THREADS
    } else {
        if (!PyUnicode_FSConverter(src, &bytes))
            return NULL;
        Py_BEGIN_ALLOW_THREADS
        st = eom_file_read(&f, PyBytes_AS_STRING(bytes), err, sizeof err);
        Py_END_ALLOW_THREADS
    }
    if (st != EOM_OK) {
        pyeom_raise(st, err);
        goto done;
    }
    if (apply_settings(f, sets) != 0)
        goto done;
    Py_BEGIN_ALLOW_THREADS
    st = eom_file_build(f, &model, err, sizeof err);
    if (st == EOM_OK)
        st = eom_system_new(&s, model, err, sizeof err);
    Py_END_ALLOW_THREADS
    if (st != EOM_OK) {
        pyeom_raise(st, err);
        goto done;
    }
    res = pyeom_system_wrap(cls, s);
done:
    eom_model_free(&model);
    eom_file_free(&f);
    Py_XDECREF(bytes);
    return res;
}

/* _core.file_settings(source, is_text) -> [(name, default, min, max,
 * description)]: the structural settings of a model file. */
static PyObject *system_file_settings(PyObject *type, PyObject *args)
{
    PyObject *src, *bytes = NULL, *list = NULL;
    int is_text, st, k;
    eom_file *f = NULL;
    char err[4096];
    (void)type;
    if (!PyArg_ParseTuple(args, "Op", &src, &is_text))
        return NULL;
    if (is_text) {
        const char *text = PyUnicode_AsUTF8(src);
        if (!text)
            return NULL;
        st = eom_file_parse(&f, text, "<string>", err, sizeof err);
    } else {
        if (!PyUnicode_FSConverter(src, &bytes))
            return NULL;
        st = eom_file_read(&f, PyBytes_AS_STRING(bytes), err, sizeof err);
        Py_DECREF(bytes);
    }
    if (st != EOM_OK)
        return pyeom_raise(st, err);
    list = PyList_New(0);
    for (k = 0; list && k < eom_file_nsettings(f); k++) {
        long d = 0, lo = 0, hi = 0;
        PyObject *t;
        eom_file_setting_range(f, k, &d, &lo, &hi);
        t = Py_BuildValue("(sllls)", eom_file_setting_name(f, k), d, lo, hi,
                          eom_file_setting_description(f, k));
        if (!t || PyList_Append(list, t) != 0)
            Py_CLEAR(list);
        Py_XDECREF(t);
    }
    eom_file_free(&f);
    return list;
}

/* Index of a parameter given by name or index; -1 with an exception. */
static int param_index(pyeom_system *self, PyObject *key)
{
    int k;
    if (PyLong_Check(key)) {
        k = (int)PyLong_AsLong(key);
        if (k < 0 || k >= self->np) {
            if (!PyErr_Occurred())
                PyErr_Format(PyExc_IndexError, "parameter index %d out of "
                             "range 0..%d", k, self->np - 1);
            return -1;
        }
        return k;
    }
    if (!PyUnicode_Check(key)) {
        PyErr_SetString(PyExc_TypeError, "a parameter is named by a str or "
                        "an int index");
        return -1;
    }
    k = eom_param_index(self->s, PyUnicode_AsUTF8(key));
    if (k < 0)
        PyErr_Format(PyExc_KeyError, "no parameter named %R", key);
    return k;
}

static PyObject *system_get_param(pyeom_system *self, PyObject *key)
{
    int k = param_index(self, key);
    return k < 0 ? NULL : PyFloat_FromDouble(eom_get_param(self->s, k));
}

static PyObject *system_set_param(pyeom_system *self, PyObject *args)
{
    PyObject *key;
    double v;
    int k, st;
    if (!PyArg_ParseTuple(args, "Od", &key, &v))
        return NULL;
    k = param_index(self, key);
    if (k < 0)
        return NULL;
    st = eom_set_param(self->s, k, v);
    if (st != EOM_OK)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    Py_RETURN_NONE;
}

static PyObject *system_initial_state(pyeom_system *self, PyObject *unused)
{
    npy_intp dim = 2 * self->n;
    PyObject *x = pyeom_empty(1, &dim);
    int st;
    (void)unused;
    if (!x)
        return NULL;
    st = eom_initial_state(self->s, PyArray_DATA((PyArrayObject *)x));
    if (st != EOM_OK) {
        Py_DECREF(x);
        return pyeom_raise(st, eom_system_errmsg(self->s));
    }
    return x;
}

static PyObject *system_set_baumgarte(pyeom_system *self, PyObject *args)
{
    double a, b;
    int st;
    if (!PyArg_ParseTuple(args, "dd", &a, &b))
        return NULL;
    st = eom_set_baumgarte(self->s, a, b);
    if (st != EOM_OK)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    Py_RETURN_NONE;
}

static PyObject *system_set_time(pyeom_system *self, PyObject *arg)
{
    double t = PyFloat_AsDouble(arg);
    int st;
    if (t == -1.0 && PyErr_Occurred())
        return NULL;
    st = eom_set_time(self->s, t);
    if (st != EOM_OK)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    Py_RETURN_NONE;
}

static PyObject *system_get_time(pyeom_system *self, PyObject *unused)
{
    (void)unused;
    return PyFloat_FromDouble(eom_get_time(self->s));
}

/* clone(): a System sharing the tapes, for another thread. */
static PyObject *system_clone(pyeom_system *self, PyObject *unused)
{
    eom_system *c = NULL;
    char err[1024];
    int st;
    (void)unused;
    st = eom_system_clone(&c, self->s, err, sizeof err);
    if (st != EOM_OK)
        return pyeom_raise(st, err);
    return pyeom_system_wrap(Py_TYPE(self), c);
}

/* set_compiled(on) -> (status, message, info dict): status 1 means the
 * interpreter stays in use (EOM_WARN_INTERPRETED, message says why). */
static PyObject *system_set_compiled(pyeom_system *self, PyObject *arg)
{
    eom_compiled_info info;
    int on = PyObject_IsTrue(arg), st;
    if (on < 0)
        return NULL;
    memset(&info, 0, sizeof info);
    Py_BEGIN_ALLOW_THREADS
    st = eom_system_set_compiled(self->s, on, &info);
    Py_END_ALLOW_THREADS
    if (st < 0)
        return pyeom_raise(st, eom_system_errmsg(self->s));
    return Py_BuildValue("(is{s:i,s:i,s:i,s:d,s:n})", st,
                         st ? eom_system_errmsg(self->s) : "",
                         "tapes", info.tapes, "cached", info.cached,
                         "rebuilt", info.rebuilt, "seconds", info.seconds,
                         "source_bytes", (Py_ssize_t)info.source_bytes);
}

/* A list of count strings from name(s, k). */
static PyObject *names(const eom_system *s, int count,
                       const char *(*name)(const eom_system *, int))
{
    PyObject *list = PyList_New(count);
    int k;
    for (k = 0; list && k < count; k++) {
        PyObject *v = PyUnicode_FromString(name(s, k));
        if (!v) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, k, v);
    }
    return list;
}

static PyObject *get_coord_names(pyeom_system *self, void *c)
{
    (void)c;
    return names(self->s, self->n, eom_coord_name);
}
static PyObject *get_coord_units(pyeom_system *self, void *c)
{
    (void)c;
    return names(self->s, self->n, eom_coord_unit);
}
static PyObject *get_param_names(pyeom_system *self, void *c)
{
    (void)c;
    return names(self->s, self->np, eom_param_name);
}
static PyObject *get_param_units(pyeom_system *self, void *c)
{
    (void)c;
    return names(self->s, self->np, eom_param_unit);
}
static PyObject *get_probe_names(pyeom_system *self, void *c)
{
    (void)c;
    return names(self->s, self->nprobes, eom_probe_name);
}
static PyObject *get_param_values(pyeom_system *self, void *c)
{
    npy_intp dim = self->np;
    PyObject *a = pyeom_empty(1, &dim);
    int k;
    (void)c;
    for (k = 0; a && k < self->np; k++)
        ((double *)PyArray_DATA((PyArrayObject *)a))[k] =
            eom_get_param(self->s, k);
    return a;
}
static PyObject *get_int(int v)
{
    return PyLong_FromLong(v);
}
static PyObject *get_ncoords(pyeom_system *self, void *c)
{
    (void)c;
    return get_int(self->n);
}
static PyObject *get_nconstraints(pyeom_system *self, void *c)
{
    (void)c;
    return get_int(self->m);
}
static PyObject *get_nvelocity(pyeom_system *self, void *c)
{
    (void)c;
    return get_int(eom_system_nvelocity_constraints(self->s));
}
static PyObject *get_nparams(pyeom_system *self, void *c)
{
    (void)c;
    return get_int(self->np);
}
static PyObject *get_nprobes(pyeom_system *self, void *c)
{
    (void)c;
    return get_int(self->nprobes);
}
static PyObject *get_compiled(pyeom_system *self, void *c)
{
    (void)c;
    return PyBool_FromLong(eom_system_compiled(self->s));
}
static PyObject *get_reads_time(pyeom_system *self, void *c)
{
    (void)c;
    return PyBool_FromLong(eom_system_reads_time(self->s));
}

static PyGetSetDef system_getset[] = {
    {"ncoords", (getter)get_ncoords, NULL, "number of coordinates n", NULL},
    {"nconstraints", (getter)get_nconstraints, NULL,
     "constraint rows m (holonomic, then velocity rows)", NULL},
    {"nvelocity_constraints", (getter)get_nvelocity, NULL,
     "of the constraint rows, the velocity (non-holonomic) ones", NULL},
    {"nparams", (getter)get_nparams, NULL, "number of parameters", NULL},
    {"nprobes", (getter)get_nprobes, NULL, "number of probes", NULL},
    {"coord_names", (getter)get_coord_names, NULL, "coordinate names", NULL},
    {"coord_units", (getter)get_coord_units, NULL, "coordinate units", NULL},
    {"param_names", (getter)get_param_names, NULL, "parameter names", NULL},
    {"param_units", (getter)get_param_units, NULL, "parameter units", NULL},
    {"param_values", (getter)get_param_values, NULL,
     "the parameter values in use, in index order", NULL},
    {"probe_names", (getter)get_probe_names, NULL, "probe names", NULL},
    {"compiled", (getter)get_compiled, NULL,
     "True when compiled tapes are in use", NULL},
    {"reads_time", (getter)get_reads_time, NULL,
     "True for a model whose energies or constraints read the time", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyMethodDef pyeom_system_base_methods[] = {
    {"_load", system_load, METH_VARARGS | METH_CLASS,
     "_load(source, is_text, sets) -> System (use autoeom.load)"},
    {"_file_settings", system_file_settings, METH_VARARGS | METH_STATIC,
     "_file_settings(source, is_text) -> the structural settings"},
    {"get_param", (PyCFunction)system_get_param, METH_O,
     "get_param(name or index) -> the value in use"},
    {"set_param", (PyCFunction)system_set_param, METH_VARARGS,
     "set_param(name or index, value)"},
    {"initial_state", (PyCFunction)system_initial_state, METH_NOARGS,
     "initial_state() -> the model's default x0 = (q0, qd0) at the "
     "parameters in use"},
    {"set_baumgarte", (PyCFunction)system_set_baumgarte, METH_VARARGS,
     "set_baumgarte(alpha, beta): Baumgarte stabilization (0, 0: off)"},
    {"set_time", (PyCFunction)system_set_time, METH_O,
     "set_time(t): the time of the calls that take none"},
    {"get_time", (PyCFunction)system_get_time, METH_NOARGS,
     "get_time() -> the system's time"},
    {"clone", (PyCFunction)system_clone, METH_NOARGS,
     "clone() -> a System sharing the tapes, for another thread"},
    {"_set_compiled", (PyCFunction)system_set_compiled, METH_O,
     "_set_compiled(on) -> (status, message, info)"},
    {NULL, NULL, 0, NULL},
};

PyTypeObject pyeom_system_type = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "autoeom._core.System",
    .tp_basicsize = sizeof(pyeom_system),
    .tp_dealloc = (destructor)system_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "A built system: recorded tapes, parameters and solvers "
              "(make one with autoeom.load or Model.build).",
    .tp_traverse = (traverseproc)system_traverse,
    .tp_clear = (inquiry)system_clear,
    .tp_weaklistoffset = offsetof(pyeom_system, weakrefs),
    .tp_dictoffset = offsetof(pyeom_system, dict),
    .tp_getset = system_getset,
};
