/* csv_reader.h - reading a CSV written by eom-run back into memory: a
 * header row of names, then rows of numbers (docs/csv.md). Used by the
 * plots, which run after the CSV is closed and read only the file, so
 * they draw exactly what the user has.
 *
 * Accepted: '\n' or "\r\n" line ends, a missing final newline, blanks
 * around fields, "nan" and "inf" as strtod reads them. Rejected with a
 * message naming the line: an empty file, a row with more or fewer
 * fields than the header, a field that is not a number. Names are looked
 * up exactly (case-sensitive). */
#ifndef APPS_CSV_READER_H
#define APPS_CSV_READER_H

#include <stddef.h>

typedef struct csv_table {
    int ncols, nrows;
    char **names; /* [ncols] column names (owned) */
    double *v;    /* [nrows x ncols] row-major values (owned) */
} csv_table;

/* Read the file at path (borrowed). Returns 0 and a new table in *out
 * (free with csv_table_free), or -1 with *out NULL and a message in err
 * (errlen bytes). */
int csv_table_read(csv_table **out, const char *path, char *err,
                   size_t errlen);
void csv_table_free(csv_table **t);

/* The index of the column named name, or -1. */
int csv_table_col(const csv_table *t, const char *name);

/* The value at row i, column j (both in range). */
double csv_table_at(const csv_table *t, int i, int j);

#endif /* APPS_CSV_READER_H */
