/* test_bad_input.c - the library never aborts: every bad input gives a
 * clear status and a message.
 *
 *  - status names and texts for every code;
 *  - model errors: malformed or duplicate names (EOM_ERR_NAME, the message
 *    quotes the name), non-finite defaults (EOM_ERR_NONFINITE), NULL
 *    callbacks, a bad constraint count; eom_system_new then returns the
 *    model's first error and copies its message (also truncated to a
 *    short buffer, or not at all with a NULL buffer);
 *  - inconsistent models (EOM_ERR_MODEL): T and L both, V and L, no
 *    energy, no coordinates, as many constraints as coordinates;
 *  - recording errors (EOM_ERR_RECORD, the message names the problem): an
 *    unknown parameter, qd in the constraints, a bad coordinate index, a
 *    callback returning non-zero, an output left unset (scalar and vector
 *    callbacks); the time read by a Lagrangian run on a context without
 *    it (eom_model_run_lagrangian with 2n independents), while T and the
 *    constraints may read it;
 *  - evaluation errors: a mass matrix that is singular (a coordinate
 *    missing from T) or indefinite -> EOM_ERR_SINGULAR_MASS with "positive
 *    definite" in the message; duplicate constraints or a closed chain
 *    stretched straight -> EOM_ERR_RANK_DEFICIENT with "rank deficient";
 *    NaN or infinite states and times -> EOM_ERR_NONFINITE from every
 *    evaluation and from eom_integ_new; a domain error met during an RK4
 *    run -> the run stops with that status, a message with the time, the
 *    last good state, and the failure is sticky;
 *  - integrator options out of range, tout not after t, max_steps
 *    exceeded;
 *  - NULL arguments to every entry point.
 * A failed call leaves a message; a later successful call of any kind
 * clears it (eom.h: "" after a success).
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_num.h"

#define HAS(msg, sub)                                                      \
    do {                                                                   \
        const char *m_ = (msg);                                            \
        check_count_++;                                                    \
        if (!m_ || !strstr(m_, (sub)))                                     \
            CHECK_FAIL_("message \"%s\" does not mention \"%s\"",          \
                        m_ ? m_ : "(null)", (sub));                        \
    } while (0)

/* ---- small models ------------------------------------------------------- */

/* T = 1/2 sum qd^2 (unit masses), V = 1/2 sum q^2. */
static int unit_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val s = tp_const(R, 0.0);
    int i;
    (void)user;
    for (i = 0; i < eom_ncoords(c); i++)
        s = tp_add(R, s, tp_sqr(R, eom_qd(c, i)));
    *out = tp_mulc(R, s, 0.5);
    return 0;
}

static int unit_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val s = tp_const(R, 0.0);
    int i;
    (void)user;
    for (i = 0; i < eom_ncoords(c); i++)
        s = tp_add(R, s, tp_sqr(R, eom_q(c, i)));
    *out = tp_mulc(R, s, 0.5);
    return 0;
}

/* T = 1/2 qd0^2 only: the other coordinates have no inertia. */
static int first_only_T(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_qd(c, 0)), 0.5);
    return 0;
}

/* T = 1/2 (qd0^2 - qd1^2): indefinite. */
static int indefinite_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_sub(R, tp_sqr(R, eom_qd(c, 0)),
                             tp_sqr(R, eom_qd(c, 1))), 0.5);
    return 0;
}

/* V = -sqrt(q0): undefined for q0 < 0. */
static int sqrt_V(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_neg(eom_rec(c), tp_sqrt(eom_rec(c), eom_q(c, 0)));
    return 0;
}

/* The same sphere constraint twice. */
static int twice_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val r2 = tp_add(R, tp_add(R, tp_sqr(R, eom_q(c, 0)),
                                 tp_sqr(R, eom_q(c, 1))),
                       tp_sqr(R, eom_q(c, 2)));
    (void)user;
    out[0] = tp_mulc(R, tp_addc(R, r2, -1.0), 0.5);
    out[1] = tp_mulc(R, tp_addc(R, r2, -1.0), 0.5);
    return 0;
}

/* The same constraint once. */
static int once_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_val two[2];
    int rc = twice_phi(c, user, two);
    out[0] = two[0];
    return rc;
}

/* Misbehaving callbacks, selected by *(int *)user. */
enum { BAD_PARAM, BAD_QD_IN_PHI, BAD_TIME_IN_PHI, BAD_TIME_IN_T, BAD_INDEX,
       BAD_RETURN, BAD_UNSET, BAD_NONE };
static int no_mistake = BAD_NONE;

static int bad_scalar(eom_ctx *c, void *user, tp_val *out)
{
    const int what = *(const int *)user;
    tp_rec *R = eom_rec(c);
    tp_val v = tp_mulc(R, tp_sqr(R, eom_qd(c, 0)), 0.5);
    switch (what) {
    case BAD_PARAM: v = tp_mul(R, v, eom_param(c, "nosuch")); break;
    case BAD_TIME_IN_T: v = tp_add(R, v, eom_time(c)); break;
    case BAD_INDEX: v = tp_add(R, v, eom_q(c, 5)); break;
    case BAD_RETURN: return 7;
    case BAD_UNSET: return 0;
    default: break;
    }
    *out = v;
    return 0;
}

static int bad_phi(eom_ctx *c, void *user, tp_val *out)
{
    const int what = *(const int *)user;
    tp_rec *R = eom_rec(c);
    out[0] = tp_addc(R, eom_q(c, 0), -1.0);
    switch (what) {
    case BAD_QD_IN_PHI: out[0] = tp_add(R, out[0], eom_qd(c, 0)); break;
    case BAD_TIME_IN_PHI: out[0] = tp_add(R, out[0], eom_time(c)); break;
    case BAD_RETURN: return -2;
    case BAD_UNSET: return 0; /* out[1] left unset */
    default: break;
    }
    out[1] = tp_addc(R, eom_q(c, 1), -1.0);
    return 0;
}

static int bad_forces(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    out[0] = eom_time(c);             /* allowed here */
    out[1] = eom_param(c, "nosuch"); /* out[2..] may stay unset (0) */
    return 0;
}

/* A model with n coordinates q1..qn and the unit T and V. */
static eom_model *unit_model(int n)
{
    eom_model *md = NULL;
    char name[16];
    int i;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    for (i = 0; i < n; i++) {
        snprintf(name, sizeof name, "q%d", i + 1);
        eom_model_add_coord(md, name, "m", 0.1 * i, 0.0);
    }
    eom_model_set_kinetic(md, unit_T, NULL);
    eom_model_set_potential(md, unit_V, NULL);
    return md;
}

/* eom_system_new on md (freed) must fail with status; the message must
 * mention sub. */
static void expect_fail(eom_model *md, int status, const char *sub)
{
    char msg[256];
    eom_system *const sentinel = (eom_system *)msg;
    eom_system *s = sentinel; /* must be reset to NULL */
    int rc;
    CHECK(md != NULL);
    if (!md)
        return;
    memset(msg, 'x', sizeof msg);
    rc = eom_system_new(&s, md, msg, sizeof msg);
    CHECK(s == NULL);
    check_count_++;
    if (rc != status)
        CHECK_FAIL_("expected %s, got %s (%s)", eom_status_name(status),
                    eom_status_name(rc), msg);
    HAS(msg, sub);
    if (s != sentinel)
        eom_system_free(&s);
    eom_model_free(&md);
}

/* ---- checks ------------------------------------------------------------- */

static void statuses(void)
{
    static const int codes[] = {
        EOM_OK, EOM_ERR_NULL, EOM_ERR_NOMEM, EOM_ERR_ARG, EOM_ERR_NAME,
        EOM_ERR_MODEL, EOM_ERR_RECORD, EOM_ERR_NONFINITE,
        EOM_ERR_SINGULAR_MASS, EOM_ERR_RANK_DEFICIENT, EOM_ERR_PROJECTION,
        EOM_ERR_SOLVER, EOM_ERR_LINALG, EOM_ERR_NOT_CONVERGED};
    size_t i;
    for (i = 0; i < sizeof codes / sizeof codes[0]; i++) {
        CHECK(strncmp(eom_status_name(codes[i]), "EOM_", 4) == 0);
        CHECK(strcmp(eom_strerror(codes[i]), "unknown status") != 0);
    }
    CHECK(strcmp(eom_status_name(EOM_ERR_SINGULAR_MASS),
                 "EOM_ERR_SINGULAR_MASS") == 0);
    CHECK(strcmp(eom_strerror(-99), "unknown status") == 0);
    CHECK(strcmp(eom_status_name(99), "EOM_UNKNOWN") == 0);
}

static void names(void)
{
    static const char *const bad[] = {"1abc", "a b", "r_dot", "", "x-y",
                                      "_dot"};
    eom_model *md;
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        md = unit_model(1);
        CHECK_INT(eom_model_add_coord(md, bad[i], NULL, 0.0, 0.0),
                  EOM_ERR_NAME);
        HAS(eom_model_errmsg(md), bad[i]);
        expect_fail(md, EOM_ERR_NAME, bad[i]);
        md = unit_model(1);
        CHECK_INT(eom_model_add_param(md, bad[i], NULL, 1.0, NULL),
                  EOM_ERR_NAME);
        HAS(eom_model_errmsg(md), "parameter");
        eom_model_free(&md);
    }
    /* allowed: underscores, digits after the first character, a name that
     * only contains "dot" */
    md = unit_model(1);
    CHECK_INT(eom_model_add_coord(md, "_x2", NULL, 0.0, 0.0), 1);
    CHECK_INT(eom_model_add_param(md, "dot", NULL, 0.0, NULL), 0);
    CHECK_INT(eom_model_add_param(md, "x_dotted", NULL, 0.0, NULL), 1);
    CHECK(eom_model_errmsg(md)[0] == '\0');
    eom_model_free(&md);

    md = unit_model(1);
    CHECK_INT(eom_model_add_coord(md, NULL, NULL, 0.0, 0.0), EOM_ERR_NAME);
    HAS(eom_model_errmsg(md), "(null)");
    eom_model_free(&md);

    /* duplicates, across the three lists */
    md = unit_model(2);
    CHECK_INT(eom_model_add_coord(md, "q2", NULL, 0.0, 0.0), EOM_ERR_NAME);
    HAS(eom_model_errmsg(md), "'q2' is already used");
    expect_fail(md, EOM_ERR_NAME, "q2");
    md = unit_model(2);
    CHECK_INT(eom_model_add_param(md, "q1", NULL, 0.0, NULL), EOM_ERR_NAME);
    expect_fail(md, EOM_ERR_NAME, "q1");
    md = unit_model(1);
    CHECK_INT(eom_model_add_param(md, "k", NULL, 0.0, NULL), 0);
    CHECK_INT(eom_model_add_probe(md, "k", NULL, unit_T, NULL),
              EOM_ERR_NAME);
    expect_fail(md, EOM_ERR_NAME, "'k'");

    /* the first error is kept */
    md = unit_model(1);
    CHECK_INT(eom_model_add_coord(md, "9a", NULL, 0.0, 0.0), EOM_ERR_NAME);
    CHECK_INT(eom_model_add_coord(md, "b c", NULL, 0.0, 0.0), EOM_ERR_NAME);
    HAS(eom_model_errmsg(md), "9a");
    eom_model_free(&md);
}

static void model_errors(void)
{
    eom_model *md;
    char small[8];
    eom_system *s = NULL;

    md = unit_model(1);
    CHECK_INT(eom_model_add_coord(md, "q2", NULL, NAN, 0.0),
              EOM_ERR_NONFINITE);
    HAS(eom_model_errmsg(md), "q2");
    expect_fail(md, EOM_ERR_NONFINITE, "not finite");
    md = unit_model(1);
    CHECK_INT(eom_model_add_coord(md, "q2", NULL, 0.0, INFINITY),
              EOM_ERR_NONFINITE);
    eom_model_free(&md);
    md = unit_model(1);
    CHECK_INT(eom_model_add_param(md, "k", NULL, -INFINITY, NULL),
              EOM_ERR_NONFINITE);
    expect_fail(md, EOM_ERR_NONFINITE, "'k'");

    md = unit_model(1);
    CHECK_INT(eom_model_set_kinetic(md, NULL, NULL), EOM_ERR_NULL);
    HAS(eom_model_errmsg(md), "kinetic");
    expect_fail(md, EOM_ERR_NULL, "NULL");
    md = unit_model(1);
    CHECK_INT(eom_model_set_forces(md, NULL, NULL), EOM_ERR_NULL);
    eom_model_free(&md);
    md = unit_model(1);
    CHECK_INT(eom_model_add_probe(md, "p", NULL, NULL, NULL), EOM_ERR_NULL);
    eom_model_free(&md);
    md = unit_model(3);
    CHECK_INT(eom_model_set_constraints(md, 0, twice_phi, NULL),
              EOM_ERR_ARG);
    expect_fail(md, EOM_ERR_ARG, "count");

    /* inconsistent models */
    md = unit_model(1);
    CHECK_INT(eom_model_set_lagrangian(md, unit_T, NULL), EOM_OK);
    expect_fail(md, EOM_ERR_MODEL, "not both");
    md = NULL;
    eom_model_new(&md);
    eom_model_add_coord(md, "q", NULL, 0.0, 0.0);
    eom_model_set_lagrangian(md, unit_T, NULL);
    eom_model_set_potential(md, unit_V, NULL);
    expect_fail(md, EOM_ERR_MODEL, "not both");
    md = NULL;
    eom_model_new(&md);
    eom_model_add_coord(md, "q", NULL, 0.0, 0.0);
    eom_model_set_potential(md, unit_V, NULL);
    expect_fail(md, EOM_ERR_MODEL, "no kinetic energy");
    md = NULL;
    eom_model_new(&md);
    eom_model_set_kinetic(md, unit_T, NULL);
    expect_fail(md, EOM_ERR_MODEL, "no coordinates");
    /* as many constraints as coordinates is no error: redundant ones
     * leave degrees of freedom (a structure with none just stands) */
    md = unit_model(2);
    eom_model_set_constraints(md, 2, bad_phi, &no_mistake);
    {
        eom_system *s2 = core_system(md);
        const double x[4] = {1.0, 1.0, 0.0, 0.0};
        double xd[4];
        eom_linear lin;
        memset(&lin, 0, sizeof lin);
        CHECK(s2 != NULL);
        CHECK_INT(eom_system_nconstraints(s2), 2);
        if (s2) {
            /* q = (1, 1) is all the constraints allow: it stays there */
            CHECK_INT(eom_rhs(s2, 0.0, x, xd), EOM_OK);
            CHECK_NEAR(xd[2], 0.0, 1e-15);
            CHECK_NEAR(xd[3], 0.0, 1e-15);
            CHECK_INT(eom_linearize(s2, x, &lin), EOM_OK);
            CHECK_INT(lin.nr, 0);
            eom_linear_free(&lin);
        }
        eom_system_free(&s2);
    }

    /* the message is cut to the buffer given, or not written at all */
    md = unit_model(1);
    eom_model_set_lagrangian(md, unit_T, NULL);
    memset(small, 'x', sizeof small);
    CHECK_INT(eom_system_new(&s, md, small, sizeof small), EOM_ERR_MODEL);
    CHECK(small[7] == '\0' && strlen(small) == 7);
    CHECK_INT(eom_system_new(&s, md, NULL, 100), EOM_ERR_MODEL);
    CHECK_INT(eom_system_new(&s, md, small, 0), EOM_ERR_MODEL);
    CHECK(s == NULL);
    eom_model_free(&md);
}

static void recording_errors(void)
{
    static int kinds[] = {BAD_PARAM, BAD_INDEX, BAD_RETURN, BAD_UNSET};
    static const char *const says[] = {"'nosuch'", "coordinate 5",
                                       "returned 7",
                                       ("kinetic energy callback did not "
                                        "set its value")};
    static int phi_kinds[] = {BAD_QD_IN_PHI, BAD_RETURN, BAD_UNSET};
    static const char *const phi_says[] = {"q only", "returned -2",
                                           "did not set value 2 of 2"};
    static int time_in_T = BAD_TIME_IN_T, time_in_phi = BAD_TIME_IN_PHI;
    eom_system *s = NULL;
    tp_rec *ev = NULL;
    double x[3] = {0.5, 0.25, 2.0};
    eom_model *md;
    size_t i;
    for (i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        md = NULL;
        eom_model_new(&md);
        eom_model_add_coord(md, "q", NULL, 0.0, 0.0);
        eom_model_set_kinetic(md, bad_scalar, &kinds[i]);
        expect_fail(md, EOM_ERR_RECORD, says[i]);
    }
    for (i = 0; i < sizeof phi_kinds / sizeof phi_kinds[0]; i++) {
        md = unit_model(3);
        eom_model_set_constraints(md, 2, bad_phi, &phi_kinds[i]);
        expect_fail(md, EOM_ERR_RECORD, phi_says[i]);
    }
    /* the same mistakes in the other callbacks */
    md = unit_model(3);
    eom_model_set_forces(md, bad_forces, NULL);
    expect_fail(md, EOM_ERR_RECORD, "'nosuch'");
    md = unit_model(1);
    eom_model_set_dissipation(md, bad_scalar, &kinds[0]);
    expect_fail(md, EOM_ERR_RECORD, "'nosuch'");
    md = unit_model(1);
    eom_model_add_probe(md, "p", NULL, bad_scalar, &kinds[2]);
    expect_fail(md, EOM_ERR_RECORD, "returned 7");
    md = unit_model(1);
    eom_model_set_potential(md, bad_scalar, &kinds[3]);
    expect_fail(md, EOM_ERR_RECORD,
                "potential energy callback did not set its value");
    /* the time in T and in the constraints is no mistake */
    md = NULL;
    eom_model_new(&md);
    eom_model_add_coord(md, "q", NULL, 0.0, 0.0);
    eom_model_set_kinetic(md, bad_scalar, &time_in_T);
    CHECK_INT(eom_system_new(&s, md, NULL, 0), EOM_OK);
    CHECK_INT(eom_system_reads_time(s), 1);
    eom_system_free(&s);
    /* ... but a Lagrangian run on a context with no time cannot read it
     * (2n independents), and can with the time as the (2n + 1)-th */
    CHECK_INT(tp_evaluator_new(&ev, 2, NULL), TP_OK);
    CHECK_INT(eom_model_run_lagrangian(md, ev, x), EOM_ERR_RECORD);
    tp_rec_free(&ev);
    CHECK_INT(tp_evaluator_new(&ev, 3, NULL), TP_OK);
    CHECK_INT(eom_model_run_lagrangian(md, ev, x), EOM_OK);
    tp_rec_free(&ev);
    eom_model_free(&md);
    md = unit_model(3);
    eom_model_set_constraints(md, 2, bad_phi, &time_in_phi);
    CHECK_INT(eom_system_new(&s, md, NULL, 0), EOM_OK);
    CHECK_INT(eom_system_reads_time(s), 1);
    eom_system_free(&s);
    eom_model_free(&md);
}

static void singular_mass(void)
{
    eom_model *md = unit_model(2);
    eom_system *s;
    eom_integ *it = NULL;
    eom_opts o;
    double x[4] = {0.1, 0.2, 0.3, 0.4}, xd[4], rM = -1.0, rS = -1.0;
    eom_model_set_kinetic(md, first_only_T, NULL);
    s = core_system(md);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_ERR_SINGULAR_MASS);
    HAS(eom_system_errmsg(s), "positive definite");
    CHECK_INT(eom_condition(s, x, &rM, &rS), EOM_ERR_SINGULAR_MASS);
    CHECK(rM == 0.0);
    eom_opts_default(&o);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    if (it) {
        double y[4];
        CHECK_INT(eom_integ_advance(it, 0.1, y, NULL),
                  EOM_ERR_SINGULAR_MASS);
        HAS(eom_integ_errmsg(it), "positive definite");
        HAS(eom_integ_errmsg(it), "t = 0");
        CHECK_SAME("state after a failed first step", y, x, 4);
    }
    eom_integ_free(&it);
    eom_system_free(&s);

    md = unit_model(2);
    eom_model_set_kinetic(md, indefinite_T, NULL);
    s = core_system(md);
    CHECK(s != NULL);
    if (s) {
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_ERR_SINGULAR_MASS);
        HAS(eom_system_errmsg(s), "positive definite");
    }
    eom_system_free(&s);
}

static void rank_deficient(void)
{
    const core_chain fb = fourbar_closed_form();
    eom_model *md = unit_model(3), *md1 = unit_model(3);
    eom_system *s, *s1;
    double x[6] = {0.6, 0.8, 0.0, 0.1, -0.2, 0.3}, xd[6], xd1[6], lam[2];
    double lam1[1];
    int rc, i, it = -1;
    /* a constraint stated twice (exactly redundant): the motion is that of
     * the constraint stated once, and the multipliers share its force
     * equally (the least-norm split) */
    eom_model_set_constraints(md, 2, twice_phi, NULL);
    eom_model_set_constraints(md1, 1, once_phi, NULL);
    s = core_system(md);
    s1 = core_system(md1);
    CHECK(s != NULL && s1 != NULL);
    if (s && s1) {
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_INT(eom_rhs(s1, 0.0, x, xd1), EOM_OK);
        for (i = 0; i < 6; i++)
            CHECK_NEAR(xd[i], xd1[i], 1e-14);
        CHECK_INT(eom_multipliers(s, 0.0, x, lam), EOM_OK);
        CHECK_INT(eom_multipliers(s1, 0.0, x, lam1), EOM_OK);
        CHECK_NEAR(lam[0], 0.5 * lam1[0], 1e-14);
        CHECK_NEAR(lam[1], 0.5 * lam1[0], 1e-14);
        x[0] = 0.7; /* off the sphere: projection needs S too */
        CHECK_INT(eom_project(s, x, 1e-12, &it), EOM_OK);
        CHECK(it > 0);
        CHECK_NEAR(x[0] * x[0] + x[1] * x[1] + x[2] * x[2], 1.0, 1e-12);
        CHECK_NEAR(x[0] * x[3] + x[1] * x[4] + x[2] * x[5], 0.0, 1e-12);
    }
    eom_system_free(&s);
    eom_system_free(&s1);

    /* the four-bar stretched straight (D = sum of the rods): C has rank
     * 1 (its x row vanishes); the accelerations satisfy the y row,
     * sum L_j thdd_j = 0 at rest, and are finite */
    s = fourbar_system();
    CHECK(s != NULL);
    if (s) {
        double y[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        CHECK_INT(core_set(s, "D", FB_L[0] + FB_L[1] + FB_L[2]), EOM_OK);
        rc = eom_rhs(s, 0.0, y, xd);
        CHECK_INT(rc, EOM_OK);
        for (i = 0; i < 6; i++)
            CHECK(isfinite(xd[i]));
        CHECK_NEAR(FB_L[0] * xd[3] + FB_L[1] * xd[4] + FB_L[2] * xd[5], 0.0,
                   1e-12);
        /* a regular state afterwards works as before */
        CHECK_INT(core_set(s, "D", FB_D), EOM_OK);
        fourbar_assemble(&fb, 0.4, 1, 1.0, y);
        CHECK_INT(eom_rhs(s, 0.0, y, xd), EOM_OK);
        CHECK(eom_system_errmsg(s)[0] == '\0');
    }
    eom_system_free(&s);
}

static void nonfinite(void)
{
    const core_chain fb = fourbar_closed_form();
    eom_system *s = fourbar_system();
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    double x[6], y[6], xd[6], M[9], C[6], phi[2], lam[2], rM, rS;
    eom_energy e;
    eom_integ *it = NULL;
    eom_opts o;
    int b, i;
    CHECK(s != NULL);
    if (!s)
        return;
    fourbar_assemble(&fb, 0.4, 1, 1.0, x);
    eom_opts_default(&o);
    for (b = 0; b < 3; b++) {
        for (i = 0; i < 6; i++) {
            memcpy(y, x, sizeof y);
            y[i] = bad[b];
            CHECK_INT(eom_rhs(s, 0.0, y, xd), EOM_ERR_NONFINITE);
            HAS(eom_system_errmsg(s), "not finite");
            CHECK_INT(eom_energy_at(s, 0.0, y, &e), EOM_ERR_NONFINITE);
            CHECK_INT(eom_project(s, y, 1e-12, NULL), EOM_ERR_NONFINITE);
            CHECK_INT(eom_multipliers(s, 0.0, y, lam), EOM_ERR_NONFINITE);
            CHECK_INT(eom_mass_matrix(s, y, M), EOM_ERR_NONFINITE);
            CHECK_INT(eom_residuals(s, y, phi, NULL), EOM_ERR_NONFINITE);
            CHECK_INT(eom_condition(s, y, &rM, &rS), EOM_ERR_NONFINITE);
            if (i < 3)
                CHECK_INT(eom_constraint_jacobian(s, y, C, phi),
                          EOM_ERR_NONFINITE);
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, y), EOM_ERR_NONFINITE);
            CHECK(it == NULL);
            HAS(eom_system_errmsg(s), "not finite");
        }
        CHECK_INT(eom_rhs(s, bad[b], x, xd), EOM_ERR_NONFINITE);
        CHECK_INT(eom_energy_at(s, bad[b], x, &e), EOM_ERR_NONFINITE);
        CHECK_INT(eom_integ_new(&it, s, &o, bad[b], x), EOM_ERR_NONFINITE);
    }
    eom_system_free(&s);

    /* probes see it too */
    {
        eom_model *md = unit_model(1);
        double p, z[2] = {NAN, 0.0};
        eom_model_add_probe(md, "p", NULL, unit_V, NULL);
        s = core_system(md);
        CHECK(s != NULL);
        if (s)
            CHECK_INT(eom_probes_at(s, z, &p), EOM_ERR_NONFINITE);
        eom_system_free(&s);
    }
}

static void domain_error_in_run(void)
{
    eom_model *md = unit_model(1);
    eom_system *s;
    eom_integ *it = NULL;
    eom_opts o;
    double x[2] = {1.0, -10.0}, y[2], W;
    eom_model_set_potential(md, sqrt_V, NULL);
    s = core_system(md);
    CHECK(s != NULL);
    if (!s)
        return;
    eom_opts_default(&o);
    o.dt = 0.01;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    if (it) {
        /* q crosses 0 near t = 0.1: sqrt of a negative number */
        int rc = eom_integ_advance(it, 1.0, y, &W);
        CHECK_INT(rc, EOM_ERR_NONFINITE);
        HAS(eom_integ_errmsg(it), "t = ");
        HAS(eom_integ_errmsg(it), "not finite");
        CHECK(isfinite(y[0]) && isfinite(y[1]) && y[0] >= 0.0);
        CHECK(y[0] < 0.2);
        CHECK(isfinite(W));
        /* sticky */
        CHECK_INT(eom_integ_advance(it, 2.0, y, NULL), rc);
        printf("domain error: %s\n", eom_integ_errmsg(it));
    }
    eom_integ_free(&it);
    eom_system_free(&s);
}

static void integrator_args(void)
{
    eom_system *s = core_system(unit_model(2));
    eom_integ *it = NULL;
    eom_opts o;
    eom_stats st;
    double x[4] = {0.1, 0.2, 0.0, 0.0}, y[4];
    CHECK(s != NULL);
    if (!s)
        return;
    eom_opts_default(&o);
    o.dt = 0.0;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    HAS(eom_system_errmsg(s), "dt");
    o.dt = NAN;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    eom_opts_default(&o);
    o.max_steps = 0;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    eom_opts_default(&o);
    o.method = (eom_method)42;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    CHECK(it == NULL);
    CHECK(strcmp(eom_method_name((eom_method)42), "unknown") == 0);
    CHECK_INT(eom_method_from_name("rk4"), EOM_RK4);
    CHECK_INT(eom_method_from_name("rk5"), -1);
    CHECK_INT(eom_method_from_name(NULL), -1);

    eom_opts_default(&o);
    o.max_steps = 10;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    if (it) {
        CHECK_INT(eom_integ_advance(it, 0.0, y, NULL), EOM_ERR_ARG);
        CHECK_INT(eom_integ_advance(it, -1.0, y, NULL), EOM_ERR_ARG);
        CHECK_INT(eom_integ_advance(it, NAN, y, NULL), EOM_ERR_ARG);
        HAS(eom_integ_errmsg(it), "tout");
        CHECK_INT(eom_integ_advance(it, 0.005, y, NULL), EOM_OK);
        CHECK_INT(eom_integ_advance(it, 1.0, y, NULL), EOM_ERR_SOLVER);
        HAS(eom_integ_errmsg(it), "max_steps");
        CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
        CHECK_INT(st.steps, 5);
    }
    eom_integ_free(&it);
    eom_system_free(&s);
}

static void null_args(void)
{
    const core_chain fb = fourbar_closed_form();
    eom_system *s = fourbar_system();
    eom_model *md = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    eom_energy e;
    eom_stats st;
    double x[6], d[9];
    int it_n;
    CHECK(s != NULL);
    if (!s)
        return;
    fourbar_assemble(&fb, 0.4, 1, 1.0, x);
    eom_opts_default(&o);

    CHECK_INT(eom_model_new(NULL), EOM_ERR_NULL);
    eom_model_free(NULL);
    eom_model_free(&md);
    CHECK(eom_model_errmsg(NULL) != NULL);
    CHECK_INT(eom_model_add_coord(NULL, "q", NULL, 0, 0), EOM_ERR_NULL);
    CHECK_INT(eom_model_add_param(NULL, "p", NULL, 0, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_model_add_probe(NULL, "p", NULL, unit_T, NULL),
              EOM_ERR_NULL);
    CHECK_INT(eom_model_set_kinetic(NULL, unit_T, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_model_set_potential(NULL, unit_V, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_model_set_lagrangian(NULL, unit_T, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_model_set_dissipation(NULL, unit_T, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_model_set_forces(NULL, bad_forces, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_model_set_constraints(NULL, 1, twice_phi, NULL),
              EOM_ERR_NULL);
    CHECK(eom_rec(NULL) == NULL);
    CHECK_INT(eom_ncoords(NULL), 0);
    CHECK(eom_q(NULL, 0).tag == 0 && eom_qd(NULL, 0).tag == 0);
    CHECK(eom_time(NULL).tag == 0 && eom_param(NULL, "m").tag == 0);

    CHECK_INT(eom_system_new(NULL, md, NULL, 0), EOM_ERR_NULL);
    {
        eom_system *t = s;
        CHECK_INT(eom_system_new(&t, NULL, NULL, 0), EOM_ERR_NULL);
        CHECK(t == NULL);
    }
    eom_system_free(NULL);
    CHECK(eom_system_errmsg(NULL) != NULL);
    CHECK_INT(eom_system_ncoords(NULL), 0);
    CHECK_INT(eom_system_nconstraints(NULL), 0);
    CHECK_INT(eom_system_nparams(NULL), 0);
    CHECK_INT(eom_system_nprobes(NULL), 0);
    CHECK_INT(eom_system_has_tv(NULL), 0);
    CHECK_INT(eom_system_has_dissipation(NULL), 0);
    CHECK(eom_coord_name(NULL, 0) == NULL && eom_probe_name(NULL, 0) == NULL);
    CHECK_INT(eom_coord_index(NULL, "th1"), -1);
    CHECK_INT(eom_param_index(NULL, "D"), -1);
    CHECK_INT(eom_initial_state(NULL, x), EOM_ERR_NULL);
    CHECK_INT(eom_initial_state(s, NULL), EOM_ERR_NULL);

    CHECK_INT(eom_rhs(NULL, 0.0, x, d), EOM_ERR_NULL);
    CHECK_INT(eom_rhs(s, 0.0, NULL, d), EOM_ERR_NULL);
    CHECK_INT(eom_rhs(s, 0.0, x, NULL), EOM_ERR_NULL);
    HAS(eom_system_errmsg(s), "NULL");
    CHECK_INT(eom_mass_matrix(NULL, x, d), EOM_ERR_NULL);
    CHECK_INT(eom_mass_matrix(s, NULL, d), EOM_ERR_NULL);
    CHECK_INT(eom_mass_matrix(s, x, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_constraint_jacobian(NULL, x, d, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_constraint_jacobian(s, NULL, d, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_constraint_jacobian(s, x, NULL, d), EOM_ERR_NULL);
    CHECK_INT(eom_multipliers(NULL, 0.0, x, d), EOM_ERR_NULL);
    CHECK_INT(eom_multipliers(s, 0.0, NULL, d), EOM_ERR_NULL);
    CHECK_INT(eom_multipliers(s, 0.0, x, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_residuals(NULL, x, d, d), EOM_ERR_NULL);
    CHECK_INT(eom_residuals(s, NULL, d, d), EOM_ERR_NULL);
    CHECK_INT(eom_residuals(s, x, NULL, NULL), EOM_OK); /* both optional */
    CHECK_INT(eom_condition(NULL, x, d, d), EOM_ERR_NULL);
    CHECK_INT(eom_condition(s, NULL, d, d), EOM_ERR_NULL);
    CHECK_INT(eom_energy_at(NULL, 0.0, x, &e), EOM_ERR_NULL);
    CHECK_INT(eom_energy_at(s, 0.0, NULL, &e), EOM_ERR_NULL);
    CHECK_INT(eom_energy_at(s, 0.0, x, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_probes_at(NULL, x, d), EOM_ERR_NULL);
    CHECK_INT(eom_project(NULL, x, 1e-12, &it_n), EOM_ERR_NULL);
    CHECK_INT(eom_project(s, NULL, 1e-12, &it_n), EOM_ERR_NULL);
    CHECK_INT(eom_set_param(NULL, 0, 1.0), EOM_ERR_NULL);

    eom_opts_default(NULL);
    CHECK_INT(eom_integ_new(NULL, s, &o, 0.0, x), EOM_ERR_NULL);
    CHECK_INT(eom_integ_new(&it, NULL, &o, 0.0, x), EOM_ERR_NULL);
    CHECK_INT(eom_integ_new(&it, s, NULL, 0.0, x), EOM_ERR_NULL);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, NULL), EOM_ERR_NULL);
    CHECK(it == NULL);
    eom_integ_free(NULL);
    eom_integ_free(&it);
    CHECK(eom_integ_errmsg(NULL) != NULL);
    CHECK_INT(eom_integ_advance(NULL, 1.0, x, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_integ_stats(NULL, &st), EOM_ERR_NULL);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    if (it) {
        CHECK_INT(eom_integ_advance(it, 1.0, NULL, NULL), EOM_ERR_NULL);
        CHECK_INT(eom_integ_stats(it, NULL), EOM_ERR_NULL);
        /* still usable */
        CHECK_INT(eom_integ_advance(it, 0.01, x, NULL), EOM_OK);
    }
    eom_integ_free(&it);
    CHECK(it == NULL);
    eom_system_free(&s);
    CHECK(s == NULL);
}

/* eom_system_errmsg: "" after a success, whichever call it was. */
static void message_cleared(void)
{
    const core_chain fb = fourbar_closed_form();
    eom_system *s = fourbar_system();
    double x[6], bad[6], d[9], lam[2], phi[2], rM, rS;
    eom_energy e;
    int k;
    CHECK(s != NULL);
    if (!s)
        return;
    fourbar_assemble(&fb, 0.4, 1, 1.0, x);
    memcpy(bad, x, sizeof bad);
    bad[0] = NAN;
    for (k = 0; k < 11; k++) {
        int rc = -100;
        CHECK_INT(eom_rhs(s, 0.0, bad, d), EOM_ERR_NONFINITE);
        CHECK(eom_system_errmsg(s)[0] != '\0');
        switch (k) {
        case 0: rc = eom_rhs(s, 0.0, x, d); break;
        case 1: rc = eom_mass_matrix(s, x, d); break;
        case 2: rc = eom_constraint_jacobian(s, x, d, phi); break;
        case 3: rc = eom_multipliers(s, 0.0, x, lam); break;
        case 4: rc = eom_residuals(s, x, phi, NULL); break;
        case 5: rc = eom_condition(s, x, &rM, &rS); break;
        case 6: rc = eom_energy_at(s, 0.0, x, &e); break;
        case 7: rc = eom_probes_at(s, x, d); break;
        case 8: rc = eom_project(s, x, 1e-12, NULL); break;
        case 9: rc = eom_set_param(s, 0, 1.0); break;
        case 10: rc = eom_set_baumgarte(s, 0.0, 0.0); break;
        default: break;
        }
        CHECK_INT(rc, EOM_OK);
        check_count_++;
        if (eom_system_errmsg(s)[0] != '\0')
            CHECK_FAIL_("call %d succeeded but left the message \"%s\"", k,
                        eom_system_errmsg(s));
    }
    eom_system_free(&s);
}

int main(void)
{
    statuses();
    names();
    model_errors();
    recording_errors();
    singular_mass();
    rank_deficient();
    nonfinite();
    domain_error_in_run();
    integrator_args();
    null_args();
    message_cleared();
    CHECK_DONE();
}
