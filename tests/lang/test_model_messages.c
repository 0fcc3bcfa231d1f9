/* test_model_messages.c - a failure is blamed on what failed: a probe's
 * domain error (sqrt of a negative) names the probe and leaves T, V and E
 * of the row, which are finite, in place; a domain error in V names V;
 * eom_integ_new with a NULL argument says so instead of repeating the
 * previous call's message.
 *
 * usage: test_model_messages */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"
#include "eom/run.h"

static eom_system *system_of(const char *text)
{
    char err[2048];
    eom_model *m = NULL;
    eom_system *s = NULL;
    if (eom_model_from_string(&m, text, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, m, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s", err);
    eom_model_free(&m);
    return s;
}

#define CHECK_MSG(s, word)                                                 \
    do {                                                                   \
        const char *m_ = eom_system_errmsg(s);                             \
        check_count_++;                                                    \
        if (!m_ || !strstr(m_, (word)))                                    \
            CHECK_FAIL_("'%s' not in the message '%s'", (word),           \
                        m_ ? m_ : "(null)");                               \
    } while (0)

/* x = 1: T = 1/2 m v^2 = 0.5 at v = 1, V = 1/2 k x^2 = 1.5 at k = 3; the
 * probe root = sqrt(x - 2) is NaN there, the probe twice = 2x is 2. */
static void probe_domain(void)
{
    eom_system *s = system_of("units off\nparam m = 1\nparam k = 3\n"
                              "coord x = 1 rate 1\nT = 1/2*m*x_dot^2\n"
                              "V = 1/2*k*x^2\nprobe twice = 2*x\n"
                              "probe root = sqrt(x - 2)\n");
    const double x[2] = {1.0, 1.0};
    double p[2] = {0.0, 0.0}, row[16];
    eom_energy e;
    eom_run_columns *c = NULL;
    eom_run_row_info info;
    char err[512];
    int k, ncol;
    if (!s)
        return;
    CHECK_INT(eom_energy_at(s, 0.0, x, &e), EOM_OK);
    CHECK(e.T == 0.5 && e.V == 1.5 && e.E == 2.0);
    CHECK_INT(eom_probes_at(s, x, p), EOM_ERR_NONFINITE);
    CHECK_MSG(s, "the probe 'root' is not finite");
    CHECK(strstr(eom_system_errmsg(s), "kinetic") == NULL);
    CHECK(p[0] == 2.0 && isnan(p[1]));

    /* the CSV's row: t, x, x_dot, T, V, E, W, twice, root */
    CHECK_INT(eom_run_columns_new(&c, s, 0, err, sizeof err), 0);
    if (!c) {
        eom_system_free(&s);
        return;
    }
    ncol = c->count;
    CHECK_INT(ncol, 9);
    for (k = 0; k < ncol && k < 16; k++)
        row[k] = -1.0;
    CHECK(eom_run_columns_fill(c, s, 0.0, x, 0.0, row, &info) < 0);
    CHECK(strstr(c->msg, "the probe 'root'") != NULL);
    CHECK(row[3] == 0.5 && row[4] == 1.5 && row[5] == 2.0);
    CHECK(info.e.T == 0.5 && info.e.V == 1.5 && info.e.E == 2.0);
    eom_run_columns_free(&c);

    /* eom_integ_new with NULL options: its own message */
    {
        eom_integ *it = NULL;
        eom_opts o;
        CHECK_INT(eom_integ_new(&it, s, NULL, 0.0, x), EOM_ERR_NULL);
        CHECK_MSG(s, "eom_integ_new: the options argument is NULL");
        eom_opts_default(&o);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, NULL), EOM_ERR_NULL);
        CHECK_MSG(s, "eom_integ_new: the initial state is NULL");
        CHECK(it == NULL);
    }
    eom_system_free(&s);
}

/* A domain error in V itself: named as V's. */
static void energy_domain(void)
{
    eom_system *s = system_of("units off\nparam m = 1\ncoord x = 1\n"
                              "T = 1/2*m*x_dot^2\nV = sqrt(x - 2)\n"
                              "probe twice = 2*x\n");
    const double x[2] = {1.0, 0.0};
    double p[1] = {0.0};
    eom_energy e;
    if (!s)
        return;
    CHECK(eom_energy_at(s, 0.0, x, &e) < 0);
    CHECK_MSG(s, "the potential energy V is not finite");
    /* the probes are not at fault */
    CHECK_INT(eom_probes_at(s, x, p), EOM_OK);
    CHECK(p[0] == 2.0);
    eom_system_free(&s);
}

int main(void)
{
    probe_domain();
    energy_domain();
    CHECK_DONE();
}
