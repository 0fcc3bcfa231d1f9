/* bench_chain.c - the chains of the bench programs (see bench_chain.h). */
#include "bench_chain.h"

#include <stdio.h>
#include <string.h>

#include "eom/chain.h"

static const double pi = 3.14159265358979323846;

const double bench_paper5[5] = {5 * pi / 12, pi / 12, 0, 17 * pi / 12,
                                13 * pi / 12};

eom_system *bench_chain_new(const chain_cfg *cfg, char *msg, size_t len)
{
    unsigned char damped[64] = {0};
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL;
    int j;
    memset(&sp, 0, sizeof sp);
    for (j = 1; j <= cfg->links && j < 64; j++)
        damped[j] = 1; /* every joint but the base */
    sp.links = cfg->links;
    sp.modes_all = cfg->modes;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = cfg->EI;
    sp.g = cfg->g;
    sp.c = cfg->c;
    sp.damped = cfg->c != 0.0 && cfg->links < 64 ? damped : NULL;
    sp.closed = cfg->closed;
    sp.D = cfg->D;
    sp.theta0 = cfg->theta0;
    /* the paper's model has no structural damping: its parameters are
     * added only when asked for */
    sp.structural = cfg->zeta != 0.0;
    sp.zeta = cfg->zeta;
    if (eom_model_new(&m) != EOM_OK || eom_chain_add(m, &sp) < 0 ||
        eom_system_new(&s, m, msg, len) != EOM_OK) {
        if (m && eom_model_errmsg(m)[0])
            snprintf(msg, len, "%s", eom_model_errmsg(m));
        s = NULL;
    }
    eom_model_free(&m);
    return s;
}
