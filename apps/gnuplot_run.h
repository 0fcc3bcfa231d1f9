/* gnuplot_run.h - running Debian's gnuplot on a script that eom-run
 * wrote. gnuplot is found on PATH and started directly (fork and execvp,
 * no shell), in the script's directory so that the script can name its
 * data files without a directory and still be rerun by hand with
 * `cd DIR && gnuplot SCRIPT`. gnuplot's own messages go to standard
 * error; its standard input is /dev/null. */
#ifndef APPS_GNUPLOT_RUN_H
#define APPS_GNUPLOT_RUN_H

#include <stddef.h>

/* Run `gnuplot script` with the working directory dir (both borrowed;
 * script is relative to dir or absolute) and wait for it. Returns 0 when
 * gnuplot exited with status 0, or -1 with a message in err (errlen
 * bytes) that says whether gnuplot could not be started (not installed,
 * not executable) or failed. */
int gnuplot_run(const char *dir, const char *script, char *err,
                size_t errlen);

#endif /* APPS_GNUPLOT_RUN_H */
