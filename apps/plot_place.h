/* plot_place.h - where the plots of a run go: beside its CSV, named after
 * it. For csv_path DIR/NAME.csv the files are DIR/NAME-SUFFIX; scripts
 * refer to the CSV by its name within DIR, since gnuplot runs there. */
#ifndef APPS_PLOT_PLACE_H
#define APPS_PLOT_PLACE_H

#include <stddef.h>

typedef struct plot_place {
    char dir[4096];      /* no trailing '/' ("." for the current one) */
    char prefix[1024];   /* the CSV's name without ".csv" */
    char csv_name[1024]; /* the CSV's name within dir */
} plot_place;

/* Split csv_path; 0, or -1 with a message in err when it cannot. */
int plot_place_of(plot_place *p, const char *csv_path, char *err,
                  size_t errlen);

/* dir/prefix-suffix into buf; -1 if it does not fit. */
int plot_place_path(const plot_place *p, const char *suffix, char *buf,
                    size_t len);

#endif
