/* file_demo.c - a model file as an eom-run demo (file_demo.h). */
#define _DEFAULT_SOURCE /* readlink, opendir */
#include <dirent.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "eom/model_file.h"
#include "file_demo.h"
#include "eom/run.h"

/* What a file demo owns. */
typedef struct file_data {
    eom_file *file;
    char *name, *summary;
    demo_setting *settings;
    char **desc;
} file_data;

static char *copy(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static int file_build(const demo *d, const double *settings, eom_model **out,
                      char *err, size_t errlen)
{
    file_data *fd = d->data;
    int k;
    for (k = 0; k < d->nsettings; k++)
        if (eom_file_set_setting(fd->file, d->settings[k].name,
                                 (long)settings[k], err, errlen) != EOM_OK)
            return -1;
    return eom_file_build(fd->file, out, err, errlen) == EOM_OK ? 0 : -1;
}

static int file_plots(const demo *d, const double *settings,
                      const eom_system *s, const char *csv_path, char *err,
                      size_t errlen)
{
    (void)settings;
    return eom_run_plots(d->name, s, csv_path, err, errlen);
}

void file_demo_free(demo **d)
{
    file_data *fd;
    int k;
    if (!d || !*d)
        return;
    fd = (*d)->data;
    if (fd) {
        for (k = 0; fd->desc && k < (*d)->nsettings; k++)
            free(fd->desc[k]);
        free(fd->desc);
        free(fd->settings);
        free(fd->name);
        free(fd->summary);
        eom_file_free(&fd->file);
        free(fd);
    }
    free(*d);
    *d = NULL;
}

int file_demo_open(const char *path, const char *name, demo **out,
                   char *err, size_t errlen)
{
    demo *d = calloc(1, sizeof *d);
    file_data *fd = calloc(1, sizeof *fd);
    int k, n;
    *out = NULL;
    if (!d || !fd) {
        free(d);
        free(fd);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    d->data = fd;
    if (eom_file_read(&fd->file, path, err, errlen) != EOM_OK) {
        file_demo_free(&d);
        return -1;
    }
    n = eom_file_nsettings(fd->file);
    fd->name = copy(name ? name : path);
    fd->summary = copy(eom_file_summary(fd->file));
    fd->settings = calloc((size_t)n + 1, sizeof *fd->settings);
    fd->desc = calloc((size_t)n + 1, sizeof *fd->desc);
    if (!fd->name || !fd->summary || !fd->settings || !fd->desc) {
        file_demo_free(&d);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (k = 0; k < n; k++) {
        demo_setting *st = &fd->settings[k];
        long dflt, lo, hi;
        eom_file_setting_range(fd->file, k, &dflt, &lo, &hi);
        if (!(fd->desc[k] = copy(eom_file_setting_description(fd->file,
                                                              k)))) {
            file_demo_free(&d);
            snprintf(err, errlen, "out of memory");
            return -1;
        }
        st->name = eom_file_setting_name(fd->file, k);
        st->unit = "";
        st->dflt = (double)dflt;
        st->min = (double)lo;
        st->max = (double)hi;
        st->integer = 1;
        st->description = fd->desc[k];
    }
    d->name = fd->name;
    d->summary = fd->summary;
    d->settings = fd->settings;
    d->nsettings = n;
    d->build = file_build;
    d->after_run = file_plots;
    *out = d;
    return 0;
}

int demo_resolve(const char *name, const demo **d, demo **fd, char *err,
                 size_t errlen)
{
    char path[4096];
    size_t len = strlen(name);
    const char *file = NULL;
    *fd = NULL;
    *d = demo_find(name);
    if (*d)
        return 0;
    if (strchr(name, '/') || (len > 4 && strcmp(name + len - 4, ".eom") == 0))
        file = name;
    else if (file_demo_shipped(name, path, sizeof path) == 0)
        file = path;
    if (!file)
        return 1;
    if (file_demo_open(file, file == name ? NULL : name, fd, err, errlen) !=
        0)
        return 2;
    *d = *fd;
    return 0;
}

/* ---- shipped models ---------------------------------------------------- */

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

const char *file_demo_models_dir(void)
{
    static char dir[PATH_MAX + 64];
    char exe[PATH_MAX];
    const char *env = getenv("EOM_MODELS");
    ssize_t n;
    if (env && env[0] && is_dir(env)) {
        snprintf(dir, sizeof dir, "%s", env);
        return dir;
    }
    n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        char *slash;
        exe[n] = '\0';
        if ((slash = strrchr(exe, '/')) != NULL) {
            *slash = '\0';
            snprintf(dir, sizeof dir, "%s/../share/autoeom/models", exe);
            if (is_dir(dir))
                return dir;
        }
    }
#ifdef EOM_SOURCE_MODELS
    if (is_dir(EOM_SOURCE_MODELS)) {
        snprintf(dir, sizeof dir, "%s", EOM_SOURCE_MODELS);
        return dir;
    }
#endif
    return NULL;
}

int file_demo_shipped(const char *name, char *path, size_t len)
{
    const char *dir = file_demo_models_dir();
    struct stat st;
    if (!dir || strchr(name, '/') || !name[0])
        return -1;
    if ((size_t)snprintf(path, len, "%s/%s.eom", dir, name) >= len)
        return -1;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) ? 0 : -1;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

void file_demo_list(FILE *f)
{
    const char *dir = file_demo_models_dir();
    char *names[256];
    int n = 0, k, w = 0;
    DIR *dp;
    struct dirent *e;
    if (!dir || !(dp = opendir(dir)))
        return;
    while ((e = readdir(dp)) != NULL && n < 256) {
        size_t l = strlen(e->d_name);
        if (l > 4 && strcmp(e->d_name + l - 4, ".eom") == 0 &&
            (names[n] = copy(e->d_name)) != NULL) {
            names[n][l - 4] = '\0';
            if ((int)l - 4 > w)
                w = (int)l - 4;
            n++;
        }
    }
    closedir(dp);
    qsort(names, (size_t)n, sizeof names[0], by_name);
    if (n > 0)
        fprintf(f, "\nmodel files in %s (eom-run NAME where no demo above "
                   "has that name,\nor eom-run PATH.eom, for these and "
                   "your own):\n", dir);
    for (k = 0; k < n; k++) {
        char path[PATH_MAX + 300], err[256];
        eom_file *ef = NULL;
        snprintf(path, sizeof path, "%s/%s.eom", dir, names[k]);
        if (eom_file_read(&ef, path, err, sizeof err) == EOM_OK)
            fprintf(f, "%-*s  %s\n", w, names[k], eom_file_summary(ef));
        else
            fprintf(f, "%-*s  (does not load: run it to see why)\n", w,
                    names[k]);
        eom_file_free(&ef);
        free(names[k]);
    }
}
