"""What a run hands back besides its rows: the progress callback, a
failure part way (the rows before it kept in the exception), the named
columns and the DataFrame where pandas is installed."""
import os

import numpy as np
import pytest

import autoeom


def test_progress_is_called_at_each_row_and_can_stop_the_run(spring):
    seen = []
    run = spring.run(t_end=0.5, sample=0.1, progress=seen.append)
    assert np.allclose(seen, run.t[1:], rtol=0, atol=1e-15)

    class Stop(Exception):
        pass

    def stop(t):
        if t > 0.25:
            raise Stop()

    with pytest.raises(Stop):
        spring.run(t_end=0.5, sample=0.1, progress=stop)


def test_failure_part_way_keeps_the_rows_before_it(spring):
    # at most 20 steps from row to row: erk at 1e-12 needs more than that
    # for the first 0.5 s
    with pytest.raises(autoeom.Error) as e:
        spring.run(t_end=5.0, sample=0.5, max_steps=20, rtol=1e-12,
                   atol=1e-14)
    run = e.value.run
    assert e.value.status_name == "EOM_ERR_SOLVER"
    assert 1 <= len(run) < 11
    assert run.t[0] == 0.0 and np.all(np.diff(run.t) > 0)
    assert np.all(np.isfinite(run.x))


def test_columns_by_name(spring):
    run = spring.run(t_end=0.2, sample=0.1, columns=["accelerations"])
    assert np.array_equal(run["r"], run.q[:, 0])
    assert np.array_equal(run["theta_dot"], run.qd[:, 1])
    assert np.array_equal(run["r_ddot"], run.accelerations[:, 0])
    # the accelerations of each row are those of its state
    for k in range(len(run)):
        assert np.array_equal(run.accelerations[k],
                              spring.accelerations(run.t[k], run.x[k]))
    assert np.allclose(run.E, run.T + run.V, rtol=1e-15)


def test_dataframe_where_pandas_is_installed(spring):
    pandas = pytest.importorskip("pandas")
    run = spring.run(t_end=0.2, sample=0.1)
    df = run.dataframe()
    assert isinstance(df, pandas.DataFrame)
    assert list(df.columns) == run.names
    assert np.array_equal(df["theta"].to_numpy(), run["theta"])


def test_multipliers_by_position_whatever_the_names(models_dir):
    s = autoeom.load(os.path.join(models_dir, "four-bar.eom"))
    run = s.run(t_end=0.1, sample=0.05,
                columns=["multipliers", "accelerations", "health"])
    assert run.multipliers.shape == (3, s.nconstraints)
    assert run.accelerations.shape == (3, s.ncoords)
    for k in range(len(run)):
        assert np.array_equal(run.multipliers[k],
                              s.multipliers(run.t[k], run.x[k]))
        assert np.array_equal(run.accelerations[k],
                              s.accelerations(run.t[k], run.x[k]))

