/* csv_writer_internal.h - what the run layer tells a CSV writer besides
 * the rows (csv_writer.c; not installed). */
#ifndef EOM_RUN_CSV_WRITER_INTERNAL_H
#define EOM_RUN_CSV_WRITER_INTERNAL_H

#include <stdio.h>

#include "eom/run.h"

/* The run writing to w failed: eom_csv_writer_close will keep the rows as
 * PATH.partial and leave PATH as it was (NULL-safe). */
void csv_writer_mark_failed(eom_csv_writer *w);

/* The stream of w, for a file that is not a CSV but wants its atomic
 * replacement (the animation page): write to it, then close w. */
FILE *csv_writer_file(eom_csv_writer *w);

#endif /* EOM_RUN_CSV_WRITER_INTERNAL_H */
