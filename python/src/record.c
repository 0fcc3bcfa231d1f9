/* record.c - autoeom.Model: a model whose energies, constraints, forces,
 * probes and start are Python functions, recorded once onto libeom's
 * tapes by Model.build (eom_system_new runs each callback once). Each
 * callback receives a Context c and returns Vars made from it:
 *
 *     def T(c): return 0.5*c.m*(c.r.dot**2 + c.r**2*c.theta.dot**2)
 *
 * c.NAME is a coordinate (with .dot, its rate) or a parameter; c.q(i),
 * c.qd(i), c.param(name) and c.t do the same by index or name. The
 * functions run with the GIL held (recording is short and calls Python
 * at every step); an exception raised inside one stops the build and is
 * raised again by build(). */
#include "pyeom.h"

#include <string.h>

#include "pyeom_record.h"

/* ---- the callbacks libeom calls -------------------------------------- */

/* A callback's result as a recorded value of r. */
static int to_val(PyObject *o, eom_ctx *c, tp_val *out)
{
    if (PyObject_TypeCheck(o, &pyeom_var_type)) {
        pyeom_var *v = (pyeom_var *)o;
        if (v->ctx->c != c) {
            PyErr_SetString(PyExc_ValueError, "a model callback returned a "
                            "value recorded by another callback");
            return -1;
        }
        *out = v->v;
        return 0;
    } else {
        double d = PyFloat_AsDouble(o);
        if (d == -1.0 && PyErr_Occurred()) {
            PyErr_Format(PyExc_TypeError, "a model callback returned %R, "
                         "not a recorded value or a number", o);
            return -1;
        }
        *out = tp_const(eom_rec(c), d);
        return 0;
    }
}

/* Call b->fn with a live Context: the result, or NULL. *ctx receives
 * the Context (a new reference, still live: the caller reads the result's
 * Vars, then ends it with done()). */
static PyObject *call(cb *b, eom_ctx *c, PyObject *model,
                      pyeom_context **ctx)
{
    *ctx = NULL;
    if (PyErr_Occurred())
        return NULL; /* an earlier callback failed: record nothing more */
    *ctx = PyObject_New(pyeom_context, &pyeom_context_type);
    if (!*ctx)
        return NULL;
    (*ctx)->c = c;
    (*ctx)->model = model;
    Py_INCREF(model);
    return PyObject_CallOneArg(b->fn, (PyObject *)*ctx);
}

/* End a callback: Vars kept beyond it now fail cleanly. */
static void done(pyeom_context *ctx)
{
    if (ctx) {
        ctx->c = NULL;
        Py_DECREF(ctx);
    }
}

/* The Model being built (set by build, for the callbacks). */
static PyObject *building;

static int scalar_cb(eom_ctx *c, void *user, tp_val *out)
{
    pyeom_context *ctx;
    PyObject *r = call(user, c, building, &ctx);
    int rc = r ? to_val(r, c, out) : -1;
    Py_XDECREF(r);
    done(ctx);
    return rc ? 1 : 0;
}

static int vector_values(PyObject *seq, eom_ctx *c, int count, tp_val *out);

static int vector_cb(eom_ctx *c, void *user, tp_val *out)
{
    cb *b = user;
    const int count = b->count > 0 ? b->count
                      : b->count == 0 ? eom_ncoords(c) : 2 * eom_ncoords(c);
    pyeom_context *ctx;
    PyObject *r = call(b, c, building, &ctx), *seq;
    int rc = 1;
    seq = r ? PySequence_Fast(r, "a vector model callback returns a "
                                 "sequence")
            : NULL;
    Py_XDECREF(r);
    if (seq)
        rc = vector_values(seq, c, count, out);
    Py_XDECREF(seq);
    done(ctx);
    return rc;
}

/* The count values of a vector callback's result. */
static int vector_values(PyObject *seq, eom_ctx *c, int count, tp_val *out)
{
    Py_ssize_t k;
    if (PySequence_Fast_GET_SIZE(seq) != count) {
        PyErr_Format(PyExc_ValueError, "a model callback returned %zd "
                     "values, not %d", PySequence_Fast_GET_SIZE(seq), count);
        return 1;
    }
    for (k = 0; k < count; k++)
        if (to_val(PySequence_Fast_GET_ITEM(seq, k), c, &out[k]) != 0)
            return 1;
    return 0;
}

/* ---- Model ---------------------------------------------------------- */

static PyObject *model_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    pyeom_model *self;
    (void)args;
    (void)kw;
    self = (pyeom_model *)type->tp_alloc(type, 0);
    if (self && eom_model_new(&self->m) != EOM_OK) {
        Py_DECREF(self);
        return PyErr_NoMemory();
    }
    return (PyObject *)self;
}

static void model_dealloc(pyeom_model *self)
{
    int k;
    PyObject_GC_UnTrack(self);
    eom_model_free(&self->m);
    for (k = 0; k < self->ncbs; k++) {
        Py_XDECREF(self->cbs[k]->fn);
        PyMem_Free(self->cbs[k]);
    }
    PyMem_Free(self->cbs);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int model_traverse(pyeom_model *self, visitproc visit, void *arg)
{
    int k;
    for (k = 0; k < self->ncbs; k++)
        Py_VISIT(self->cbs[k]->fn);
    Py_VISIT(Py_TYPE(self));
    return 0;
}

/* Keep fn and return its cb (count as in struct cb). */
static cb *keep(pyeom_model *self, PyObject *fn, int count)
{
    cb **grown, *b;
    if (!PyCallable_Check(fn)) {
        PyErr_Format(PyExc_TypeError, "%R is not callable", fn);
        return NULL;
    }
    grown = PyMem_Realloc(self->cbs, ((size_t)self->ncbs + 1) * sizeof *grown);
    if (!grown)
        return (cb *)PyErr_NoMemory();
    self->cbs = grown;
    b = PyMem_Malloc(sizeof *b);
    if (!b)
        return (cb *)PyErr_NoMemory();
    Py_INCREF(fn);
    b->fn = fn;
    b->count = count;
    self->cbs[self->ncbs++] = b;
    return b;
}

/* The library's status as an exception with the model's message. */
static PyObject *model_status(pyeom_model *self, int st)
{
    if (st < 0)
        return pyeom_raise(st, eom_model_errmsg(self->m));
    Py_RETURN_NONE;
}

/* set_kinetic(f), add_kinetic(f), ...: one C entry per scalar kind. */
typedef int (*set_scalar)(eom_model *, eom_scalar_fn, void *);

static PyObject *scalar_setter(pyeom_model *self, PyObject *fn,
                               set_scalar f)
{
    cb *b = keep(self, fn, -1);
    return b ? model_status(self, f(self->m, scalar_cb, b)) : NULL;
}

#define SCALAR(name)                                                           \
    static PyObject *model_##name(pyeom_model *self, PyObject *fn)             \
    {                                                                          \
        return scalar_setter(self, fn, eom_model_##name);                      \
    }
SCALAR(set_kinetic)
SCALAR(add_kinetic)
SCALAR(set_potential)
SCALAR(add_potential)
SCALAR(set_lagrangian)
SCALAR(set_dissipation)
SCALAR(add_dissipation)

static PyObject *model_set_forces(pyeom_model *self, PyObject *fn)
{
    cb *b = keep(self, fn, 0);
    return b ? model_status(self, eom_model_set_forces(self->m, vector_cb, b))
             : NULL;
}

static PyObject *model_set_initial(pyeom_model *self, PyObject *fn)
{
    cb *b = keep(self, fn, -2);
    return b ? model_status(self,
                            eom_model_set_initial(self->m, vector_cb, b))
             : NULL;
}

typedef int (*set_vector)(eom_model *, int, eom_vector_fn, void *);

static PyObject *vector_setter(pyeom_model *self, PyObject *args,
                               set_vector f)
{
    PyObject *fn;
    int count;
    cb *b;
    if (!PyArg_ParseTuple(args, "iO", &count, &fn))
        return NULL;
    if (count <= 0) {
        PyErr_SetString(PyExc_ValueError, "count must be positive");
        return NULL;
    }
    b = keep(self, fn, count);
    return b ? model_status(self, f(self->m, count, vector_cb, b)) : NULL;
}

static PyObject *model_set_constraints(pyeom_model *self, PyObject *args)
{
    return vector_setter(self, args, eom_model_set_constraints);
}
static PyObject *model_add_constraints(pyeom_model *self, PyObject *args)
{
    return vector_setter(self, args, eom_model_add_constraints);
}
static PyObject *model_add_velocity_constraints(pyeom_model *self,
                                                PyObject *args)
{
    return vector_setter(self, args, eom_model_add_velocity_constraints);
}

/* Record name in self._names as (kind, index). */
static int remember(pyeom_model *self, const char *name, int kind, int index)
{
    PyObject *names = PyObject_GetAttrString((PyObject *)self, "_names");
    PyObject *entry;
    int rc;
    if (!names)
        return -1;
    entry = Py_BuildValue("(ii)", kind, index);
    rc = entry ? PyDict_SetItemString(names, name, entry) : -1;
    Py_XDECREF(entry);
    Py_DECREF(names);
    return rc;
}

static PyObject *model_add_coord(pyeom_model *self, PyObject *args,
                                 PyObject *kw)
{
    /* PyArg_ParseTupleAndKeywords takes char *, not const */
    static char k_name[] = "name", k_q0[] = "q0", k_qd0[] = "qd0",
                k_unit[] = "unit";
    static char *kwlist[] = {k_name, k_q0, k_qd0, k_unit, NULL};
    const char *name, *unit = NULL;
    double q0 = 0.0, qd0 = 0.0;
    int i;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "s|ddz", kwlist, &name, &q0,
                                     &qd0, &unit))
        return NULL;
    i = eom_model_add_coord(self->m, name, unit, q0, qd0);
    if (i < 0)
        return pyeom_raise(i, eom_model_errmsg(self->m));
    if (remember(self, name, 0, i) != 0)
        return NULL;
    return PyLong_FromLong(i);
}

static PyObject *model_add_param(pyeom_model *self, PyObject *args,
                                 PyObject *kw)
{
    /* PyArg_ParseTupleAndKeywords takes char *, not const */
    static char k_name[] = "name", k_default[] = "default",
                k_unit[] = "unit", k_description[] = "description";
    static char *kwlist[] = {k_name, k_default, k_unit, k_description, NULL};
    const char *name, *unit = NULL, *desc = NULL;
    double dflt;
    int k;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "sd|zz", kwlist, &name,
                                     &dflt, &unit, &desc))
        return NULL;
    k = eom_model_add_param(self->m, name, unit, dflt, desc);
    if (k < 0)
        return pyeom_raise(k, eom_model_errmsg(self->m));
    if (remember(self, name, 1, k) != 0)
        return NULL;
    return PyLong_FromLong(k);
}

static PyObject *model_add_probe(pyeom_model *self, PyObject *args,
                                 PyObject *kw)
{
    /* PyArg_ParseTupleAndKeywords takes char *, not const */
    static char k_name[] = "name", k_f[] = "f", k_unit[] = "unit";
    static char *kwlist[] = {k_name, k_f, k_unit, NULL};
    const char *name, *unit = NULL;
    PyObject *fn;
    cb *b;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "sO|z", kwlist, &name, &fn,
                                     &unit))
        return NULL;
    b = keep(self, fn, -1);
    if (!b)
        return NULL;
    return model_status(self, eom_model_add_probe(self->m, name, unit,
                                                  scalar_cb, b));
}

/* _build(cls) -> System: record every callback once. */
static PyObject *model_build(pyeom_model *self, PyObject *cls)
{
    eom_system *s = NULL;
    char err[4096];
    int st;
    if (!PyType_Check(cls) ||
        !PyType_IsSubtype((PyTypeObject *)cls, &pyeom_system_type)) {
        PyErr_SetString(PyExc_TypeError, "_build needs a System type");
        return NULL;
    }
    if (building) {
        PyErr_SetString(PyExc_RuntimeError, "Model.build called from inside "
                        "a model callback");
        return NULL;
    }
    err[0] = '\0';
    building = (PyObject *)self;
    st = eom_system_new(&s, self->m, err, sizeof err);
    building = NULL;
    if (PyErr_Occurred()) {
        /* the callback's own exception says most: keep it */
        eom_system_free(&s);
        return NULL;
    }
    if (st != EOM_OK)
        return pyeom_raise(st, err);
    return pyeom_system_wrap((PyTypeObject *)cls, s);
}

#define O(name, doc) {#name, (PyCFunction)model_##name, METH_O, doc}
static PyMethodDef model_methods[] = {
    {"add_coord", (PyCFunction)(void (*)(void))model_add_coord,
     METH_VARARGS | METH_KEYWORDS,
     "add_coord(name, q0=0, qd0=0, unit=None) -> index"},
    {"add_param", (PyCFunction)(void (*)(void))model_add_param,
     METH_VARARGS | METH_KEYWORDS,
     "add_param(name, default, unit=None, description=None) -> index"},
    {"add_probe", (PyCFunction)(void (*)(void))model_add_probe,
     METH_VARARGS | METH_KEYWORDS, "add_probe(name, f, unit=None)"},
    O(set_kinetic, "set_kinetic(f): T(c)"),
    O(add_kinetic, "add_kinetic(f): one more term of T"),
    O(set_potential, "set_potential(f): V(c)"),
    O(add_potential, "add_potential(f): one more term of V"),
    O(set_lagrangian, "set_lagrangian(f): a whole L(c) instead of T, V"),
    O(set_dissipation, "set_dissipation(f): Rayleigh's R(c)"),
    O(add_dissipation, "add_dissipation(f): one more term of R"),
    O(set_forces, "set_forces(f): Q(c), a sequence of n values"),
    O(set_initial, "set_initial(f): x0(c) from the parameters, 2n values"),
    {"set_constraints", (PyCFunction)model_set_constraints, METH_VARARGS,
     "set_constraints(count, f): phi(c) = 0, count values"},
    {"add_constraints", (PyCFunction)model_add_constraints, METH_VARARGS,
     "add_constraints(count, f): one more block of phi"},
    {"add_velocity_constraints",
     (PyCFunction)model_add_velocity_constraints, METH_VARARGS,
     "add_velocity_constraints(count, f): A(q) qd + b = 0, count values"},
    {"_build", (PyCFunction)model_build, METH_O,
     "_build(cls) -> System (use Model.build)"},
    {NULL, NULL, 0, NULL},
};

PyTypeObject pyeom_model_type = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "autoeom._core.Model",
    .tp_basicsize = sizeof(pyeom_model),
    .tp_dealloc = (destructor)model_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "A model recorded from Python functions (use autoeom.Model).",
    .tp_traverse = (traverseproc)model_traverse,
    .tp_new = model_new,
    .tp_methods = model_methods,
};
