/* plot_place.c - names of the plot files beside a CSV (eom/run.h). */
#include "eom/run.h"

#include <stdio.h>
#include <string.h>

int eom_plot_place_of(eom_plot_place *p, const char *csv_path, char *err,
                      size_t errlen)
{
    const char *slash = strrchr(csv_path, '/');
    const char *base = slash ? slash + 1 : csv_path;
    size_t lb = strlen(base), ld = slash ? (size_t)(slash - csv_path) : 0;
    if (lb == 0 || lb >= sizeof p->prefix || ld >= sizeof p->dir) {
        snprintf(err, errlen, "cannot make plot names from '%s'", csv_path);
        return -1;
    }
    if (!slash)
        snprintf(p->dir, sizeof p->dir, ".");
    else if (ld == 0)
        snprintf(p->dir, sizeof p->dir, "/");
    else
        snprintf(p->dir, sizeof p->dir, "%.*s", (int)ld, csv_path);
    snprintf(p->csv_name, sizeof p->csv_name, "%s", base);
    if (lb > 4 && strcmp(base + lb - 4, ".csv") == 0)
        lb -= 4;
    snprintf(p->prefix, sizeof p->prefix, "%.*s", (int)lb, base);
    return 0;
}

int eom_plot_place_path(const eom_plot_place *p, const char *suffix, char *buf,
                        size_t len)
{
    int w = snprintf(buf, len, "%s/%s-%s", p->dir, p->prefix, suffix);
    return w > 0 && (size_t)w < len ? 0 : -1;
}
