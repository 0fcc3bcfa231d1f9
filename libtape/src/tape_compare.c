/* tape_compare.c - tp_tape_equal: two finished tapes compared op for op
 * (what a second front end, such as the C++ operators of eom/eom.hpp,
 * must record to be the same as the C calls). */
#include <string.h>

#include "tape_internal.h"

static int same_names(char **a, char **b, uint32_t n)
{
    uint32_t i;
    for (i = 0; i < n; i++)
        if (strcmp(a[i], b[i]) != 0)
            return 0;
    return 1;
}

int tp_tape_equal(const tp_tape *a, const tp_tape *b, size_t *first_diff)
{
    uint32_t i, n;
    if (first_diff)
        *first_diff = 0;
    if (!a || !b)
        return 0;
    n = a->n_ops < b->n_ops ? a->n_ops : b->n_ops;
    for (i = 0; i < n; i++) {
        /* the operands of an op are slots or pool indices, so equal pools
         * (checked below) make equal fields mean equal ops */
        if (a->opc[i] != b->opc[i] || a->a0[i] != b->a0[i] ||
            a->a1[i] != b->a1[i] || a->dep[i] != b->dep[i])
            break;
    }
    if (first_diff)
        *first_diff = i;
    if (i < n || a->n_ops != b->n_ops)
        return 0;
    if (a->n_indep != b->n_indep || a->n_param != b->n_param ||
        a->n_out != b->n_out || a->n_const != b->n_const ||
        (a->n_const &&
         memcmp(a->konst, b->konst, a->n_const * sizeof(double)) != 0) ||
        (a->n_out && memcmp(a->out_slot, b->out_slot,
                            a->n_out * sizeof(uint32_t)) != 0) ||
        !same_names(a->out_name, b->out_name, a->n_out) ||
        !same_names(a->param_name, b->param_name, a->n_param) ||
        (a->n_param && memcmp(a->param_dflt, b->param_dflt,
                              a->n_param * sizeof(double)) != 0) ||
        (a->n_indep &&
         memcmp(a->group, b->group, a->n_indep) != 0))
        return 0;
    return 1;
}
