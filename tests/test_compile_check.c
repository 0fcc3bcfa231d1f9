/* test_compile_check.c - tp_compile's check of a loaded object against the
 * interpreter (compile.c: every result within 1e-13 relative, else the
 * object is refused and the tape stays on the interpreter).
 *
 * An object that computes something slightly different is made the way a
 * user could make one by accident, through the compiler flags: `-include
 * FILE` with a header that redefines exp() as exp() times (1 + d). The
 * generated code then differs from the interpreter by a relative d in
 * every value that passes through EXP, and in the gradients after it.
 *
 *   - d = 1e-12 and 1e-8 (above the check's 1e-13, below 1e-6): refused,
 *     the message says the compiled tape differs, and the tape gives the
 *     interpreter's numbers;
 *   - d = 0 (the same header, a factor of exactly 1): accepted, bit for
 *     bit the interpreter's values;
 *   - d = 2^-50 (about 9e-16, rounding-sized): accepted.
 * Public API only; one scratch folder holds the cache and the headers. */
#define _GNU_SOURCE

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "tape/tape.h"

#define NX 4

static char root[64]; /* the scratch folder */

static int rec_exp(tp_rec *r, void *user)
{
    tp_val x[NX];
    int i;
    (void)user;
    for (i = 0; i < NX; i++)
        x[i] = tp_indep(r, i);
    /* L = exp(x0) sin(x1) + x2 exp(x3) */
    tp_output(r, "L",
              tp_add(r, tp_mul(r, tp_exp(r, x[0]), tp_sin(r, x[1])),
                     tp_mul(r, x[2], tp_exp(r, x[3]))));
    return 0;
}

static tp_tape *record(void)
{
    unsigned char group[NX] = {0, 0, 1, 1};
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    if (tp_recorder_new(&r, NX, group, NULL) != TP_OK ||
        tp_rec_run(r, NULL, rec_exp, NULL) != TP_OK ||
        tp_recorder_finish(r, &t) != TP_OK)
        t = NULL;
    tp_rec_free(&r);
    return t;
}

static const double X[NX] = {0.1, 0.2, 0.3, 0.4};

/* A header, given to the compiler with -include, that makes the
 * generated code's exp() return exp() * factor (factor a C literal). */
static void write_header(const char *file, const char *factor)
{
    FILE *f = fopen(file, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f, "#include <math.h>\n#define exp(x) (exp(x) * (%s))\n",
            factor);
    CHECK(fclose(f) == 0);
}

/* Compile t with the header that scales exp() by factor; the status,
 * the message in info. The tape's value and gradient at X, through the
 * compiled object if it was accepted, go to y and g. */
static int compile_with(tp_tape *t, const char *name, const char *factor,
                        tp_compile_info *info, double *y, double *g)
{
    char header[256], flags[400], cache[256];
    tp_compile_opts o;
    tp_compiled *c = NULL;
    tp_ws *w = NULL;
    const double wt = 1.0;
    int st;
    snprintf(header, sizeof header, "%s/%s.h", root, name);
    snprintf(flags, sizeof flags, "-O1 -include %s", header);
    snprintf(cache, sizeof cache, "%s/cache", root);
    write_header(header, factor);
    memset(&o, 0, sizeof o);
    o.cache_dir = cache;
    o.cflags = flags;
    st = tp_compile(t, &o, &c, info);
    CHECK(st == TP_OK ? c != NULL : c == NULL);
    CHECK_INT(tp_ws_new(&w, t, 1, NULL), TP_OK);
    if (c)
        CHECK_INT(tp_ws_set_compiled(w, c), TP_OK);
    CHECK_INT(tp_eval(w, X, y), TP_OK);
    CHECK_INT(tp_vjp(w, X, &wt, NULL, g), TP_OK);
    tp_ws_free(&w);
    tp_compiled_free(&c);
    unlink(header);
    return st;
}

static int has(const char *s, const char *part)
{
    if (!strstr(s, part)) {
        fprintf(stderr, "  message: %s\n  lacks: %s\n", s, part);
        return 0;
    }
    return 1;
}

int main(void)
{
    static const struct {
        const char *name, *factor;
        int refused;
    } cases[] = {
        {"exact", "1.0", 0},
        {"rounding", "(1.0 + 0x1p-50)", 0},
        {"above", "(1.0 + 1e-12)", 1},
        {"far", "(1.0 + 1e-8)", 1},
    };
    /* the interpreter's numbers, and the closed form */
    const double L = exp(X[0]) * sin(X[1]) + X[2] * exp(X[3]);
    const double G[NX] = {exp(X[0]) * sin(X[1]), exp(X[0]) * cos(X[1]),
                          exp(X[3]), X[2] * exp(X[3])};
    tp_tape *t = record();
    tp_ws *w = NULL;
    double y0 = 0, g0[NX], y, g[NX];
    const double wt = 1.0;
    size_t k;
    int i;
    char cmd[128];

    CHECK(t != NULL);
    snprintf(root, sizeof root, "/tmp/autoeom-check-XXXXXX");
    CHECK(mkdtemp(root) != NULL);
    if (!t)
        CHECK_DONE();
    CHECK_INT(tp_ws_new(&w, t, 1, NULL), TP_OK);
    CHECK_INT(tp_eval(w, X, &y0), TP_OK);
    CHECK_INT(tp_vjp(w, X, &wt, NULL, g0), TP_OK);
    tp_ws_free(&w);
    CHECK_NEAR(y0, L, 1e-15);
    for (i = 0; i < NX; i++)
        CHECK_NEAR(g0[i], G[i], 1e-15);

    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        tp_compile_info info;
        int st = compile_with(t, cases[k].name, cases[k].factor, &info, &y, g);
        fprintf(stderr, "exp() times %s: status %d: %s\n", cases[k].factor,
                st, info.msg);
        if (cases[k].refused) {
            CHECK_INT(st, TP_ERR_COMPILE);
            CHECK(has(info.msg, "the compiled tape differs from the "
                                "interpreter"));
            /* refused: the interpreter's numbers, exactly */
            CHECK(y == y0);
            for (i = 0; i < NX; i++)
                CHECK(g[i] == g0[i]);
        } else {
            CHECK_INT(st, TP_OK);
            CHECK(!strstr(info.msg, "differs"));
            if (k == 0) { /* a factor of 1: bit for bit */
                CHECK(y == y0);
                for (i = 0; i < NX; i++)
                    CHECK(g[i] == g0[i]);
            } else {
                CHECK_NEAR(y, y0, 1e-14);
                for (i = 0; i < NX; i++)
                    CHECK_NEAR(g[i], g0[i], 1e-14);
            }
        }
    }
    tp_tape_free(&t);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    CHECK(system(cmd) == 0);
    CHECK_DONE();
}
