/* test_chain_joints.c - the chain element's joint springs and dampers
 * against values derived by hand, not from the element's code.
 *
 * Rigid uniform rods (modes 0), gravity off, so only the joints act.
 * Rod j of mass m_j and length L_j; link 1 turns about the ground pin
 * with inertia I = m L^2 / 3.
 *   - A spring k at joint j holds the relative angle: V = k/2 (th_j+1 -
 *     th_j)^2 (joint 0: th_1 against the ground). One sprung rod
 *     oscillates at omega = sqrt(k / I).
 *   - A damper c at joint j: R = c/2 (relative rate)^2, so the power of
 *     the joint forces is P = -c (relative rate)^2, and on one rod
 *     qdd = -c thd / I.
 *   - A closed chain's joint N pins link N to the ground: its relative
 *     rate is th_N's own.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"
#include "eom/eom.h"

/* A chain of n rigid rods (m = 2 kg, L = 1.5 m, g = 0) with a spring k
 * and a damper c at the joints flagged in sprung and damped (n + 1). */
static eom_system *chain(int n, int closed, const unsigned char *sprung,
                         const unsigned char *damped, double k, double c)
{
    eom_chain_spec sp;
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    memset(&sp, 0, sizeof sp);
    sp.links = n;
    sp.modes_all = 0;
    sp.closed = closed;
    sp.m = 2.0;
    sp.L = 1.5;
    sp.EI = 1.0;
    sp.g = 0.0;
    sp.k = k;
    sp.c = c;
    sp.D = closed ? 2.0 : 0.0;
    sp.sprung = sprung;
    sp.damped = damped;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    if (eom_chain_add(md, &sp) < 0)
        fprintf(stderr, "eom_chain_add: %s\n", eom_model_errmsg(md));
    else if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        fprintf(stderr, "eom_system_new: %s\n", msg);
    eom_model_free(&md);
    return s;
}

static void test_springs(void)
{
    const double m = 2.0, L = 1.5, k = 7.0, I = m * L * L / 3.0;
    const unsigned char base[2] = {1, 0}, mid[3] = {0, 1, 0};
    double x1[2] = {0.3, 0.0}, x2[4] = {0.2, -0.5, 0.0, 0.0}, q0[1] = {0.0};
    eom_system *s = chain(1, 0, base, NULL, k, 0.0);
    eom_energy e;
    eom_linear lin;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_energy_at(s, 0.0, x1, &e), EOM_OK);
    CHECK_NEAR(e.V, 0.5 * k * 0.3 * 0.3, 1e-15);
    memset(&lin, 0, sizeof lin);
    CHECK_INT(eom_linearize(s, q0, &lin), EOM_OK);
    CHECK_INT(lin.nr, 1);
    if (lin.nr == 1)
        CHECK_NEAR(lin.omega[0], sqrt(k / I), 1e-12);
    eom_linear_free(&lin);
    eom_system_free(&s);

    /* between links 1 and 2: the relative angle, not either absolute one */
    s = chain(2, 0, mid, NULL, k, 0.0);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_energy_at(s, 0.0, x2, &e), EOM_OK);
    CHECK_NEAR(e.V, 0.5 * k * 0.7 * 0.7, 1e-15);
    eom_system_free(&s);
}

static void test_dampers(void)
{
    const double m = 2.0, L = 1.5, c = 0.9, I = m * L * L / 3.0;
    const unsigned char base[2] = {1, 0}, mid[3] = {0, 1, 0};
    const unsigned char pin[4] = {0, 0, 0, 1};
    double x1[2] = {0.3, 1.7}, xd1[2];
    double x2[4] = {0.2, -0.5, 0.4, -1.1};
    eom_system *s = chain(1, 0, NULL, base, 0.0, c);
    eom_energy e;
    CHECK(s != NULL);
    if (!s)
        return;
    /* the base pin's damper: qdd = -c thd / I, P = -c thd^2 */
    CHECK_INT(eom_rhs(s, 0.0, x1, xd1), EOM_OK);
    CHECK_NEAR(xd1[1], -c * 1.7 / I, 1e-14);
    CHECK_INT(eom_energy_at(s, 0.0, x1, &e), EOM_OK);
    CHECK_NEAR(e.P, -c * 1.7 * 1.7, 1e-14);
    eom_system_free(&s);

    /* between links: the relative rate 0.4 - (-1.1) */
    s = chain(2, 0, NULL, mid, 0.0, c);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_energy_at(s, 0.0, x2, &e), EOM_OK);
    CHECK_NEAR(e.P, -c * 1.5 * 1.5, 1e-14);
    eom_system_free(&s);

    /* a closed chain's ground pin at the tip: the rate of link N */
    s = chain(3, 1, NULL, pin, 0.0, c);
    CHECK(s != NULL);
    if (!s)
        return;
    {
        const double x3[6] = {0.5, -0.2, -0.6, 0.3, 0.8, -0.4};
        CHECK_INT(eom_energy_at(s, 0.0, x3, &e), EOM_OK);
        CHECK_NEAR(e.P, -c * 0.4 * 0.4, 1e-14);
    }
    eom_system_free(&s);
}

int main(void)
{
    test_springs();
    test_dampers();
    CHECK_DONE();
}
