/* pyeom_record.h - the recording types of the extension: Model (the
 * model being recorded), Context (what a model callback receives while
 * it records) and Var (a recorded value), shared by record.c (Model),
 * context.c (Context) and var.c (Var, math functions). */
#ifndef PYEOM_RECORD_H
#define PYEOM_RECORD_H

#include "pyeom.h"

/* Live only during one callback: c is NULL afterwards, so that Vars kept
 * beyond it fail cleanly. */
typedef struct pyeom_context {
    PyObject_HEAD
    eom_ctx *c;
    PyObject *model; /* the Model being built (for names) */
} pyeom_context;

typedef struct pyeom_var {
    PyObject_HEAD
    pyeom_context *ctx; /* strong reference */
    tp_val v;
    int coord;          /* the coordinate's index when this is q_i (it
                           then has .dot), else -1 */
} pyeom_var;

/* One registered callback: the function, and the number of values a
 * vector callback returns (-1: scalar, 0: n, -2: 2n). */
typedef struct cb {
    PyObject *fn;
    int count;
} cb;

typedef struct pyeom_model {
    PyObject_HEAD
    eom_model *m;
    cb **cbs;     /* every callback registered (owned) */
    int ncbs;
} pyeom_model;

/* A new Var of ctx holding v (coord as above). */
PyObject *pyeom_var_new(pyeom_context *ctx, tp_val v, int coord);

#endif /* PYEOM_RECORD_H */
