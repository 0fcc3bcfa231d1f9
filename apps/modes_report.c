/* modes_report.c - eom-run --modes (see modes_report.h). */
#include "modes_report.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom/run.h"
#include "eom/steady.h"

static const double two_pi = 6.28318530717958647692;

static void print_coords(FILE *f, const eom_system *s, const double *q)
{
    const int n = eom_system_ncoords(s);
    int i, w = 0;
    for (i = 0; i < n; i++) {
        int len = (int)strlen(eom_coord_name(s, i));
        w = len > w ? len : w;
    }
    fprintf(f, "equilibrium coordinates:\n");
    for (i = 0; i < n; i++) {
        char v[32];
        eom_numtext_format(v, sizeof v, q[i]);
        fprintf(f, "  %-*s  %-24s %s\n", w, eom_coord_name(s, i), v,
                eom_coord_unit(s, i));
    }
}

/* The table of frequencies and a closing verdict on stability. */
static void print_frequencies(FILE *f, const eom_linear *lin)
{
    double wmax = 0.0;
    int i, unstable = 0, neutral = 0;
    for (i = 0; i < lin->nr; i++)
        wmax = fmax(wmax, fabs(lin->omega[i]));
    fprintf(f, "natural frequencies about the equilibrium (undamped; %d "
            "independent directions of %d coordinates):\n", lin->nr,
            lin->n);
    if (lin->nr == 0) {
        fprintf(f, "  none: the constraints leave no motion\n");
        return;
    }
    fprintf(f, "  %4s  %-24s  %s\n", "mode", "omega (rad/s)", "f (Hz)");
    for (i = 0; i < lin->nr; i++) {
        const double w = lin->omega[i];
        char a[32], b[32];
        eom_numtext_format(a, sizeof a, w);
        if (fabs(w) <= MODES_NEUTRAL * wmax || wmax == 0.0) {
            neutral++;
            fprintf(f, "  %4d  %-24s  %-24s  neutral (about 0: a free "
                    "motion)\n", i + 1, a, "0");
        } else if (w < 0.0) {
            unstable++;
            fprintf(f, "  %4d  %-24s  %-24s  UNSTABLE: grows like "
                    "exp(%.6g t)\n", i + 1, a, "-", -w);
        } else {
            eom_numtext_format(b, sizeof b, w / two_pi);
            fprintf(f, "  %4d  %-24s  %s\n", i + 1, a, b);
        }
    }
    if (unstable)
        fprintf(f, "the equilibrium is unstable: %d unstable "
                "direction%s\n", unstable, unstable == 1 ? "" : "s");
    else if (neutral)
        fprintf(f, "the equilibrium is neutrally stable: %d direction%s "
                "with a frequency of about 0\n", neutral,
                neutral == 1 ? "" : "s");
    else
        fprintf(f, "the equilibrium is stable: every frequency is real "
                "and positive\n");
}

int modes_report(FILE *f, eom_system *s, const double *x0,
                 const char *label, const char *origin)
{
    const int n = eom_system_ncoords(s);
    double *q = malloc((size_t)n * sizeof(double) + 1);
    eom_linear lin;
    int iters = 0, rc;
    memset(&lin, 0, sizeof lin);
    if (!q) {
        fprintf(stderr, "eom-run: out of memory\n");
        return 1;
    }
    if (eom_system_nvelocity_constraints(s) > 0) {
        /* no equilibrium search with velocity constraints: the start
         * itself, at rest or moving steadily */
        free(q);
        return modes_steady_report(f, s, x0, NULL, 0, label);
    }
    memcpy(q, x0, (size_t)n * sizeof(double));
    rc = eom_equilibrium(s, q, MODES_EQ_TOL, &iters);
    if (rc == EOM_ERR_MODEL) {
        fprintf(stderr, "eom-run: %s: no static equilibrium to search: "
                "%s\n", label, eom_system_errmsg(s));
        free(q);
        return 1;
    }
    if (rc != EOM_OK) {
        fprintf(stderr, "eom-run: %s: no static equilibrium found from %s: "
                "%s\n", label, origin, eom_system_errmsg(s));
        free(q);
        return 1;
    }
    rc = eom_linearize(s, q, &lin);
    if (rc == EOM_ERR_MODEL && strstr(eom_system_errmsg(s), "unsymmetric")) {
        /* a circulatory force: no undamped frequencies; the eigenvalues
         * of the state matrix about the equilibrium at rest instead */
        double *x = calloc(2 * (size_t)n, sizeof(double));
        if (!x) {
            fprintf(stderr, "eom-run: out of memory\n");
            free(q);
            return 1;
        }
        memcpy(x, q, (size_t)n * sizeof(double));
        fprintf(f, "%s: static equilibrium found from %s in %d Newton "
                "step%s; the forces' stiffness is unsymmetric (no undamped "
                "frequencies):\n", label, origin, iters,
                iters == 1 ? "" : "s");
        rc = modes_steady_report(f, s, x, NULL, 0, label);
        free(x);
        free(q);
        return rc;
    }
    if (rc != EOM_OK) {
        fprintf(stderr, "eom-run: %s: cannot linearize about the "
                "equilibrium: %s\n", label, eom_system_errmsg(s));
        free(q);
        return 1;
    }
    fprintf(f, "%s: static equilibrium found from %s in %d Newton step%s\n"
            "(tolerance %g on the unbalanced generalized forces and on "
            "|phi|: the potential,\nthe constraints and every force at "
            "rest; dampers do not act at rest)\n\n", label, origin, iters,
            iters == 1 ? "" : "s", MODES_EQ_TOL);
    print_coords(f, s, q);
    fputc('\n', f);
    print_frequencies(f, &lin);
    eom_linear_free(&lin);
    free(q);
    return 0;
}

/* The name of state i: a coordinate, or its rate NAME_dot. */
static void state_name(const eom_system *s, int i, char *buf, size_t len)
{
    const int n = eom_system_ncoords(s);
    if (i < n)
        snprintf(buf, len, "%s", eom_coord_name(s, i));
    else
        snprintf(buf, len, "%s_dot", eom_coord_name(s, i - n));
}

/* One number, -0 printed as 0. */
static void num(char *buf, size_t len, double v)
{
    eom_numtext_format(buf, len, v == 0.0 ? 0.0 : v);
}

static void print_start(FILE *f, const eom_system *s, const double *x)
{
    const int n = eom_system_ncoords(s);
    int i, w = 0;
    for (i = 0; i < n; i++) {
        int len = (int)strlen(eom_coord_name(s, i));
        w = len > w ? len : w;
    }
    fprintf(f, "start state:\n  %-*s  %-24s %-24s %s\n", w, "", "value",
            "rate", "unit");
    for (i = 0; i < n; i++) {
        char a[32], b[32];
        num(a, sizeof a, x[i]);
        num(b, sizeof b, x[n + i]);
        fprintf(f, "  %-*s  %-24s %-24s %s\n", w, eom_coord_name(s, i), a,
                b, eom_coord_unit(s, i));
    }
}

int modes_steady_report(FILE *f, eom_system *s, const double *x,
                        const int *keep, int nkeep, const char *label)
{
    const int n = eom_system_ncoords(s);
    eom_steady_linear lin;
    double emax = 0.0, dmax = 0.0;
    int i, any = 0, unstable = 0, neutral = 0, moving = 0;
    char name[160], a[32], b[32];
    for (i = 0; i < n; i++)
        moving |= x[n + i] != 0.0;
    if (eom_linearize_steady(s, 0.0, x, keep, nkeep, &lin) != EOM_OK) {
        fprintf(stderr, "eom-run: %s: cannot linearize about the start "
                "state: %s\n", label, eom_system_errmsg(s));
        return 1;
    }
    fprintf(f, "%s: linearized about the start state, %s\n(max |qdd| = "
            "%.3g against %.3g for its terms; the constraints restrict the "
            "perturbations)\n\n", label,
            moving ? "a steady motion" : "at rest", lin.acc, lin.acc_scale);
    print_start(f, s, x);
    fputs("\ncyclic coordinates (the equations do not read them):", f);
    for (i = 0; i < n; i++)
        if (lin.cyclic[i]) {
            fprintf(f, "%s %s", any ? "," : "", eom_coord_name(s, i));
            any = 1;
        }
    fprintf(f, "%s\n%s states (%d of the %d on the constraints):",
            any ? "" : " none", keep ? "named independent" :
            "independent", lin.nr, lin.full.nz);
    for (i = 0; i < lin.nr; i++) {
        state_name(s, lin.kept[i], name, sizeof name);
        fprintf(f, "%s %s", i ? "," : "", name);
    }
    fputc('\n', f);
    for (i = 0; i < lin.nr; i++)
        emax = fmax(emax, hypot(lin.eig_re[i], lin.eig_im[i]));
    fprintf(f, "\neigenvalues of the reduced state matrix (1/s):\n"
            "  %4s  %-24s  %-24s\n", "k", "re", "im");
    for (i = 0; i < lin.nr; i++) {
        const double re = lin.eig_re[i], im = lin.eig_im[i];
        const char *note = "";
        num(a, sizeof a, re);
        num(b, sizeof b, im);
        if (hypot(re, im) <= MODES_NEUTRAL * emax || emax == 0.0) {
            neutral++;
            note = "  about 0 (a neighbouring steady motion)";
        } else if (re > MODES_NEUTRAL * emax) {
            unstable++;
            note = "  UNSTABLE";
        } else if (re >= -MODES_NEUTRAL * emax) {
            neutral++;
            note = "  oscillating, not damped";
        }
        fprintf(f, "  %4d  %-24s  %-24s%s\n", i + 1, a, b, note);
    }
    for (i = 0; i < lin.ndrop; i++)
        dmax = fmax(dmax, hypot(lin.drop_re[i], lin.drop_im[i]));
    if (lin.ndrop > 0) {
        num(a, sizeof a, dmax);
        fprintf(f, "left out: %d direction%s of the cyclic coordinates and "
                "the speeds the others\ndetermine, whose eigenvalues are "
                "%s (largest modulus %s)\n", lin.ndrop,
                lin.ndrop == 1 ? "" : "s",
                dmax <= MODES_NEUTRAL * fmax(emax, 1.0) ? "about 0"
                                                        : "not all 0",
                a);
    }
    if (unstable)
        fprintf(f, "the %s is unstable: %d eigenvalue%s with a positive "
                "real part\n", moving ? "motion" : "state", unstable,
                unstable == 1 ? "" : "s");
    else if (neutral)
        fprintf(f, "the %s is not unstable to first order: %d "
                "eigenvalue%s with a real part of about 0\n",
                moving ? "motion" : "state", neutral,
                neutral == 1 ? "" : "s");
    else
        fprintf(f, "the %s is stable: every real part is negative\n",
                moving ? "motion" : "state");
    eom_steady_linear_free(&lin);
    return 0;
}
