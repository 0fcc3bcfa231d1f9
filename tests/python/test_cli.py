"""A run from Python equals eom-run's CSV for the same options (to 1e-14
relative: in fact the same numbers, as both drive the same library the
same way)."""
import csv
import os
import subprocess

import numpy as np
import pytest

import autoeom

CASES = [
    # (model, eom-run options, the same as keywords of load and run)
    ("spring-pendulum", ["--set", "k=100", "--set", "theta_dot=0.3",
                         "--t-end", "2", "--sample", "0.05"],
     dict(k=100, theta_dot=0.3), dict(t_end=2, sample=0.05)),
    ("spring-pendulum", ["--integrator", "rk4", "--dt", "0.002",
                         "--t-end", "1.03", "--sample", "0.1",
                         "--columns", "accelerations"],
     {}, dict(integrator="rk4", dt=0.002, t_end=1.03, sample=0.1,
              columns=["accelerations"])),
    ("four-bar", ["--integrator", "bdf", "--rtol", "1e-7",
                  "--t-end", "0.5", "--sample", "0.05",
                  "--columns", "multipliers,health"],
     {}, dict(integrator="bdf", rtol=1e-7, t_end=0.5, sample=0.05,
              columns=["multipliers", "health"])),
    ("double-pendulum", ["--integrator", "adams", "--t-end", "1",
                         "--sensitivity", "m1"],
     {}, dict(integrator="adams", t_end=1, sensitivity=["m1"])),
]


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.parametrize("model, argv, sets, opts", CASES)
def test_run_equals_eom_run_csv(tmp_path, eom_run, models_dir, model, argv,
                                sets, opts):
    out = tmp_path / "run.csv"
    subprocess.run([eom_run, os.path.join(models_dir, model + ".eom")] +
                   argv + ["--out", str(out), "--quiet"], check=True)
    names, data = read_csv(out)
    s = autoeom.load(os.path.join(models_dir, model + ".eom"), **sets)
    run = s.run(**opts)
    assert run.names == names
    assert run.data.shape == data.shape
    scale = np.maximum(np.abs(data), 1e-300)
    assert np.all(np.abs(run.data - data) <= 1e-14 * scale + 1e-300), \
        np.max(np.abs(run.data - data) / scale)
