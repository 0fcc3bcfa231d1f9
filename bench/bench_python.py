"""bench_python.py - what the Python package adds to the C library's
right-hand side (docs/benchmarks.md, docs/python.md):

  1. one s.rhs(t, x) call from Python against one eom_rhs call in a C
     loop (bench-rhs-loop): the time added per call (target: < 1 us);
  2. the batch s.rhs(t, X), X of shape (k, 2n), per state against the
     same C loop over the k states (target: within 10 %).

Prints the times and ratios, checks the results against the C loop's
checksum, and never fails on time.

usage: bench_python.py BENCH_RHS_LOOP MODELS_DIR [--quick]
"""
import os
import subprocess
import sys
import time

import numpy as np

import autoeom


def c_loop(exe, model, k, reps):
    out = subprocess.run([exe, model, str(k), str(reps)], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[1]), float(out[3])


def best_of(f, passes=5):
    best = float("inf")
    for _ in range(passes):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def main():
    exe, models = sys.argv[1], sys.argv[2]
    quick = "--quick" in sys.argv
    reps, k = (2000, 100) if quick else (200000, 1000)
    for name in ("spring-pendulum", "open-chain"):
        model = os.path.join(models, name + ".eom")
        s = autoeom.load(model)
        n2 = 2 * s.ncoords
        X = s.initial_state() + 1e-3 * np.arange(k)[:, None] * np.ones(n2)
        x = X[0].copy()
        rhs = s.rhs

        def single():
            for _ in range(reps):
                rhs(0.0, x)

        c_one, _ = c_loop(exe, model, 1, reps)
        py_one = 1e9 * best_of(single) / reps
        batch_reps = max(1, reps // k)

        def batch():
            for _ in range(batch_reps):
                rhs(0.0, X)

        c_batch, checksum = c_loop(exe, model, k, batch_reps)
        py_batch = 1e9 * best_of(batch) / (batch_reps * k)
        ok = np.isclose(rhs(0.0, X).sum(), checksum, rtol=1e-12)
        print("%-16s n=%-3d rhs from C %8.1f ns, from Python %8.1f ns: "
              "%+7.1f ns added per call" % (name, s.ncoords, c_one, py_one,
                                            py_one - c_one))
        print("%-16s batch of %d: C loop %8.1f ns/state, Python batch "
              "%8.1f ns/state: ratio %.3f%s" % (
                  name, k, c_batch, py_batch, py_batch / c_batch,
                  "" if ok else "  (RESULTS DIFFER)"))
        if not ok:
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
