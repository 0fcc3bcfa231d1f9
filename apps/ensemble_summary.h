/* ensemble_summary.h - eom-ensemble's summary file (docs/ensembles.md):
 * its header and rows, the record of the inputs that made it
 * (SUMMARY.inputs, beside it), the lock that keeps two processes from
 * writing it at once, and --resume's checks of what is already in it.
 *
 * The inputs record is text, one "KEY VALUE" line per input: the model
 * (a demo's name, or the SHA-256 of the model file), the runs (the
 * SHA-256 of the runs file, the sweeps, or the random distributions with
 * their count and seed), --set, and every option that changes a run's
 * numbers. --resume refuses a summary whose record differs, naming the
 * keys (options) that changed. */
#ifndef APPS_ENSEMBLE_SUMMARY_H
#define APPS_ENSEMBLE_SUMMARY_H

#include <stdio.h>

#include "ensemble_pool.h"
#include "ensemble_runs.h"
#include "eom/eom.h"

/* The header line of the summary of runs on s, with its '\n', in a new
 * string (the caller frees it; any length), or NULL when out of memory. */
char *ensemble_summary_header(const ensemble_runs *runs, const eom_system *s);

/* Write run i's row (n coordinates) to f, the summary that
 * ensemble_summary_open returned, at once (no buffer). 0, or -1 after
 * one message on standard error naming path and the reason (strerror:
 * "No space left on device"); the file is then cut back to the whole
 * rows before this one. */
int ensemble_summary_put(FILE *f, const char *path, const ensemble_runs *runs,
                         long i, int n, const run_result *r);

/* Sync (fsync) and close *f, which becomes NULL. 0, or -1 after a message
 * naming path and the reason when speak is set (a caller that has
 * already reported a failed write passes 0: said once). */
int ensemble_summary_close(FILE **f, const char *path, int speak);

/* The SHA-256 of the file at path as "sha256:HEX" into out (72 bytes);
 * 0, or -1 with a message in err. */
int ensemble_file_digest(const char *path, char out[72], char *err,
                         size_t errlen);

/* Open the summary at path for writing and lock it (flock, exclusive,
 * without waiting) for as long as the file stays open: another process
 * that holds the lock makes this call fail with a message. head is the
 * header line, inputs the inputs record (both borrowed).
 *   resume 0, or resume with no summary or an empty one: the file is
 *     emptied, the header written, and PATH.inputs (re)written.
 *   resume 1: PATH.inputs must be there and equal inputs (otherwise the
 *     message names what changed), the header must be head, and every
 *     complete line after it a row of this ensemble: the right number of
 *     fields, a run number in range not seen before, the run's own input
 *     values, a status, numbers where numbers go, a quoted message
 *     (otherwise the message names the line). A last line cut short is
 *     dropped. skip[i] is set for the runs found and *ndone counts them.
 * n: the system's coordinates. Returns the file positioned for appending
 * rows (its buffer flushed: write rows with ensemble_summary_put), or
 * NULL after a message on standard error (naming the reason when the
 * header cannot be written). */
FILE *ensemble_summary_open(const char *path, int resume, const char *head,
                            const char *inputs, const ensemble_runs *runs,
                            int n, unsigned char *skip, long *ndone);

#endif /* APPS_ENSEMBLE_SUMMARY_H */
