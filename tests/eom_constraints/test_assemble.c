/* test_assemble.c - eom_assemble's refusals and its rates, on a model
 * whose closure is known by construction: coordinates x, y, z, rows
 *     a = x - y,   b = x + y + z - 3,
 * so with x held the closure is y = x, z = 3 - 2x, and the rates yd =
 * xd, zd = -2 xd (the CLI test, model_assemble, checks a four-bar against
 * its geometry). Refused: a NULL state, every coordinate held, a bad
 * tolerance, a NaN; held rates that contradict a row (x and y held with
 * different rates) are an error naming the row, and leave the state as
 * given. */
#include <string.h>

#include "check.h"
#include "eom/eom.h"

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

static int rows(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[0] = tp_sub(R, eom_q(c, 0), eom_q(c, 1));
    out[1] = tp_subc(R, tp_add(R, tp_add(R, eom_q(c, 0), eom_q(c, 1)),
                               eom_q(c, 2)),
                     3.0);
    return 0;
}

int main(void)
{
    const char *names[] = {"a", "b"};
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[256];
    int held[3] = {1, 0, 0}, all[3] = {1, 1, 1}, xy[3] = {1, 1, 0}, it = -1;
    double x[6] = {0.7, 0.0, 0.0, 0.5, 0.0, 0.0}, keep[6];
    CHECK_INT(eom_model_new(&m), EOM_OK);
    eom_model_add_coord(m, "x", "m", 0.0, 0.0);
    eom_model_add_coord(m, "y", "m", 0.0, 0.0);
    eom_model_add_coord(m, "z", "m", 0.0, 0.0);
    eom_model_set_kinetic(m, T3, NULL);
    eom_model_add_constraints(m, 2, rows, NULL);
    eom_model_name_constraints(m, 2, names);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        return 1;
    CHECK_INT(eom_assemble(s, x, held, 1e-12, &it), EOM_OK);
    CHECK(x[0] == 0.7 && x[3] == 0.5);
    CHECK_NEAR(x[1], 0.7, 1e-12);
    CHECK_NEAR(x[2], 3.0 - 1.4, 1e-12);
    CHECK_NEAR(x[4], 0.5, 1e-12);
    CHECK_NEAR(x[5], -1.0, 1e-12);
    CHECK(it >= 1);

    CHECK_INT(eom_assemble(s, NULL, held, 1e-12, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_assemble(s, x, NULL, 1e-12, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_assemble(s, x, all, 1e-12, NULL), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "every coordinate is held") != NULL);
    CHECK_INT(eom_assemble(s, x, held, 0.0, NULL), EOM_ERR_ARG);
    x[2] = NAN;
    CHECK_INT(eom_assemble(s, x, held, 1e-12, NULL), EOM_ERR_NONFINITE);

    /* x and y held apart: row a cannot close; then on the closure, with
     * rates that contradict row a */
    x[0] = 0.7;
    x[1] = 0.2;
    x[2] = 0.0;
    memcpy(keep, x, sizeof keep);
    CHECK_INT(eom_assemble(s, x, xy, 1e-12, NULL), EOM_ERR_PROJECTION);
    CHECK(strstr(eom_system_errmsg(s), "the constraint 'a' stays open") !=
          NULL);
    CHECK(memcmp(x, keep, sizeof keep) == 0);
    x[1] = 0.7;
    x[4] = 0.1;
    memcpy(keep, x, sizeof keep);
    CHECK_INT(eom_assemble(s, x, xy, 1e-12, NULL), EOM_ERR_PROJECTION);
    CHECK(strstr(eom_system_errmsg(s), "the velocity form of 'a'") != NULL);
    CHECK(memcmp(x, keep, sizeof keep) == 0);
    eom_system_free(&s);
    CHECK_DONE();
}
