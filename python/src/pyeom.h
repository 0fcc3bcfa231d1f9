/* pyeom.h - shared declarations of the autoeom extension module
 * (autoeom._core): the System and Model types, the exception, and the
 * helpers every file of the module uses to turn NumPy arrays into C
 * arrays and library statuses into Python exceptions.
 *
 * The module uses only the public headers of libeom and libtape. Every
 * function here follows CPython's convention: a new reference (or 0) on
 * success, NULL (or -1) with an exception set on failure. */
#ifndef PYEOM_H
#define PYEOM_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#ifndef PYEOM_MODULE_C
#define NO_IMPORT_ARRAY
#endif
#define PY_ARRAY_UNIQUE_SYMBOL pyeom_ARRAY_API
#include <numpy/arrayobject.h>

#include "eom/eom.h"

/* A built system and what the module keeps beside it. */
typedef struct pyeom_system {
    PyObject_HEAD
    eom_system *s;
    int n, m, np, nprobes; /* coordinates, constraint rows, parameters,
                              probes (fixed once built) */
    double *scratch;       /* 2n doubles for single evaluations */
    PyObject *weakrefs;    /* so Python code may hold weak references */
    PyObject *dict;        /* instance attributes of Python subclasses */
} pyeom_system;

extern PyTypeObject pyeom_system_type;
extern PyTypeObject pyeom_model_type;
extern PyTypeObject pyeom_var_type;
extern PyTypeObject pyeom_context_type;
extern PyObject *pyeom_error;

/* Raise autoeom.Error for libeom status st with message msg (the
 * library's own text, e.g. "file:line:col: ..."); msg NULL or "" falls
 * back to eom_strerror(st). Returns NULL. */
PyObject *pyeom_raise(int st, const char *msg);

/* Wrap a new system (taken over: freed with the object). NULL on error
 * (s is freed then). cls: the type to make (System or a subclass). */
PyObject *pyeom_system_wrap(PyTypeObject *cls, eom_system *s);

/* A C-contiguous float64 array of exactly `count` values from obj (a new
 * reference; a copy only when obj is not already one). what names the
 * argument in the ValueError. NULL with an exception on failure. */
PyArrayObject *pyeom_vector(PyObject *obj, npy_intp count, const char *what);

/* A new float64 array of the given shape (uninitialised). */
PyObject *pyeom_empty(int nd, const npy_intp *dims);

/* The methods of System implemented in each file (NULL-terminated). */
extern PyMethodDef pyeom_system_base_methods[];
extern PyMethodDef pyeom_eval_methods[];
extern PyMethodDef pyeom_run_methods[];
extern PyMethodDef pyeom_analysis_methods[];
extern PyMethodDef pyeom_ensemble_methods[];

/* Module-level functions of the recording file (sin, cos, ...). */
extern PyMethodDef pyeom_math_functions[];

/* Fill eom_opts from the keyword arguments of run() and ensemble()
 * (integrator, dt, rtol, ...). sens_out receives a malloc'ed array of
 * inputs when sensitivity= is given (caller frees). -1 with an
 * exception. */
int pyeom_parse_opts(pyeom_system *self, PyObject *kw, eom_opts *o,
                     int **sens_out);

#endif /* PYEOM_H */
