/* run.h - the run layer: what eom-run gives a demo, for any program that
 * builds its own system (library eomrun, pkg-config module libeomrun;
 * docs/run.md).
 *
 *   eom_run            integrate a system from t = 0 to t_end, writing a
 *                      CSV row at every sample time (the CSV contract of
 *                      docs/csv.md), with a progress line and a summary
 *                      (steps, right-hand sides, wall time, energy drift,
 *                      constraint residuals) on standard error
 *   eom_run_prepare_start   project a start that is off the constraints
 *   eom_run_plots      the standard plots of a run beside its CSV
 *                      (coordinates, energies, residuals, probes) with
 *                      gnuplot
 * and the pieces they are made of, for programs that write or plot their
 * own: the CSV columns of a system and their values, a checked CSV writer
 * and reader, strict number text, and running gnuplot on a script.
 *
 * Conventions as in libeom. Functions that can fail return 0, or -1 (or a
 * libeom status where stated) with a message in err (errlen bytes) or on
 * standard error where stated; none aborts. Messages on standard error
 * start with the program name given in eom_run_opts.prog.
 */
#ifndef EOM_RUN_H
#define EOM_RUN_H

#include <signal.h>
#include <stddef.h>
#include <stdio.h>

#include "eom/eom.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- numbers as text --------------------------------------------------- */

/* Why a string is not accepted as a number. */
enum {
    EOM_NUMTEXT_OK = 0,
    EOM_NUMTEXT_EMPTY,      /* "" */
    EOM_NUMTEXT_NOT_NUMBER, /* does not start with a number (or starts with
                               white space) */
    EOM_NUMTEXT_TRAILING,   /* a number followed by other characters */
    EOM_NUMTEXT_NONFINITE,  /* inf or nan */
    EOM_NUMTEXT_RANGE,      /* too large for a double, or for a long */
    EOM_NUMTEXT_NOT_INTEGER /* eom_numtext_parse_long: a fraction or
                               exponent */
};

/* A short phrase for an EOM_NUMTEXT_* code ("is not a number", ...). */
EOM_API const char *eom_numtext_error(int code);
/* Parse all of s (borrowed) as a finite double into *out; returns an
 * EOM_NUMTEXT_* code and leaves *out alone on failure. Decimal and
 * hexadecimal floating forms as strtod reads them. */
EOM_API int eom_numtext_parse_double(const char *s, double *out);
/* Parse all of s as a decimal integer (optional sign, digits only). */
EOM_API int eom_numtext_parse_long(const char *s, long *out);
/* The shortest of %.15g, %.16g and %.17g that reads back as exactly v;
 * "nan", "inf" or "-inf" for non-finite values. buf needs 32 bytes. */
EOM_API void eom_numtext_format(char *buf, size_t len, double v);

/* ---- CSV output -------------------------------------------------------- */

/* A header row of names, then rows of numbers in the shortest form that
 * reads back exactly, separated by ',' and ended by '\n'. Names are
 * written as given (C identifiers need no quoting). Every write is
 * checked, so a full disk or a closed pipe is an error the caller sees.
 *
 * A file is replaced, never written in place: the rows go to a new file
 * beside it, PATH.tmp-XXXXXX (six random characters; created exclusively,
 * never through a symbolic link), which eom_csv_writer_close syncs and
 * renames onto PATH. Until then PATH keeps its previous content, even if
 * the process is killed (a killed run leaves its PATH.tmp-XXXXXX behind).
 * After a failed write, a failed eom_run, or eom_csv_writer_discard, the
 * rows are kept as PATH.partial (replacing an older one) and PATH is left
 * as it was. A path that exists and is not a regular file (/dev/null, a
 * FIFO) is written directly; a symbolic link to a file replaces the file
 * it names. A replaced file keeps its permissions; a new one gets 0666
 * less the umask. */
typedef struct eom_csv_writer eom_csv_writer;

/* Open a writer for path, or for standard output when path is NULL. */
EOM_API int eom_csv_writer_open(eom_csv_writer **out, const char *path,
                                char *err, size_t errlen);
/* The header row: count names (borrowed). */
EOM_API int eom_csv_writer_header(eom_csv_writer *w, char *const *names,
                                  int count, char *err, size_t errlen);
/* One row of count values. */
EOM_API int eom_csv_writer_row(eom_csv_writer *w, const double *v,
                               int count, char *err, size_t errlen);
/* Push buffered rows to the file. */
EOM_API int eom_csv_writer_flush(eom_csv_writer *w, char *err,
                                 size_t errlen);
/* Flush and close (standard output is flushed, not closed) and put the
 * file in place; *w becomes NULL; NULL-safe. -1 with a message when data
 * could not be written or the run writing to w failed (eom_run returned
 * 1): then the message names PATH.partial, where the rows are, and PATH
 * is unchanged. */
EOM_API int eom_csv_writer_close(eom_csv_writer **w, char *err,
                                 size_t errlen);
/* Close without putting the file in place: the rows are kept as
 * PATH.partial, PATH is unchanged, and -1 comes back with a message that
 * says so (0 for standard output or a device, which are only flushed).
 * *w becomes NULL; NULL-safe. */
EOM_API int eom_csv_writer_discard(eom_csv_writer **w, char *err,
                                   size_t errlen);

/* ---- whole text files (plot scripts and their data) -------------------- */

/* A writer for a file that is not a CSV table (a gnuplot script, the data
 * it reads): write it through eom_csv_writer_stream, then put it in place
 * with eom_csv_writer_close (or drop it with eom_csv_writer_discard). It
 * is written like a CSV (a new file PATH.tmp-XXXXXX beside it, created
 * exclusively and never through a symbolic link, synced and renamed onto
 * PATH at the close), with these differences: a symbolic link at path is
 * never followed (the link itself is replaced by the new file; the file
 * it named is untouched); a path that exists and is neither a regular
 * file nor a symbolic link (a FIFO, a device, a folder) is refused; after
 * a failed write or a discard the temporary file is removed (no
 * PATH.partial) and PATH is as it was. path must not be NULL. */
EOM_API int eom_csv_writer_open_text(eom_csv_writer **out, const char *path,
                                     char *err, size_t errlen);
/* The stream w writes to (borrowed: closed by eom_csv_writer_close or
 * _discard); NULL when w is NULL. Every write to it is checked at the
 * close. */
EOM_API FILE *eom_csv_writer_stream(eom_csv_writer *w);

/* ---- the CSV contract (docs/csv.md) ------------------------------------ */

/* The columns of a system's CSV, in this order:
 *   t, q_1 .. q_n (coordinate names), NAME_dot for each rate,
 *   T, V, E, W, phi1 .. phiM, phidot1 .. phidotM, probes by name
 * (the phi groups are absent without constraints), then the optional
 * groups asked for, in the order of the flags below. */
enum {
    EOM_RUN_ACCELERATIONS = 1, /* NAME_ddot: the accelerations qdd */
    EOM_RUN_MULTIPLIERS = 2,   /* lambda1 .. lambdaM: the constraint
                                  forces are C^T lambda (none without
                                  constraints) */
    EOM_RUN_CONDITION = 4,     /* rcond_M, rcond_S: reciprocal condition
                                  estimates of M and of C M^-1 C^T at the
                                  row's state (eom_condition; rcond_S is 1
                                  without constraints) */
    EOM_RUN_HEALTH = 8         /* projections, svd_solves,
                                  singular_passes, branch_switches: the
                                  integrator's counts up to the row
                                  (eom_stats), given by
                                  eom_run_columns_set_stats; NaN until
                                  then */
};

typedef struct eom_run_columns {
    int n, m, nprobes;    /* coordinates, constraints, probes */
    unsigned extra;       /* the optional groups (EOM_RUN_* flags) */
    int count;            /* columns: 1 + 2n + 4 + 2m + nprobes, plus n,
                             m, 2 and 4 for the optional groups */
    char **names;         /* [count] column names (owned) */
    double *phi, *phidot; /* [m] scratch */
    double *xd;           /* [2n] scratch */
    char msg[512];        /* why the last eom_run_columns_fill failed */
    double health[4];     /* the EOM_RUN_HEALTH values (NaN: not set) */
} eom_run_columns;

/* What a row holds besides its values. */
typedef struct eom_run_row_info {
    eom_energy e;      /* energies at the row's state (NaN if not computed) */
    double phi_max;    /* max |phi_k|, 0 without constraints */
    double phidot_max; /* max |(C qd + dphi/dt)_k| */
} eom_run_row_info;

/* The column of constraint row j (from 0) for base "phi", "phidot" or
 * "lambda": "<base>_<name>" for a row named in the model (phi_drive),
 * "<base><j + 1>" otherwise (phi3); NULL when j is out of range. The
 * caller frees it. */
EOM_API char *eom_run_constraint_column(const eom_system *s,
                                        const char *base, int j);

/* The columns of s (borrowed; only read) with the optional groups extra
 * (EOM_RUN_* flags, 0 for none). Every name must be unique: a coordinate
 * or probe named like another column is an error. */
EOM_API int eom_run_columns_new(eom_run_columns **out, const eom_system *s,
                                unsigned extra, char *err, size_t errlen);
EOM_API void eom_run_columns_free(eom_run_columns **c);
/* The integrator's counts for the EOM_RUN_HEALTH columns of the rows
 * filled next (st NULL: NaN). eom_run sets them at every row. */
EOM_API void eom_run_columns_set_stats(eom_run_columns *c,
                                       const eom_stats *st);
/* Fill row (c->count values) for time t, state x (2n values) and work W;
 * *info receives the energies and largest residuals. Returns EOM_OK, or
 * the first failing libeom status with its message in c->msg and the
 * values that could not be computed set to NaN. */
EOM_API int eom_run_columns_fill(eom_run_columns *c, eom_system *s,
                                 double t, const double *x, double W,
                                 double *row, eom_run_row_info *info);

/* ---- a run ------------------------------------------------------------- */

typedef struct eom_run_opts {
    const char *prog;  /* prefix of the messages (NULL: "eom_run") */
    const char *label; /* the model's name in messages (NULL: "model") */
    double t_end;      /* >= 0 */
    double sample;     /* > 0: rows at k * sample (see eom_run_grid) */
    eom_opts opts;     /* passed to eom_integ_new as they are */
    unsigned extra;    /* optional CSV columns (EOM_RUN_* flags) */
    int quiet;         /* no summary */
    int progress;      /* draw a progress line on standard error (for a
                          terminal: the caller decides, e.g. isatty) */
    const volatile sig_atomic_t *stop; /* NULL, or a flag (a signal
                          handler's) read before each sample: when it is
                          non-zero the run stops after its last whole row
                          (eom_run returns 2) */
    int accept_unhealthy; /* 1: a run whose verdict fails (eom_run_judge)
                          still returns 0; the summary and a note on
                          standard error say so (default 0) */
} eom_run_opts;

/* Defaults: t_end 10, sample 0.01, eom_opts_default, not quiet, no
 * progress line, an unhealthy run not accepted. */
EOM_API void eom_run_opts_default(eom_run_opts *o);

/* The sample grid: t_k = k * sample for k = 0 .. *K, each computed as
 * that product in double precision, where K is the largest k with t_k <=
 * t_end; t_end counts as on the grid (*exact = 1) when it is within 1e-9
 * sample intervals (or a few rounding errors of t_end) of a multiple.
 * Otherwise one more row follows at t_end exactly. Valid for t_end /
 * sample <= 1e12. */
EOM_API void eom_run_grid(double t_end, double sample, long long *K,
                          int *exact);

/* Integrate s (borrowed) from (0, x0) as o says, writing the header and
 * the rows to w (with o->opts.n_sens, the columns d(x)/d(INPUT) of the
 * sensitivities follow the others: for each input in order, for each
 * state, the coordinates then their rates; docs/csv.md) (borrowed; flushed at least once a second and before
 * returning, not closed). Messages and the summary go to standard error.
 * Returns 0, or 1 after a message on a failure (integrator, evaluation or
 * write): the rows before the failure are in w, and w is marked failed,
 * so that eom_csv_writer_close keeps them as PATH.partial and leaves PATH
 * as it was. Returns 2 when *o->stop was found non-zero before a sample:
 * a message says at which time, and w holds the whole rows up to it,
 * marked failed as after a failure. A run that reaches t_end ends with
 * its verdict (eom_run_judge) in the summary; when the verdict fails, a
 * message on standard error names the measure, its value and its
 * threshold, and 3 is returned (0 with o->accept_unhealthy); every row is
 * in w, which is not marked failed. */
EOM_API int eom_run(eom_system *s, const double *x0, const eom_run_opts *o,
                    eom_csv_writer *w);

/* Check, and project when o->project is set, the start x (2n values,
 * updated in place) of a constrained system with tolerance o->proj_tol,
 * at t = 0, where eom_run starts (the system's time is set to 0,
 * eom_set_time): if max |phi| or max |C qd + dphi/dt| exceeds it, x is
 * projected onto phi = 0 and C qd + dphi/dt = 0 by the least change of
 * the coordinates (eom_project_start)
 * and one line on standard error says so; with o->project off a warning
 * says that the run starts off the constraints. Returns 0 (x is the state
 * to start from), or 1 after a message. prog and label as in
 * eom_run_opts (NULL: the defaults). */
EOM_API int eom_run_prepare_start(eom_system *s, double *x,
                                  const eom_opts *o, const char *prog,
                                  const char *label);

/* ---- the health verdict (docs/run.md, "The verdict") ------------------ */

/* What a run measured of itself. NaN: not measured (not judged). */
typedef struct eom_run_measures {
    double drift_rel;  /* max |E + W - E0| over the rows divided by the
                          energy scale max(|E|, |L|) over the rows */
    double phi_max;    /* max |phi| over the rows and after every step
                          (eom_stats.max_residual: the projection's
                          residual), 0 without constraints */
    double phidot_max; /* max |C qd + dphi/dt| over the rows */
} eom_run_measures;

typedef struct eom_run_verdict {
    int healthy;               /* 1: every measure within its threshold */
    const char *measure;       /* the first one out of it (static text), or
                                  NULL */
    double value, threshold;   /* its value and threshold */
    double tol;                /* the run's tolerance: max(rtol,
                                  eom_stats.tol_reachable) */
    double energy_threshold;   /* for drift_rel */
    double residual_threshold; /* for phi_max and phidot_max */
    char text[256];            /* "relative energy drift 0.0222 exceeds
                                  1e-05 (1000 x the run's tolerance
                                  1e-08)" when not healthy, else "" */
} eom_run_verdict;

/* The verdict on a run made with options o (its rtol, atol, proj_tol)
 * whose integrator counted st (NULL: no integrator ran; its steps,
 * branch switches and reachable tolerance count as 0) and that measured
 * m (all borrowed), into *v. With tau = max(o->rtol, st->tol_reachable)
 * (rk4 is judged against the rtol it was given), k = st->steps and
 * allow(x) = clamp(x max(1000, 10 k), 1e-8, 1e-2), healthy when
 *   drift_rel <= allow(tau),
 *   phi_max and phidot_max <= max(allow(max(tau, atol)), 10 proj_tol),
 *   st->branch_switches == 0.
 * The measures are judged in that order, and the first out of its
 * threshold is named. */
EOM_API void eom_run_judge(const eom_opts *o, const eom_stats *st,
                           const eom_run_measures *m, eom_run_verdict *v);

/* ---- plots ------------------------------------------------------------- */

/* The standard plots of a run of s whose CSV is at csv_path, beside it
 * under the CSV's name without ".csv" (PREFIX), each as .png and .svg
 * from a kept gnuplot script: PREFIX-coordinates (one panel per unit),
 * PREFIX-energy (T, V, E, W, E + W and the drift of E + W), and when s
 * has them PREFIX-residuals and PREFIX-probes. label titles them. Needs
 * gnuplot on PATH (the message says when it is missing). */
EOM_API int eom_run_plots(const char *label, const eom_system *s,
                          const char *csv_path, char *err, size_t errlen);

/* The animation page of a run of s whose CSV is at csv_path, when s has
 * drawings (eom/drawing.h; without, nothing is written and 0 comes
 * back): PREFIX-animation.html beside the CSV, one file that needs no
 * network, playing the run with the drawings and a plot of T, V and E
 * (docs/run.md, "The animation page"). Frames are the CSV's rows, thinned
 * to at most 2000 frames and 300000 drawn values (every k-th row and the
 * last). The file is replaced atomically as the CSV is. eom_run_plots
 * writes it too. */
EOM_API int eom_run_animation(const char *label, const eom_system *s,
                              const char *csv_path, char *err,
                              size_t errlen);

/* One page of nruns runs of s drawn over each other (an ensemble's
 * trajectories; docs/ensembles.md), when s has drawings (without,
 * nothing is written and 0 comes back): csv_paths[r] is run r's CSV (as
 * eom_run writes it; every one borrowed), run_labels[r] its name in the
 * page's legend (NULL: "run R"), page_path the page (replaced
 * atomically). Run r is drawn in the r-th of ten colours, in turn; one
 * time slider goes through the frames of the run with the most rows and
 * shows each run at its last frame at or before that time; the plot
 * below is E of each run. The frame budget is shared: one stride for
 * every run, the smallest that keeps the longest run within
 * min(2000, 300000 / (nruns x drawn values per frame)) frames (at least
 * 2). 0, or -1 with a message naming the CSV that could not be read. */
EOM_API int eom_run_animation_runs(const char *label, const eom_system *s,
                                   int nruns, const char *const *csv_paths,
                                   const char *const *run_labels,
                                   const char *page_path, char *err,
                                   size_t errlen);

/* Where the plots of a CSV go: for csv_path DIR/NAME.csv the files are
 * DIR/NAME-SUFFIX; a script names the CSV within DIR, as gnuplot runs
 * there. */
typedef struct eom_plot_place {
    char dir[4096];      /* no trailing '/' ("." for the current one) */
    char prefix[1024];   /* the CSV's name without ".csv" */
    char csv_name[1024]; /* the CSV's name within dir */
} eom_plot_place;
EOM_API int eom_plot_place_of(eom_plot_place *p, const char *csv_path,
                              char *err, size_t errlen);
/* dir/prefix-suffix into buf; -1 if it does not fit. */
EOM_API int eom_plot_place_path(const eom_plot_place *p, const char *suffix,
                                char *buf, size_t len);

/* Run `gnuplot script` in the directory dir (both borrowed) and wait for
 * it: found on PATH, started directly (no shell), standard input
 * /dev/null, its messages on standard error. -1 with a message that says
 * whether gnuplot could not be started (not installed) or failed. */
EOM_API int eom_gnuplot_run(const char *dir, const char *script, char *err,
                            size_t errlen);

/* ---- CSV input --------------------------------------------------------- */

/* A CSV of a header row and rows of numbers, read whole. Accepted: '\n'
 * or "\r\n" line ends, a missing final newline, blanks around fields,
 * "nan" and "inf". Rejected with a message naming the line: an empty
 * file, a row with more or fewer fields than the header, a field that is
 * not a number. */
typedef struct eom_csv_table {
    int ncols, nrows;
    char **names; /* [ncols] column names (owned) */
    double *v;    /* [nrows x ncols] row-major values (owned) */
} eom_csv_table;
EOM_API int eom_csv_table_read(eom_csv_table **out, const char *path,
                               char *err, size_t errlen);
EOM_API void eom_csv_table_free(eom_csv_table **t);
/* The index of the column named name (exactly), or -1. */
EOM_API int eom_csv_table_col(const eom_csv_table *t, const char *name);
/* The value at row i, column j (both in range). */
EOM_API double eom_csv_table_at(const eom_csv_table *t, int i, int j);

#ifdef __cplusplus
}
#endif
#endif /* EOM_RUN_H */
