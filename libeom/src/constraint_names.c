/* constraint_names.c - names of constraint rows: given per block on the
 * model (eom_model_name_constraints), gathered in row order when the
 * system is built (holonomic rows, then velocity rows), checked unique,
 * and looked up by row or by name. The names belong to the tapes' shared
 * part: clones read the same array. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

static char *dup_name(const char *name)
{
    size_t n = strlen(name) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, name, n);
    return d;
}

int eom_model_name_constraints(eom_model *m, int count,
                               const char *const *names)
{
    eom_callback *cb;
    char **copy;
    int i;
    if (!m)
        return EOM_ERR_NULL;
    if (m->status != EOM_OK)
        return m->status;
    if (!names)
        return eom__model_fail(m, EOM_ERR_NULL,
                               "eom_model_name_constraints: names is NULL");
    if (!m->last_con || m->last_con->n == 0)
        return eom__model_fail(m, EOM_ERR_ARG, "eom_model_name_constraints: "
                               "no constraint block has been added to name");
    cb = &m->last_con->v[m->last_con->n - 1];
    if (count < 1 || count != cb->count)
        return eom__model_fail(m, EOM_ERR_ARG, "eom_model_name_constraints: "
                               "%d names for a block of %d rows", count,
                               cb->count);
    for (i = 0; i < count; i++)
        if (names[i] && !eom__valid_name(names[i]))
            return eom__model_fail(m, EOM_ERR_ARG, "constraint name '%s' "
                                   "(row %d of the block): not an "
                                   "identifier", names[i], i + 1);
    copy = calloc((size_t)count, sizeof *copy);
    if (!copy)
        return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
    for (i = 0; i < count; i++)
        if (names[i] && !(copy[i] = dup_name(names[i]))) {
            eom__free_names(copy, count);
            return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
        }
    eom__free_names(cb->names, cb->count);
    cb->names = copy;
    return EOM_OK;
}

void eom__free_names(char **names, int count)
{
    int i;
    if (!names)
        return;
    for (i = 0; i < count; i++)
        free(names[i]);
    free(names);
}

/* qsort's comparison of row indices by name (the rows' names through a
 * file-scope pointer would not be thread-safe: the indices are sorted
 * together with their names instead). */
typedef struct named_row {
    const char *name;
    int row;
} named_row;

static int by_name(const void *a, const void *b)
{
    const named_row *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : (x->row > y->row) - (x->row < y->row);
}

/* Copy the blocks' names into rows first .. of names; 1 if any. */
static int gather(const eom_cblist *list, char **names, int first,
                  int *any)
{
    int b, i, row = first;
    for (b = 0; b < list->n; b++) {
        const eom_callback *cb = &list->v[b];
        for (i = 0; i < cb->count; i++, row++)
            if (cb->names && cb->names[i]) {
                if (!(names[row] = dup_name(cb->names[i])))
                    return -1;
                *any = 1;
            }
    }
    return 0;
}

int eom__constraint_names(eom_system *s, const eom_model *m)
{
    eom_shared *sh = s->shared;
    named_row *v;
    int any = 0, i, k = 0;
    if (s->m == 0)
        return EOM_OK;
    sh->con_names = calloc((size_t)s->m, sizeof *sh->con_names);
    if (!sh->con_names)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    if ((s->mh > 0 && gather(&m->phi, sh->con_names, 0, &any) < 0) ||
        (s->mv > 0 && gather(&m->psi, sh->con_names, s->mh, &any) < 0))
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    if (!any) {
        eom__free_names(sh->con_names, s->m);
        sh->con_names = NULL;
        return EOM_OK;
    }
    v = malloc((size_t)s->m * sizeof *v);
    sh->con_sorted = malloc((size_t)s->m * sizeof *sh->con_sorted);
    if (!v || !sh->con_sorted) {
        free(v);
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    }
    for (i = 0; i < s->m; i++)
        if (sh->con_names[i]) {
            v[k].name = sh->con_names[i];
            v[k++].row = i;
        }
    qsort(v, (size_t)k, sizeof *v, by_name);
    for (i = 0; i < k; i++) {
        if (i > 0 && strcmp(v[i].name, v[i - 1].name) == 0) {
            int a = v[i - 1].row, b = v[i].row;
            free(v);
            return eom__fail(s, EOM_ERR_MODEL, "the constraint name '%s' is "
                             "given to rows %d and %d (names of constraint "
                             "rows must differ)", sh->con_names[a], a + 1,
                             b + 1);
        }
        sh->con_sorted[i] = v[i].row;
    }
    sh->n_named = k;
    free(v);
    return EOM_OK;
}

void eom__constraint_names_free(eom_shared *sh, int m)
{
    eom__free_names(sh->con_names, m);
    free(sh->con_sorted);
    sh->con_names = NULL;
    sh->con_sorted = NULL;
}

const char *eom_constraint_name(const eom_system *s, int j)
{
    if (!s || j < 0 || j >= s->m)
        return NULL;
    return s->shared->con_names && s->shared->con_names[j]
               ? s->shared->con_names[j]
               : "";
}

void eom__row_label(const eom_system *s, int j, char *buf, size_t len)
{
    const char *name = eom_constraint_name(s, j);
    if (name && name[0])
        snprintf(buf, len, "'%s'", name);
    else
        snprintf(buf, len, "row %d", j + 1);
}

int eom_constraint_index(const eom_system *s, const char *name)
{
    int lo = 0, hi;
    if (!s || !name || !s->shared->con_names)
        return -1;
    hi = s->shared->n_named - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        int row = s->shared->con_sorted[mid];
        int c = strcmp(s->shared->con_names[row], name);
        if (c == 0)
            return row;
        if (c < 0)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}
