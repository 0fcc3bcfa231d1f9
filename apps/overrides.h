/* overrides.h - the --set NAME=VALUE options of eom-run. Each names a
 * structural setting of the demo (read before the model is built), a
 * parameter, a coordinate (its initial value) or a coordinate with the
 * suffix _dot (its initial rate). The syntax is checked when the option is
 * read; names are resolved once the demo, and then its system, exist.
 * When a name is set twice the last value wins. */
#ifndef APPS_OVERRIDES_H
#define APPS_OVERRIDES_H

#include <stddef.h>

#include "demos/demos.h"
#include "eom/eom.h"

typedef struct override {
    const char *arg; /* the whole NAME=VALUE text (borrowed: from argv) */
    size_t namelen;  /* NAME is arg[0 .. namelen) */
    double value;
} override;

/* Parse arg (borrowed, kept in *o) as NAME=VALUE: a non-empty name, '='
 * and one finite number with nothing after it. Returns 0, or -1 with a
 * message in err (errlen bytes). */
int override_parse(const char *arg, override *o, char *err, size_t errlen);

/* The structural settings of d: settings (d->nsettings values) receives
 * the defaults, then the values of the overrides that name a setting,
 * each checked against the setting's range and, for counts, integrality.
 * Returns 0, or -1 with a message in err. */
int overrides_settings(const override *ov, int n, const demo *d,
                       double *settings, char *err, size_t errlen);

/* The other overrides: parameters of s through eom_set_param first, then
 * x (2n values: q, then qd) taken again from eom_initial_state when a
 * parameter was set (a model's start may follow its parameters), then
 * NAME and NAME_dot into x. Overrides that name a setting of d are
 * skipped. Returns 0, or -1 with a message in err that names the unknown
 * name and the known ones. */
int overrides_apply(const override *ov, int n, const demo *d, eom_system *s,
                    double *x, char *err, size_t errlen);

/* The coordinates and rates of the overrides alone, into x (2n values);
 * parameters and settings are skipped. eom-run --modes --sweep places
 * them on the start it takes again at each value of the swept parameter.
 * Returns 0, or -1 with a message in err. */
int overrides_apply_state(const override *ov, int n, const demo *d,
                          eom_system *s, double *x, char *err,
                          size_t errlen);

#endif /* APPS_OVERRIDES_H */
