/* test_cli_parts.c - the parts of eom-run that the command line alone
 * cannot reach yet, linked in directly: strict number parsing and
 * round-trip formatting (numtext), structural settings and --set
 * resolution against a demo that has settings (overrides), and the
 * registry's checks. The demo here is made up for the test; it builds
 * the same model as spring-pendulum. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "demos/demos.h"
#include "eom/run.h"
#include "overrides.h"

static void test_numtext(void)
{
    static const struct {
        const char *text;
        int code;
        double value;
    } cases[] = {
        {"75", EOM_NUMTEXT_OK, 75.0},
        {"-0.5", EOM_NUMTEXT_OK, -0.5},
        {"1e-3", EOM_NUMTEXT_OK, 1e-3},
        {"0x1p-4", EOM_NUMTEXT_OK, 0.0625},
        {"", EOM_NUMTEXT_EMPTY, 0},
        {"abc", EOM_NUMTEXT_NOT_NUMBER, 0},
        {" 5", EOM_NUMTEXT_NOT_NUMBER, 0},
        {"5 ", EOM_NUMTEXT_TRAILING, 0},
        {"5x", EOM_NUMTEXT_TRAILING, 0},
        {"1,5", EOM_NUMTEXT_TRAILING, 0},
        {"inf", EOM_NUMTEXT_NONFINITE, 0},
        {"-infinity", EOM_NUMTEXT_NONFINITE, 0},
        {"nan", EOM_NUMTEXT_NONFINITE, 0},
        {"1e999", EOM_NUMTEXT_RANGE, 0},
        {"-1e999", EOM_NUMTEXT_RANGE, 0},
    };
    size_t i;
    long l = 0;
    char buf[32];
    unsigned long long seed = 12345;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double v = -7.0;
        int rc = eom_numtext_parse_double(cases[i].text, &v);
        CHECK_INT(rc, cases[i].code);
        if (cases[i].code == EOM_NUMTEXT_OK)
            CHECK(v == cases[i].value);
        else
            CHECK(v == -7.0); /* untouched on failure */
        CHECK(strlen(eom_numtext_error(rc)) > 0);
    }
    CHECK_INT(eom_numtext_parse_long("42", &l), EOM_NUMTEXT_OK);
    CHECK_INT(l, 42);
    CHECK_INT(eom_numtext_parse_long("-3", &l), EOM_NUMTEXT_OK);
    CHECK_INT(l, -3);
    CHECK_INT(eom_numtext_parse_long("2.5", &l), EOM_NUMTEXT_NOT_INTEGER);
    CHECK_INT(eom_numtext_parse_long("1e3", &l), EOM_NUMTEXT_NOT_INTEGER);
    CHECK_INT(eom_numtext_parse_long("12a", &l), EOM_NUMTEXT_TRAILING);
    CHECK_INT(eom_numtext_parse_long(" 1", &l), EOM_NUMTEXT_NOT_NUMBER);
    CHECK_INT(eom_numtext_parse_long("", &l), EOM_NUMTEXT_EMPTY);
    CHECK_INT(eom_numtext_parse_long("99999999999999999999999", &l),
              EOM_NUMTEXT_RANGE);

    eom_numtext_format(buf, sizeof buf, 0.01);
    CHECK(strcmp(buf, "0.01") == 0);
    eom_numtext_format(buf, sizeof buf, 3 * 0.1);
    CHECK(strcmp(buf, "0.30000000000000004") == 0);
    eom_numtext_format(buf, sizeof buf, -NAN);
    CHECK(strcmp(buf, "nan") == 0);
    eom_numtext_format(buf, sizeof buf, -INFINITY);
    CHECK(strcmp(buf, "-inf") == 0);
    /* every double reads back exactly: random bit patterns */
    for (i = 0; i < 20000; i++) {
        double v, back;
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        memcpy(&v, &seed, sizeof v);
        if (!isfinite(v))
            continue;
        eom_numtext_format(buf, sizeof buf, v);
        back = strtod(buf, NULL);
        check_count_++;
        if (memcmp(&back, &v, sizeof v) != 0)
            CHECK_FAIL_("%.17g formats as %s", v, buf);
    }
}

static const demo_setting test_settings[] = {
    {"links", "", 3, 1, 20, 1, "number of links"},
    {"width", "m", 0.5, 0.0, 2.0, 0, "width"},
};

static int test_build(const demo *d, const double *settings,
                      eom_model **out, char *err, size_t errlen)
{
    /* the model does not depend on the settings: borrow a real demo's */
    (void)d;
    (void)settings;
    return demo_spring_pendulum.build(&demo_spring_pendulum, NULL, out, err,
                                      errlen);
}

static const demo test_demo = {"test-demo", "a demo with settings",
                               test_settings, 2, test_build, NULL, NULL,
                               NULL};

/* A demo whose setting is also a parameter name: a registry error. */
static const demo_setting clash_settings[] = {
    {"k", "", 1, 1, 2, 1, "clashes with the parameter k"},
};
static const demo clash_demo = {"clash", "bad", clash_settings, 1,
                                test_build, NULL, NULL, NULL};

static void test_overrides(void)
{
    static const char *const ok[] = {"links=5", "k=100", "width=1.5",
                                     "links=7", "r=1.3", "theta_dot=0.2"};
    override ov[8];
    double settings[2], x[4];
    char err[1024];
    eom_model *m = NULL;
    eom_system *s = NULL;
    size_t i;

    for (i = 0; i < sizeof ok / sizeof ok[0]; i++)
        CHECK_INT(override_parse(ok[i], &ov[i], err, sizeof err), 0);
    CHECK(ov[0].namelen == 5 && ov[0].value == 5.0);
    CHECK(override_parse("links", &ov[6], err, sizeof err) != 0);
    CHECK(strstr(err, "NAME=VALUE") != NULL);
    CHECK(override_parse("=1", &ov[6], err, sizeof err) != 0);
    CHECK(strstr(err, "empty name") != NULL);

    /* settings: defaults, then the values that name them (last wins) */
    CHECK_INT(overrides_settings(ov, 0, &test_demo, settings, err,
                                 sizeof err), 0);
    CHECK(settings[0] == 3.0 && settings[1] == 0.5);
    CHECK_INT(overrides_settings(ov, 6, &test_demo, settings, err,
                                 sizeof err), 0);
    CHECK(settings[0] == 7.0 && settings[1] == 1.5);
    CHECK_INT(override_parse("links=2.5", &ov[6], err, sizeof err), 0);
    CHECK(overrides_settings(ov, 7, &test_demo, settings, err,
                             sizeof err) != 0);
    CHECK(strstr(err, "integer") != NULL);
    CHECK_INT(override_parse("links=21", &ov[6], err, sizeof err), 0);
    CHECK(overrides_settings(ov, 7, &test_demo, settings, err,
                             sizeof err) != 0);
    CHECK(strstr(err, "between 1 and 20") != NULL);
    CHECK_INT(override_parse("width=-0.1", &ov[6], err, sizeof err), 0);
    CHECK(overrides_settings(ov, 7, &test_demo, settings, err,
                             sizeof err) != 0);

    /* the rest goes to the system; settings are skipped there */
    CHECK_INT(test_demo.build(&test_demo, settings, &m, err, sizeof err), 0);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    CHECK_INT(demo_check_names(&test_demo, s, err, sizeof err), 0);
    CHECK(demo_check_names(&clash_demo, s, err, sizeof err) != 0);
    CHECK(strstr(err, "'k'") != NULL);
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK_INT(overrides_apply(ov, 6, &test_demo, s, x, err, sizeof err), 0);
    CHECK(eom_get_param(s, eom_param_index(s, "k")) == 100.0);
    CHECK(x[0] == 1.3 && x[1] == 0.5 && x[2] == 0.0 && x[3] == 0.2);
    /* an unknown name lists the names, settings first */
    CHECK_INT(override_parse("links_dot=1", &ov[6], err, sizeof err), 0);
    CHECK(overrides_apply(ov, 7, &test_demo, s, x, err, sizeof err) != 0);
    CHECK(strstr(err, "named 'links_dot'") != NULL);
    CHECK(strstr(err, "its names are links, width, m, k, r0, g, r, theta, "
                      "r_dot, theta_dot") != NULL);
    eom_system_free(&s);
}

static void test_registry(void)
{
    int n, i, j;
    const demo *const *all = demos_all(&n);
    CHECK(n >= 1);
    CHECK(demo_find("spring-pendulum") == &demo_spring_pendulum);
    CHECK(demo_find("spring") == NULL);
    CHECK(demo_find(NULL) == NULL);
    for (i = 0; i < n; i++) {
        /* every demo builds with its default settings, and its settings
         * are well formed */
        double settings[16];
        eom_model *m = NULL;
        eom_system *s = NULL;
        char err[512];
        CHECK(all[i]->nsettings <= 16);
        for (j = 0; j < all[i]->nsettings && j < 16; j++) {
            const demo_setting *st = &all[i]->settings[j];
            CHECK(st->min <= st->dflt && st->dflt <= st->max);
            CHECK(!st->integer || st->dflt == floor(st->dflt));
            settings[j] = st->dflt;
        }
        CHECK(strlen(all[i]->summary) > 0 && !strchr(all[i]->summary, '\n'));
        CHECK_INT(all[i]->build(all[i], settings, &m, err, sizeof err), 0);
        CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
        if (s)
            CHECK_INT(demo_check_names(all[i], s, err, sizeof err), 0);
        eom_system_free(&s);
        eom_model_free(&m);
    }
}

int main(void)
{
    test_numtext();
    test_overrides();
    test_registry();
    CHECK_DONE();
}
