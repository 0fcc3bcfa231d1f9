/* test_model_compiled.c - systems on compiled tapes (eom_system_set_compiled),
 * public API only.
 *
 *   1. Every shipped model file and three chains of the element library
 *      (rigid, flexible with structural damping, closed): the compiled
 *      system against an interpreted clone at 30 states around the
 *      initial one: right-hand sides, energies and probes to 1e-14
 *      relative; a clone of the compiled system is compiled too.
 *   2. No compiler: eom_system_set_compiled returns EOM_WARN_INTERPRETED
 *      with the reason, the system stays on the interpreter and gives the
 *      interpreter's answers.
 *
 * usage: test_model_compiled MODELS_DIR
 */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"
#include "eom/model_file.h"
#include "support_rng.h"

#define MAXN 256

/* The compiled system s against the interpreted c at states around x0. */
static void compare(eom_system *s, eom_system *c, const char *what)
{
    const int n = eom_system_ncoords(s), np = eom_system_nprobes(s);
    double x0[2 * MAXN], x[2 * MAXN], a[2 * MAXN], b[2 * MAXN];
    double pa[64], pb[64];
    rng g = rng_seed(11);
    int k, i, fails = check_failures_;
    if (n > MAXN || np > 64)
        return;
    eom_initial_state(s, x0);
    for (k = 0; k < 30; k++) {
        eom_energy ea, eb;
        for (i = 0; i < 2 * n; i++)
            x[i] = x0[i] + (k ? 0.2 * (rng_unit(&g) - 0.5) : 0.0);
        CHECK_INT(eom_rhs(s, 0.3, x, a), eom_rhs(c, 0.3, x, b));
        for (i = 0; i < 2 * n; i++)
            CHECK_NEAR(a[i], b[i], 1e-14);
        CHECK_INT(eom_energy_at(s, 0.3, x, &ea), EOM_OK);
        CHECK_INT(eom_energy_at(c, 0.3, x, &eb), EOM_OK);
        CHECK_NEAR(ea.T, eb.T, 1e-14);
        CHECK_NEAR(ea.V, eb.V, 1e-14);
        CHECK_NEAR(ea.E, eb.E, 1e-14);
        CHECK_NEAR(ea.P, eb.P, 1e-14);
        if (np > 0) {
            CHECK_INT(eom_probes_at(s, x, pa), EOM_OK);
            CHECK_INT(eom_probes_at(c, x, pb), EOM_OK);
            for (i = 0; i < np; i++)
                CHECK_NEAR(pa[i], pb[i], 1e-14);
        }
    }
    if (check_failures_ != fails)
        fprintf(stderr, "  (in %s)\n", what);
}

/* Compile s; compare with a clone made before (interpreted) and with one
 * made after (compiled by inheritance). */
static void check_system(eom_system *s, const char *what)
{
    eom_system *before = NULL, *after = NULL;
    eom_compiled_info info;
    int st;
    CHECK_INT(eom_system_clone(&before, s, NULL, 0), EOM_OK);
    st = eom_system_set_compiled(s, 1, &info);
    CHECK_INT(st, EOM_OK);
    if (st != EOM_OK)
        fprintf(stderr, "%s: %s\n", what, eom_system_errmsg(s));
    CHECK_INT(eom_system_compiled(s), 1);
    CHECK_INT(eom_system_compiled(before), 0);
    CHECK(info.tapes >= 1);
    compare(s, before, what);
    CHECK_INT(eom_system_clone(&after, s, NULL, 0), EOM_OK);
    CHECK_INT(eom_system_compiled(after), 1);
    compare(after, before, what);
    /* and back */
    CHECK_INT(eom_system_set_compiled(s, 0, NULL), EOM_OK);
    CHECK_INT(eom_system_compiled(s), 0);
    compare(s, before, what);
    eom_system_free(&before);
    eom_system_free(&after);
}

static void model_files(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int count = 0;
    CHECK(d != NULL);
    while (d && (e = readdir(d))) {
        char path[1024], err[512];
        size_t len = strlen(e->d_name);
        eom_model *m = NULL;
        eom_system *s = NULL;
        if (len < 5 || strcmp(e->d_name + len - 4, ".eom") != 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        CHECK_INT(eom_model_from_file(&m, path, err, sizeof err), EOM_OK);
        CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
        if (s)
            check_system(s, e->d_name);
        eom_system_free(&s);
        eom_model_free(&m);
        count++;
    }
    if (d)
        closedir(d);
    CHECK(count >= 7);
}

static eom_system *chain(int links, int modes, int closed, int structural)
{
    static const double th[4] = {-1.2, -1.9, 0.4, 1.1};
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[256];
    memset(&sp, 0, sizeof sp);
    sp.links = links;
    sp.modes_all = modes;
    sp.closed = closed;
    sp.m = 1.0;
    sp.L = closed ? 10.0 : 2.0;
    sp.EI = 4e4;
    sp.g = 9.81;
    sp.D = 20.0;
    sp.theta0 = th;
    sp.structural = structural;
    sp.zeta = 0.02;
    if (eom_model_new(&m) == EOM_OK && eom_chain_add(m, &sp) >= 0)
        eom_system_new(&s, m, err, sizeof err);
    eom_model_free(&m);
    CHECK(s != NULL);
    return s;
}

static void chains(void)
{
    eom_system *s;
    if ((s = chain(4, 0, 0, 0)) != NULL)
        check_system(s, "rigid chain");
    eom_system_free(&s);
    if ((s = chain(3, 2, 0, 1)) != NULL)
        check_system(s, "flexible chain with structural damping");
    eom_system_free(&s);
    if ((s = chain(4, 1, 1, 0)) != NULL)
        check_system(s, "closed chain");
    eom_system_free(&s);
}

static void no_compiler(void)
{
    eom_system *s = chain(3, 0, 0, 0), *c = NULL;
    eom_compiled_info info;
    if (!s)
        return;
    CHECK_INT(eom_system_clone(&c, s, NULL, 0), EOM_OK);
    setenv("CC", "/nonexistent/bin/cc", 1);
    CHECK_INT(eom_system_set_compiled(s, 1, &info), EOM_WARN_INTERPRETED);
    CHECK(strstr(eom_system_errmsg(s), "compiled tapes are not in use") !=
          NULL);
    CHECK(strstr(eom_system_errmsg(s), "/nonexistent/bin/cc") != NULL);
    CHECK_INT(eom_system_compiled(s), 0);
    compare(s, c, "no compiler");
    unsetenv("CC");
    eom_system_free(&c);
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    char dir[] = "/tmp/test-model-compiled-XXXXXX", cmd[128];
    if (argc < 2) {
        fprintf(stderr, "usage: test_model_compiled MODELS_DIR\n");
        return EXIT_FAILURE;
    }
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return EXIT_FAILURE;
    }
    /* a cache of this run's own */
    setenv("AUTOEOM_CACHE_DIR", dir, 1);
    unsetenv("CC");
    unsetenv("AUTOEOM_CFLAGS");
    model_files(argv[1]);
    chains();
    no_compiler();
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    CHECK_DONE();
}
