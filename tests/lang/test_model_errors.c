/* test_model_errors.c - one case per class of error a model file can
 * have: each must be reported before anything runs, as
 * "<string>:LINE:COL: message", with the source line, a caret under the
 * column, and the suggestion where one is knowable. A case names the
 * line, the column and words of the message and of the hint. The time t
 * is refused only where a value is fixed when the file is read; what it
 * once was refused in (a potential energy) now builds. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"

typedef struct err_case {
    const char *what;
    const char *text;
    int line, col;
    const char *msg;  /* in the first line */
    const char *hint; /* anywhere (NULL: none checked) */
} err_case;

#define HEAD "param m = 1 [kg]\ncoord x = 0 [m]\n"

static const err_case cases[] = {
    {"unknown name, nearest suggested", HEAD "T = 1/2*m*x_dto^2\n", 3, 11,
     "unknown name 'x_dto'", "did you mean 'x_dot'?"},
    {"unknown function", HEAD "T = 1/2*m*x_dot^2\nV = m*9.81*zzyzx(x)\n", 4,
     12, "unknown function 'zzyzx'", "the functions are sqrt"},
    {"misspelled function", HEAD "T = 1/2*m*x_dot^2\nV = m*9.81*x*cso(0)\n",
     4, 14, "unknown function 'cso'", "did you mean 'cos'?"},
    {"defined twice", HEAD "param m = 2 [kg]\nT = 1/2*m*x_dot^2\n", 3, 7,
     "m is defined twice", "first definition is on line 1"},
    {"definition defined twice", HEAD "a = x\na = 2*x\nT = 1/2*m*x_dot^2\n",
     4, 1, "a is defined twice", "line 3"},
    {"energy defined twice", HEAD "T = 1/2*m*x_dot^2\nT = m*x_dot^2\n", 4, 1,
     "T is defined twice", "line 3"},
    {"wrong number of arguments", HEAD "T = 1/2*m*x_dot^2*sin(x, 2)\n", 3,
     19, "sin takes 1 argument, not 2", NULL},
    {"wrong number of indices",
     "setting n = 2\nparam m = 1 [kg]\ncoord x[j in 1..n] = 0 [m]\n"
     "T = 1/2*m*x_dot^2\n",
     4, 11, "x_dot has 1 index, not 0", "write x_dot[j]"},
    {"index out of range",
     "setting n = 3\nparam m = 1 [kg]\ncoord x[j in 1..n] = 0 [m]\n"
     "T = 1/2*m*sum(j in 1..n, x_dot[j+1]^2)\n",
     4, 26, "x[4]: index 4 is out of range", "1..3"},
    {"recurrence without a base case",
     "setting n = 3\nparam m = 1 [kg]\ncoord x[j in 1..n] = 0 [m]\n"
     "v[j in 1..n] = v[j-1] + x_dot[j]\n"
     "T = 1/2*m*sum(j in 1..n, v[j]^2)\n",
     4, 16, "v[0] is not defined", "needs a base case: add a line such as "
                                      "v[0] = ..."},
    {"cycle among definitions",
     "units off\nparam m = 1\ncoord x = 0\na = b + 1\nb = 2*a\n"
     "T = 1/2*m*x_dot^2 + 0*a + b*x_dot^2\n",
     5, 7, "a depends on itself", "recurrence must reach a base case"},
    {"missing T", HEAD "V = 9.81*m*x\n", 1, 1,
     "the model has no kinetic energy T", NULL},
    {"missing T (no energy at all)", HEAD "a = x\n", 1, 1,
     "the model has no kinetic energy T", "T = 1/2*m*x_dot^2"},
    {"T does not depend on a rate", HEAD "coord y = 0 [m]\nT = 1/2*m*x_dot^2\n",
     4, 1, "T does not depend on y_dot: the mass matrix would be singular",
     "1/2*m*y_dot^2"},
    {"unit that does not parse", "param m = 1 [kgs]\ncoord x = 0 [m]\n"
     "T = 1/2*m*x_dot^2\n", 1, 14, "'kgs' is not a unit", "SI symbols"},
    {"unit with a prefix", "param m = 1 [kg]\ncoord x = 0 [mm]\n"
     "T = 1/2*m*x_dot^2\n", 2, 14, "'mm' is not a unit", "without prefixes"},
    {"missing unit", "param m = 1\ncoord x = 0 [m]\nT = 1/2*m*x_dot^2\n", 1,
     7, "parameter m has no unit", "units off"},
    {"units that do not add", HEAD "T = 1/2*m*x_dot^2 + m*x\n", 3, 19,
     "units do not agree: kg m^2 s^-2 (J) plus kg m", NULL},
    {"T not in energy units", HEAD "T = 1/2*m*x_dot\n", 3, 1,
     "the kinetic energy T is in kg m s^-1, not in kg m^2 s^-2 (J)", NULL},
    {"R not a power", HEAD "T = 1/2*m*x_dot^2\nR = 1/2*m*x_dot^2\n", 4, 1,
     "the dissipation function R is in kg m^2 s^-2 (J), not in kg m^2 s^-3 "
     "(W)", NULL},
    {"force in the wrong units", HEAD "T = 1/2*m*x_dot^2\nforce x = m*x\n", 4,
     1, "this force is in kg m, not in kg m s^-2 (N)", "J/(m)"},
    {"time in an initial value",
     "units off\nparam m = 1\ncoord x = 2*t\nT = 1/2*m*x_dot^2\n", 3, 13,
     "the time t cannot be used here", "constraints and probes"},
    {"time in the wrong units", HEAD "T = 1/2*m*x_dot^2\nV = m*x*t\n", 4, 1,
     "the potential energy V is in kg m s, not in kg m^2 s^-2 (J)", NULL},
    {"time without a rate in a function",
     HEAD "coord y = 0 [m]\nT = 1/2*m*(x_dot^2 + y_dot^2)\n"
     "constraint c = x - sin(t)\n", 5, 20, "sin() needs a pure number, not s",
     NULL},
    {"time in a parameter's default",
     "param m = 1 + t [kg]\ncoord x = 0 [m]\nT = 1/2*m*x_dot^2\n", 1, 15,
     "the time t cannot be used here", "T, V, L, R"},
    {"rate in a constraint",
     "units off\nparam m = 1\ncoord x = 0\ncoord y = 1\n"
     "T = 1/2*m*(x_dot^2 + y_dot^2)\nconstraint c = x*y_dot\n",
     6, 18, "the rate y_dot cannot appear in the constraint c", NULL},
    /* a coordinate's initial value may use a parameter; a parameter's
     * default may not (it would not follow the other's changes) */
    {"parameter in a parameter's default",
     "param m = 1 [kg]\nparam r0 = 1 [m]\nparam r1 = 2*r0 [m]\n"
     "coord x = r0 [m]\nT = 1/2*m*x_dot^2\n", 3, 14,
     "the parameter r0 cannot be used here", NULL},
    {"comparison of a coordinate", HEAD "T = 1/2*m*x_dot^2*if(x > 0, 1, 2)\n",
     3, 24, "a comparison must be known when the file is read",
     "not coordinates or parameters"},
    {"reserved name", "param L = 1 [m]\ncoord x = 0 [m]\n", 1, 7,
     "'L' is reserved (the Lagrangian)", "len"},
    {"name ending in _dot", "param m = 1 [kg]\ncoord x_dot = 0 [m]\n", 2, 7,
     "a name cannot end in _dot", NULL},
    {"unclosed parenthesis", HEAD "T = 1/2*m*(x_dot^2\nV = 0\n", 3, 11,
     "'(' is never closed", NULL},
    {"line starting with an operator", HEAD "T = 1/2*m*x_dot^2\n  + m*x\n", 4,
     3, "a line cannot start with an operator", "end the line before"},
    {"number followed by a name", HEAD "T = 1/2m*x_dot^2\n", 3, 8,
     "a name cannot follow a number", "2*x"},
    {"bad character", HEAD "T = 1/2*m*x_dot^2 $\n", 3, 19,
     "unexpected character '$'", NULL},
    {"non-ASCII byte", HEAD "T = 1/2*m*x_dot\xc2\xb2\n", 3, 16,
     "unexpected byte 0xc2", "plain ASCII"},
    {"setting default outside its range",
     "setting n = 5 in 1..3\n" HEAD "T = 1/2*m*x_dot^2\n", 1, 13,
     "the default of n is outside its range", "1..3"},
    {"space before an index",
     "setting n = 2\nparam m = 1 [kg]\ncoord x[j in 1..n] = 0 [m]\n"
     "T = 1/2*m*x_dot [1]^2\n", 4, 17, "unexpected '['", "theta[j]"},
    {"L together with T", HEAD "T = 1/2*m*x_dot^2\nL = 1/2*m*x_dot^2\n", 4, 1,
     "a Lagrangian L together with T", NULL},
    /* vectors, matrices, der() */
    {"an energy that is a vector",
     HEAD "T = 1/2*m*x_dot^2\nV = vec(x, 0, 0)\n", 4, 1,
     "the potential energy V is a vector; it must be a scalar",
     "take a component"},
    {"a scalar function of a vector",
     HEAD "p = vec(x, 0, 0)\nT = 1/2*m*x_dot^2*sin(p)\n", 4, 23,
     "sin() needs a scalar, not a vector", "dot() or norm()"},
    {"a vector function of a scalar", HEAD "T = 1/2*m*dot(x_dot, x_dot)\n",
     3, 15, "dot() needs a vector, not a scalar", NULL},
    {"a vector plus a matrix",
     HEAD "a = vec(x, x, x) + diag(x, x, x)\nT = 1/2*m*x_dot^2\n", 3, 18,
     "a vector plus or minus a matrix", "same shape"},
    {"a vector times a vector",
     HEAD "a = vec(x, 0, 0)*vec(x, 0, 0)\nT = 1/2*m*x_dot^2\n", 3, 17,
     "a vector times a vector", "dot(a, b)"},
    {"a vector times a matrix",
     HEAD "a = vec(x, 0, 0)*rotx(1)\nT = 1/2*m*x_dot^2\n", 3, 17,
     "a vector times a matrix", "transpose(M)*v"},
    {"a component of a scalar", HEAD "T = 1/2*m*x_dot.x^2\n", 3, 17,
     "a scalar has no component .x", "only vectors and matrices"},
    {"a matrix's component of a vector",
     HEAD "a = vec(x, 0, 0)\nT = 1/2*m*x_dot^2 + 0*a.xy\n", 4, 25,
     "a vector has no component .xy", ".x .y .z"},
    {"not a component", HEAD "a = vec(x, 0, 0)\nT = 1/2*m*x_dot^2*a.w\n", 4,
     21, "expected a component after '.'", ".xx .xy"},
    {"mat() of two", HEAD "a = mat(vec(x, 0, 0), vec(x, 0, 0))\n"
     "T = 1/2*m*x_dot^2\n", 3, 5, "mat takes 9 numbers or 3 rows, not 2",
     "mat(row1, row2, row3)"},
    {"a definition that changes shape",
     "setting n = 2\n" HEAD "a[0] = x\na[j in 1..n] = vec(x, 0, 0)\n"
     "T = 1/2*m*x_dot^2\n", 5, 1, "a is a vector here but not on line 4",
     "on line 4 it is a scalar"},
    {"units mixed in a vector",
     HEAD "a = vec(x, m, 0)\nT = 1/2*m*x_dot^2\n", 3, 12,
     "units do not agree: kg in one vector or matrix with m", NULL},
    {"a rotation by a length", HEAD "a = rotx(x)\nT = 1/2*m*x_dot^2\n", 3,
     10, "rotx() needs a pure number, not m", "angles are in rad"},
    {"der() of a rate",
     "units off\nparam m = 1\ncoord x = 0\nT = 1/2*m*der(x_dot)^2\n", 4,
     15, "der() of an expression that holds the rate x_dot",
     "write der() of the position"},
    {"der() inside der()",
     "units off\nparam m = 1\ncoord x = 0\nT = 1/2*m*der(der(x))^2\n", 4,
     15, "der() of an expression that already holds rates",
     "accelerations"},
    {"a velocity constraint not linear in the rates",
     "units off\nparam m = 1\ncoord x = 0\ncoord y = 0\n"
     "T = 1/2*m*(x_dot^2 + y_dot^2)\n"
     "velocity constraint skid = x_dot*sin(y_dot) - y_dot\n", 6, 34,
     "the velocity constraint skid is not linear in the rates here",
     "A(q, t) qd + b(q, t) = 0"},
    {"a velocity constraint with a product of rates",
     "units off\nparam m = 1\ncoord x = 0\ncoord y = 0\n"
     "T = 1/2*m*(x_dot^2 + y_dot^2)\n"
     "a = x*y_dot\nvelocity constraint skid = y_dot + x_dot*a\n", 7, 41,
     "the velocity constraint skid is not linear in the rates here", NULL},
    {"a velocity constraint without rates",
     HEAD "coord y = 0 [m]\nT = 1/2*m*x_dot^2\n"
     "velocity constraint c = x - y\n", 5, 21,
     "the velocity constraint c reads no rates", "`constraint NAME = ...`"},
    {"a multiplier in an energy",
     HEAD "constraint c = x\nT = 1/2*m*x_dot^2 + lambda_c*x\n", 4, 21,
     "the multiplier lambda_c can be read by a probe only, not by the "
     "kinetic energy", "a probe may report it"},
    {"a vector constraint's multiplier without its component",
     HEAD "T = 1/2*m*x_dot^2\nconstraint at = vec(x, x, x)\n"
     "probe p = lambda_at\n", 5, 11,
     "the constraint at has a row per component: write lambda_at_x", NULL},
    {"a scalar constraint's multiplier with a component",
     HEAD "T = 1/2*m*x_dot^2\nconstraint c = x\nprobe p = lambda_c_y\n",
     5, 11, "the constraint c is a scalar: write lambda_c", NULL},
    {"der() of a multiplier",
     HEAD "T = 1/2*m*x_dot^2\nconstraint c = x\n"
     "probe p = der(lambda_c) [N/s]\n", 5, 15,
     "der() of an expression that holds the multiplier lambda_c", NULL},
    {"a multiplier in the wrong unit",
     HEAD "T = 1/2*m*x_dot^2\nconstraint c = x\nprobe p = lambda_c [J]\n",
     5, 7, "kg m s^-2", NULL},
    {"a matrix constraint",
     HEAD "T = 1/2*m*x_dot^2\nconstraint c = diag(x, x, x)\n", 4, 12,
     "the constraint c is a matrix", NULL},
    {"a number beyond the doubles", "param a = 1e999 [m]\n" HEAD
     "T = 1/2*m*x_dot^2\n", 1, 11, "the number 1e999 is too large", NULL},
    {"chained comparisons",
     HEAD "T = 1/2*m*x_dot^2*if(1 < 2 < 3, 1, 0)\n", 3, 28,
     "comparisons do not chain", "(a < b)*(b < c)"},
    {"a scalar and an indexed definition of one name",
     HEAD "a = x\na[j in 1..2] = x\nT = 1/2*m*x_dot^2\n", 4, 1,
     "a is defined twice", "line 3"},
    {"the square root of an odd power of a unit",
     HEAD "T = 1/2*m*x_dot^2 + 0*sqrt(sqrt(m))\n", 3, 23,
     "the square root of kg^0.5 has a fractional unit", NULL},
    {"too many indices", "param m = 1 [kg]\n"
     "coord x[a in 1..2, b in 1..2, c in 1..2, d in 1..2, e in 1..2] = 0 "
     "[m]\nT = 1/2*m*x_dot[1, 1, 1, 1]^2\n", 2, 53, "too many indices",
     NULL},
    {"a long name two edits away",
     HEAD "param theta_long_name = 1 [m]\n"
     "T = 1/2*m*x_dot^2 + 0*m*theta_lnog_nmae\n", 4, 25,
     "unknown name 'theta_lnog_nmae'", "did you mean 'theta_long_name'?"},
    {"a quaternion that is not of unit length at the start",
     "units off\nparam m = 1\ncoord a = 0.3\n"
     "Rq = quat(cos(a/2), sin(a/2), 0, 0.1)\nT = 1/2*m*a_dot^2 + 0*Rq.xx\n",
     4, 6, "the quaternion of quat() has length 1.00498756211", "= 1"},
    {"a constant quaternion not of unit length",
     "units off\nparam m = 1\ncoord a = 0.3\nT = 1/2*m*a_dot^2\n"
     "probe z = quat(2, 0, 0, 0).zz\n",
     5, 11, "the quaternion of quat() has length 2, not 1", NULL},
    {"der() in a holonomic constraint",
     HEAD "T = 1/2*m*x_dot^2\nconstraint c = der(x)\n", 4, 20,
     "der() cannot appear in the constraint c", "velocity constraint"},
};

/* "<string>:LINE:COL: message..." */
static void check_case(const err_case *c)
{
    char err[4096], *nl;
    eom_model *m = NULL;
    int line = 0, col = 0, rc;
    rc = eom_model_from_string(&m, c->text, err, sizeof err);
    if (rc != EOM_ERR_FILE || m) {
        CHECK_FAIL_("%s: status %d, expected EOM_ERR_FILE", c->what, rc);
        eom_model_free(&m);
        return;
    }
    if (sscanf(err, "<string>:%d:%d:", &line, &col) != 2) {
        CHECK_FAIL_("%s: no place in '%s'", c->what, err);
        return;
    }
    if (line != c->line || col != c->col)
        CHECK_FAIL_("%s: at %d:%d, expected %d:%d\n%s", c->what, line, col,
                    c->line, c->col, err);
    /* the source line and a caret under the column */
    nl = strchr(err, '\n');
    if (!nl || !strchr(nl + 1, '\n') || !strchr(nl, '^'))
        CHECK_FAIL_("%s: no source line and caret in\n%s", c->what, err);
    if (c->msg) {
        char first[1024];
        size_t n = nl ? (size_t)(nl - err) : strlen(err);
        snprintf(first, sizeof first, "%.*s", (int)n, err);
        if (!strstr(first, c->msg))
            CHECK_FAIL_("%s: message lacks '%s':\n%s", c->what, c->msg, err);
    }
    if (c->hint && !strstr(err, c->hint))
        CHECK_FAIL_("%s: hint lacks '%s':\n%s", c->what, c->hint, err);
    check_count_++;
}

/* The caret sits under the reported column. */
static void check_caret(void)
{
    char err[2048];
    eom_model *m = NULL;
    const char *src, *caret;
    CHECK(eom_model_from_string(&m, HEAD "T = 1/2*m*x_dto^2\n", err,
                                sizeof err) == EOM_ERR_FILE);
    src = strchr(err, '\n');
    caret = src ? strchr(src + 1, '\n') : NULL;
    CHECK(src && caret);
    if (src && caret) {
        /* "  T = ..." then "  ^" under column 11 */
        CHECK(strncmp(src + 1, "  T = 1/2*m*x_dto^2", 19) == 0);
        CHECK(caret[1 + 2 + 10] == '^');
    }
}

/* Limits: file size, nesting, and the settings' API. */
static void check_limits(void)
{
    char err[2048];
    size_t n = (1u << 20) + 10, k;
    char *big = malloc(n + 1), *deep = malloc(4000);
    eom_model *m = NULL;
    eom_file *f = NULL;
    memset(big, '#', n);
    big[n] = '\0';
    CHECK(eom_model_from_string(&m, big, err, sizeof err) == EOM_ERR_FILE);
    CHECK(strstr(err, "longer than 1 MiB") != NULL);
    /* 300 nested parentheses: beyond the documented 200 */
    strcpy(deep, HEAD "T = ");
    for (k = 0; k < 300; k++)
        strcat(deep, "(");
    strcat(deep, "x_dot");
    for (k = 0; k < 300; k++)
        strcat(deep, ")");
    strcat(deep, "\n");
    CHECK(eom_model_from_string(&m, deep, err, sizeof err) == EOM_ERR_FILE);
    CHECK(strstr(err, "deeper than 200") != NULL);
    CHECK(strstr(err, "<string>:3:") == err);
    /* settings: unknown name and out of range */
    CHECK(eom_file_parse(&f, "setting n = 2 in 1..4 \"a count, with a "
                         "description longer than sixty-four characters "
                         "to keep whole\"\n" HEAD "T = 1/2*m*x_dot^2\n",
                         "s.eom", err, sizeof err) == EOM_OK);
    CHECK(strcmp(eom_file_setting_description(f, 0),
                 "a count, with a description longer than sixty-four "
                 "characters to keep whole") == 0);
    CHECK(eom_file_setting_description(f, 1) == NULL);
    CHECK(eom_file_set_setting(f, "links", 3, err, sizeof err) ==
          EOM_ERR_NAME);
    CHECK(strstr(err, "links is not a setting of s.eom") != NULL);
    CHECK(eom_file_set_setting(f, "n", 5, err, sizeof err) == EOM_ERR_ARG);
    CHECK(strstr(err, "outside its range 1..4") != NULL);
    CHECK(eom_file_set_setting(f, "n", 4, err, sizeof err) == EOM_OK);
    CHECK(eom_file_setting(f, 0) == 4);
    eom_file_free(&f);
    /* a file that does not exist */
    CHECK(eom_model_from_file(&m, "/nonexistent/x.eom", err, sizeof err) ==
          EOM_ERR_FILE);
    CHECK(strstr(err, "cannot open the model file") != NULL);
    free(big);
    free(deep);
}

/* Energies, dissipation and constraints may read the time: the file that
 * was once refused for V = x*t builds, and its system says it reads the
 * time. */
static void time_allowed(void)
{
    static const char *const texts[] = {
        "units off\nparam m = 1\ncoord x = 0\nT = 1/2*m*x_dot^2\nV = x*t\n",
        "units off\nparam m = 1\ncoord x = 0\nT = 1/2*m*(x_dot - t)^2\n",
        "units off\nparam m = 1\ncoord x = 0\nT = 1/2*m*x_dot^2\n"
        "R = 1/2*t*x_dot^2\n",
        "units off\nparam m = 1\ncoord x = 0\ncoord y = 1\n"
        "T = 1/2*m*(x_dot^2 + y_dot^2)\nconstraint c = x - 2*t\n",
        "units off\nparam m = 1\ncoord x = 0\nT = 1/2*m*x_dot^2\n"
        "probe p = x*t\n"};
    char err[2048];
    size_t k;
    for (k = 0; k < sizeof texts / sizeof texts[0]; k++) {
        eom_model *m = NULL;
        eom_system *s = NULL;
        int rc = eom_model_from_string(&m, texts[k], err, sizeof err);
        if (rc != EOM_OK) {
            CHECK_FAIL_("time case %zu refused: %s", k, err);
            continue;
        }
        CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
        CHECK_INT(eom_system_reads_time(s), 1);
        eom_system_free(&s);
        eom_model_free(&m);
    }
}

/* Forms that must build: a mutant that refuses them is caught here. */
static void accepted(void)
{
    static const char *const ok[] = {
        /* a pure number raised to a parameter's power */
        "param n = 2 [1]\nparam l = 1 [m]\nparam g = 9.81 [m/s^2]\n" HEAD
        "V = m*g*l*(x/l)^n\nT = 1/2*m*x_dot^2\n",
        /* a family whose name ends in a digit */
        "param m = 1 [kg]\ncoord x1[j in 1..2] = 0 [m]\n"
        "T = 1/2*m*sum(j in 1..2, x1_dot[j]^2)\n",
    };
    char err[4096];
    eom_model *m = NULL;
    eom_system *s = NULL;
    eom_file *f = NULL;
    size_t k;
    for (k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        if (eom_model_from_string(&m, ok[k], err, sizeof err) != EOM_OK)
            CHECK_FAIL_("refused:\n%s\n%s", ok[k], err);
        else
            check_count_++;
        if (k == 1 && m && eom_system_new(&s, m, err, sizeof err) == EOM_OK) {
            /* members of x1 are x1_1 and x1_2, never x11 */
            CHECK(strcmp(eom_coord_name(s, 0), "x1_1") == 0);
            CHECK(strcmp(eom_coord_name(s, 1), "x1_2") == 0);
        }
        eom_system_free(&s);
        eom_model_free(&m);
    }
    /* a setting below or above its range, through the API */
    CHECK_INT(eom_file_parse(&f, "setting n = 2 in 1..3\n" HEAD
                             "T = 1/2*m*x_dot^2\n", "s", err, sizeof err),
              EOM_OK);
    CHECK(eom_file_set_setting(f, "n", 0, err, sizeof err) != EOM_OK);
    CHECK(strstr(err, "1..3") != NULL);
    CHECK(eom_file_set_setting(f, "n", 4, err, sizeof err) != EOM_OK);
    CHECK_INT(eom_file_set_setting(f, "n", 3, err, sizeof err), EOM_OK);
    eom_file_free(&f);
}

int main(void)
{
    size_t k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++)
        check_case(&cases[k]);
    time_allowed();
    check_caret();
    check_limits();
    accepted();
    CHECK_DONE();
}
