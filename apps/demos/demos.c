/* demos.c - the list of demos eom-run knows and lookups in it. */
#include "demos.h"

#include <stdio.h>
#include <string.h>

static const demo *const all_demos[] = {
    &demo_spring_pendulum,
    &demo_open_chain,
    &demo_closed_chain,
};

const demo *const *demos_all(int *count)
{
    *count = (int)(sizeof all_demos / sizeof all_demos[0]);
    return all_demos;
}

const demo *demo_find(const char *name)
{
    size_t i;
    for (i = 0; name && i < sizeof all_demos / sizeof all_demos[0]; i++)
        if (strcmp(all_demos[i]->name, name) == 0)
            return all_demos[i];
    return NULL;
}

int demo_setting_index(const demo *d, const char *name, size_t namelen)
{
    int i;
    for (i = 0; i < d->nsettings; i++)
        if (strlen(d->settings[i].name) == namelen &&
            strncmp(d->settings[i].name, name, namelen) == 0)
            return i;
    return -1;
}

int demo_model_done(eom_model **m, eom_model **out, char *err,
                    size_t errlen)
{
    *out = NULL;
    if (!*m) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (eom_model_errmsg(*m)[0]) {
        snprintf(err, errlen, "%s", eom_model_errmsg(*m));
        eom_model_free(m);
        return -1;
    }
    *out = *m;
    *m = NULL;
    return 0;
}

int demo_check_names(const demo *d, const eom_system *s, char *err,
                     size_t errlen)
{
    int i;
    for (i = 0; i < d->nsettings; i++) {
        const char *name = d->settings[i].name;
        if (eom_param_index(s, name) >= 0 || eom_coord_index(s, name) >= 0) {
            snprintf(err, errlen,
                     "demo %s: setting '%s' is also the name of a parameter "
                     "or coordinate", d->name, name);
            return -1;
        }
    }
    return 0;
}
