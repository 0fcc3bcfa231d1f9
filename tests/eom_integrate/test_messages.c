/* test_messages.c - a solver failure always says why: when SUNDIALS
 * stops without a message of its own and no callback failed, the message
 * names what the run's figures suggest (libeom/src/integrate_sundials.c),
 * never an empty reason; with constraints the solver's own reason comes
 * with the smallest condition estimate of their solve, and below 1e-3
 * with the likely cause. Driven through the internal call every SUNDIALS
 * backend reports its failures with. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom_models.h"
#include "integrate_internal.h"

static char *dup(const char *s)
{
    char *p = malloc(strlen(s) + 1);
    if (p)
        strcpy(p, s);
    return p;
}

static void case_model(eom_model *md, double rcond_min, const char *sun,
                       const char *want)
{
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    eom_sun_report r;
    double x[8];
    char msg[256];
    int rc;
    CHECK_INT(eom_system_new(&s, md, msg, sizeof msg), EOM_OK);
    eom_model_free(&md);
    if (!s)
        return;
    eom_opts_default(&o);
    o.method = EOM_ERK;
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    if (!it) {
        eom_system_free(&s);
        return;
    }
    s->rcond_S_min = rcond_min;
    eom__sun_report_reset(&r);
    snprintf(r.sun_msg, sizeof r.sun_msg, "%s", sun);
    rc = eom__sun_failed(it, &r, "erk", dup("ARK_ERR_FAILURE"), 0.25);
    CHECK_INT(rc, EOM_ERR_SOLVER);
    printf("%s\n", eom_integ_errmsg(it));
    CHECK(strstr(eom_integ_errmsg(it), "ARK_ERR_FAILURE at t = 0.25: ") !=
          NULL);
    CHECK(strstr(eom_integ_errmsg(it), want) != NULL);
    eom_integ_free(&it);
    eom_system_free(&s);
}

int main(void)
{
    const double m[3] = {1, 1, 1}, l[3] = {1, 1, 1}, th[3] = {0.3, 1.2, 2.9};
    case_model(eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81), 1.0, "",
               "a discontinuity, a singularity or a domain edge");
    /* a four-bar near a singular position: the condition is the clue */
    case_model(eom_models_rod_chain(3, m, l, th, 9.81, 1, 1.5), 2e-9, "",
               "smallest rcond so far is 2e-09");
    case_model(eom_models_rod_chain(3, m, l, th, 9.81, 1, 1.5), 0.5, "",
               "a discontinuity, a singularity or a domain edge");
    /* the solver's own reason, with the constraint system's health */
    case_model(eom_models_rod_chain(3, m, l, th, 9.81, 1, 1.5), 3e-12,
               "ERKStep: error test failed", "ERKStep: error test failed "
               "(constraint system's smallest rcond so far 3e-12: a "
               "singular position");
    case_model(eom_models_rod_chain(3, m, l, th, 9.81, 1, 1.5), 0.25,
               "ERKStep: error test failed", "ERKStep: error test failed "
               "(constraint system's smallest rcond so far 0.25)");
    case_model(eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81), 1.0,
               "ERKStep: error test failed", "at t = 0.25: ERKStep: error "
               "test failed");
    CHECK_DONE();
}
