/* modes_report.c - eom-run --modes (see modes_report.h). */
#include "modes_report.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom/run.h"

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
    memcpy(q, x0, (size_t)n * sizeof(double));
    rc = eom_equilibrium(s, q, MODES_EQ_TOL, &iters);
    if (rc != EOM_OK) {
        fprintf(stderr, "eom-run: %s: no static equilibrium found from %s: "
                "%s\n", label, origin, eom_system_errmsg(s));
        free(q);
        return 1;
    }
    rc = eom_linearize(s, q, &lin);
    if (rc != EOM_OK) {
        fprintf(stderr, "eom-run: %s: cannot linearize about the "
                "equilibrium: %s\n", label, eom_system_errmsg(s));
        free(q);
        return 1;
    }
    fprintf(f, "%s: static equilibrium found from %s in %d Newton step%s\n"
            "(tolerance %g on the unbalanced generalized forces and on "
            "|phi|; gravity and\nsprings only: dampers do not act at "
            "rest)\n\n", label, origin, iters, iters == 1 ? "" : "s",
            MODES_EQ_TOL);
    print_coords(f, s, q);
    fputc('\n', f);
    print_frequencies(f, &lin);
    eom_linear_free(&lin);
    free(q);
    return 0;
}
