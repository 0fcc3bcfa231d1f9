/* module.c - autoeom._core: module initialisation, the exception type
 * autoeom.Error, and the array helpers shared by the other files.
 *
 * NumPy's C API is imported here once (PYEOM_MODULE_C); the other files
 * reach it through the same unique symbol (pyeom.h). */
#define PYEOM_MODULE_C
#include "pyeom.h"

#include <string.h>

#include "eom/model_file.h"

PyObject *pyeom_error;

PyObject *pyeom_raise(int st, const char *msg)
{
    PyObject *exc, *v;
    if (!msg || !*msg)
        msg = eom_strerror(st);
    /* str(e) is the message alone, as the library wrote it (file:line:col
     * for model files); the status rides along as attributes */
    exc = PyObject_CallFunction(pyeom_error, "s", msg);
    if (!exc)
        return NULL;
    v = PyLong_FromLong(st);
    if (!v || PyObject_SetAttrString(exc, "status", v) != 0)
        goto done;
    Py_DECREF(v);
    v = PyUnicode_FromString(eom_status_name(st));
    if (!v || PyObject_SetAttrString(exc, "status_name", v) != 0)
        goto done;
    PyErr_SetObject(pyeom_error, exc);
done:
    Py_XDECREF(v);
    Py_DECREF(exc);
    return NULL;
}

PyArrayObject *pyeom_vector(PyObject *obj, npy_intp count, const char *what)
{
    PyArrayObject *a;
    /* the common case first and cheaply: already what we need */
    if (PyArray_Check(obj) &&
        PyArray_TYPE((PyArrayObject *)obj) == NPY_DOUBLE &&
        PyArray_IS_C_CONTIGUOUS((PyArrayObject *)obj) &&
        PyArray_NDIM((PyArrayObject *)obj) == 1) {
        a = (PyArrayObject *)obj;
        Py_INCREF(a);
    } else {
        a = (PyArrayObject *)PyArray_FROMANY(obj, NPY_DOUBLE, 0, 0,
                                             NPY_ARRAY_IN_ARRAY);
        if (!a)
            return NULL;
    }
    if (PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != count) {
        PyErr_Format(PyExc_ValueError,
                     "%s must be a vector of %zd values (got %d "
                     "dimension(s), %zd values)", what, (Py_ssize_t)count,
                     PyArray_NDIM(a), (Py_ssize_t)PyArray_SIZE(a));
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

PyObject *pyeom_empty(int nd, const npy_intp *dims)
{
    npy_intp d[NPY_MAXDIMS];
    int k;
    for (k = 0; k < nd && k < NPY_MAXDIMS; k++)
        d[k] = dims[k]; /* NumPy takes them without const */
    return PyArray_SimpleNew(nd, d, NPY_DOUBLE);
}

/* autoeom._core.strerror(status): the library's text for a status. */
static PyObject *mod_strerror(PyObject *mod, PyObject *arg)
{
    long st = PyLong_AsLong(arg);
    (void)mod;
    if (st == -1 && PyErr_Occurred())
        return NULL;
    return PyUnicode_FromString(eom_strerror((int)st));
}

/* autoeom._core.status_name(status): EOM_ERR_FILE, ... */
static PyObject *mod_status_name(PyObject *mod, PyObject *arg)
{
    long st = PyLong_AsLong(arg);
    (void)mod;
    if (st == -1 && PyErr_Occurred())
        return NULL;
    return PyUnicode_FromString(eom_status_name((int)st));
}

/* The methods of the integrators, by their command-line names. */
static PyObject *mod_methods(PyObject *mod, PyObject *unused)
{
    PyObject *list = PyList_New(0);
    const char *name;
    int k;
    (void)mod;
    (void)unused;
    if (!list)
        return NULL;
    for (k = 0; (name = eom_method_name((eom_method)k)) != NULL &&
                eom_method_from_name(name) == k; k++) {
        PyObject *s = PyUnicode_FromString(name);
        if (!s || PyList_Append(list, s) != 0) {
            Py_XDECREF(s);
            Py_DECREF(list);
            return NULL;
        }
        Py_DECREF(s);
    }
    return list;
}

/* The ERK tables erk_table= accepts. */
static PyObject *mod_erk_tables(PyObject *mod, PyObject *unused)
{
    PyObject *list = PyList_New(0);
    const char *name;
    int k;
    (void)mod;
    (void)unused;
    if (!list)
        return NULL;
    for (k = 0; (name = eom_erk_table_name(k)) != NULL; k++) {
        PyObject *s = PyUnicode_FromString(name);
        if (!s || PyList_Append(list, s) != 0) {
            Py_XDECREF(s);
            Py_DECREF(list);
            return NULL;
        }
        Py_DECREF(s);
    }
    return list;
}

static PyMethodDef mod_functions[] = {
    {"strerror", mod_strerror, METH_O,
     "strerror(status) -> the library's text for a status code"},
    {"status_name", mod_status_name, METH_O,
     "status_name(status) -> the status code's name (EOM_ERR_FILE, ...)"},
    {"methods", mod_methods, METH_NOARGS,
     "methods() -> the integrators' names (rk4, erk, ...)"},
    {"erk_tables", mod_erk_tables, METH_NOARGS,
     "erk_tables() -> the ARKODE tables erk_table= accepts"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef core_module = {
    PyModuleDef_HEAD_INIT, "_core",
    "The C extension behind autoeom (use the autoeom package).", -1,
    mod_functions, NULL, NULL, NULL, NULL,
};

/* The System type's methods come from several files: joined here. */
static PyMethodDef system_methods[96];

static int join_methods(void)
{
    PyMethodDef *parts[] = {pyeom_system_base_methods, pyeom_eval_methods,
                            pyeom_run_methods, pyeom_analysis_methods,
                            pyeom_ensemble_methods};
    size_t k = 0, p;
    for (p = 0; p < sizeof parts / sizeof parts[0]; p++) {
        PyMethodDef *d;
        for (d = parts[p]; d->ml_name; d++) {
            if (k + 1 >= sizeof system_methods / sizeof system_methods[0]) {
                PyErr_SetString(PyExc_SystemError, "too many methods");
                return -1;
            }
            system_methods[k++] = *d;
        }
    }
    memset(&system_methods[k], 0, sizeof system_methods[k]);
    pyeom_system_type.tp_methods = system_methods;
    return 0;
}

static int add_type(PyObject *m, PyTypeObject *t, const char *name)
{
    if (PyType_Ready(t) < 0)
        return -1;
    Py_INCREF(t);
    if (PyModule_AddObject(m, name, (PyObject *)t) < 0) {
        Py_DECREF(t);
        return -1;
    }
    return 0;
}

PyMODINIT_FUNC PyInit__core(void);
PyMODINIT_FUNC PyInit__core(void)
{
    PyObject *m;
    import_array();
    if (join_methods() != 0)
        return NULL;
    m = PyModule_Create(&core_module);
    if (!m)
        return NULL;
    /* Error(message, status, status_name): the library's message and
     * status code; defined in Python so that it pickles and subclasses
     * like any exception */
    pyeom_error = PyErr_NewExceptionWithDoc(
        "autoeom.Error",
        "An error reported by libeom: str(e) is the library's message "
        "(file:line:col for model files); e.status is the status code and "
        "e.status_name its name (EOM_ERR_FILE, ...).",
        PyExc_RuntimeError, NULL);
    if (!pyeom_error || PyModule_AddObject(m, "Error", pyeom_error) < 0)
        goto fail;
    Py_INCREF(pyeom_error); /* the module's reference, and ours */
    if (add_type(m, &pyeom_system_type, "System") != 0 ||
        add_type(m, &pyeom_model_type, "Model") != 0 ||
        add_type(m, &pyeom_var_type, "Var") != 0 ||
        add_type(m, &pyeom_context_type, "Context") != 0)
        goto fail;
    if (PyModule_AddFunctions(m, pyeom_math_functions) != 0)
        goto fail;
    return m;
fail:
    Py_DECREF(m);
    return NULL;
}
