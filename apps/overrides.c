/* overrides.c - parsing and applying --set NAME=VALUE (see overrides.h). */
#include "overrides.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "eom/run.h"

int override_parse(const char *arg, override *o, char *err, size_t errlen)
{
    const char *eq = strchr(arg, '=');
    int rc;
    if (!eq) {
        snprintf(err, errlen,
                 "--set '%s': expected NAME=VALUE (no '=' found)", arg);
        return -1;
    }
    if (eq == arg) {
        snprintf(err, errlen, "--set '%s': empty name before '='", arg);
        return -1;
    }
    rc = eom_numtext_parse_double(eq + 1, &o->value);
    if (rc != EOM_NUMTEXT_OK) {
        snprintf(err, errlen, "--set '%s': the value '%s' %s", arg, eq + 1,
                 eom_numtext_error(rc));
        return -1;
    }
    o->arg = arg;
    o->namelen = (size_t)(eq - arg);
    return 0;
}

int overrides_settings(const override *ov, int n, const demo *d,
                       double *settings, char *err, size_t errlen)
{
    int i, k;
    for (k = 0; k < d->nsettings; k++)
        settings[k] = d->settings[k].dflt;
    for (i = 0; i < n; i++) {
        const demo_setting *st;
        double v = ov[i].value;
        k = demo_setting_index(d, ov[i].arg, ov[i].namelen);
        if (k < 0)
            continue;
        st = &d->settings[k];
        if (st->integer && v != floor(v)) {
            snprintf(err, errlen, "--set '%s': setting '%s' takes an "
                     "integer value", ov[i].arg, st->name);
            return -1;
        }
        if (!(v >= st->min && v <= st->max)) {
            snprintf(err, errlen, "--set '%s': setting '%s' must be between "
                     "%g and %g", ov[i].arg, st->name, st->min, st->max);
            return -1;
        }
        settings[k] = v;
    }
    return 0;
}

/* Append s to buf (size len, holding a string) as far as it fits. */
static void append(char *buf, size_t len, const char *s)
{
    size_t used = strlen(buf);
    if (used + 1 < len)
        snprintf(buf + used, len - used, "%s", s);
}

/* The message for an unknown name: the known names when they are few
 * enough to read, and always the way to see them all. */
static void unknown_name(const override *o, const demo *d,
                         const eom_system *s, char *err, size_t errlen)
{
    const int np = eom_system_nparams(s), nc = eom_system_ncoords(s);
    const int total = d->nsettings + np + 2 * nc;
    int i;
    snprintf(err, errlen, "--set '%s': %s has no setting, parameter or "
             "coordinate named '%.*s'", o->arg, d->name, (int)o->namelen,
             o->arg);
    if (total <= 40) {
        append(err, errlen, "; its names are ");
        for (i = 0; i < total; i++) {
            const char *name;
            if (i > 0)
                append(err, errlen, ", ");
            if (i < d->nsettings)
                name = d->settings[i].name;
            else if (i < d->nsettings + np)
                name = eom_param_name(s, i - d->nsettings);
            else
                name = eom_coord_name(s, (i - d->nsettings - np) % nc);
            append(err, errlen, name);
            if (i >= d->nsettings + np + nc)
                append(err, errlen, "_dot");
        }
    }
    append(err, errlen, " (see: eom-run ");
    append(err, errlen, d->name);
    append(err, errlen, " --describe)");
}

int overrides_apply(const override *ov, int n, const demo *d, eom_system *s,
                    double *x, char *err, size_t errlen)
{
    char name[256];
    int i, k, nparams = 0;
    /* the parameters first: a model's start may follow them */
    for (i = 0; i < n; i++) {
        size_t len = ov[i].namelen;
        if (demo_setting_index(d, ov[i].arg, len) >= 0 || len >= sizeof name)
            continue;
        memcpy(name, ov[i].arg, len);
        name[len] = '\0';
        if ((k = eom_param_index(s, name)) < 0)
            continue;
        if (eom_set_param(s, k, ov[i].value) != EOM_OK) {
            snprintf(err, errlen, "--set '%s': %s", ov[i].arg,
                     eom_system_errmsg(s));
            return -1;
        }
        nparams++;
    }
    if (nparams > 0 && eom_initial_state(s, x) != EOM_OK) {
        snprintf(err, errlen, "the initial state is not finite with these "
                 "parameters");
        return -1;
    }
    /* then the coordinates and rates, and every unknown name */
    return overrides_apply_state(ov, n, d, s, x, err, errlen);
}

int overrides_apply_state(const override *ov, int n, const demo *d,
                          eom_system *s, double *x, char *err, size_t errlen)
{
    static const char dot[] = "_dot";
    const size_t ldot = sizeof dot - 1;
    const int nc = eom_system_ncoords(s);
    char name[256];
    int i, k;
    for (i = 0; i < n; i++) {
        size_t len = ov[i].namelen;
        if (demo_setting_index(d, ov[i].arg, len) >= 0)
            continue;
        if (len < sizeof name) {
            memcpy(name, ov[i].arg, len);
            name[len] = '\0';
            if (eom_param_index(s, name) >= 0)
                continue;
            if ((k = eom_coord_index(s, name)) >= 0) {
                x[k] = ov[i].value;
                continue;
            }
            if (len > ldot && strcmp(name + len - ldot, dot) == 0) {
                name[len - ldot] = '\0';
                if ((k = eom_coord_index(s, name)) >= 0) {
                    x[nc + k] = ov[i].value;
                    continue;
                }
            }
        }
        unknown_name(&ov[i], d, s, err, errlen);
        return -1;
    }
    return 0;
}
