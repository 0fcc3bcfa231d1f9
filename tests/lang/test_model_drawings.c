/* test_model_drawings.c - draw statements (docs/models.md, "Drawings")
 * and the drawings' C API (eom/drawing.h): the values of each kind
 * against positions worked out here by hand from the same coordinates,
 * families, the time, the defaults of optional arguments, a clone, the
 * probes left alone, and every error with its line and column. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/drawing.h"
#include "eom/model_file.h"

static eom_system *build(const char *text)
{
    char err[4096];
    eom_model *m = NULL;
    eom_system *s = NULL;
    if (eom_model_from_string(&m, text, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("model: %s", err);
        return NULL;
    }
    if (eom_system_new(&s, m, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("system: %s", err);
    eom_model_free(&m);
    return s;
}

/* The drawing called name, or a failed check. */
static int find(const eom_system *s, const char *name, eom_drawing *d)
{
    int k;
    for (k = 0; k < eom_system_ndrawings(s); k++)
        if (eom_drawing_get(s, k, d) == EOM_OK && strcmp(d->name, name) == 0)
            return k;
    CHECK_FAIL_("no drawing %s", name);
    return -1;
}

/* A planar double pendulum: rods, the bob with a trail, a polyline, a
 * circle with its default normal, a family of points. */
static const char planar[] =
    "param l1 = 1.3 [m]\n"
    "param l2 = 0.7 [m]\n"
    "param m = 1 [kg]\n"
    "param g = 9.81 [m/s^2]\n"
    "coord th1 = 0.4 [rad]\n"
    "coord th2 = -1.1 [rad]\n"
    "p1 = vec(l1*sin(th1), -l1*cos(th1), 0)\n"
    "p2 = p1 + vec(l2*sin(th2), -l2*cos(th2), 0)\n"
    "T = 1/2*m*(dot(der(p1), der(p1)) + dot(der(p2), der(p2)))\n"
    "V = m*g*(p1.y + p2.y)\n"
    "probe y2 = p2.y [m]\n"
    "draw segment rod1 = vec(0, 0, 0), p1 color \"blue\"\n"
    "draw segment rod2 = p1, p2\n"
    "draw point bob = p2 color \"#ff0000\" trail\n"
    "draw polyline arm = vec(0, 0, 0), p1,\n"
    "                    p2\n"
    "draw circle ring = p1, l2/2\n"
    "draw point mark[j in 1..3] = j/3*p2 color \"green\"\n";

static void check_planar(void)
{
    eom_system *s = build(planar);
    const double th1 = 0.4, th2 = -1.1, l1 = 1.3, l2 = 0.7;
    const double x1 = l1 * sin(th1), y1 = -l1 * cos(th1);
    const double x2 = x1 + l2 * sin(th2), y2 = y1 - l2 * cos(th2);
    double x[4] = {th1, th2, 0.3, -0.2}, *v;
    eom_drawing d;
    int k;
    if (!s)
        return;
    /* drawings are not probes: the CSV keeps its one probe */
    CHECK_INT(eom_system_nprobes(s), 1);
    CHECK_INT(eom_system_ndrawings(s), 8);
    CHECK_INT(eom_system_ndrawing_values(s), 6 + 6 + 3 + 9 + 7 + 3 * 3);
    v = calloc((size_t)eom_system_ndrawing_values(s), sizeof *v);
    CHECK_INT(eom_drawings_at(s, 0.0, x, v), EOM_OK);

    if ((k = find(s, "rod1", &d)) >= 0) {
        CHECK_INT(d.kind, EOM_DRAW_SEGMENT);
        CHECK_INT(d.count, 6);
        CHECK_INT(d.rgb, 0x1f5fbf);
        CHECK_INT(d.flags, 0);
        CHECK_NEAR(v[d.offset + 0], 0.0, 1e-15);
        CHECK_NEAR(v[d.offset + 3], x1, 1e-15);
        CHECK_NEAR(v[d.offset + 4], y1, 1e-15);
        CHECK_NEAR(v[d.offset + 5], 0.0, 1e-15);
    }
    if ((k = find(s, "rod2", &d)) >= 0) {
        CHECK_NEAR(v[d.offset + 0], x1, 1e-15);
        CHECK_NEAR(v[d.offset + 3], x2, 1e-15);
        CHECK_NEAR(v[d.offset + 4], y2, 1e-15);
    }
    if ((k = find(s, "bob", &d)) >= 0) {
        CHECK_INT(d.kind, EOM_DRAW_POINT);
        CHECK_INT(d.rgb, 0xff0000);
        CHECK_INT(d.flags, EOM_DRAW_TRAIL);
        CHECK_NEAR(v[d.offset + 0], x2, 1e-15);
        CHECK_NEAR(v[d.offset + 1], y2, 1e-15);
    }
    if ((k = find(s, "arm", &d)) >= 0) {
        CHECK_INT(d.kind, EOM_DRAW_POLYLINE);
        CHECK_INT(d.count, 9);
        CHECK_NEAR(v[d.offset + 6], x2, 1e-15);
        CHECK_NEAR(v[d.offset + 7], y2, 1e-15);
    }
    if ((k = find(s, "ring", &d)) >= 0) {
        CHECK_INT(d.kind, EOM_DRAW_CIRCLE);
        CHECK_NEAR(v[d.offset + 3], l2 / 2, 1e-15);
        CHECK_NEAR(v[d.offset + 4], 0.0, 0.0); /* normal (0, 0, 1) */
        CHECK_NEAR(v[d.offset + 6], 1.0, 0.0);
    }
    if ((k = find(s, "mark2", &d)) >= 0) {
        CHECK_INT(d.rgb, 0x2ca02c);
        CHECK_NEAR(v[d.offset + 0], 2.0 / 3.0 * x2, 1e-15);
        CHECK_NEAR(v[d.offset + 1], 2.0 / 3.0 * y2, 1e-15);
    }
    /* a clone draws the same */
    {
        eom_system *c = NULL;
        double *w = calloc((size_t)eom_system_ndrawing_values(s), sizeof *w);
        char err[256];
        CHECK_INT(eom_system_clone(&c, s, err, sizeof err), EOM_OK);
        CHECK_INT(eom_system_ndrawings(c), 8);
        CHECK_INT(eom_drawings_at(c, 0.0, x, w), EOM_OK);
        for (k = 0; k < eom_system_ndrawing_values(s); k++)
            CHECK_NEAR(w[k], v[k], 0.0);
        free(w);
        eom_system_free(&c);
    }
    /* a parameter set on the system moves the drawings */
    CHECK_INT(eom_set_param(s, eom_param_index(s, "l1"), 2.0), EOM_OK);
    CHECK_INT(eom_drawings_at(s, 0.0, x, v), EOM_OK);
    if ((k = find(s, "rod1", &d)) >= 0)
        CHECK_NEAR(v[d.offset + 3], 2.0 * sin(th1), 1e-15);
    CHECK_INT(eom_drawing_get(s, 8, &d), EOM_ERR_ARG);
    x[0] = NAN;
    CHECK(eom_drawings_at(s, 0.0, x, v) == EOM_ERR_NONFINITE);
    free(v);
    eom_system_free(&s);
}

/* Spatial kinds: a box turned about z, a frame, a cylinder, a sphere, a
 * disk with its normal, a point that reads the time. */
static const char spatial[] =
    "param m = 2 [kg]\n"
    "param g = 9.81 [m/s^2]\n"
    "param a = 0.5 [m]\n"
    "param v = 1 [m/s]\n"
    "coord psi = 0.3 [rad]\n"
    "coord h = 0.2 [m]\n"
    "Rz = rotz(psi)\n"
    "T = 1/2*m*(h_dot^2 + a^2*psi_dot^2)\n"
    "V = m*g*h\n"
    "draw box body = vec(0, 0, h), vec(2*a, a, a/2), Rz color \"orange\"\n"
    "draw box crate = vec(1, 2, 3), vec(a, a, a)\n"
    "draw frame axes = vec(0, 0, h), Rz, a\n"
    "draw cylinder axle = vec(0, 0, 0), vec(0, 0, h), a/10\n"
    "draw sphere ball = Rz*vec(a, 0, 0), a/5\n"
    "draw disk wheel = vec(0, 0, h), a, Rz*vec(1, 0, 0)\n"
    "draw point clock = v*vec(t, 0, 0)\n";

static void check_spatial(void)
{
    eom_system *s = build(spatial);
    const double psi = 0.3, h = 0.2, a = 0.5, c = cos(psi), sn = sin(psi);
    double x[4] = {psi, h, 0, 0}, *v;
    eom_drawing d;
    int k;
    if (!s)
        return;
    v = calloc((size_t)eom_system_ndrawing_values(s), sizeof *v);
    CHECK_INT(eom_drawings_at(s, 2.5, x, v), EOM_OK);
    if ((k = find(s, "body", &d)) >= 0) {
        const double want[15] = {0, 0, h, 2 * a, a, a / 2, c, -sn, 0,
                                 sn, c, 0, 0, 0, 1};
        int j;
        CHECK_INT(d.kind, EOM_DRAW_BOX);
        CHECK_INT(d.count, 15);
        for (j = 0; j < 15; j++)
            CHECK_NEAR(v[d.offset + j], want[j], 1e-15);
    }
    if ((k = find(s, "crate", &d)) >= 0) { /* the identity by default */
        CHECK_NEAR(v[d.offset + 6], 1.0, 0.0);
        CHECK_NEAR(v[d.offset + 7], 0.0, 0.0);
        CHECK_NEAR(v[d.offset + 10], 1.0, 0.0);
        CHECK_NEAR(v[d.offset + 14], 1.0, 0.0);
    }
    if ((k = find(s, "axes", &d)) >= 0) {
        CHECK_INT(d.count, 13);
        CHECK_NEAR(v[d.offset + 3], c, 1e-15);
        CHECK_NEAR(v[d.offset + 6], sn, 1e-15);
        CHECK_NEAR(v[d.offset + 12], a, 1e-15);
    }
    if ((k = find(s, "axle", &d)) >= 0) {
        CHECK_NEAR(v[d.offset + 5], h, 1e-15);
        CHECK_NEAR(v[d.offset + 6], a / 10, 1e-15);
    }
    if ((k = find(s, "ball", &d)) >= 0) {
        CHECK_NEAR(v[d.offset + 0], a * c, 1e-15);
        CHECK_NEAR(v[d.offset + 1], a * sn, 1e-15);
        CHECK_NEAR(v[d.offset + 3], a / 5, 1e-15);
    }
    if ((k = find(s, "wheel", &d)) >= 0) {
        CHECK_INT(d.kind, EOM_DRAW_DISK);
        CHECK_NEAR(v[d.offset + 4], c, 1e-15);
        CHECK_NEAR(v[d.offset + 5], sn, 1e-15);
    }
    if ((k = find(s, "clock", &d)) >= 0)
        CHECK_NEAR(v[d.offset + 0], 2.5, 0.0);
    free(v);
    eom_system_free(&s);
}

/* The C API's own checks. */
static int cb_point(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    out[0] = eom_q(c, 0);
    out[1] = tp_const(eom_rec(c), 0.0);
    out[2] = tp_const(eom_rec(c), 0.0);
    return 0;
}

static int cb_half(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    out[0] = eom_q(c, 0); /* the other two left unset */
    return 0;
}

static int cb_T(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mul(eom_rec(c), eom_qd(c, 0), eom_qd(c, 0));
    return 0;
}

static void check_c_api(void)
{
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[512];
    double x[2] = {0.25, 0}, v[3];
    eom_model_new(&m);
    eom_model_add_coord(m, "x", "m", 0, 0);
    eom_model_add_kinetic(m, cb_T, NULL);
    CHECK_INT(eom_model_add_drawing(m, "p", EOM_DRAW_POINT, 3, 0xff, 0,
                                    cb_point, NULL), 0);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    CHECK_INT(eom_drawings_at(s, 0, x, v), EOM_OK);
    CHECK_NEAR(v[0], 0.25, 0.0);
    eom_system_free(&s);
    eom_model_free(&m);

    /* a count that does not fit the kind; a trail on a segment; a name
     * given twice; an unset value */
    eom_model_new(&m);
    CHECK_INT(eom_model_add_drawing(m, "p", EOM_DRAW_POINT, 4, 0, 0,
                                    cb_point, NULL), EOM_ERR_ARG);
    eom_model_free(&m);
    eom_model_new(&m);
    CHECK_INT(eom_model_add_drawing(m, "s", EOM_DRAW_SEGMENT, 6, 0,
                                    EOM_DRAW_TRAIL, cb_point, NULL),
              EOM_ERR_ARG);
    eom_model_free(&m);
    eom_model_new(&m);
    CHECK_INT(eom_model_add_drawing(m, "pl", EOM_DRAW_POLYLINE, 7, 0, 0,
                                    cb_point, NULL), EOM_ERR_ARG);
    eom_model_free(&m);
    eom_model_new(&m);
    eom_model_add_drawing(m, "p", EOM_DRAW_POINT, 3, 0, 0, cb_point, NULL);
    CHECK_INT(eom_model_add_drawing(m, "p", EOM_DRAW_POINT, 3, 0, 0,
                                    cb_point, NULL), EOM_ERR_NAME);
    eom_model_free(&m);
    eom_model_new(&m);
    eom_model_add_coord(m, "x", "m", 0, 0);
    eom_model_add_kinetic(m, cb_T, NULL);
    eom_model_add_drawing(m, "p", EOM_DRAW_POINT, 3, 0, 0, cb_half, NULL);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_ERR_RECORD);
    CHECK(strstr(err, "did not set value 2 of 3") != NULL);
    eom_model_free(&m);
    CHECK(eom_draw_kind_name(EOM_DRAW_FRAME) &&
          strcmp(eom_draw_kind_name(EOM_DRAW_FRAME), "frame") == 0);
    CHECK(eom_draw_kind_name(0) == NULL);
}

typedef struct err_case {
    const char *what;
    const char *text;
    int line, col;
    const char *msg;
} err_case;

#define HEAD                                                               \
    "param m = 1 [kg]\ncoord x = 0 [m]\nT = 1/2*m*x_dot^2\n"

static const err_case cases[] = {
    {"a non-length", HEAD "draw point p = vec(m, 0, 0)\n", 4, 16,
     "the point of the point p is in kg, not in m"},
    {"a rotation where a point is needed", HEAD "draw point p = rotz(0.5)\n",
     4, 16, "the point of the point p is a matrix (a rotation?); it must be "
            "a vector"},
    {"a scalar where a point is needed",
     HEAD "draw segment s = vec(0, 0, 0), x\n", 4, 32,
     "the second end of the segment s is a scalar"},
    {"a vector radius", HEAD "draw sphere b = vec(x, 0, 0), vec(1, 0, 0)\n",
     4, 31, "the radius of the sphere b is a vector"},
    {"a rotation with units",
     HEAD "draw frame f = vec(0, 0, 0), x*rotz(1), 1\n", 4, 30,
     "the rotation of the frame f is in m, not in 1"},
    {"a point in a plane of lengths and times",
     HEAD "draw polyline l = vec(0, 0, 0), vec(x, 0, 0), vec(x_dot, 0, 0)\n",
     4, 47, "a point of the polyline l is in m s^-1, not in m"},
    {"an unknown kind", HEAD "draw blob b = vec(x, 0, 0)\n", 4, 6,
     "'blob' is not a kind of drawing"},
    {"too few arguments", HEAD "draw segment s = vec(x, 0, 0)\n", 4, 6,
     "a segment takes 2 arguments, not 1"},
    {"too many arguments", HEAD "draw circle c = vec(x, 0, 0), 1, "
                           "vec(0, 0, 1), 2\n",
     4, 6, "a circle takes 2 or 3 arguments, not 4"},
    {"a trail on a segment",
     HEAD "draw segment s = vec(0, 0, 0), vec(x, 0, 0) trail\n", 4, 45,
     "only a point has a trail, not a segment"},
    {"an unknown colour", HEAD "draw point p = vec(x, 0, 0) color \"mauve\"\n",
     4, 35, "unknown colour \"mauve\""},
    {"a drawing named like a probe",
     HEAD "probe p = x [m]\ndraw point p = vec(x, 0, 0)\n", 5, 12,
     "p is defined twice"},
    {"an unknown name", HEAD "draw point p = vec(y, 0, 0)\n", 4, 20,
     "unknown name 'y'"},
    {"something after the arguments",
     HEAD "draw point p = vec(x, 0, 0) big\n", 4, 29,
     "expected color \"...\" or trail"},
};

static void check_errors(void)
{
    size_t k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const err_case *c = &cases[k];
        char err[4096];
        eom_model *m = NULL;
        int line = 0, col = 0;
        int rc = eom_model_from_string(&m, c->text, err, sizeof err);
        if (rc != EOM_ERR_FILE || m) {
            CHECK_FAIL_("%s: status %d, expected EOM_ERR_FILE", c->what, rc);
            eom_model_free(&m);
            continue;
        }
        if (sscanf(err, "<string>:%d:%d:", &line, &col) != 2 ||
            line != c->line || col != c->col)
            CHECK_FAIL_("%s: at %d:%d, expected %d:%d\n%s", c->what, line,
                        col, c->line, c->col, err);
        if (!strstr(err, c->msg))
            CHECK_FAIL_("%s: message lacks '%s':\n%s", c->what, c->msg, err);
        check_count_++;
    }
}

/* A value named draw is still a value, and units off lets a drawing be in
 * anything. */
static void check_accepted(void)
{
    eom_system *s = build("param m = 1 [kg]\nparam g = 9.81 [m/s^2]\n"
                          "coord x = 0 [m]\ndraw = 2*x\n"
                          "T = 1/2*m*x_dot^2\nV = m*g*draw\n");
    CHECK(s && eom_system_ndrawings(s) == 0);
    eom_system_free(&s);
    s = build("units off\nparam m = 1\ncoord x = 0\nT = 1/2*m*x_dot^2\n"
              "draw point p = vec(m, x, 0)\n");
    CHECK(s && eom_system_ndrawings(s) == 1);
    eom_system_free(&s);
}

int main(void)
{
    check_planar();
    check_spatial();
    check_c_api();
    check_errors();
    check_accepted();
    CHECK_DONE();
}
