/* memory_fit.c - refusing, before allocating, a workspace the machine
 * cannot hold: a model within its settings' ranges (the closed chain at
 * 1000 links of 20 modes) may ask for tens of gigabytes in one tape
 * workspace, which would otherwise end in a bare "out of memory" or, in
 * an instrumented build, an abort. The bound is the machine's physical
 * memory (sysconf): past it a run would only swap, if the allocation
 * succeeded at all. */
#define _DEFAULT_SOURCE /* _SC_PHYS_PAGES */
#include <stdint.h>
#include <unistd.h>

#include "eom_internal.h"

/* The machine's physical memory in bytes, or SIZE_MAX when unknown. */
static size_t machine_memory(void)
{
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0)
        return SIZE_MAX;
    if ((unsigned long)pages > SIZE_MAX / (unsigned long)page)
        return SIZE_MAX;
    return (size_t)pages * (size_t)page;
}

int eom__workspace_fits(eom_system *s, const tp_tape *t, int dirs,
                        const char *what)
{
    const size_t need = tp_ws_bytes(t, dirs), have = machine_memory();
    const double gb = 1e-9;
    tp_tape_stats st;
    if (need <= have && s->ws_bytes <= have - need) {
        s->ws_bytes += need;
        return EOM_OK;
    }
    if (tp_tape_stats_get(t, &st) != TP_OK)
        st.n_ops = 0;
    return eom__fail(s, EOM_ERR_NOMEM,
                     "the %s workspace would need %.3g GB (%zu tape "
                     "operations x %d directions, one per coordinate or "
                     "independent: %d coordinates)%s, more than this "
                     "machine's %.3g GB of memory: a model with fewer "
                     "coordinates (fewer links or modes) fits",
                     what,
                     need == SIZE_MAX ? 1.8e10 : (double)need * gb,
                     st.n_ops, dirs, s->n,
                     s->ws_bytes ? " besides the workspaces made before"
                                 : "",
                     (double)have * gb);
}

int eom__arrays_fit(eom_system *s, double bytes)
{
    const size_t have = machine_memory();
    const double gb = 1e-9;
    if (bytes <= (double)have && (double)s->ws_bytes <= (double)have - bytes) {
        s->ws_bytes += (size_t)bytes;
        return EOM_OK;
    }
    return eom__fail(s, EOM_ERR_NOMEM,
                     "the system's matrices would need %.3g GB (the mass "
                     "matrix and its factor are %d x %d, one row and column "
                     "per coordinate, beside %d constraint rows)%s, more "
                     "than this machine's %.3g GB of memory: a model with "
                     "fewer coordinates (fewer links or modes) fits",
                     bytes * gb, s->n, s->n, s->m,
                     s->ws_bytes ? " besides the workspaces made before"
                                 : "",
                     (double)have * gb);
}
