"""The GIL is released while a run integrates: two threads integrate at
once. Checked on what each thread records about itself (when its run
entered and left the library, and whether the other thread ran Python
code meanwhile), not on a ratio of times: a held GIL would keep every
other thread out for the whole of a run, however fast the machine."""
import sys
import threading
import time

import numpy as np

import autoeom


def long_enough_run(s):
    # long against the interpreter's switch interval, so that the edges
    # (where a thread may legitimately switch) are a small part of it
    si = sys.getswitchinterval()
    t_end = 1.0
    while True:
        t0 = time.perf_counter()
        s.run(t_end=t_end, sample=0.01)
        if time.perf_counter() - t0 > 40 * si:
            return t_end
        t_end *= 2


def test_other_threads_run_python_during_a_run(spring):
    t_end = long_enough_run(spring)
    si = sys.getswitchinterval()
    span = {}

    def worker():
        span["enter"] = time.perf_counter()
        spring.run(t_end=t_end, sample=0.01)
        span["leave"] = time.perf_counter()

    th = threading.Thread(target=worker)
    ticks = []
    th.start()
    while th.is_alive():
        ticks.append(time.perf_counter())
    th.join()
    lo, hi = span["enter"] + 2 * si, span["leave"] - 2 * si
    inside = [t for t in ticks if lo < t < hi]
    # with the GIL held by the run this thread could not have run at all
    # in the middle of it
    assert len(inside) > 100


def test_two_threads_integrate_at_once(spring):
    other = spring.clone()
    t_end = long_enough_run(spring)
    si = sys.getswitchinterval()
    spans = [None, None]
    barrier = threading.Barrier(2)

    def worker(k, s):
        barrier.wait()
        enter = time.perf_counter()
        run = s.run(t_end=t_end, sample=0.01)
        spans[k] = (enter, time.perf_counter(), run.x[-1])

    threads = [threading.Thread(target=worker, args=(k, s))
               for k, s in enumerate((spring, other))]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    (a0, a1, xa), (b0, b1, xb) = spans
    overlap = min(a1, b1) - max(a0, b0)
    shorter = min(a1 - a0, b1 - b0)
    assert overlap > 0.5 * shorter, (overlap, shorter, 4 * si)
    # the same run on a clone gives the same bits
    assert np.array_equal(xa, xb)
