/* test_constraint_names.c - constraint rows by name and redundant rows
 * named.
 *
 * Names: three coordinates x, y, z; blocks added in the order holonomic
 * (a, unnamed), velocity (v), holonomic (c). Rows are stacked holonomic
 * first, so the rows are a, row 2, c, v: names and lookups in that order,
 * a clone reads the same names, and the refusals (a count that is not
 * the block's, a name that is not an identifier, naming before any
 * block, one name on two rows, in two blocks) say which.
 *
 * Redundancy, against rows whose dependence is known by construction:
 *     a = x - 1,  b = y - 2,  c = x + 3 y - 7 = a + 3 b,  d = z
 * (linear, so C is constant): rank 3 of 4, c the dependent row, its
 * combination 1 a + 3 b in the sentence; a pendulum's rod and 2 rod
 * (rank 1 of 2, "'rod2' = 2 'rod'"); full rank gives no dependent row
 * and an empty sentence; unnamed rows are "row K".
 *
 * adams and ida refuse to start on the rod given twice, and name the
 * rows ("rank 1 of 2 rows there: 'rod2' = 1 'rod'").
 *
 * eom_multiplier: refused outside a probe and out of range; in a probe,
 * the multiplier of a row holding z against V = 3 z at rest is 3. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"

static int T3(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_add(R, tp_add(R, tp_sqr(R, eom_qd(c, 0)),
                                       tp_sqr(R, eom_qd(c, 1))),
                             tp_sqr(R, eom_qd(c, 2))),
                   0.5);
    return 0;
}

/* a = x - 1, row 2 = y - 2 */
static int block1(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[0] = tp_subc(R, eom_q(c, 0), 1.0);
    out[1] = tp_subc(R, eom_q(c, 1), 2.0);
    return 0;
}

/* c = x + 3 y - 7 (= a + 3 b) */
static int block_c(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[0] = tp_subc(R, tp_add(R, eom_q(c, 0), tp_mulc(R, eom_q(c, 1), 3.0)),
                     7.0);
    return 0;
}

/* d = z */
static int block_d(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    out[0] = eom_q(c, 2);
    return 0;
}

/* v = zd (a velocity row) */
static int block_v(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    out[0] = eom_qd(c, 2);
    return 0;
}

static eom_model *three(void)
{
    eom_model *m = NULL;
    CHECK_INT(eom_model_new(&m), EOM_OK);
    eom_model_add_coord(m, "x", "m", 1.0, 0.0);
    eom_model_add_coord(m, "y", "m", 2.0, 0.0);
    eom_model_add_coord(m, "z", "m", 0.0, 0.0);
    eom_model_set_kinetic(m, T3, NULL);
    return m;
}

static void names(void)
{
    const char *n1[] = {"a", NULL}, *nv[] = {"v"}, *nc[] = {"c"};
    eom_model *m = three();
    eom_system *s = NULL, *cl = NULL;
    char err[256];
    CHECK_INT(eom_model_add_constraints(m, 2, block1, NULL), EOM_OK);
    CHECK_INT(eom_model_name_constraints(m, 2, n1), EOM_OK);
    CHECK_INT(eom_model_add_velocity_constraints(m, 1, block_v, NULL),
              EOM_OK);
    CHECK_INT(eom_model_name_constraints(m, 1, nv), EOM_OK);
    CHECK_INT(eom_model_add_constraints(m, 1, block_c, NULL), EOM_OK);
    CHECK_INT(eom_model_name_constraints(m, 1, nc), EOM_OK);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    CHECK_INT(eom_system_nconstraints(s), 4);
    CHECK(strcmp(eom_constraint_name(s, 0), "a") == 0);
    CHECK(strcmp(eom_constraint_name(s, 1), "") == 0);
    CHECK(strcmp(eom_constraint_name(s, 2), "c") == 0);
    CHECK(strcmp(eom_constraint_name(s, 3), "v") == 0);
    CHECK(eom_constraint_name(s, 4) == NULL);
    CHECK(eom_constraint_name(s, -1) == NULL);
    CHECK_INT(eom_constraint_index(s, "a"), 0);
    CHECK_INT(eom_constraint_index(s, "c"), 2);
    CHECK_INT(eom_constraint_index(s, "v"), 3);
    CHECK_INT(eom_constraint_index(s, "b"), -1);
    CHECK_INT(eom_constraint_index(s, ""), -1);
    CHECK_INT(eom_constraint_index(s, NULL), -1);
    CHECK_INT(eom_system_clone(&cl, s, err, sizeof err), EOM_OK);
    eom_system_free(&s);
    if (cl) {
        CHECK(strcmp(eom_constraint_name(cl, 3), "v") == 0);
        CHECK_INT(eom_constraint_index(cl, "c"), 2);
    }
    eom_system_free(&cl);
}

static void refusals(void)
{
    const char *two[] = {"a", "b"}, *bad[] = {"1a"}, *a[] = {"a"};
    eom_model *m = three();
    eom_system *s = NULL;
    char err[256];
    /* before any block */
    CHECK_INT(eom_model_name_constraints(m, 1, a), EOM_ERR_ARG);
    CHECK(strstr(eom_model_errmsg(m), "no constraint block") != NULL);
    eom_model_free(&m);
    /* a count that is not the block's */
    m = three();
    eom_model_add_constraints(m, 1, block_c, NULL);
    CHECK_INT(eom_model_name_constraints(m, 2, two), EOM_ERR_ARG);
    CHECK(strstr(eom_model_errmsg(m), "2 names for a block of 1") != NULL);
    eom_model_free(&m);
    /* not an identifier */
    m = three();
    eom_model_add_constraints(m, 1, block_c, NULL);
    CHECK_INT(eom_model_name_constraints(m, 1, bad), EOM_ERR_ARG);
    CHECK(strstr(eom_model_errmsg(m), "'1a'") != NULL);
    CHECK_INT(eom_model_name_constraints(m, 1, NULL), EOM_ERR_ARG);
    eom_model_free(&m);
    /* one name on two rows of two blocks: refused when the system is
     * built, both rows named */
    m = three();
    eom_model_add_constraints(m, 1, block_c, NULL);
    eom_model_name_constraints(m, 1, a);
    eom_model_add_constraints(m, 1, block_d, NULL);
    eom_model_name_constraints(m, 1, a);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_ERR_MODEL);
    CHECK(s == NULL);
    CHECK(strstr(err, "'a' is given to rows 1 and 2") != NULL);
    eom_model_free(&m);
}

/* rank of the rows named by nm (NULL: unnamed) of a, b, c, d */
static void redundant(void)
{
    const char *n1[] = {"a", "b"}, *nc[] = {"c"}, *nd[] = {"d"};
    const double x[6] = {1.0, 2.0, 0.0, 0.0, 0.0, 0.0};
    eom_model *m = three();
    eom_system *s = NULL;
    char err[256], text[512];
    int dep[4], rank = -1;
    eom_model_add_constraints(m, 2, block1, NULL);
    eom_model_name_constraints(m, 2, n1);
    eom_model_add_constraints(m, 1, block_c, NULL);
    eom_model_name_constraints(m, 1, nc);
    eom_model_add_constraints(m, 1, block_d, NULL);
    eom_model_name_constraints(m, 1, nd);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    CHECK_INT(eom_constraint_rank(s, x, 0.0, &rank, dep, text, sizeof text),
              EOM_OK);
    CHECK_INT(rank, 3);
    CHECK_INT(dep[0], -1);
    CHECK_INT(dep[1], -1);
    CHECK_INT(dep[3], -1);
    CHECK_INT(dep[2], 1); /* the larger coefficient: 3 on b */
    CHECK(strstr(text, "'c' = 1 'a' + 3 'b'") != NULL);
    if (!strstr(text, "'c' = 1 'a' + 3 'b'"))
        fprintf(stderr, "text: %s\n", text);
    eom_system_free(&s);

    /* full rank: a, b, d */
    m = three();
    eom_model_add_constraints(m, 2, block1, NULL);
    eom_model_add_constraints(m, 1, block_d, NULL);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    CHECK_INT(eom_constraint_rank(s, x, 0.0, &rank, dep, text, sizeof text),
              EOM_OK);
    CHECK_INT(rank, 3);
    CHECK(dep[0] == -1 && dep[1] == -1 && dep[2] == -1);
    CHECK(text[0] == '\0');
    CHECK_INT(eom_constraint_rank(s, NULL, 0.0, &rank, dep, text,
                                  sizeof text), EOM_ERR_NULL);
    eom_system_free(&s);

    /* unnamed rows by number: c twice (rows 1 and 2) */
    m = three();
    eom_model_add_constraints(m, 1, block_c, NULL);
    eom_model_add_constraints(m, 1, block_c, NULL);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    CHECK_INT(eom_constraint_rank(s, x, 0.0, &rank, NULL, text, sizeof text),
              EOM_OK);
    CHECK_INT(rank, 1);
    CHECK(strstr(text, "row 2 = 1 row 1") != NULL);
    eom_system_free(&s);
}

/* eom_multiplier outside a probe, and out of range in one */
static int T_lambda(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_add(eom_rec(c), eom_multiplier(c, 0),
                  tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_qd(c, 0)), 0.5));
    return 0;
}

/* V = 3 z: at rest on d = z, C^T lambda = dV/dq gives lambda = 3 */
static int V3(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), eom_q(c, 2), 3.0);
    return 0;
}

static int probe_row(eom_ctx *c, void *user, tp_val *out)
{
    *out = eom_multiplier(c, *(const int *)user);
    return 0;
}

static void multiplier_refusals(void)
{
    static int row0 = 0, row4 = 4;
    const double x[6] = {1.0, 2.0, 0.0, 0.0, 0.0, 0.0};
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[256];
    double p[1] = {NAN};
    CHECK_INT(eom_model_new(&m), EOM_OK);
    eom_model_add_coord(m, "x", "m", 1.0, 0.0);
    eom_model_set_kinetic(m, T_lambda, NULL);
    eom_model_add_constraints(m, 1, block_d, NULL);
    CHECK(eom_system_new(&s, m, err, sizeof err) != EOM_OK);
    CHECK(strstr(err, "a multiplier may be read by a probe only") != NULL);
    eom_model_free(&m);
    m = three();
    eom_model_add_constraints(m, 1, block_d, NULL);
    eom_model_add_probe(m, "p", "N", probe_row, (void *)&row4);
    CHECK(eom_system_new(&s, m, err, sizeof err) != EOM_OK);
    CHECK(strstr(err, "constraint row 4 outside 0 .. 0") != NULL);
    eom_model_free(&m);
    /* in range: the probe is the multiplier, here 3 (the pull of V on
     * z held by d) */
    m = three();
    eom_model_set_potential(m, V3, NULL);
    eom_model_add_constraints(m, 1, block_d, NULL);
    eom_model_add_probe(m, "p", "N", probe_row, (void *)&row0);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (s) {
        CHECK_INT(eom_probes_at(s, x, p), EOM_OK);
        CHECK_NEAR(p[0], 3.0, 1e-14);
    }
    eom_system_free(&s);
}

/* adams and ida cannot start on a singular constraint system: their
 * refusal names the rows, here a pendulum's rod given twice */
static void refused_by_name(void)
{
    static const char text[] =
        "param m = 1 [kg]\n"
        "coord x = 1 [m]\n"
        "coord y = 0 [m]\n"
        "T = m*(x_dot^2 + y_dot^2)/2\n"
        "param g = 9.81 [m/s^2]\n"
        "V = m*g*y\n"
        "param l = 1 [m]\n"
        "constraint rod = x^2 + y^2 - l^2\n"
        "constraint rod2 = x^2 + y^2 - l^2\n";
    static const eom_method methods[] = {EOM_ADAMS, EOM_IDA};
    char err[1024];
    eom_model *m = NULL;
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    double x[4];
    int k;
    CHECK_INT(eom_model_from_string(&m, text, err, sizeof err), EOM_OK);
    if (m)
        CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    for (k = 0; k < 2; k++) {
        eom_opts_default(&o);
        o.method = methods[k];
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x),
                  EOM_ERR_RANK_DEFICIENT);
        printf("%s: %s\n", eom_method_name(methods[k]),
               eom_system_errmsg(s));
        CHECK(strstr(eom_system_errmsg(s),
                     "rank 1 of 2 rows there: 'rod2' = 1 'rod'") != NULL);
        eom_integ_free(&it);
    }
    eom_system_free(&s);
}

int main(void)
{
    refused_by_name();
    multiplier_refusals();
    names();
    refusals();
    redundant();
    CHECK_DONE();
}
