/* sympy_chains.h - the rigid chains derived by SymPy at build time
 * (chain_sympy.py): for each N, M and f with M qdd = f at x = (theta,
 * theta_dot) for masses m, lengths L and gravity g, and what deriving and
 * compiling the function took. The table ends with N = 0. Which SymPy
 * derived them matters for the times: the build's python3 may not be the
 * system's. */
#ifndef BENCH_SYMPY_CHAINS_H
#define BENCH_SYMPY_CHAINS_H

typedef void (*sympy_chain_fn)(const double *m, const double *L, double g,
                               const double *x, double *M, double *f);

typedef struct sympy_chain {
    int N;
    sympy_chain_fn fn;
    double derive_seconds;  /* CPU s: LagrangesMethod and cse */
    double compile_seconds; /* CPU s: cc -O2 of the function alone (0:
                             * failed) */
} sympy_chain;

extern const sympy_chain sympy_chains[];
extern const char sympy_version[]; /* the SymPy that derived them */

#endif
