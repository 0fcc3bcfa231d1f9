/* csv_writer.h - eom-run's CSV output: a header row of names, then rows
 * of numbers in the shortest form that reads back exactly (numtext.h),
 * separated by ',' and ended by '\n'. Names are written as given (the
 * caller passes names that need no quoting: C identifiers). Every write
 * is checked, so a full disk or a closed pipe is an error the caller
 * sees, not a silently short file. */
#ifndef APPS_CSV_WRITER_H
#define APPS_CSV_WRITER_H

#include <stddef.h>

typedef struct csv_writer csv_writer;

/* Open path for writing (created or truncated), or standard output when
 * path is NULL. Returns 0 and a writer in *out, or -1 with a message in
 * err (errlen bytes). */
int csv_writer_open(csv_writer **out, const char *path, char *err,
                    size_t errlen);

/* The header row: count names (borrowed). 0, or -1 with a message. */
int csv_writer_header(csv_writer *w, char *const *names, int count,
                      char *err, size_t errlen);

/* One row of count values. 0, or -1 with a message. */
int csv_writer_row(csv_writer *w, const double *v, int count, char *err,
                   size_t errlen);

/* Push buffered rows to the file. 0, or -1 with a message. */
int csv_writer_flush(csv_writer *w, char *err, size_t errlen);

/* Flush and close (standard output is flushed, not closed); *w becomes
 * NULL. 0, or -1 with a message when data could not be written. */
int csv_writer_close(csv_writer **w, char *err, size_t errlen);

#endif /* APPS_CSV_WRITER_H */
