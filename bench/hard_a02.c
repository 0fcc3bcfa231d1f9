/* hard_a02.c - bench-hard's a02 section: the IFToMM benchmark A02 (N
 * four-bar loops in a row; Gonzalez, Dopico, Cuadrado 2006) at its own
 * size, N = 40, for its 20 s and 20 flat singular positions, in natural
 * coordinates and in absolute angles (tests/eom_constraints/models), with
 * every method at rtol = atol = 1e-8 (rk4 at 1e-3 s).
 *
 * The exact motion keeps the loops parallelograms: every crank angle is
 * th(t) with I th'' = -G cos th (I = m l^2 ((N+1)/3 + N), G = m g l
 * ((N+1)/2 + N)), th(0) = pi/2, th'(0) = -1 rad/s, integrated here by a
 * classical RK4 at 2e-5 s. Reported at the benchmark's 400 outputs: the
 * largest distance of B_0 (the first crank's tip, the benchmark's
 * reference point; its tolerances are 1e-1 and 1e-3) and of every crank
 * tip from the exact motion, the flat passes the branch monitor saw and
 * its branch switches, the singular stretches handed to another method
 * (adams and ida to bdf; bdf, esdirk and imex, and adams and ida where
 * their bdf failed, to erk: integrate_handover.c), steps, evaluations
 * and the processor time. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "eom/eom.h"
#include "eom/model_file.h"
#include "hard_a02.h"

#define PI_ 3.14159265358979323846

void hard_a02_pendulum(double a, double *th, double *w, double dt)
{
    const long k = (long)ceil(dt / 2e-5);
    const double h = dt / (double)k;
    long i;
    for (i = 0; i < k; i++) {
        const double t0 = *th, w0 = *w;
        const double k1t = w0, k1w = -a * cos(t0);
        const double k2t = w0 + h / 2 * k1w, k2w = -a * cos(t0 + h / 2 * k1t);
        const double k3t = w0 + h / 2 * k2w, k3w = -a * cos(t0 + h / 2 * k2t);
        const double k4t = w0 + h * k3w, k4w = -a * cos(t0 + h * k3t);
        *th = t0 + h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
        *w = w0 + h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
    }
}

static double cpu_now(void)
{
    return (double)clock() / CLOCKS_PER_SEC;
}

/* one run, its row printed; 1 when the model could not be read */
static int one(const char *dir, int natural, eom_method method,
               double t_end)
{
    const int N = 40, nout = (int)lround(t_end * 20);
    const double a = 9.81 * ((N + 1) / 2.0 + N) / ((N + 1) / 3.0 + N);
    char path[4096], err[1024], msg[1100] = "";
    eom_file *f = NULL;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    eom_stats st;
    double *x = NULL, th = PI_ / 2, w = -1.0, tprev = 0.0, eb = 0.0,
           ea = 0.0, treached = 0.0, c0 = cpu_now();
    int n, k, i, rc = EOM_ERR_ARG, unread = 1;
    memset(&st, 0, sizeof st);
    snprintf(path, sizeof path, "%s/a02-%s.eom", dir,
             natural ? "natural" : "angles");
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_set_setting(f, "N", N, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &mo, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, mo, err, sizeof err) != EOM_OK) {
        snprintf(msg, sizeof msg, "%s", err);
        goto done;
    }
    unread = 0;
    n = eom_system_ncoords(s);
    if (!(x = malloc(2 * (size_t)n * sizeof *x)) ||
        eom_initial_state(s, x) != EOM_OK)
        goto done;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = o.atol = 1e-8;
    o.dt = 1e-3;
    if ((rc = eom_integ_new(&it, s, &o, 0.0, x)) != EOM_OK) {
        snprintf(msg, sizeof msg, "%s", eom_system_errmsg(s));
        goto done;
    }
    for (k = 1; k <= nout; k++) {
        const double t = t_end * k / nout;
        double bx, by;
        if ((rc = eom_integ_advance(it, t, x, NULL)) != EOM_OK) {
            snprintf(msg, sizeof msg, "%s", eom_integ_errmsg(it));
            break;
        }
        treached = t;
        hard_a02_pendulum(a, &th, &w, t - tprev);
        tprev = t;
        bx = natural ? x[0] : cos(x[0]);
        by = natural ? x[N + 1] : sin(x[0]);
        eb = fmax(eb, hypot(bx - cos(th), by - sin(th)));
        for (i = 0; i <= N; i++)
            ea = fmax(ea, natural ? hypot(x[i] - i - cos(th),
                                          x[N + 1 + i] - sin(th))
                                  : fabs(x[i] - th));
    }
    eom_integ_stats(it, &st);
done:
    printf("| %s | %s | %s | %.2f | %.1e | %.1e | %ld | %ld | %ld (%ld) | "
           "%ld | %ld | %.1f |%s%s\n",
           natural ? "natural" : "angles", eom_method_name(method),
           rc == EOM_OK ? "ok" : eom_status_name(rc), treached, eb, ea,
           st.singular_passes, st.branch_switches, st.singular_handovers,
           st.singular_handovers_erk, st.steps, st.rhs_evals,
           cpu_now() - c0, msg[0] ? " " : "", msg);
    fflush(stdout);
    eom_integ_free(&it);
    eom_system_free(&s);
    eom_model_free(&mo);
    eom_file_free(&f);
    free(x);
    return unread;
}

int hard_a02(const char *models_dir, int quick)
{
    static const eom_method methods[] = {EOM_RK4, EOM_ERK,    EOM_ADAMS,
                                         EOM_BDF, EOM_IDA,    EOM_ESDIRK,
                                         EOM_IMEX};
    /* quick: erk alone */
    const int k0 = quick ? 1 : 0,
              nm = quick ? 2 : (int)(sizeof methods / sizeof *methods);
    int form, k, rc = 0;
    printf("| A02, N = 40 | method | status | t reached | B0 error | every "
           "tip | flat passes seen | branch switches | stretches handed over "
           "(to erk) | steps | rhs | cpu (s) |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (form = 0; form < 2; form++)
        for (k = k0; k < nm; k++)
            rc |= one(models_dir, form == 0, methods[k], quick ? 1.0 : 20.0);
    return rc;
}
