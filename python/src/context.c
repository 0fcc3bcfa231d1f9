/* context.c - autoeom.Context: what a model callback receives while it
 * records (record.c makes one per call and ends it when the call
 * returns). c.NAME is a coordinate (a Var with .dot) or a parameter, by
 * the names the Model noted as they were added; c.q(i), c.qd(i),
 * c.param(name) and c.t give the same by index or name. Every access
 * checks that the callback is still running. */
#include "pyeom.h"

#include "pyeom_record.h"

static void context_dealloc(pyeom_context *self)
{
    Py_XDECREF(self->model);
    PyObject_Free(self);
}

static eom_ctx *live(pyeom_context *self)
{
    if (!self->c)
        PyErr_SetString(PyExc_RuntimeError, "a recording context is used "
                        "after its model callback returned");
    return self->c;
}

/* The coordinate index from an int or a name; -1 with an exception. */
static int coord_of(pyeom_context *self, PyObject *key)
{
    pyeom_model *mo = (pyeom_model *)self->model;
    int n = eom_model_ncoords(mo->m), i;
    if (PyLong_Check(key)) {
        i = (int)PyLong_AsLong(key);
        if (i < 0 || i >= n) {
            if (!PyErr_Occurred())
                PyErr_Format(PyExc_IndexError, "coordinate index %d out of "
                             "range 0..%d", i, n - 1);
            return -1;
        }
        return i;
    }
    PyErr_Format(PyExc_TypeError, "a coordinate is given by its index "
                 "here (c.NAME gives it by name)");
    return -1;
}

static PyObject *ctx_q(pyeom_context *self, PyObject *key)
{
    int i;
    if (!live(self) || (i = coord_of(self, key)) < 0)
        return NULL;
    return pyeom_var_new(self, eom_q(self->c, i), i);
}

static PyObject *ctx_qd(pyeom_context *self, PyObject *key)
{
    int i;
    if (!live(self) || (i = coord_of(self, key)) < 0)
        return NULL;
    return pyeom_var_new(self, eom_qd(self->c, i), -1);
}

static PyObject *ctx_param(pyeom_context *self, PyObject *name)
{
    const char *s;
    if (!live(self))
        return NULL;
    s = PyUnicode_AsUTF8(name);
    if (!s)
        return NULL;
    /* an unknown name makes the recording fail with the library's
     * message naming it */
    return pyeom_var_new(self, eom_param(self->c, s), -1);
}

static PyObject *ctx_time(pyeom_context *self, void *unused)
{
    (void)unused;
    if (!live(self))
        return NULL;
    return pyeom_var_new(self, eom_time(self->c), -1);
}

static PyObject *ctx_ncoords(pyeom_context *self, void *unused)
{
    (void)unused;
    if (!live(self))
        return NULL;
    return PyLong_FromLong(eom_ncoords(self->c));
}

/* c.NAME: the model's names are kept in the Model's _names dict (name ->
 * ("coord", i) or ("param", k)), filled by coord() and param(). */
static PyObject *ctx_getattro(pyeom_context *self, PyObject *name)
{
    PyObject *r = PyObject_GenericGetAttr((PyObject *)self, name), *names,
             *entry;
    if (r || !PyErr_ExceptionMatches(PyExc_AttributeError))
        return r;
    names = PyObject_GetAttrString(self->model, "_names");
    if (!names)
        return NULL;
    entry = PyDict_GetItemWithError(names, name); /* borrowed */
    Py_DECREF(names);
    if (!entry) {
        if (!PyErr_Occurred())
            PyErr_Format(PyExc_AttributeError, "the model has no "
                         "coordinate or parameter named %R (yet)", name);
        return NULL;
    }
    PyErr_Clear();
    if (!live(self))
        return NULL;
    if (PyLong_AsLong(PyTuple_GET_ITEM(entry, 0)) == 0)
        return ctx_q(self, PyTuple_GET_ITEM(entry, 1));
    return ctx_param(self, name);
}

static PyMethodDef ctx_methods[] = {
    {"q", (PyCFunction)ctx_q, METH_O, "q(i) -> coordinate i (with .dot)"},
    {"qd", (PyCFunction)ctx_qd, METH_O, "qd(i) -> the rate of coordinate i"},
    {"param", (PyCFunction)ctx_param, METH_O,
     "param(name) -> the parameter"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef ctx_getset[] = {
    {"t", (getter)ctx_time, NULL, "the time", NULL},
    {"ncoords", (getter)ctx_ncoords, NULL, "number of coordinates", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject pyeom_context_type = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "autoeom.Context",
    .tp_basicsize = sizeof(pyeom_context),
    .tp_dealloc = (destructor)context_dealloc,
    .tp_getattro = (getattrofunc)ctx_getattro,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "What a model callback records with: c.NAME (a coordinate, "
              "with .dot, or a parameter), c.q(i), c.qd(i), c.param(name), "
              "c.t.",
    .tp_methods = ctx_methods,
    .tp_getset = ctx_getset,
};
