/* sweep.h - what the sweep drivers (forward.c, reverse.c) share: the
 * per-op kernels of sweep_ops.h, the view of a workspace they run on, and
 * the vector clones of the row-heavy loops. Private to the sweep files. */
#ifndef TAPE_SWEEP_H
#define TAPE_SWEEP_H

#include <stdint.h>

#include "codegen.h"
#include "sweep_ops.h"
#include "tape_internal.h"

/* The row-heavy kernels are also compiled for AVX2 and picked at load time
 * (GCC's function multi-versioning), so a generic build uses 4-wide
 * vectors where the machine has them. No FMA: both versions round alike.
 * Not under ThreadSanitizer: the clones of a static function are chosen
 * while the library is relocated, before that sanitizer's runtime is up,
 * and the choice crashes there. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) &&    \
    defined(__linux__) && !defined(__SANITIZE_THREAD__)
#define TP_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define TP_VECTOR_CLONES
#endif

/* A sweep's view of workspace ws with pr columns and seed mask. */
static inline tp_kx tp__kx(tp_ws *ws, int pr, unsigned mask)
{
    tp_kx x;
    x.K = ws->t->konst;
    x.v = ws->v;
    x.aux = ws->aux;
    x.adj = ws->adj;
    x.tan = ws->tan;
    x.atan = ws->atan;
    x.anz = ws->anz;
    x.d1 = ws->d1;
    x.d2 = ws->d2;
    x.P = (size_t)ws->P;
    x.pr = pr;
    x.mask = mask;
    return x;
}

#endif /* TAPE_SWEEP_H */
