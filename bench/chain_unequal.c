/* chain_unequal.c - the unequal chains of the right-hand-side benchmarks
 * (chain_unequal.h). */
#include "chain_unequal.h"

#include <math.h>
#include <string.h>

#include "eom/chain.h"

static const double pi = 3.14159265358979323846;

void chain_unequal(chain_plain *c, int links, int modes, double *m,
                   double *L, double *EI)
{
    int j;
    for (j = 0; j < links; j++) {
        m[j] = 1.0 + 0.1 * (j % 7);
        L[j] = 10.0 - 0.3 * (j % 5);
        EI[j] = 4e4;
    }
    c->links = links;
    c->modes = modes;
    c->m = m;
    c->L = L;
    c->EI = EI;
    c->g = 9.81;
}

/* c as a model, open or closed (D 0.9 of the total length). */
static int model_of(const chain_plain *c, int closed, eom_model **out)
{
    eom_chain_spec sp;
    int rc, j;
    memset(&sp, 0, sizeof sp);
    sp.links = c->links;
    sp.modes_all = c->modes;
    sp.m_link = c->m;
    sp.L_link = c->L;
    sp.EI_link = c->EI;
    sp.g = c->g;
    sp.closed = closed;
    for (j = 0; closed && j < c->links; j++)
        sp.D += 0.9 * c->L[j];
    if ((rc = eom_model_new(out)) != EOM_OK)
        return rc;
    if ((rc = eom_chain_add(*out, &sp)) < 0) {
        eom_model_free(out);
        return rc;
    }
    return EOM_OK;
}

int chain_unequal_model(const chain_plain *c, eom_model **out)
{
    return model_of(c, 0, out);
}

int chain_unequal_closed_model(const chain_plain *c, eom_model **out)
{
    return model_of(c, 1, out);
}

void chain_unequal_state(const chain_plain *c, int n, double *x)
{
    int j;
    for (j = 0; j < c->links; j++) {
        x[j] = -pi / 2 + (j % 2 ? -0.4 : 0.3) + 0.01 * j;
        x[n + j] = 0.2 * sin(1.0 + j);
    }
    for (j = c->links; j < n; j++) {
        x[j] = 1e-3 * cos(j);
        x[n + j] = 1e-2 * sin(2.0 * j);
    }
}
