/* test_header.c - the public header compiles alone: this file includes
 * nothing but "tape/tape.h" (no libc header before it) and uses a few of
 * its declarations, so a missing include or a dependency on a private
 * header breaks the build. The checks are hand-rolled for the same
 * reason: check.h would bring in <stdio.h>. */
#include "tape/tape.h"

static int square(tp_rec *r, void *user)
{
    (void)user;
    return tp_output(r, "y", tp_sqr(r, tp_indep(r, 0)));
}

int main(void)
{
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    tp_ws *ws = NULL;
    tp_tape_stats st;
    const tp_allocator *al = NULL;
    const double x[1] = {3.0};
    double y = 0.0, g = 0.0;
    size_t n_ops = 0;
    int fails = 0;

    fails += tp_recorder_new(&r, 1, NULL, al) != TP_OK;
    fails += tp_rec_run(r, NULL, square, NULL) != TP_OK;
    fails += tp_recorder_finish(r, &t) != TP_OK;
    fails += tp_ws_new(&ws, t, 1, al) != TP_OK;
    fails += tp_gradient(ws, x, 0, &y, &g) != TP_OK;
    fails += y != 9.0 || g != 6.0;
    fails += tp_tape_stats_get(t, &st) != TP_OK;
    n_ops = st.n_ops;
    fails += n_ops != 2; /* INDEP, SQR */
    fails += tp_status_name(TP_ERR_NOMEM)[0] != 'T';
    tp_ws_free(&ws);
    tp_tape_free(&t);
    tp_rec_free(&r);
    fails += r != NULL || t != NULL || ws != NULL;
    return fails ? 1 : 0;
}
