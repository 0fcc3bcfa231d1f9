/* test_misuse.c - bad input never crashes and always names itself.
 *
 * Public API only. Checks that
 *   - every status in TP_STATUS_LIST has its description and name;
 *   - NULL for every pointer argument is TP_ERR_NULL (or an invalid handle,
 *     a 0 / -1 / NULL / NaN answer from a query), never a crash;
 *   - a handle of another recording is TP_ERR_FOREIGN, an invalid one
 *     (zero-initialised, or the result of a failed op) TP_ERR_HANDLE,
 *     recording into a finished recorder TP_ERR_FINISHED;
 *   - out-of-range sizes and indices are TP_ERR_SIZE (independents,
 *     outputs, parameters, Jacobian and Hessian columns, including sums
 *     that overflow an int, max_dirs 0, group numbers);
 *   - duplicate output names and a parameter redeclared with another
 *     default are TP_ERR_NAME; an evaluator used outside tp_rec_run and
 *     backend-specific calls on the wrong backend are TP_ERR_BACKEND; a
 *     recording without outputs is TP_ERR_EMPTY; a user function that
 *     returns non-zero is TP_ERR_USER on every backend;
 *   - errors are sticky (the first one is kept) and the message of the
 *     context or workspace names the function that failed;
 *   - domain errors (log(-1), sqrt(-1), 1/0) and non-finite inputs give
 *     NaN or infinite results with TP_WARN_NONFINITE from every sweep and
 *     both evaluators, while results that do not depend on them stay
 *     finite, correct and TP_OK;
 *   - tp_lagrange_t warns when any one of its results alone (L's
 *     gradient, dL/dt, M or h) is not finite, and not when that result
 *     is not asked for.
 */
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "tape/tape.h"

/* Does s contain word, ignoring case? (Op errors name the op as ADD.) */
static bool mentions(const char *s, const char *word)
{
    size_t n = strlen(word), i, j;
    if (!s)
        return false;
    for (i = 0; s[i]; i++) {
        for (j = 0; j < n && s[i + j]; j++)
            if (tolower((unsigned char)s[i + j]) !=
                tolower((unsigned char)word[j]))
                break;
        if (j == n)
            return true;
    }
    return false;
}

#define CHECK_MSG(msg, word)                                               \
    do {                                                                   \
        const char *m_ = (msg);                                            \
        check_count_++;                                                    \
        if (!mentions(m_, (word)))                                         \
            CHECK_FAIL_("message '%s' does not name '%s'",                 \
                        m_ ? m_ : "(null)", (word));                       \
    } while (0)

#define CHECK_INVALID(v) CHECK_INT((v).tag, 0)

/* ---- helpers ---------------------------------------------------------- */

/* f(x) = (x0 + x1 sin x2) / 2 as "y", and x3 as "x3" */
static int simple(tp_rec *r, void *user)
{
    tp_val x[4];
    int i;
    (void)user;
    for (i = 0; i < 4; i++)
        x[i] = tp_indep(r, i);
    tp_output(r, "y", tp_mulc(r, tp_add(r, x[0], tp_mul(r, x[1],
                                                       tp_sin(r, x[2]))),
                              0.5));
    tp_output(r, "x3", tp_mul(r, x[3], tp_param(r, "p", 2.0)));
    return 0;
}

static tp_tape *record(tp_func f, void *user, int n)
{
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    CHECK_INT(tp_recorder_new(&r, n, NULL, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, f, user), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    return T;
}

/* ---- status codes ----------------------------------------------------- */

static void status_table(void)
{
    static const int values[] = {
#define V_(name, value, text) value,
        TP_STATUS_LIST(V_)
#undef V_
    };
    const size_t nv = sizeof values / sizeof values[0];
    size_t i, j;
#define S_(name, value, text)                                              \
    CHECK(strcmp(tp_strerror(name), text) == 0);                           \
    CHECK(strcmp(tp_status_name(name), #name) == 0);                       \
    CHECK(value == 0 ? name == TP_OK                                       \
                     : (strncmp(#name, "TP_WARN_", 8) == 0) == (value > 0));
    TP_STATUS_LIST(S_)
#undef S_
    for (i = 0; i < nv; i++)
        for (j = i + 1; j < nv; j++)
            CHECK(values[i] != values[j]);
    CHECK(strcmp(tp_strerror(12345), "unknown status") == 0);
    CHECK(tp_status_name(-12345) != NULL);
    for (i = 0; i < nv; i++)
        CHECK(strcmp(tp_status_name(-12345), tp_status_name(values[i])));
}

/* ---- NULL arguments --------------------------------------------------- */

typedef tp_val (*binary_fn)(tp_rec *, tp_val, tp_val);
typedef tp_val (*unary_fn)(tp_rec *, tp_val);

static const binary_fn binaries[] = {tp_add, tp_sub, tp_mul, tp_div,
                                     tp_pow, tp_atan2, tp_hypot};
static const unary_fn unaries[] = {
    tp_neg, tp_sqr, tp_sqrt, tp_exp, tp_log, tp_sin, tp_cos, tp_tan,
    tp_asin, tp_acos, tp_atan, tp_sinh, tp_cosh, tp_tanh, tp_abs};
#define N_BIN (sizeof binaries / sizeof binaries[0])
#define N_UN (sizeof unaries / sizeof unaries[0])

static void null_contexts(void)
{
    const tp_val z = {0, 0};
    tp_val arr[2] = {{0, 0}, {0, 0}};
    tp_rec *r = NULL;
    tp_tape *T = (tp_tape *)&r; /* must be overwritten with NULL */
    tp_ws *ws = (tp_ws *)&r;
    double v = 0.0, x[4] = {0};
    size_t i;

    /* constructors and destructors */
    CHECK_INT(tp_recorder_new(NULL, 2, NULL, NULL), TP_ERR_NULL);
    CHECK_INT(tp_evaluator_new(NULL, 2, NULL), TP_ERR_NULL);
    CHECK_INT(tp_tuple_new(NULL, 2, NULL), TP_ERR_NULL);
    CHECK_INT(tp_recorder_finish(NULL, &T), TP_ERR_NULL);
    CHECK(T == NULL);
    CHECK_INT(tp_ws_new(&ws, NULL, 1, NULL), TP_ERR_NULL);
    CHECK(ws == NULL);
    CHECK_INT(tp_ws_new(NULL, NULL, 1, NULL), TP_ERR_NULL);
    tp_rec_free(NULL);
    tp_rec_free(&r);
    tp_tape_free(NULL);
    tp_tape_free(&T);
    tp_ws_free(NULL);
    tp_ws_free(&ws);

    /* context calls on a NULL context */
    CHECK_INT(tp_rec_run(NULL, x, simple, NULL), TP_ERR_NULL);
    CHECK_INT(tp_rec_set_param(NULL, "p", 1.0), TP_ERR_NULL);
    CHECK_INT(tp_rec_status(NULL), TP_ERR_NULL);
    CHECK(tp_rec_errmsg(NULL) != NULL);
    CHECK_INT(tp_rec_n_indep(NULL), 0);
    CHECK_INT(tp_rec_n_outputs(NULL), 0);
    CHECK_INT(tp_rec_output_index(NULL, "y"), -1);
    CHECK_INT(tp_rec_output_value(NULL, 0, &v), TP_ERR_NULL);
    CHECK_INT(tp_tuple_output(NULL, 0, x, x), TP_ERR_NULL);
    CHECK_INT(tp_tuple_lagrange(NULL, 0, &v, x, x, x), TP_ERR_NULL);
    CHECK_INVALID(tp_indep(NULL, 0));
    CHECK_INVALID(tp_param(NULL, "p", 1.0));
    CHECK_INVALID(tp_const(NULL, 1.0));
    CHECK_INT(tp_output(NULL, "y", z), TP_ERR_NULL);
    for (i = 0; i < N_BIN; i++)
        CHECK_INVALID(binaries[i](NULL, z, z));
    for (i = 0; i < N_UN; i++)
        CHECK_INVALID(unaries[i](NULL, z));
    CHECK_INVALID(tp_powi(NULL, z, 3));
    CHECK_INVALID(tp_powc(NULL, z, 2.5));
    CHECK_INVALID(tp_addc(NULL, z, 1.0));
    CHECK_INVALID(tp_mulc(NULL, z, 2.0));
    CHECK_INVALID(tp_csub(NULL, 1.0, z));
    CHECK_INVALID(tp_cdiv(NULL, 1.0, z));
    CHECK_INVALID(tp_sum(NULL, 2, arr));
    CHECK_INVALID(tp_dot(NULL, 2, arr, arr));

    /* tape queries */
    CHECK_INT(tp_tape_n_indep(NULL), 0);
    CHECK_INT(tp_tape_n_outputs(NULL), 0);
    CHECK_INT(tp_tape_n_params(NULL), 0);
    CHECK_INT(tp_tape_output_index(NULL, "y"), -1);
    CHECK_INT(tp_tape_param_index(NULL, "p"), -1);
    CHECK(tp_tape_output_name(NULL, 0) == NULL);
    CHECK(tp_tape_param_name(NULL, 0) == NULL);
    CHECK(isnan(tp_tape_param_default(NULL, 0)));
    CHECK_INT(tp_tape_stats_get(NULL, NULL), TP_ERR_NULL);
    CHECK_INT(tp_tape_count_dependent(NULL, 1u), 0);

    /* workspace calls on a NULL workspace */
    CHECK(tp_ws_errmsg(NULL) != NULL);
    CHECK_INT(tp_ws_set_param(NULL, 0, 1.0), TP_ERR_NULL);
    CHECK_INT(tp_ws_get_param(NULL, 0, &v), TP_ERR_NULL);
    CHECK_INT(tp_eval(NULL, x, x), TP_ERR_NULL);
    CHECK_INT(tp_jvp(NULL, x, 1, x, x, x), TP_ERR_NULL);
    CHECK_INT(tp_jacobian(NULL, x, 0, 1, x, x), TP_ERR_NULL);
    CHECK_INT(tp_vjp(NULL, x, x, x, x), TP_ERR_NULL);
    CHECK_INT(tp_gradient(NULL, x, 0, x, x), TP_ERR_NULL);
    CHECK_INT(tp_hvp(NULL, x, x, 1, x, x, x), TP_ERR_NULL);
    CHECK_INT(tp_hessian_cols(NULL, x, 0, 0, 1, x, x), TP_ERR_NULL);
    CHECK_INT(tp_hessian(NULL, x, 0, x), TP_ERR_NULL);
    CHECK_INT(tp_taylor2(NULL, x, x, x, x, x), TP_ERR_NULL);
    CHECK_INT(tp_lagrange(NULL, x, 0, x, x, x, x), TP_ERR_NULL);
}

/* NULL pointers next to a valid context, tape and workspace. */
static void null_pointers(void)
{
    tp_rec *ev = NULL, *rec = NULL;
    tp_tape *T = record(simple, NULL, 4);
    tp_ws *ws = NULL;
    tp_tape_stats st;
    double x[4] = {0.1, 0.2, 0.3, 0.4}, y[2], J[8], H[16], g[4], w[2] = {1,
                                                                        1};
    double v;

    CHECK_INT(tp_ws_new(&ws, T, 2, NULL), TP_OK);
    CHECK_INT(tp_evaluator_new(&ev, 4, NULL), TP_OK);
    CHECK_INT(tp_recorder_new(&rec, 4, NULL, NULL), TP_OK);
    if (!T || !ws || !ev || !rec)
        goto done;

    /* tape */
    CHECK_INT(tp_tape_stats_get(T, NULL), TP_ERR_NULL);
    CHECK_INT(tp_tape_stats_get(T, &st), TP_OK);
    CHECK_INT(tp_tape_output_index(T, NULL), -1);
    CHECK_INT(tp_tape_param_index(T, NULL), -1);

    /* workspace: every required pointer, one at a time */
    CHECK_INT(tp_ws_get_param(ws, 0, NULL), TP_ERR_NULL);
    CHECK_INT(tp_eval(ws, NULL, y), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_eval");
    CHECK_INT(tp_eval(ws, x, NULL), TP_ERR_NULL);
    CHECK_INT(tp_jvp(ws, NULL, 1, x, y, J), TP_ERR_NULL);
    CHECK_INT(tp_jvp(ws, x, 1, NULL, y, J), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_jvp");
    CHECK_INT(tp_jvp(ws, x, 1, x, y, NULL), TP_ERR_NULL);
    CHECK_INT(tp_jvp(ws, x, 0, NULL, y, NULL), TP_OK); /* nothing to do */
    CHECK_INT(tp_jacobian(ws, NULL, 0, 4, y, J), TP_ERR_NULL);
    CHECK_INT(tp_jacobian(ws, x, 0, 4, y, NULL), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_jacobian");
    CHECK_INT(tp_jacobian(ws, x, 0, 0, y, NULL), TP_OK);
    CHECK_INT(tp_vjp(ws, NULL, w, y, g), TP_ERR_NULL);
    CHECK_INT(tp_vjp(ws, x, NULL, y, g), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_vjp");
    CHECK_INT(tp_vjp(ws, x, w, y, NULL), TP_ERR_NULL);
    CHECK_INT(tp_gradient(ws, NULL, 0, &v, g), TP_ERR_NULL);
    CHECK_INT(tp_gradient(ws, x, 0, &v, NULL), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_gradient");
    CHECK_INT(tp_hvp(ws, NULL, w, 1, x, g, H), TP_ERR_NULL);
    CHECK_INT(tp_hvp(ws, x, NULL, 1, x, g, H), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_hvp");
    CHECK_INT(tp_hvp(ws, x, w, 1, NULL, g, H), TP_ERR_NULL);
    CHECK_INT(tp_hvp(ws, x, w, 1, x, g, NULL), TP_ERR_NULL);
    CHECK_INT(tp_hessian_cols(ws, NULL, 0, 0, 4, g, H), TP_ERR_NULL);
    CHECK_INT(tp_hessian_cols(ws, x, 0, 0, 4, g, NULL), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_hessian_cols");
    CHECK_INT(tp_hessian(ws, NULL, 0, H), TP_ERR_NULL);
    CHECK_INT(tp_hessian(ws, x, 0, NULL), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_hessian");
    CHECK_INT(tp_taylor2(ws, NULL, x, y, y, y), TP_ERR_NULL);
    CHECK_INT(tp_taylor2(ws, x, NULL, y, y, y), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_taylor2");
    CHECK_INT(tp_taylor2(ws, x, x, y, y, NULL), TP_ERR_NULL);
    CHECK_INT(tp_lagrange(ws, NULL, 0, &v, g, H, g), TP_ERR_NULL);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_lagrange");
    /* optional outputs may be NULL */
    CHECK_INT(tp_jvp(ws, x, 1, x, NULL, J), TP_OK);
    CHECK_INT(tp_vjp(ws, x, w, NULL, g), TP_OK);
    CHECK_INT(tp_gradient(ws, x, 0, NULL, g), TP_OK);
    CHECK_INT(tp_hvp(ws, x, w, 1, x, NULL, H), TP_OK);
    CHECK_INT(tp_hessian_cols(ws, x, 0, 0, 4, NULL, H), TP_OK);
    CHECK_INT(tp_taylor2(ws, x, x, NULL, NULL, y), TP_OK);
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, NULL, NULL), TP_OK);

    /* evaluator and recorder */
    CHECK_INT(tp_rec_run(ev, x, NULL, NULL), TP_ERR_NULL);
    CHECK_MSG(tp_rec_errmsg(ev), "tp_rec_run");
    CHECK_INT(tp_rec_run(ev, NULL, simple, NULL), TP_ERR_NULL);
    CHECK_INT(tp_rec_set_param(ev, NULL, 1.0), TP_ERR_NULL);
    CHECK_INT(tp_rec_output_index(ev, NULL), -1);
    CHECK_INT(tp_rec_run(ev, x, simple, NULL), TP_OK);
    CHECK_INT(tp_rec_output_value(ev, 0, NULL), TP_ERR_NULL);
    CHECK_INT(tp_recorder_finish(rec, NULL), TP_ERR_NULL);
    CHECK_INT(tp_rec_status(rec), TP_ERR_NULL); /* sticky */
    CHECK_MSG(tp_rec_errmsg(rec), "tp_recorder_finish");
done:
    tp_rec_free(&ev);
    tp_rec_free(&rec);
    tp_ws_free(&ws);
    tp_tape_free(&T);
}

/* NULL names and arrays inside a run: sticky TP_ERR_NULL. */
static int null_inside(tp_rec *r, void *user)
{
    const int which = *(const int *)user;
    tp_val a = tp_indep(r, 0);
    switch (which) {
    case 0: tp_param(r, NULL, 1.0); break;
    case 1: tp_output(r, NULL, a); break;
    case 2: tp_sum(r, 2, NULL); break;
    case 3: tp_dot(r, 2, &a, NULL); break;
    default: tp_dot(r, 2, NULL, &a); break;
    }
    tp_output(r, "a", a); /* after the error: refused */
    return 0;
}

static void null_in_runs(void)
{
    static const char *const fn[5] = {"tp_param", "tp_output", "tp_sum",
                                      "tp_dot", "tp_dot"};
    double x[1] = {0.5};
    int which;
    for (which = 0; which < 5; which++) {
        tp_rec *r = NULL, *ev = NULL;
        tp_tape *T = NULL;
        CHECK_INT(tp_recorder_new(&r, 1, NULL, NULL), TP_OK);
        CHECK_INT(tp_evaluator_new(&ev, 1, NULL), TP_OK);
        CHECK_INT(tp_rec_run(r, NULL, null_inside, &which), TP_ERR_NULL);
        CHECK_INT(tp_rec_status(r), TP_ERR_NULL);
        CHECK_MSG(tp_rec_errmsg(r), fn[which]);
        CHECK_INT(tp_recorder_finish(r, &T), TP_ERR_NULL);
        CHECK(T == NULL);
        CHECK_INT(tp_rec_run(ev, x, null_inside, &which), TP_ERR_NULL);
        CHECK_MSG(tp_rec_errmsg(ev), fn[which]);
        CHECK_INT(tp_rec_n_outputs(ev), 0);
        tp_rec_free(&r);
        tp_rec_free(&ev);
    }
}

/* ---- handles ---------------------------------------------------------- */

typedef struct handle_case {
    int which;
    tp_val foreign; /* a handle of another context */
    tp_val kept;    /* a handle kept from the previous run */
} handle_case;

static int bad_handles(tp_rec *r, void *user)
{
    handle_case *hc = user;
    const tp_val z = {0, 0};
    tp_val a = tp_indep(r, 0), v;
    switch (hc->which) {
    case 0: v = tp_add(r, a, hc->foreign); break;  /* FOREIGN */
    case 1: v = tp_sin(r, hc->foreign); break;     /* FOREIGN */
    case 2: v = tp_mul(r, z, a); break;            /* HANDLE */
    case 3: tp_output(r, "z", z); v = a; break;    /* HANDLE */
    case 4: /* the result of a failed op is invalid: the first error is
             * kept */
        v = tp_indep(r, 7);
        v = tp_exp(r, v);
        break;
    default: v = tp_powi(r, hc->foreign, 2); break; /* FOREIGN */
    }
    tp_output(r, "v", v);
    return 0;
}

static void handles(void)
{
    static const int expect[6] = {TP_ERR_FOREIGN, TP_ERR_FOREIGN,
                                  TP_ERR_HANDLE,  TP_ERR_HANDLE,
                                  TP_ERR_SIZE,    TP_ERR_FOREIGN};
    static const char *const fn[6] = {"add", "sin", "mul", "tp_output",
                                      "tp_indep", "powi"};
    tp_rec *other = NULL;
    handle_case hc;
    double x[2] = {0.3, 0.4};
    int k, b;

    /* a handle from another recorder */
    CHECK_INT(tp_recorder_new(&other, 2, NULL, NULL), TP_OK);
    if (!other)
        return;
    hc.foreign = tp_indep(other, 1);
    CHECK(hc.foreign.tag != 0);
    for (k = 0; k < 6; k++) {
        for (b = 0; b < 3; b++) {
            tp_rec *r = NULL;
            int rc;
            hc.which = k;
            rc = b == 0   ? tp_recorder_new(&r, 2, NULL, NULL)
                 : b == 1 ? tp_evaluator_new(&r, 2, NULL)
                          : tp_tuple_new(&r, 2, NULL);
            CHECK_INT(rc, TP_OK);
            if (!r)
                continue;
            CHECK_INT(tp_rec_run(r, x, bad_handles, &hc), expect[k]);
            CHECK_INT(tp_rec_status(r), expect[k]);
            CHECK_MSG(tp_rec_errmsg(r), fn[k]);
            tp_rec_free(&r);
        }
    }
    tp_rec_free(&other);
}

/* A handle kept from an evaluator's earlier run is not a value of the
 * new run when the new run has fewer values. */
static int make_many(tp_rec *r, void *user)
{
    tp_val *keep = user, a = tp_indep(r, 0);
    int i;
    for (i = 0; i < 10; i++)
        a = tp_sin(r, a);
    *keep = a;
    tp_output(r, "a", a);
    return 0;
}

static int use_kept(tp_rec *r, void *user)
{
    tp_val *keep = user;
    tp_output(r, "a", tp_add(r, tp_indep(r, 0), *keep));
    return 0;
}

static void stale_handles(void)
{
    tp_rec *ev = NULL;
    tp_val keep;
    double x[1] = {0.5};
    CHECK_INT(tp_evaluator_new(&ev, 1, NULL), TP_OK);
    if (!ev)
        return;
    CHECK_INT(tp_rec_run(ev, x, make_many, &keep), TP_OK);
    CHECK_INT(tp_rec_run(ev, x, use_kept, &keep), TP_ERR_HANDLE);
    CHECK_MSG(tp_rec_errmsg(ev), "add");
    tp_rec_free(&ev);
}

/* simple(), keeping a handle of the run in *user */
static int simple_keep(tp_rec *r, void *user)
{
    *(tp_val *)user = tp_indep(r, 0);
    return simple(r, NULL);
}

static void finished(void)
{
    tp_rec *r = NULL;
    tp_tape *T = NULL, *T2 = NULL;
    tp_val a = {0, 0};
    CHECK_INT(tp_recorder_new(&r, 4, NULL, NULL), TP_OK);
    if (!r)
        return;
    CHECK_INT(tp_rec_run(r, NULL, simple_keep, &a), TP_OK);
    CHECK(a.tag != 0);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    CHECK(T != NULL);
    /* everything after finishing is refused */
    CHECK_INVALID(tp_add(r, a, a));
    CHECK_INT(tp_rec_status(r), TP_ERR_FINISHED);
    CHECK_MSG(tp_rec_errmsg(r), "add");
    CHECK_INVALID(tp_indep(r, 0));
    CHECK_INVALID(tp_const(r, 1.0));
    CHECK_INT(tp_rec_run(r, NULL, simple, NULL), TP_ERR_FINISHED);
    CHECK_INT(tp_recorder_finish(r, &T2), TP_ERR_FINISHED);
    CHECK(T2 == NULL);
    CHECK_INT(tp_output(r, "late", a), TP_ERR_FINISHED);
    tp_rec_free(&r);
    /* the tape outlives its recorder */
    CHECK_INT(tp_tape_n_outputs(T), 2);
    tp_tape_free(&T);
    CHECK(T == NULL);
}

/* ---- sizes and indices ------------------------------------------------ */

static int indep_out_of_range(tp_rec *r, void *user)
{
    tp_output(r, "a", tp_indep(r, *(int *)user));
    return 0;
}

static void sizes(void)
{
    unsigned char grp[4] = {0, 1, 2, 5};
    tp_tape *T = record(simple, NULL, 4);
    tp_rec *r = (tp_rec *)&grp; /* must be overwritten with NULL */
    tp_ws *ws = (tp_ws *)&grp;
    double x[4] = {0.1, 0.2, 0.3, 0.4}, y[2], J[8], H[16], g[4], v;
    double w[2] = {1, 1};
    int bad[3] = {-1, 4, INT_MAX}, k;

    /* constructors */
    CHECK_INT(tp_recorder_new(&r, -1, NULL, NULL), TP_ERR_SIZE);
    CHECK(r == NULL);
    CHECK_INT(tp_evaluator_new(&r, -1, NULL), TP_ERR_SIZE);
    CHECK(r == NULL);
    CHECK_INT(tp_tuple_new(&r, -1, NULL), TP_ERR_SIZE);
    CHECK(r == NULL);
    CHECK_INT(tp_recorder_new(&r, 4, grp, NULL), TP_OK); /* groups 0..5 */
    tp_rec_free(&r);
    grp[2] = 8;
    CHECK_INT(tp_recorder_new(&r, 4, grp, NULL), TP_ERR_SIZE);
    CHECK(r == NULL);
    grp[2] = 255;
    CHECK_INT(tp_recorder_new(&r, 4, grp, NULL), TP_ERR_SIZE);
    CHECK(r == NULL);
    if (!T)
        return;
    CHECK_INT(tp_ws_new(&ws, T, 0, NULL), TP_ERR_SIZE);
    CHECK(ws == NULL);
    CHECK_INT(tp_ws_new(&ws, T, -3, NULL), TP_ERR_SIZE);
    CHECK(ws == NULL);

    /* tp_indep out of range, on every backend */
    for (k = 0; k < 3; k++) {
        int b;
        for (b = 0; b < 3; b++) {
            int rc = b == 0   ? tp_recorder_new(&r, 4, NULL, NULL)
                     : b == 1 ? tp_evaluator_new(&r, 4, NULL)
                              : tp_tuple_new(&r, 4, NULL);
            CHECK_INT(rc, TP_OK);
            if (!r)
                continue;
            CHECK_INT(tp_rec_run(r, x, indep_out_of_range, &bad[k]),
                      TP_ERR_SIZE);
            CHECK_MSG(tp_rec_errmsg(r), "tp_indep");
            tp_rec_free(&r);
        }
    }

    /* tape queries */
    CHECK(tp_tape_output_name(T, -1) == NULL);
    CHECK(tp_tape_output_name(T, 2) == NULL);
    CHECK(tp_tape_param_name(T, 1) == NULL);
    CHECK(isnan(tp_tape_param_default(T, -1)));
    CHECK(isnan(tp_tape_param_default(T, 1)));
    CHECK_INT(tp_tape_output_index(T, "nope"), -1);
    CHECK_INT(tp_tape_param_index(T, "nope"), -1);

    /* workspace indices */
    CHECK_INT(tp_ws_new(&ws, T, 3, NULL), TP_OK);
    if (!ws)
        goto done;
    CHECK_INT(tp_ws_set_param(ws, -1, 1.0), TP_ERR_SIZE);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_ws_set_param");
    CHECK_INT(tp_ws_set_param(ws, 1, 1.0), TP_ERR_SIZE);
    CHECK_INT(tp_ws_get_param(ws, 1, &v), TP_ERR_SIZE);
    CHECK_INT(tp_ws_get_param(ws, -1, &v), TP_ERR_SIZE);
    CHECK_INT(tp_jvp(ws, x, -1, x, y, J), TP_ERR_SIZE);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_jvp");
    CHECK_INT(tp_hvp(ws, x, w, -1, x, g, H), TP_ERR_SIZE);
    CHECK_MSG(tp_ws_errmsg(ws), "tp_hvp");
    for (k = 0; k < 3; k++) {
        const int o = bad[k] == 4 ? 2 : bad[k]; /* 2 outputs */
        CHECK_INT(tp_gradient(ws, x, o, &v, g), TP_ERR_SIZE);
        CHECK_MSG(tp_ws_errmsg(ws), "tp_gradient");
        CHECK_INT(tp_hessian(ws, x, o, H), TP_ERR_SIZE);
        CHECK_MSG(tp_ws_errmsg(ws), "tp_hessian");
        CHECK_INT(tp_hessian_cols(ws, x, o, 0, 1, g, H), TP_ERR_SIZE);
        CHECK_INT(tp_lagrange(ws, x, o, &v, g, H, g), TP_ERR_SIZE);
        CHECK_MSG(tp_ws_errmsg(ws), "tp_lagrange");
    }
    /* Jacobian and Hessian columns: first, count and their sum; the sum
     * must not overflow an int on the way */
    {
        static const int fc[][2] = {{-1, 1}, {0, -1}, {0, 5}, {4, 1},
                                    {3, 2},  {5, 0},  {INT_MAX, 1},
                                    {1, INT_MAX}, {INT_MAX, INT_MAX},
                                    {INT_MIN, 1}};
        size_t i;
        for (i = 0; i < sizeof fc / sizeof fc[0]; i++) {
            CHECK_INT(tp_jacobian(ws, x, fc[i][0], fc[i][1], y, J),
                      TP_ERR_SIZE);
            CHECK_MSG(tp_ws_errmsg(ws), "tp_jacobian");
            CHECK_INT(tp_hessian_cols(ws, x, 0, fc[i][0], fc[i][1], g, H),
                      TP_ERR_SIZE);
            CHECK_MSG(tp_ws_errmsg(ws), "tp_hessian_cols");
        }
        CHECK_INT(tp_jacobian(ws, x, 4, 0, y, J), TP_OK); /* empty */
        CHECK_INT(tp_jacobian(ws, x, 2, 2, y, J), TP_OK);
        CHECK_INT(tp_hessian_cols(ws, x, 1, 3, 1, g, H), TP_OK);
    }
done:
    tp_ws_free(&ws);
    tp_tape_free(&T);
}

/* tp_lagrange reads an odd number of independents as (q, qd, t); the
 * tuple engine's tp_tuple_lagrange knows only (q, qd) pairs. */
static int odd(tp_rec *r, void *user)
{
    (void)user;
    tp_output(r, "L", tp_mul(r, tp_indep(r, 0), tp_sqr(r, tp_indep(r, 2))));
    return 0;
}

static void odd_lagrange(void)
{
    tp_tape *T = record(odd, NULL, 3);
    tp_ws *ws = NULL;
    tp_rec *tu = NULL;
    double x[3] = {1, 2, 3}, L, v[9];
    CHECK_INT(tp_ws_new(&ws, T, 2, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 3, NULL), TP_OK);
    if (ws) {
        /* L = q x t^2 with n = 1: dL/dq = t^2 = 9, M = 0, h = 0 */
        CHECK_INT(tp_lagrange(ws, x, 0, &L, v, v + 1, v + 2), TP_OK);
        CHECK(L == 9.0 && v[0] == 9.0 && v[1] == 0.0 && v[2] == 0.0);
    }
    if (tu) {
        CHECK_INT(tp_rec_run(tu, x, odd, NULL), TP_OK);
        CHECK_INT(tp_tuple_lagrange(tu, 0, &L, v, v, v), TP_ERR_SIZE);
        CHECK_INT(tp_tuple_lagrange(tu, 1, &L, v, v, v), TP_ERR_SIZE);
        CHECK_INT(tp_tuple_output(tu, 1, v, v), TP_ERR_SIZE);
        CHECK_INT(tp_tuple_output(tu, -1, v, v), TP_ERR_SIZE);
    }
    tp_rec_free(&tu);
    tp_ws_free(&ws);
    tp_tape_free(&T);
}

/* ---- names ------------------------------------------------------------ */

static int names_fn(tp_rec *r, void *user)
{
    const int which = *(const int *)user;
    tp_val a = tp_indep(r, 0), p, q;
    switch (which) {
    case 0: /* duplicate output */
        tp_output(r, "y", a);
        tp_output(r, "y", tp_sqr(r, a));
        break;
    case 1: /* parameter redeclared with another default */
        p = tp_param(r, "k", 2.0);
        q = tp_param(r, "k", 3.0);
        tp_output(r, "y", tp_add(r, p, q));
        break;
    case 2: /* an empty name */
        tp_output(r, "", a);
        break;
    case 3: /* an empty parameter name */
        tp_output(r, "y", tp_param(r, "", 1.0));
        break;
    default: /* the same default again is the same parameter */
        p = tp_param(r, "k", 2.0);
        q = tp_param(r, "k", 2.0);
        if (p.id != q.id || p.tag != q.tag)
            return 1;
        p = tp_param(r, "nan", NAN);
        q = tp_param(r, "nan", NAN);
        if (p.id != q.id)
            return 1;
        tp_output(r, "y", tp_mul(r, a, tp_add(r, p, q)));
        break;
    }
    return 0;
}

static void names(void)
{
    static const int expect[5] = {TP_ERR_NAME, TP_ERR_NAME, TP_ERR_NAME,
                                  TP_ERR_NAME, TP_OK};
    static const char *const fn[5] = {"tp_output", "tp_param", "tp_output",
                                      "tp_param", ""};
    double x[1] = {0.5};
    int which, b;
    for (which = 0; which < 5; which++) {
        for (b = 0; b < 3; b++) {
            tp_rec *r = NULL;
            int rc = b == 0   ? tp_recorder_new(&r, 1, NULL, NULL)
                     : b == 1 ? tp_evaluator_new(&r, 1, NULL)
                              : tp_tuple_new(&r, 1, NULL);
            CHECK_INT(rc, TP_OK);
            if (!r)
                continue;
            CHECK_INT(tp_rec_run(r, x, names_fn, &which), expect[which]);
            if (expect[which] != TP_OK)
                CHECK_MSG(tp_rec_errmsg(r), fn[which]);
            tp_rec_free(&r);
        }
    }
}

/* ---- backends --------------------------------------------------------- */

static int reenter(tp_rec *r, void *user)
{
    tp_output(r, "a", tp_indep(r, 0));
    return tp_rec_run(r, user, simple, NULL) == TP_ERR_BACKEND ? 0 : 7;
}

static void backends(void)
{
    tp_rec *ev = NULL, *tu = NULL, *rec = NULL;
    tp_tape *T = NULL;
    tp_val a;
    double x[4] = {0.1, 0.2, 0.3, 0.4}, v, g[4], h[10];
    CHECK_INT(tp_evaluator_new(&ev, 4, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 4, NULL), TP_OK);
    CHECK_INT(tp_recorder_new(&rec, 4, NULL, NULL), TP_OK);
    if (!ev || !tu || !rec)
        goto done;

    /* an evaluator computes only inside tp_rec_run */
    a = tp_indep(ev, 0);
    CHECK_INVALID(a);
    CHECK_INT(tp_rec_status(ev), TP_ERR_BACKEND);
    CHECK_MSG(tp_rec_errmsg(ev), "tp_indep");
    CHECK_INVALID(tp_const(tu, 1.0));
    CHECK_INT(tp_rec_status(tu), TP_ERR_BACKEND);
    CHECK_MSG(tp_rec_errmsg(tu), "tp_const");
    /* a new run starts afresh */
    CHECK_INT(tp_rec_run(ev, x, simple, NULL), TP_OK);
    CHECK_INT(tp_rec_status(ev), TP_OK);
    CHECK_INT(tp_rec_output_value(ev, 0, &v), TP_OK);
    /* ... and nothing is computed after the run */
    CHECK_INVALID(tp_sin(ev, tp_indep(ev, 0)));
    CHECK_INT(tp_rec_status(ev), TP_ERR_BACKEND);

    /* calls for another backend */
    CHECK_INT(tp_recorder_finish(ev, &T), TP_ERR_BACKEND);
    CHECK(T == NULL);
    CHECK_INT(tp_recorder_finish(tu, &T), TP_ERR_BACKEND);
    CHECK_INT(tp_rec_set_param(rec, "p", 1.0), TP_ERR_BACKEND);
    CHECK_INT(tp_rec_output_value(rec, 0, &v), TP_ERR_BACKEND);
    CHECK_INT(tp_rec_run(ev, x, simple, NULL), TP_OK);
    CHECK_INT(tp_tuple_output(ev, 0, g, h), TP_ERR_BACKEND);
    CHECK_INT(tp_tuple_lagrange(ev, 0, &v, g, h, g), TP_ERR_BACKEND);
    CHECK_INT(tp_tuple_output(rec, 0, g, h), TP_ERR_BACKEND);

    /* tp_rec_run from inside a run */
    CHECK_INT(tp_rec_run(ev, x, reenter, x), TP_ERR_BACKEND);
    CHECK_MSG(tp_rec_errmsg(ev), "tp_rec_run");
    CHECK_INT(tp_rec_run(rec, x, reenter, x), TP_ERR_BACKEND);
done:
    tp_rec_free(&ev);
    tp_rec_free(&tu);
    tp_rec_free(&rec);
}

/* ---- empty recordings and user errors --------------------------------- */

static int no_outputs(tp_rec *r, void *user)
{
    (void)user;
    tp_sin(r, tp_indep(r, 0));
    return 0;
}

static int fails(tp_rec *r, void *user)
{
    tp_output(r, "a", tp_indep(r, 0));
    return *(const int *)user;
}

static void empty_and_user(void)
{
    static int codes[3] = {1, -1, 42};
    double x[1] = {0.5}, v, g[1], h[1];
    tp_tape *T = NULL;
    int b, k;
    for (b = 0; b < 3; b++) {
        tp_rec *r = NULL;
        int rc = b == 0   ? tp_recorder_new(&r, 1, NULL, NULL)
                 : b == 1 ? tp_evaluator_new(&r, 1, NULL)
                          : tp_tuple_new(&r, 1, NULL);
        CHECK_INT(rc, TP_OK);
        if (!r)
            continue;
        CHECK_INT(tp_rec_run(r, x, no_outputs, NULL), TP_OK);
        if (b == 0) {
            CHECK_INT(tp_recorder_finish(r, &T), TP_ERR_EMPTY);
            CHECK(T == NULL);
            CHECK_MSG(tp_rec_errmsg(r), "tp_recorder_finish");
        } else {
            CHECK_INT(tp_rec_n_outputs(r), 0);
            CHECK_INT(tp_rec_output_value(r, 0, &v), TP_ERR_EMPTY);
            if (b == 2) {
                CHECK_INT(tp_tuple_output(r, 0, g, h), TP_ERR_EMPTY);
                CHECK_INT(tp_tuple_lagrange(r, 0, &v, g, h, g),
                          TP_ERR_EMPTY);
            }
        }
        tp_rec_free(&r);
        for (k = 0; k < 3; k++) {
            rc = b == 0   ? tp_recorder_new(&r, 1, NULL, NULL)
                 : b == 1 ? tp_evaluator_new(&r, 1, NULL)
                          : tp_tuple_new(&r, 1, NULL);
            if (!r)
                continue;
            CHECK_INT(tp_rec_run(r, x, fails, &codes[k]),
                      TP_ERR_USER);
            CHECK_INT(tp_rec_status(r), TP_ERR_USER);
            CHECK_MSG(tp_rec_errmsg(r), "tp_rec_run");
            if (b == 0) {
                CHECK_INT(tp_recorder_finish(r, &T), TP_ERR_USER);
                CHECK(T == NULL);
                /* a failed recording cannot be continued */
                CHECK_INT(tp_rec_run(r, x, simple, NULL), TP_ERR_USER);
            }
            tp_rec_free(&r);
        }
    }
}

/* ---- sticky errors ---------------------------------------------------- */

static int several_errors(tp_rec *r, void *user)
{
    const tp_val z = {0, 0};
    tp_val a = tp_indep(r, 0);
    (void)user;
    a = tp_sin(r, a);
    tp_indep(r, -2);           /* the first error: SIZE */
    a = tp_add(r, a, z);       /* then HANDLE */
    tp_output(r, "a", a);      /* then HANDLE again */
    tp_param(r, "", 1.0);      /* then NAME */
    return 3;                  /* then USER */
}

static void sticky(void)
{
    double x[1] = {0.5};
    int b;
    for (b = 0; b < 3; b++) {
        tp_rec *r = NULL;
        tp_tape *T = NULL;
        int rc = b == 0   ? tp_recorder_new(&r, 1, NULL, NULL)
                 : b == 1 ? tp_evaluator_new(&r, 1, NULL)
                          : tp_tuple_new(&r, 1, NULL);
        CHECK_INT(rc, TP_OK);
        if (!r)
            continue;
        CHECK_INT(tp_rec_run(r, x, several_errors, NULL), TP_ERR_SIZE);
        CHECK_INT(tp_rec_status(r), TP_ERR_SIZE);
        CHECK_MSG(tp_rec_errmsg(r), "tp_indep");
        CHECK_INVALID(tp_indep(r, 0));
        CHECK_INT(tp_rec_status(r), TP_ERR_SIZE);
        if (b == 0) {
            CHECK_INT(tp_recorder_finish(r, &T), TP_ERR_SIZE);
            CHECK(T == NULL);
            CHECK_MSG(tp_rec_errmsg(r), "tp_indep");
        } else {
            /* an evaluator's next run starts afresh */
            CHECK_INT(tp_rec_run(r, x, fails, &(int){0}), TP_OK);
            CHECK_INT(tp_rec_status(r), TP_OK);
            CHECK(tp_rec_errmsg(r)[0] == '\0');
        }
        tp_rec_free(&r);
    }
}

/* ---- domain errors ---------------------------------------------------- */

/* Outputs: "ok" (finite, recorded first), four domain errors, and
 * "late" = x3 sin x3 (finite, recorded after the bad ops). */
static int domain_fn(tp_rec *r, void *user)
{
    tp_val x[4];
    int i;
    (void)user;
    for (i = 0; i < 4; i++)
        x[i] = tp_indep(r, i);
    tp_output(r, "ok", tp_add(r, tp_sqr(r, x[3]), x[2]));
    tp_output(r, "log", tp_log(r, x[0]));
    tp_output(r, "sqrt", tp_sqrt(r, x[1]));
    tp_output(r, "inv", tp_div(r, tp_const(r, 1.0), x[2]));
    tp_output(r, "div", tp_div(r, x[3], x[2]));
    tp_output(r, "late", tp_mul(r, x[3], tp_sin(r, x[3])));
    return 0;
}

enum { D_OK, D_LOG, D_SQRT, D_INV, D_DIV, D_LATE, D_N };

static bool all_finite(const double *a, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(a[i]))
            return false;
    return true;
}

static void domain(void)
{
    const double x[4] = {-1.0, -1.0, 0.0, 0.5};
    const double s3 = sin(0.5), c3 = cos(0.5);
    tp_tape *T = record(domain_fn, NULL, 4);
    tp_ws *ws = NULL, *ws1 = NULL;
    tp_rec *ev = NULL, *tu = NULL;
    double y[D_N], J[D_N * 4], S[4 * 2] = {1, 0, 0, 1, 0.5, 0, 0, 1};
    double w[D_N] = {1, 1, 1, 1, 1, 1}, g[4], H[16], HS[8], L, dLdq[2],
           M[4], h[2], y1[D_N], y2[D_N], v, hp[10];
    const double grad_late[4] = {0, 0, 0, s3 + 0.5 * c3};
    double Hlate[16] = {0};
    int o;

    Hlate[15] = 2.0 * c3 - 0.5 * s3;
    CHECK_INT(tp_ws_new(&ws, T, 3, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&ws1, T, 1, NULL), TP_OK);
    CHECK_INT(tp_evaluator_new(&ev, 4, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 4, NULL), TP_OK);
    if (!T || !ws || !ws1 || !ev || !tu)
        goto done;

    /* every sweep over all outputs warns, and the bad outputs are bad */
    CHECK_INT(tp_eval(ws, x, y), TP_WARN_NONFINITE);
    CHECK(isnan(y[D_LOG]) && isnan(y[D_SQRT]));
    CHECK(isinf(y[D_INV]) && isinf(y[D_DIV]));
    CHECK(isfinite(y[D_OK]) && isfinite(y[D_LATE]));
    CHECK_INT(tp_jvp(ws, x, 2, S, y, J), TP_WARN_NONFINITE);
    CHECK_INT(tp_jacobian(ws, x, 0, 4, y, J), TP_WARN_NONFINITE);
    CHECK(!all_finite(J + 4 * D_SQRT, 4)); /* d sqrt(u) = 1 / (2 sqrt u) */
    CHECK(all_finite(J + 4 * D_OK, 4) && all_finite(J + 4 * D_LATE, 4));
    CHECK_INT(tp_vjp(ws, x, w, NULL, g), TP_WARN_NONFINITE);
    CHECK_INT(tp_hvp(ws, x, w, 2, S, g, HS), TP_WARN_NONFINITE);
    CHECK_INT(tp_hvp(ws1, x, w, 2, S, NULL, HS), TP_WARN_NONFINITE);
    CHECK_INT(tp_taylor2(ws, x, S, y, y1, y2), TP_WARN_NONFINITE);
    for (o = D_LOG; o <= D_DIV; o++) {
        CHECK_INT(tp_gradient(ws, x, o, &v, g), TP_WARN_NONFINITE);
        if (o != D_LOG) { /* the partials of log at -1 are finite */
            CHECK_INT(tp_hessian(ws, x, o, H), TP_WARN_NONFINITE);
            CHECK_INT(tp_hessian_cols(ws1, x, o, 1, 2, g, H),
                      TP_WARN_NONFINITE);
        }
        CHECK_INT(tp_lagrange(ws, x, o, &L, dLdq, M, h), TP_WARN_NONFINITE);
        CHECK_INT(tp_lagrange(ws1, x, o, &L, NULL, NULL, NULL),
                  TP_WARN_NONFINITE);
    }

    /* results that do not depend on the bad ops are finite and right,
     * wherever their output sits on the tape */
    for (o = 0; o < D_N; o += D_LATE) {
        const double *gr = o == D_LATE ? grad_late : NULL;
        char ctx[32];
        int q;
        snprintf(ctx, sizeof ctx, "output %d", o);
        for (q = 0; q < 2; q++) {
            tp_ws *wq = q ? ws1 : ws;
            CHECK_INT(tp_gradient(wq, x, o, &v, g), TP_OK);
            CHECK_INT(tp_hessian(wq, x, o, H), TP_OK);
            CHECK_INT(tp_lagrange(wq, x, o, &L, dLdq, M, h), TP_OK);
            CHECK_INT(tp_hessian_cols(wq, x, o, 2, 2, g, HS), TP_OK);
            CHECK(all_finite(H, 16) && all_finite(g, 4));
            if (gr) {
                int i;
                for (i = 0; i < 4; i++)
                    CHECK_NEAR(g[i], gr[i], 1e-15);
                for (i = 0; i < 16; i++)
                    CHECK_NEAR(H[i], Hlate[i], 1e-15);
            }
        }
        {
            double wo[D_N] = {0}, sg[4], sh[8];
            wo[o] = 1.0;
            CHECK_INT(tp_hvp(ws, x, wo, 2, S, sg, sh), TP_OK);
            CHECK_INT(tp_vjp(ws, x, wo, NULL, sg), TP_OK);
        }
    }

    /* both evaluators: a domain error is not an error; values warn */
    CHECK_INT(tp_rec_run(ev, x, domain_fn, NULL), TP_OK);
    CHECK_INT(tp_rec_run(tu, x, domain_fn, NULL), TP_OK);
    CHECK_INT(tp_rec_status(ev), TP_OK);
    for (o = 0; o < D_N; o++) {
        const int expect = o == D_OK || o == D_LATE ? TP_OK
                                                    : TP_WARN_NONFINITE;
        CHECK_INT(tp_rec_output_value(ev, o, &v), expect);
        CHECK_INT(tp_rec_output_value(tu, o, &v), expect);
        CHECK_INT(tp_tuple_output(tu, o, g, hp), expect);
        CHECK_INT(tp_tuple_lagrange(tu, o, &L, dLdq, M, h), expect);
    }

    /* a non-finite input */
    {
        double xn[4] = {NAN, 1.0, 1.0, 1.0}, xi[4] = {1.0, 1.0, 1.0, INFINITY};
        CHECK_INT(tp_eval(ws, xn, y), TP_WARN_NONFINITE);
        CHECK_INT(tp_gradient(ws, xn, D_LOG, &v, g), TP_WARN_NONFINITE);
        CHECK_INT(tp_hessian(ws, xn, D_LOG, H), TP_WARN_NONFINITE);
        CHECK_INT(tp_gradient(ws, xi, D_OK, NULL, g), TP_WARN_NONFINITE);
        /* inf * 0 may make H non-finite here: only no error is promised */
        CHECK(tp_hessian(ws, xi, D_OK, H) >= 0);
        CHECK_INT(tp_rec_run(ev, xn, domain_fn, NULL), TP_OK);
        CHECK_INT(tp_rec_output_value(ev, D_LOG, &v), TP_WARN_NONFINITE);
    }
    /* and the workspace recovers at a good point */
    {
        double xg[4] = {2.0, 4.0, 0.5, 0.25};
        CHECK_INT(tp_eval(ws, xg, y), TP_OK);
        CHECK_NEAR(y[D_SQRT], 2.0, 1e-15);
        CHECK_INT(tp_hessian(ws, xg, D_LOG, H), TP_OK);
        CHECK_NEAR(H[0], -0.25, 1e-15);
    }
done:
    tp_rec_free(&ev);
    tp_rec_free(&tu);
    tp_ws_free(&ws);
    tp_ws_free(&ws1);
    tp_tape_free(&T);
}

/* ---- one bad result of tp_lagrange_t ---------------------------------- */

/* Lagrangians of n coordinates, x = (q, qd, t), where exactly one of
 * tp_lagrange_t's results is not finite at x = 0 (qd_1 = 1e300 for h):
 * each result is checked on its own, in every way the block is stored
 * (n = 2: the unrolled copy; n = 7: the general one; max_dirs 1: in
 * chunks). */
enum { BAD_M, BAD_DLDQ, BAD_DLDT, BAD_H, BAD_N };

typedef struct bad_case {
    int which, n;
} bad_case;

static int bad_fn(tp_rec *r, void *user)
{
    const bad_case *c = user;
    const tp_val q0 = tp_indep(r, 0), q1 = tp_indep(r, 1),
                 qd0 = tp_indep(r, c->n), t = tp_indep(r, 2 * c->n);
    tp_val L;
    switch (c->which) {
    case BAD_M: /* d2L/dqd0^2 = 0.75 / sqrt(qd0) */
        L = tp_powc(r, qd0, 1.5);
        break;
    case BAD_DLDQ: /* dL/dq0 = 0.5 / sqrt(q0) */
        L = tp_powc(r, q0, 0.5);
        break;
    case BAD_DLDT: /* dL/dt = 0.5 / sqrt(t) */
        L = tp_powc(r, t, 0.5);
        break;
    default: /* h_0 = 1e10 qd1 overflows; its Hessian entry is 1e10 */
        L = tp_mulc(r, tp_mul(r, q1, qd0), 1e10);
        break;
    }
    tp_output(r, "L", L);
    return 0;
}

static void lagrange_one_bad(void)
{
    static const int sizes[2] = {2, 7};
    int which, k, d;
    for (which = 0; which < BAD_N; which++)
        for (k = 0; k < 2; k++) {
            const int n = sizes[k];
            bad_case c;
            unsigned char group[15];
            double x[15] = {0}, L, dLdq[7], dLdt, M[49], h[7];
            tp_rec *r = NULL;
            tp_tape *T = NULL;
            int i;
            c.which = which;
            c.n = n;
            for (i = 0; i < 2 * n + 1; i++)
                group[i] = (unsigned char)(i < n ? 0 : i < 2 * n ? 1 : 2);
            if (which == BAD_H)
                x[n + 1] = 1e300;
            CHECK_INT(tp_recorder_new(&r, 2 * n + 1, group, NULL), TP_OK);
            CHECK_INT(tp_rec_run(r, NULL, bad_fn, &c), TP_OK);
            CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
            tp_rec_free(&r);
            for (d = 0; T && d < 2; d++) {
                tp_ws *ws = NULL;
                const int fails = check_failures_;
                char ctx[64];
                snprintf(ctx, sizeof ctx, "case %d, n = %d, max_dirs %d",
                         which, n, d ? 1 : n);
                CHECK_INT(tp_ws_new(&ws, T, d ? 1 : n, NULL), TP_OK);
                if (!ws)
                    continue;
                CHECK_INT(tp_lagrange_t(ws, x, 0, &L, dLdq, &dLdt, M, h),
                          TP_WARN_NONFINITE);
                /* without the bad result, the others are finite */
                CHECK_INT(tp_lagrange_t(ws, x, 0, &L,
                                        which == BAD_DLDQ ? NULL : dLdq,
                                        which == BAD_DLDT ? NULL : &dLdt,
                                        which == BAD_M ? NULL : M,
                                        which == BAD_H ? NULL : h),
                          TP_OK);
                if (check_failures_ != fails)
                    fprintf(stderr, "  (in %s)\n", ctx);
                tp_ws_free(&ws);
            }
            tp_tape_free(&T);
        }
}

int main(void)
{
    status_table();
    null_contexts();
    null_pointers();
    null_in_runs();
    handles();
    stale_handles();
    finished();
    sizes();
    odd_lagrange();
    names();
    backends();
    empty_and_user();
    sticky();
    domain();
    lagrange_one_bad();
    CHECK_DONE();
}
