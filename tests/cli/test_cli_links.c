/* test_cli_links.c - the files --plots writes beside the CSV (gnuplot
 * scripts and the chain's snapshot data) against what may already sit at
 * their names: a symbolic link to someone's file, a dangling link, a
 * FIFO. Each is written through the run layer's text writer
 * (eom_csv_writer_open_text): a link is replaced by the new file and
 * never followed (its target keeps its content, a dangling link's target
 * is not created), a FIFO is refused with a message instead of hanging
 * the run, and no temporary file is left behind.
 *
 * usage: test_cli_links EOM_RUN CASE, CASE one of
 *   links_model  a model file's plots (libeom/run/model_plots.c)
 *   links_demos  the spring pendulum's and the closed chain's plots
 *                (apps/demos/spring_plots.c, chain_plot_scripts.c)
 *   links_modes  --modes --sweep --plots (apps/modes_sweep.c)
 *   links_fifo   a FIFO at a script's name
 * eom-run runs with a PATH that holds no gnuplot: the scripts are written
 * before gnuplot is looked for, so nothing here depends on it, and the
 * run ends with status 1 and a message that gnuplot is missing. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static const char victim_text[] = "a file the run must not touch\n";

/* A victim file with known content at scratch name victim, and a link to
 * it at scratch name link. */
static void plant_link(const char *link, const char *victim)
{
    char l[300], v[300];
    FILE *f;
    scratch(l, sizeof l, link);
    scratch(v, sizeof v, victim);
    f = fopen(v, "w");
    CHECK(f != NULL);
    if (f) {
        fputs(victim_text, f);
        CHECK(fclose(f) == 0);
    }
    CHECK(symlink(v, l) == 0);
}

/* A link at scratch name link to the scratch name target, which does not
 * exist. */
static void plant_dangling(const char *link, const char *target)
{
    char l[300], t[300];
    scratch(l, sizeof l, link);
    scratch(t, sizeof t, target);
    CHECK(access(t, F_OK) != 0);
    CHECK(symlink(t, l) == 0);
}

/* The victim still holds its text alone. */
static void check_victim(const char *victim)
{
    char v[300], *text;
    scratch(v, sizeof v, victim);
    text = read_file(v, NULL);
    check_count_++;
    if (!text || strcmp(text, victim_text) != 0)
        CHECK_FAIL_("%s was changed through a link: %s", victim,
                    text ? text : "(gone)");
    free(text);
}

/* The scratch name is now a regular file (not a link) that starts with
 * head. */
static void check_replaced(const char *name, const char *head)
{
    char p[300], *text;
    struct stat st;
    scratch(p, sizeof p, name);
    CHECK(lstat(p, &st) == 0 && S_ISREG(st.st_mode));
    text = read_file(p, NULL);
    check_count_++;
    if (!text || strncmp(text, head, strlen(head)) != 0)
        CHECK_FAIL_("%s does not start with '%s'", name, head);
    free(text);
}

/* No NAME.tmp-XXXXXX is left in the scratch directory. */
static void check_no_temporaries(void)
{
    char dir[300];
    DIR *d;
    struct dirent *e;
    scratch(dir, sizeof dir, "");
    d = opendir(dir);
    CHECK(d != NULL);
    while (d && (e = readdir(d)) != NULL) {
        check_count_++;
        if (strstr(e->d_name, ".tmp-"))
            CHECK_FAIL_("a temporary file is left: %s", e->d_name);
    }
    if (d)
        closedir(d);
}

/* Run eom-run with args and a PATH without gnuplot: the scripts are
 * written, then the run stops because gnuplot is missing. */
static void run_plots(const char *const *args)
{
    char empty[300];
    result r;
    scratch(empty, sizeof empty, "no-gnuplot");
    (void)mkdir(empty, 0700);
    run_path(&r, args, empty);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "gnuplot");
    result_free(&r);
}

static void case_model(void)
{
    char out[300];
    const char *args[] = {"double-pendulum", "--t-end", "0.1", "--plots",
                          "-q", "--out", out, NULL};
    scratch(out, sizeof out, "dp.csv");
    plant_link("dp-coordinates.gp", "victim-coordinates");
    plant_dangling("dp-energy.gp", "created-through-link");
    run_plots(args);
    check_victim("victim-coordinates");
    check_replaced("dp-coordinates.gp", "# the coordinates over time");
    check_replaced("dp-energy.gp", "# energies over time");
    {
        char t[300];
        scratch(t, sizeof t, "created-through-link");
        CHECK(access(t, F_OK) != 0);
    }
    check_no_temporaries();
}

static void case_demos(void)
{
    char sp[300], cc[300];
    const char *spring[] = {"spring-pendulum", "--t-end", "0.1", "--plots",
                            "-q", "--out", sp, NULL};
    const char *chain[] = {"closed-chain", "--t-end", "0.02", "--sample",
                           "0.01", "--plots", "-q", "--out", cc, NULL};
    scratch(sp, sizeof sp, "sp.csv");
    scratch(cc, sizeof cc, "cc.csv");
    plant_link("sp-energy.gp", "victim-sp");
    plant_link("cc-energy.gp", "victim-cc");
    plant_link("cc-snapshots.dat", "victim-dat");
    run_plots(spring);
    run_plots(chain);
    check_victim("victim-sp");
    check_victim("victim-cc");
    check_victim("victim-dat");
    check_replaced("sp-energy.gp", "# energies over time");
    check_replaced("cc-energy.gp", "#");
    check_replaced("cc-snapshots.dat", "# The deformed chain");
    check_no_temporaries();
}

static void case_modes(void)
{
    char out[300];
    /* about the hanging rest */
    const char *args[] = {"double-pendulum", "--set", "th1=0", "--set",
                          "th2=0", "--modes", "--sweep", "m1=1:2:3",
                          "--plots", "-q", "--out", out, NULL};
    scratch(out, sizeof out, "sweep.csv");
    plant_link("sweep-eigenvalues.gp", "victim-sweep");
    run_plots(args);
    check_victim("victim-sweep");
    check_replaced("sweep-eigenvalues.gp", "# eigenvalues of");
    check_no_temporaries();
}

static void case_fifo(void)
{
    char out[300], fifo[300];
    const char *args[] = {"spring-pendulum", "--t-end", "0.1", "--plots",
                          "-q", "--out", out, NULL};
    struct stat st;
    result r;
    scratch(out, sizeof out, "sf.csv");
    scratch(fifo, sizeof fifo, "sf-path.gp");
    CHECK(mkfifo(fifo, 0600) == 0);
    /* a writer that opened the FIFO would wait for a reader for ever
     * (the test's time limit): refused instead */
    run(&r, args);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "sf-path.gp");
    CHECK_HAS(r.err, "not a regular file");
    result_free(&r);
    CHECK(lstat(fifo, &st) == 0 && S_ISFIFO(st.st_mode));
    check_no_temporaries();
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"links_model", case_model},
    {"links_demos", case_demos},
    {"links_modes", case_modes},
    {"links_fifo", case_fifo},
};

int main(int argc, char **argv)
{
    size_t i;
    int found = 0;
    if (argc < 3) {
        fprintf(stderr, "usage: test_cli_links EOM_RUN CASE\n");
        return EXIT_FAILURE;
    }
    cli_program = argv[1];
    if (cli_setup() != 0)
        return EXIT_FAILURE;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (strcmp(cases[i].name, argv[2]) == 0) {
            cases[i].fn();
            found = 1;
        }
    cli_cleanup();
    if (!found) {
        fprintf(stderr, "test_cli_links: unknown case '%s'\n", argv[2]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
