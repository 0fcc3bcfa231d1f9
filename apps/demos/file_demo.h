/* file_demo.h - a model file (.eom, docs/models.md) run by eom-run like a
 * built-in demo: its structural settings become the demo's settings, its
 * model is built from the file for each run, and --plots draws the
 * generic plots of model_plots.h. Also where the shipped model files
 * (models/ in the source tree) are found. */
#ifndef APPS_FILE_DEMO_H
#define APPS_FILE_DEMO_H

#include <stddef.h>
#include <stdio.h>

#include "demos.h"

/* Read the model file at path (borrowed) into a new demo named name (or
 * path when NULL). Returns 0, or -1 with the file's message in err (on
 * failure *out is NULL). */
int file_demo_open(const char *path, const char *name, demo **out,
                   char *err, size_t errlen);
void file_demo_free(demo **d);

/* The demo or model file called name: a built-in demo, a path to a model
 * file (it ends in .eom or has a '/'), or a shipped model by name. *fd
 * receives a file's demo (the caller frees it with file_demo_free; NULL
 * for a built-in demo) and *d the demo to use. Returns 0; 1 when name is
 * none of these; 2 when the model file does not load (message in err). */
int demo_resolve(const char *name, const demo **d, demo **fd, char *err,
                 size_t errlen);

/* The folder of the shipped model files: $EOM_MODELS if set, else the
 * installed share/autoeom/models beside the program, else the source
 * tree's models/. NULL when none exists. */
const char *file_demo_models_dir(void);

/* path receives DIR/name.eom for a shipped model called name; 0 if that
 * file exists, else -1. */
int file_demo_shipped(const char *name, char *path, size_t len);

/* --list: the shipped models, "NAME  SUMMARY" (SUMMARY is the file's
 * first comment line), after a heading; nothing when there are none. */
void file_demo_list(FILE *f);

#endif /* APPS_FILE_DEMO_H */
