/* demos.h - the demo registry of eom-run. A demo is a model with names,
 * defaults and units for everything a user may change, plus what eom-run
 * must know before the model exists.
 *
 * Two kinds of values can be set from the command line:
 *   - structural settings (demo_setting): they decide the model's shape,
 *     for example the number of links or of modes per link, so they are
 *     read before build() and passed to it;
 *   - parameters and initial values: declared in the model itself
 *     (eom_model_add_param, eom_model_add_coord) and applied by eom-run to
 *     the built system with eom_set_param and to the initial state.
 * A setting's name must differ from every parameter and coordinate name
 * of the model it builds (eom-run checks this).
 *
 * Adding a demo: a file in apps/demos/ that defines a const demo, its
 * declaration below, one line in demos.c and one in apps/meson.build. */
#ifndef APPS_DEMOS_H
#define APPS_DEMOS_H

#include <stddef.h>

#include "eom/eom.h"

typedef struct demo_setting {
    const char *name;        /* a C identifier */
    const char *unit;        /* "" when dimensionless or a count */
    double dflt;             /* default value, within [min, max] */
    double min, max;         /* allowed values, inclusive */
    int integer;             /* 1: only integral values (counts) */
    const char *description; /* one line */
} demo_setting;

typedef struct demo {
    const char *name;    /* as typed on the command line ("spring-pendulum") */
    const char *summary; /* one line for --list */
    const demo_setting *settings; /* nsettings structural settings */
    int nsettings;
    /* Build the model for the structural settings (nsettings values, in
     * the order of settings, already checked against their ranges).
     * Returns 0 and a new model in *out (transferred to the caller), or
     * non-zero with *out NULL and a message in err (errlen bytes). The
     * model must own whatever its callbacks read (eom_model_attach). */
    int (*build)(const struct demo *d, const double *settings,
                 eom_model **out, char *err, size_t errlen);
    /* Optional (NULL: none). Called with --plots after a run that
     * finished and wrote its CSV to the file csv_path, for extra output
     * beside it such as plots. settings as for build; s is the system
     * that ran. Returns 0, or non-zero with a message in err (eom-run then
     * exits with status 1). */
    int (*after_run)(const struct demo *d, const double *settings,
                     const eom_system *s, const char *csv_path, char *err,
                     size_t errlen);
    /* Optional (NULL: start from the initial state). Where --modes starts
     * its search for the static equilibrium when no coordinate was set on
     * the command line: writes n coordinates to q (a guess near the
     * demo's stable rest state) and returns 0, or non-zero to use the
     * initial state. */
    int (*rest_guess)(const struct demo *d, const double *settings,
                      const eom_system *s, double *q);
    /* Whatever the hooks need beyond the settings (a model file's demo:
     * the parsed file); NULL for the built-in demos. Each hook receives
     * its demo as d. */
    void *data;
} demo;

/* The demos, in the order --list shows them. */
extern const demo demo_spring_pendulum;
extern const demo demo_open_chain;
extern const demo demo_closed_chain;

/* All demos: *count receives their number. */
const demo *const *demos_all(int *count);

/* The demo named name, or NULL. */
const demo *demo_find(const char *name);

/* The index of the structural setting named by the first namelen
 * characters of name, or -1. */
int demo_setting_index(const demo *d, const char *name, size_t namelen);

/* Check that no structural setting of d shares a name with a parameter
 * or coordinate of s (built by d). Returns 0, or -1 with a message. */
int demo_check_names(const demo *d, const eom_system *s, char *err,
                     size_t errlen);

/* For build(): turn the finished description *m into the result. If the
 * model recorded an error (eom_model_errmsg), frees it and returns
 * non-zero with that message in err; else moves it to *out and returns
 * 0. */
int demo_model_done(eom_model **m, eom_model **out, char *err,
                    size_t errlen);

#endif /* APPS_DEMOS_H */
