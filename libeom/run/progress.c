/* progress.c - wall clock and progress line (see progress.h). */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"

#include <stdio.h>
#include <time.h>

double progress_clock(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void progress_start(progress *p, int enabled, double t_end,
                    const char *prog)
{
    p->prog = prog;
    p->enabled = enabled;
    p->shown = 0;
    p->t_end = t_end;
    p->start = p->last = progress_clock();
}

void progress_update(progress *p, double t)
{
    double now;
    if (!p->enabled)
        return;
    now = progress_clock();
    if (now - p->last < 1.0)
        return;
    p->last = now;
    /* trailing blanks cover a longer line drawn before */
    fprintf(stderr, "\r%s: t = %.6g / %.6g (%.0f%%)    ", p->prog, t, p->t_end,
            p->t_end > 0.0 ? 100.0 * t / p->t_end : 100.0);
    fflush(stderr);
    p->shown = 1;
}

void progress_clear(progress *p)
{
    if (!p->shown)
        return;
    fprintf(stderr, "\r%60s\r", "");
    fflush(stderr);
    p->shown = 0;
}
