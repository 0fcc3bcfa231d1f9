/* describe.h - the listings of eom-run: --list (every demo with its one
 * line summary) and DEMO --describe (structural settings, parameters,
 * coordinates and initial values with defaults and units, constraints,
 * probes and the CSV columns). */
#ifndef APPS_DESCRIBE_H
#define APPS_DESCRIBE_H

#include <stdio.h>

#include "demos/demos.h"
#include "eom/eom.h"

/* --list: one line per demo, "NAME  SUMMARY". */
void describe_list(FILE *f);

/* --describe: d with the structural settings in use (d->nsettings
 * values) and its system s built from them. x0 is the initial state in
 * use (2n values); where a value in use differs from its default (after
 * --set), it is shown beside the default. extra: the optional CSV
 * columns asked for (EOM_RUN_* flags). Returns 0, or -1 when out of
 * memory. */
int describe_demo(FILE *f, const demo *d, const double *settings,
                  const eom_system *s, const double *x0, unsigned extra);

#endif /* APPS_DESCRIBE_H */
