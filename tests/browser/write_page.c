/* write_page.c - the animation page of a model file's run from its CSV,
 * without the plots (tests/browser/test_pages.py: eom-run --out writes
 * the CSV, this the page, as eom-run --plots would, and no gnuplot runs).
 *
 * usage: write_page MODEL.eom RUN.csv   (writes RUN-animation.html) */
#include <stdio.h>

#include "eom/model_file.h"
#include "eom/run.h"

int main(int argc, char **argv)
{
    char err[4096];
    eom_model *m = NULL;
    eom_system *s = NULL;
    int rc = 1;
    if (argc != 3) {
        fprintf(stderr, "usage: write_page MODEL.eom RUN.csv\n");
        return 2;
    }
    if (eom_model_from_file(&m, argv[1], err, sizeof err) == EOM_OK &&
        eom_system_new(&s, m, err, sizeof err) == EOM_OK &&
        eom_run_animation(argv[1], s, argv[2], err, sizeof err) == 0)
        rc = 0;
    else
        fprintf(stderr, "write_page: %s\n", err);
    eom_system_free(&s);
    eom_model_free(&m);
    return rc;
}
