/* model_file.c - the public face of the model language (eom/model_file.h):
 * read a file, run the stages of lang.h on it, keep its structural
 * settings, and build models from it. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/model_file.h"
#include "eom_internal.h"
#include "lang.h"

int lang_build(lang_prog *p, const double *setting, eom_model **out,
               char *err, size_t len);

struct eom_file {
    lang_prog *p;
    int nset;
    int *sym;          /* [nset] setting symbols */
    long *value, *dflt, *lo, *hi;
    char **desc;       /* [nset] descriptions ("" when none) */
    char summary[160];
};

static void put(char *err, size_t len, const char *fmt, const char *a,
                const char *b)
{
    if (err && len)
        snprintf(err, len, fmt, a, b);
}

void eom_file_free(eom_file **f)
{
    int k;
    if (!f || !*f)
        return;
    lang_prog_release((*f)->p);
    free((*f)->sym);
    free((*f)->value);
    free((*f)->dflt);
    free((*f)->lo);
    free((*f)->hi);
    for (k = 0; (*f)->desc && k < (*f)->nset; k++)
        free((*f)->desc[k]);
    free((*f)->desc);
    free(*f);
    *f = NULL;
}

/* The settings' defaults and ranges: whole numbers written in the file. */
static int settings(eom_file *f, char *err, size_t len)
{
    lang_prog *p = f->p;
    lang_inst in;
    int k, n = 0;
    for (k = 0; k < p->nsyms; k++)
        n += p->syms[k].kind == S_SETTING;
    f->sym = calloc((size_t)n + 1, sizeof *f->sym);
    f->value = calloc((size_t)n + 1, sizeof *f->value);
    f->dflt = calloc((size_t)n + 1, sizeof *f->dflt);
    f->lo = calloc((size_t)n + 1, sizeof *f->lo);
    f->hi = calloc((size_t)n + 1, sizeof *f->hi);
    f->desc = calloc((size_t)n + 1, sizeof *f->desc);
    if (!f->sym || !f->value || !f->dflt || !f->lo || !f->hi || !f->desc) {
        put(err, len, "%s%s", "out of memory", "");
        return -1;
    }
    memset(&in, 0, sizeof in);
    in.p = p;
    for (k = 0; k < p->nsyms; k++) {
        const sym *s = &p->syms[k];
        const int i = f->nset;
        if (s->kind != S_SETTING)
            continue;
        lang_begin(&in, NULL, EOM_ROLE_STATE, "a setting");
        f->sym[i] = k;
        f->lo[i] = 0;
        f->hi[i] = LANG_MAX_SETTING;
        if (lang_eval_int(&in, s->value, "a setting's default",
                          &f->dflt[i]) < 0 ||
            (s->lo >= 0 &&
             (lang_eval_int(&in, s->lo, "a setting's range", &f->lo[i]) < 0 ||
              lang_eval_int(&in, s->hi, "a setting's range", &f->hi[i]) <
                  0))) {
            put(err, len, "%s%s", in.err, "");
            free(in.memo);
            return -1;
        }
        if (f->lo[i] > f->hi[i] || f->lo[i] < -LANG_MAX_SETTING ||
            f->hi[i] > LANG_MAX_SETTING) {
            lang_diag(p, s->lo >= 0 ? p->nodes[s->lo].tok : s->tok, err, len,
                      NULL, "the range of %s must be within -%d..%d and "
                      "not empty", s->name, LANG_MAX_SETTING,
                      LANG_MAX_SETTING);
            return -1;
        }
        if (f->dflt[i] < f->lo[i] || f->dflt[i] > f->hi[i]) {
            char hint[120];
            snprintf(hint, sizeof hint, "the range is %ld..%ld", f->lo[i],
                     f->hi[i]);
            lang_diag(p, p->nodes[s->value].tok, err, len, hint,
                      "the default of %s is outside its range", s->name);
            return -1;
        }
        f->value[i] = f->dflt[i];
        {
            const token *t = s->desc_tok >= 0 ? &p->toks[s->desc_tok] : NULL;
            size_t dlen = t ? (size_t)(t->len - 2) : 0;
            if (!(f->desc[i] = malloc(dlen + 1))) {
                put(err, len, "%s%s", "out of memory", "");
                return -1;
            }
            if (t)
                memcpy(f->desc[i], p->text + t->off + 1, dlen);
            f->desc[i][dlen] = '\0';
        }
        f->nset++;
    }
    free(in.memo);
    return 0;
}

static void summary(eom_file *f)
{
    const char *s = f->p->text;
    size_t n = 0;
    f->summary[0] = '\0';
    if (s[0] != '#')
        return;
    s++;
    while (*s == ' ' || *s == '#')
        s++;
    while (s[n] && s[n] != '\n' && s[n] != '\r' &&
           n + 1 < sizeof f->summary)
        n++;
    memcpy(f->summary, s, n);
    f->summary[n] = '\0';
}

/* Takes text (malloc'd, NUL-terminated, len bytes) in every case. */
static int from_text(eom_file **out, char *text, long len, const char *name,
                     char *err, size_t errlen)
{
    eom_file *f = calloc(1, sizeof *f);
    lang_prog *p = calloc(1, sizeof *p);
    char dummy[8];
    if (!err || errlen == 0) {
        err = dummy;
        errlen = sizeof dummy;
    }
    err[0] = '\0';
    if (!f || !p || !(p->path = lang_strdup(name))) {
        free(f);
        free(p);
        free(text);
        snprintf(err, errlen, "out of memory");
        return EOM_ERR_NOMEM;
    }
    p->refs = 1;
    p->budget = LANG_BUDGET;
    p->max_count = LANG_MAX_COUNT;
    p->text = text;
    p->text_len = len;
    f->p = p;
    if ((long)strlen(text) != len) {
        long at = (long)strlen(text), line = 1, col = 1, k;
        for (k = 0; k < at; k++) {
            col++;
            if (text[k] == '\n') {
                line++;
                col = 1;
            }
        }
        lang_diag_at(p, (int)line, (int)col, err, errlen,
                     "a model file is text", "a NUL byte");
        eom_file_free(&f);
        return EOM_ERR_FILE;
    }
    if (lang_lex(p, err, errlen) != 0 || lang_parse(p, err, errlen) != 0 ||
        lang_resolve(p, err, errlen) != 0 || lang_shapes(p, err, errlen) != 0 ||
        lang_rates(p, err, errlen) != 0 ||
        lang_units(p, err, errlen) != 0 || lang_draws(p, err, errlen) != 0 ||
        settings(f, err, errlen) != 0) {
        eom_file_free(&f);
        return EOM_ERR_FILE;
    }
    summary(f);
    *out = f;
    return EOM_OK;
}

int eom_file_parse(eom_file **out, const char *text, const char *name,
                   char *err, size_t errlen)
{
    char *copy;
    size_t n;
    if (err && errlen)
        err[0] = '\0';
    if (!out)
        return EOM_ERR_NULL;
    *out = NULL;
    if (!text)
        return EOM_ERR_NULL;
    n = strlen(text);
    if (n > (size_t)LANG_MAX_FILE) {
        put(err, errlen, "%s: the text is longer than 1 MiB%s",
            name ? name : "<string>", "");
        return EOM_ERR_FILE;
    }
    if (!(copy = malloc(n + 1)))
        return EOM_ERR_NOMEM;
    memcpy(copy, text, n + 1);
    return from_text(out, copy, (long)n, name ? name : "<string>", err,
                     errlen);
}

int eom_file_read(eom_file **out, const char *path, char *err,
                  size_t errlen)
{
    FILE *fp;
    char *text;
    size_t n;
    if (err && errlen)
        err[0] = '\0';
    if (!out)
        return EOM_ERR_NULL;
    *out = NULL;
    if (!path)
        return EOM_ERR_NULL;
    fp = fopen(path, "rb");
    if (!fp) {
        put(err, errlen, "%s: cannot open the model file: %s", path,
            strerror(errno));
        return EOM_ERR_FILE;
    }
    text = malloc((size_t)LANG_MAX_FILE + 2);
    if (!text) {
        fclose(fp);
        return EOM_ERR_NOMEM;
    }
    n = fread(text, 1, (size_t)LANG_MAX_FILE + 1, fp);
    if (ferror(fp)) {
        put(err, errlen, "%s: cannot read the model file: %s", path,
            strerror(errno));
        fclose(fp);
        free(text);
        return EOM_ERR_FILE;
    }
    fclose(fp);
    if (n > (size_t)LANG_MAX_FILE) {
        put(err, errlen, "%s: the file is larger than 1 MiB, the limit for "
            "a model file%s", path, "");
        free(text);
        return EOM_ERR_FILE;
    }
    text[n] = '\0';
    return from_text(out, text, (long)n, path, err, errlen);
}

void lang_file_limits(eom_file *f, long budget, int max_count)
{
    if (f) {
        f->p->budget = budget;
        f->p->max_count = max_count;
    }
}

const char *eom_file_summary(const eom_file *f)
{
    return f ? f->summary : "";
}

int eom_file_nsettings(const eom_file *f) { return f ? f->nset : 0; }

const char *eom_file_setting_name(const eom_file *f, int k)
{
    if (!f || k < 0 || k >= f->nset)
        return NULL;
    return f->p->syms[f->sym[k]].name;
}

const char *eom_file_setting_description(const eom_file *f, int k)
{
    if (!f || k < 0 || k >= f->nset)
        return NULL;
    return f->desc[k];
}

int eom_file_setting_range(const eom_file *f, int k, long *dflt, long *min,
                           long *max)
{
    if (!f)
        return EOM_ERR_NULL;
    if (k < 0 || k >= f->nset)
        return EOM_ERR_ARG;
    if (dflt)
        *dflt = f->dflt[k];
    if (min)
        *min = f->lo[k];
    if (max)
        *max = f->hi[k];
    return EOM_OK;
}

long eom_file_setting(const eom_file *f, int k)
{
    if (!f || k < 0 || k >= f->nset)
        return 0;
    return f->value[k];
}

int eom_file_set_setting(eom_file *f, const char *name, long value,
                         char *err, size_t errlen)
{
    int k;
    if (err && errlen)
        err[0] = '\0';
    if (!f || !name)
        return EOM_ERR_NULL;
    for (k = 0; k < f->nset; k++)
        if (strcmp(name, f->p->syms[f->sym[k]].name) == 0) {
            if (value < f->lo[k] || value > f->hi[k]) {
                if (err && errlen)
                    snprintf(err, errlen, "setting %s = %ld is outside its "
                             "range %ld..%ld", name, value, f->lo[k],
                             f->hi[k]);
                return EOM_ERR_ARG;
            }
            f->value[k] = value;
            return EOM_OK;
        }
    if (err && errlen)
        snprintf(err, errlen, "%s is not a setting of %s", name, f->p->path);
    return EOM_ERR_NAME;
}

int eom_file_build(const eom_file *f, eom_model **out, char *err,
                   size_t errlen)
{
    double *set;
    char dummy[8];
    int k, rc;
    if (!err || errlen == 0) {
        err = dummy;
        errlen = sizeof dummy;
    }
    err[0] = '\0';
    if (!out)
        return EOM_ERR_NULL;
    *out = NULL;
    if (!f)
        return EOM_ERR_NULL;
    set = calloc((size_t)f->p->nsyms + 1, sizeof *set);
    if (!set)
        return EOM_ERR_NOMEM;
    for (k = 0; k < f->nset; k++)
        set[f->sym[k]] = (double)f->value[k];
    rc = lang_build(f->p, set, out, err, errlen);
    free(set);
    return rc;
}

int eom_model_from_file(eom_model **out, const char *path, char *err,
                        size_t errlen)
{
    eom_file *f = NULL;
    int rc;
    if (out)
        *out = NULL;
    rc = eom_file_read(&f, path, err, errlen);
    if (rc == EOM_OK)
        rc = eom_file_build(f, out, err, errlen);
    eom_file_free(&f);
    return rc;
}

int eom_model_from_string(eom_model **out, const char *text, char *err,
                          size_t errlen)
{
    eom_file *f = NULL;
    int rc;
    if (out)
        *out = NULL;
    rc = eom_file_parse(&f, text, NULL, err, errlen);
    if (rc == EOM_OK)
        rc = eom_file_build(f, out, err, errlen);
    eom_file_free(&f);
    return rc;
}
