/* var.c - autoeom.Var: a value being recorded onto a tape, with Python's
 * arithmetic operators, so that a model's energies are written as their
 * formulas in Python (T = 0.5*m*x.dot**2) and recorded exactly as the
 * same nested calls of libtape's C API would be (the operator table of
 * eom/eom.hpp: a + c is tp_addc, c - a is tp_csub, a**2 is tp_powi, ...).
 *
 * A Var is valid only while the callback that made it runs: it holds its
 * Context, which is marked dead when the callback returns, and using a
 * dead Var raises RuntimeError instead of touching a finished recording.
 * The math functions (autoeom.sin, ...) take Vars or plain numbers. */
#include "pyeom.h"

#include <math.h>

#include "pyeom_record.h"

PyObject *pyeom_var_new(pyeom_context *ctx, tp_val v, int coord)
{
    pyeom_var *self = PyObject_New(pyeom_var, &pyeom_var_type);
    if (!self)
        return NULL;
    Py_INCREF(ctx);
    self->ctx = ctx;
    self->v = v;
    self->coord = coord;
    return (PyObject *)self;
}

static void var_dealloc(pyeom_var *self)
{
    Py_DECREF(self->ctx);
    PyObject_Free(self);
}

/* The recording behind a live Var; NULL with RuntimeError when its
 * callback has returned. */
static tp_rec *live_rec(pyeom_var *a)
{
    if (!a->ctx->c) {
        PyErr_SetString(PyExc_RuntimeError, "a recorded value is used "
                        "after the model callback that made it returned");
        return NULL;
    }
    return eom_rec(a->ctx->c);
}

/* A plain number (Python or NumPy scalar) as a double: 1 if o is one,
 * else 0 (then the operator returns NotImplemented, so that NumPy can
 * apply it element by element to an array of Vars). */
static int number_of(PyObject *o, double *c)
{
    if (!PyFloat_Check(o) && !PyLong_Check(o) &&
        !PyArray_IsScalar(o, Floating) && !PyArray_IsScalar(o, Integer))
        return 0;
    *c = PyFloat_AsDouble(o);
    if (*c == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        return 0;
    }
    return 1;
}

#define IS_VAR(o) PyObject_TypeCheck((o), &pyeom_var_type)

/* The four operators: op(a, b), op_c(a, c) for a Var a and a number c
 * on the right, c_op(c, a) for a number c on the left. */
typedef tp_val (*op2)(tp_rec *, tp_val, tp_val);
typedef tp_val (*op2c)(tp_rec *, tp_val, double);
typedef tp_val (*opc2)(tp_rec *, double, tp_val);

static PyObject *binary(PyObject *a, PyObject *b, op2 f, op2c fc, opc2 cf)
{
    double c;
    if (IS_VAR(a) && IS_VAR(b)) {
        pyeom_var *x = (pyeom_var *)a, *y = (pyeom_var *)b;
        tp_rec *r = live_rec(x);
        if (!r || !live_rec(y))
            return NULL;
        if (x->ctx->c != y->ctx->c) {
            PyErr_SetString(PyExc_ValueError, "the operands were recorded "
                            "by different model callbacks");
            return NULL;
        }
        return pyeom_var_new(x->ctx, f(r, x->v, y->v), -1);
    }
    if (IS_VAR(a) && number_of(b, &c)) {
        pyeom_var *x = (pyeom_var *)a;
        tp_rec *r = live_rec(x);
        return r ? pyeom_var_new(x->ctx, fc(r, x->v, c), -1) : NULL;
    }
    if (IS_VAR(b) && number_of(a, &c)) {
        pyeom_var *y = (pyeom_var *)b;
        tp_rec *r = live_rec(y);
        return r ? pyeom_var_new(y->ctx, cf(r, c, y->v), -1) : NULL;
    }
    Py_RETURN_NOTIMPLEMENTED;
}

/* c + a and c * a commute: recorded as a + c, a * c (as eom.hpp does) */
static tp_val addc_rev(tp_rec *r, double c, tp_val a)
{
    return tp_addc(r, a, c);
}
static tp_val mulc_rev(tp_rec *r, double c, tp_val a)
{
    return tp_mulc(r, a, c);
}
/* c ** a: the constant's own value, then tp_pow */
static tp_val const_pow(tp_rec *r, double c, tp_val a)
{
    return tp_pow(r, tp_const(r, c), a);
}
/* a ** c: tp_powi for a whole exponent, as pow(a, int) in eom.hpp */
static tp_val powc(tp_rec *r, tp_val a, double c)
{
    if (c == floor(c) && fabs(c) <= 1024.0)
        return tp_powi(r, a, (int)c);
    return tp_powc(r, a, c);
}

static PyObject *var_add(PyObject *a, PyObject *b)
{
    return binary(a, b, tp_add, tp_addc, addc_rev);
}
static PyObject *var_sub(PyObject *a, PyObject *b)
{
    return binary(a, b, tp_sub, tp_subc, tp_csub);
}
static PyObject *var_mul(PyObject *a, PyObject *b)
{
    return binary(a, b, tp_mul, tp_mulc, mulc_rev);
}
static PyObject *var_div(PyObject *a, PyObject *b)
{
    return binary(a, b, tp_div, tp_divc, tp_cdiv);
}
static PyObject *var_pow(PyObject *a, PyObject *b, PyObject *mod)
{
    if (mod != Py_None) {
        PyErr_SetString(PyExc_TypeError, "pow() with a modulus is not "
                        "defined for recorded values");
        return NULL;
    }
    return binary(a, b, tp_pow, powc, const_pow);
}

/* A unary op of libtape on a Var. */
static PyObject *unary(PyObject *a, tp_val (*f)(tp_rec *, tp_val))
{
    pyeom_var *x = (pyeom_var *)a;
    tp_rec *r = live_rec(x);
    return r ? pyeom_var_new(x->ctx, f(r, x->v), -1) : NULL;
}

static PyObject *var_neg(PyObject *a)
{
    return unary(a, tp_neg);
}
static PyObject *var_pos(PyObject *a)
{
    Py_INCREF(a);
    return a;
}
static PyObject *var_abs(PyObject *a)
{
    return unary(a, tp_abs);
}

/* No truth value: a tape has no branches, so `if x > 0` cannot be
 * recorded; say so instead of silently taking one branch. */
static int var_bool(PyObject *a)
{
    (void)a;
    PyErr_SetString(PyExc_TypeError, "a recorded value has no truth value: "
                    "the tape records arithmetic, not branches (use abs, "
                    "tanh, ... for a switch)");
    return -1;
}

static PyNumberMethods var_number = {
    .nb_add = var_add,
    .nb_subtract = var_sub,
    .nb_multiply = var_mul,
    .nb_true_divide = var_div,
    .nb_power = var_pow,
    .nb_negative = var_neg,
    .nb_positive = var_pos,
    .nb_absolute = var_abs,
    .nb_bool = var_bool,
};

/* x.dot: the rate of the coordinate x (for coordinates only). */
static PyObject *var_dot(pyeom_var *self, void *unused)
{
    (void)unused;
    if (self->coord < 0) {
        PyErr_SetString(PyExc_AttributeError, "only a coordinate has a "
                        "rate (.dot)");
        return NULL;
    }
    if (!live_rec(self))
        return NULL;
    return pyeom_var_new(self->ctx, eom_qd(self->ctx->c, self->coord), -1);
}

static PyGetSetDef var_getset[] = {
    {"dot", (getter)var_dot, NULL, "the rate of a coordinate", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

/* ---- math functions: Vars are recorded, numbers computed ---------- */

typedef struct math1 {
    const char *name;
    tp_val (*rec)(tp_rec *, tp_val);
    double (*num)(double);
} math1;

static double sqr_d(double x)
{
    return x * x;
}

static const math1 math1_table[] = {
    {"sqr", tp_sqr, sqr_d},     {"sqrt", tp_sqrt, sqrt},
    {"exp", tp_exp, exp},       {"log", tp_log, log},
    {"sin", tp_sin, sin},       {"cos", tp_cos, cos},
    {"tan", tp_tan, tan},       {"asin", tp_asin, asin},
    {"acos", tp_acos, acos},    {"atan", tp_atan, atan},
    {"sinh", tp_sinh, sinh},    {"cosh", tp_cosh, cosh},
    {"tanh", tp_tanh, tanh},
};

static PyObject *apply1(int k, PyObject *x)
{
    double v;
    if (IS_VAR(x))
        return unary(x, math1_table[k].rec);
    v = PyFloat_AsDouble(x);
    if (v == -1.0 && PyErr_Occurred())
        return NULL;
    return PyFloat_FromDouble(math1_table[k].num(v));
}

/* One C function per entry (METH_O cannot carry an index). */
#define MATH1(k, name)                                                         \
    static PyObject *m_##name(PyObject *mod, PyObject *x)                      \
    {                                                                          \
        (void)mod;                                                             \
        return apply1(k, x);                                                   \
    }
MATH1(0, sqr)
MATH1(1, sqrt)
MATH1(2, exp)
MATH1(3, log)
MATH1(4, sin)
MATH1(5, cos)
MATH1(6, tan)
MATH1(7, asin)
MATH1(8, acos)
MATH1(9, atan)
MATH1(10, sinh)
MATH1(11, cosh)
MATH1(12, tanh)

/* atan2(y, x) and hypot(a, b): recorded when either is a Var. */
static PyObject *two(PyObject *args, tp_val (*f)(tp_rec *, tp_val, tp_val),
                     double (*num)(double, double))
{
    PyObject *a, *b;
    pyeom_var *any;
    tp_rec *r;
    tp_val va, vb;
    if (!PyArg_ParseTuple(args, "OO", &a, &b))
        return NULL;
    if (!IS_VAR(a) && !IS_VAR(b)) {
        double x = PyFloat_AsDouble(a), y = PyFloat_AsDouble(b);
        if (PyErr_Occurred())
            return NULL;
        return PyFloat_FromDouble(num(x, y));
    }
    any = (pyeom_var *)(IS_VAR(a) ? a : b);
    r = live_rec(any);
    if (!r)
        return NULL;
    va = IS_VAR(a) ? ((pyeom_var *)a)->v : tp_const(r, PyFloat_AsDouble(a));
    vb = IS_VAR(b) ? ((pyeom_var *)b)->v : tp_const(r, PyFloat_AsDouble(b));
    if (PyErr_Occurred())
        return NULL;
    return pyeom_var_new(any->ctx, f(r, va, vb), -1);
}

static PyObject *m_atan2(PyObject *mod, PyObject *args)
{
    (void)mod;
    return two(args, tp_atan2, atan2);
}

static PyObject *m_hypot(PyObject *mod, PyObject *args)
{
    (void)mod;
    return two(args, tp_hypot, hypot);
}

#define M1(name, doc) {#name, m_##name, METH_O, doc}
PyMethodDef pyeom_math_functions[] = {
    M1(sqr, "sqr(x) = x*x"),   M1(sqrt, "sqrt(x)"), M1(exp, "exp(x)"),
    M1(log, "log(x)"),         M1(sin, "sin(x)"),   M1(cos, "cos(x)"),
    M1(tan, "tan(x)"),         M1(asin, "asin(x)"), M1(acos, "acos(x)"),
    M1(atan, "atan(x)"),       M1(sinh, "sinh(x)"), M1(cosh, "cosh(x)"),
    M1(tanh, "tanh(x)"),
    {"atan2", m_atan2, METH_VARARGS, "atan2(y, x): the angle of (x, y)"},
    {"hypot", m_hypot, METH_VARARGS, "hypot(a, b) = sqrt(a*a + b*b)"},
    {NULL, NULL, 0, NULL},
};

/* The same functions as methods, under NumPy's names, so that np.sin(x)
 * and np.arctan(x) work on a Var (NumPy calls x.sin() for objects). */
#define VM(pyname, name)                                                       \
    static PyObject *vm_##pyname(PyObject *self, PyObject *unused)             \
    {                                                                          \
        (void)unused;                                                          \
        return m_##name(NULL, self);                                           \
    }
VM(sqrt, sqrt)
VM(exp, exp)
VM(log, log)
VM(sin, sin)
VM(cos, cos)
VM(tan, tan)
VM(arcsin, asin)
VM(arccos, acos)
VM(arctan, atan)
VM(sinh, sinh)
VM(cosh, cosh)
VM(tanh, tanh)

#define VMD(name) {#name, vm_##name, METH_NOARGS, NULL}
static PyMethodDef var_methods[] = {
    VMD(sqrt), VMD(exp),    VMD(log),    VMD(sin),  VMD(cos),
    VMD(tan),  VMD(arcsin), VMD(arccos), VMD(arctan), VMD(sinh),
    VMD(cosh), VMD(tanh),   {NULL, NULL, 0, NULL},
};

PyTypeObject pyeom_var_type = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "autoeom.Var",
    .tp_basicsize = sizeof(pyeom_var),
    .tp_dealloc = (destructor)var_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A value being recorded onto a tape (inside a model "
              "callback): combine with +, -, *, /, ** and autoeom.sin, ...; "
              "a coordinate's rate is x.dot.",
    .tp_as_number = &var_number,
    .tp_methods = var_methods,
    .tp_getset = var_getset,
};
