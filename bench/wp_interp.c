/* wp_interp.c - time to reach an error, from a method's sweep (see
 * wp_interp.h). Errors and times of one method follow a power law in
 * the step size or tolerance, so a straight line in log-log between two
 * neighbouring runs is the natural interpolant. The first crossing in
 * sweep order is taken: a sweep that dips below the target and comes
 * back above (round-off, or an error that is smaller by luck) is
 * credited with its cheapest run that reached it. */
#include "wp_interp.h"

#include <math.h>

static double time_of(const wp_run *r, int cpu)
{
    return cpu ? r->cpu : r->wall;
}

wp_reach wp_time_at_error(const wp_run *runs, int nruns, double target,
                          int cpu, double *time)
{
    const wp_run *prev = NULL;
    int i;
    *time = NAN;
    for (i = 0; i < nruns; i++) {
        const wp_run *r = &runs[i];
        if (r->status != 0 || !isfinite(r->err) || !(time_of(r, cpu) > 0.0))
            continue;
        if (r->err <= target) {
            double le0, le1, f, t0, t1;
            if (!prev) {
                *time = time_of(r, cpu);
                return WP_AT_LOOSEST;
            }
            le0 = log(prev->err);
            le1 = log(fmax(r->err, 1e-300));
            f = le1 < le0 ? (log(target) - le0) / (le1 - le0) : 1.0;
            t0 = log(time_of(prev, cpu));
            t1 = log(time_of(r, cpu));
            *time = exp(t0 + f * (t1 - t0));
            return WP_INTERPOLATED;
        }
        prev = r;
    }
    return WP_NOT_REACHED;
}
