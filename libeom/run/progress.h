/* progress.h - the wall clock of eom-run and its progress line. The line
 * ("eom-run: t = 3.2 / 10 (32%)") is drawn on standard error with '\r' so
 * that it rewrites itself; it appears only when enabled (eom-run enables
 * it when standard error is a terminal and --quiet is not given), not
 * before the run has taken a second, and at most once a second. */
#ifndef APPS_PROGRESS_H
#define APPS_PROGRESS_H

/* Seconds on a monotonic clock (only differences mean anything). */
double progress_clock(void);

typedef struct progress {
    int enabled;   /* draw the line at all */
    int shown;     /* a line is on the screen now */
    double t_end;  /* simulated end time, for the percentage */
    double start;  /* progress_clock() at progress_start */
    double last;   /* time of the last drawing */
    const char *prog; /* the prefix of the line (borrowed) */
} progress;

void progress_start(progress *p, int enabled, double t_end,
                    const char *prog);
/* The run has reached simulated time t. */
void progress_update(progress *p, double t);
/* Erase the line (before other messages and at the end). */
void progress_clear(progress *p);

#endif /* APPS_PROGRESS_H */
