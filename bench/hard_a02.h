/* hard_a02.h - bench-hard's a02 section (hard_a02.c). */
#ifndef BENCH_HARD_A02_H
#define BENCH_HARD_A02_H

/* The IFToMM benchmark A02, N = 40 four-bar loops, 20 s through its 20
 * flat singular positions, in natural coordinates and in angles, with
 * every method: status, cost and error against the exact motion,
 * printed as markdown. models_dir holds a02-natural.eom and
 * a02-angles.eom. quick: 1 s (one flat position) with erk, to keep the
 * section working. Returns 0, or 1 when a model could not be
 * read. */
int hard_a02(const char *models_dir, int quick);

/* The exact motion's pendulum, th'' = -a cos th, advanced from (*th, *w)
 * by dt with classical RK4 steps of at most 2e-5 s (its error far below
 * the benchmark's tolerance); bench-a02-growth uses it too. */
void hard_a02_pendulum(double a, double *th, double *w, double dt);

#endif
