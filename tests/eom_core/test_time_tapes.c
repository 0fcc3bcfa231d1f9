/* test_time_tapes.c - a model that does not read the time pays nothing for
 * the possibility (white-box: eom_internal.h). For every shipped model
 * file that does not read it and for the C test models: the system says
 * so, no tape carries the time (neither as an independent nor as the
 * EOM_TIME_NAME parameter), the L and phi tapes have 2n and n
 * independents, and the L tape is op for op the tape a plain recording of
 * the same Lagrangian on 2n independents gives. A model that reads the
 * time gets it exactly where it reads it: as the last independent of the
 * L and phi tapes, as a parameter of the E and R tapes, and nowhere else.
 *
 * usage: test_time_tapes MODELS_DIR */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"
#include "eom_internal.h"
#include "eom_models.h"

/* The tape of eom_model_run_lagrangian on a recorder of 2n independents,
 * grouped as the system groups them. */
static tp_tape *plain_L(const eom_model *md, int n)
{
    unsigned char group[256];
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    int k;
    if (2 * n > (int)sizeof group)
        return NULL;
    for (k = 0; k < 2 * n; k++)
        group[k] = (unsigned char)(k < n ? 0 : 1);
    if (tp_recorder_new(&r, 2 * n, group, NULL) == TP_OK &&
        eom_model_run_lagrangian(md, r, NULL) == EOM_OK)
        tp_recorder_finish(r, &t);
    tp_rec_free(&r);
    return t;
}

static int has_time_param(const eom_tape *et)
{
    return et->tape && tp_tape_param_index(et->tape, EOM_TIME_NAME) >= 0;
}

/* md (freed here) does not read the time. */
static void timeless(const char *what, eom_model *md)
{
    eom_system *s = NULL;
    tp_tape *plain;
    char msg[512];
    size_t diff = 0;
    int n;
    if (!md || eom_system_new(&s, md, msg, sizeof msg) != EOM_OK) {
        CHECK_FAIL_("%s: %s", what, md ? msg : "no model");
        eom_model_free(&md);
        return;
    }
    n = s->n;
    CHECK_INT(eom_system_reads_time(s), 0);
    CHECK_INT(tp_tape_n_indep(s->tL.tape), 2 * n);
    CHECK(s->tL.tindex < 0 && s->tphi.tindex < 0);
    CHECK(!has_time_param(&s->tL) && !has_time_param(&s->tE) &&
          !has_time_param(&s->tR) && !has_time_param(&s->tphi) &&
          !has_time_param(&s->tQ));
    if (s->m > 0)
        CHECK_INT(tp_tape_n_indep(s->tphi.tape), n);
    plain = plain_L(md, n);
    CHECK(plain != NULL);
    if (plain && !tp_tape_equal(s->tL.tape, plain, &diff))
        CHECK_FAIL_("%s: the L tape differs from a plain recording at op "
                    "%zu", what, diff);
    if (plain) {
        tp_tape_stats st;
        tp_tape_stats_get(s->tL.tape, &st);
        printf("%-22s n %2d: L tape of %zu ops, as a plain recording\n",
               what, n, st.n_ops);
    }
    tp_tape_free(&plain);
    eom_system_free(&s);
    eom_model_free(&md);
}

/* A model whose T, R, constraints and probe read the time. */
static int tt_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_addc(R, tp_sqr(R, eom_time(c)), 1.0),
                  tp_add(R, tp_sqr(R, eom_qd(c, 0)), tp_sqr(R, eom_qd(c, 1))));
    return 0;
}

static int tt_T_plain(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_add(R, tp_sqr(R, eom_qd(c, 0)), tp_sqr(R, eom_qd(c, 1)));
    return 0;
}

static int tt_R(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, eom_time(c), tp_sqr(R, eom_qd(c, 0)));
    return 0;
}

static int tt_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[0] = tp_sub(R, eom_q(c, 0), tp_sin(R, eom_time(c)));
    return 0;
}

static int tt_phi_plain(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[0] = tp_sub(R, eom_q(c, 0), eom_q(c, 1));
    return 0;
}

static int tt_probe(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = eom_time(c);
    return 0;
}

/* which: bit 0 T, bit 1 R, bit 2 phi, bit 3 probe read the time */
static eom_system *timed(unsigned which)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    eom_model_new(&md);
    eom_model_add_coord(md, "a", NULL, 0.0, 0.0);
    eom_model_add_coord(md, "b", NULL, 0.0, 0.0);
    eom_model_set_kinetic(md, which & 1 ? tt_T : tt_T_plain, NULL);
    eom_model_set_dissipation(md, which & 2 ? tt_R : tt_T_plain, NULL);
    eom_model_set_constraints(md, 1, which & 4 ? tt_phi : tt_phi_plain,
                              NULL);
    if (which & 8)
        eom_model_add_probe(md, "p", NULL, tt_probe, NULL);
    CHECK_INT(eom_system_new(&s, md, NULL, 0), EOM_OK);
    eom_model_free(&md);
    return s;
}

static void time_where_read(void)
{
    unsigned which;
    for (which = 0; which < 16; which++) {
        eom_system *s = timed(which);
        if (!s)
            continue;
        CHECK_INT(eom_system_reads_time(s), which != 0);
        CHECK_INT(tp_tape_n_indep(s->tL.tape), which & 1 ? 5 : 4);
        CHECK_INT(tp_tape_n_indep(s->tphi.tape), which & 4 ? 3 : 2);
        CHECK_INT(tp_tape_n_indep(s->tR.tape), 4);
        CHECK_INT(s->tL.tindex, which & 1 ? 4 : -1);
        CHECK_INT(s->tphi.tindex, which & 4 ? 2 : -1);
        /* the E tape holds T and V, and the probe */
        CHECK(has_time_param(&s->tE) == ((which & 9) != 0));
        CHECK(has_time_param(&s->tR) == ((which & 2) != 0));
        CHECK(!has_time_param(&s->tL) && !has_time_param(&s->tphi));
        eom_system_free(&s);
    }
}

int main(int argc, char **argv)
{
    static const char *const files[] = {"spring-pendulum", "open-chain",
                                        "closed-chain", "cart-pole",
                                        "double-pendulum", "four-bar"};
    const double m[3] = {1, 2, 3}, l[3] = {1, 1.5, 2}, th[3] = {0.1, 0.2, 0.3};
    char path[1024], err[2048];
    size_t i;
    if (argc < 2) {
        fprintf(stderr, "usage: test_time_tapes MODELS_DIR\n");
        return 2;
    }
    for (i = 0; i < sizeof files / sizeof files[0]; i++) {
        eom_model *md = NULL;
        snprintf(path, sizeof path, "%s/%s.eom", argv[1], files[i]);
        if (eom_model_from_file(&md, path, err, sizeof err) != EOM_OK) {
            CHECK_FAIL_("%s", err);
            continue;
        }
        timeless(files[i], md);
    }
    timeless("C spring pendulum",
             eom_models_spring_pendulum(1.0, 10.0, 1.0, 9.81));
    timeless("C closed rod chain",
             eom_models_rod_chain(3, m, l, th, 9.81, 1, 2.5));
    timeless("C bead on a circle", eom_models_bead_on_circle(1, 1, 9.81));
    time_where_read();
    CHECK_DONE();
}
