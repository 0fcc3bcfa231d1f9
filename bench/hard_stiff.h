/* hard_stiff.h - bench-hard's stiff-target section (hard_stiff.c). */
#ifndef BENCH_HARD_STIFF_H
#define BENCH_HARD_STIFF_H

/* The closed chain with EI x 100 and two modes per link, undamped and
 * with 2% modal damping: every method's work against precision over
 * 10 s, printed as markdown. quick: a short run that only keeps the
 * section working. Returns 0, or 1 when a case could not run (its
 * reference failed). */
int hard_stiff_target(int quick);

#endif
