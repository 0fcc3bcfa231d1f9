"""Loading: every shipped model loads and runs; settings, parameters and
start values by keyword; bad files, bad arguments and NaN states raise
exceptions that carry the library's message."""
import glob
import os

import numpy as np
import pytest

import autoeom


def shipped(models_dir):
    return sorted(glob.glob(os.path.join(models_dir, "*.eom")))


def test_every_shipped_model_loads_and_runs(models_dir):
    paths = shipped(models_dir)
    assert len(paths) >= 10
    for path in paths:
        s = autoeom.load(path)
        run = s.run(t_end=0.05, sample=0.01)
        assert len(run) == 6, path
        assert np.all(np.isfinite(run.x)), path
        # the first row is the start (projected onto any constraints)
        assert run.t[0] == 0.0 and run.t[-1] == 0.05


def test_keywords_set_settings_parameters_and_start(models_dir):
    chain = autoeom.load(os.path.join(models_dir, "open-chain.eom"))
    fewer = autoeom.load(os.path.join(models_dir, "open-chain.eom"),
                         modes=1)
    assert fewer.ncoords < chain.ncoords
    s = autoeom.load(os.path.join(models_dir, "spring-pendulum.eom"),
                     k=100, theta=0.25, theta_dot=0.5)
    assert s.get_param("k") == 100.0
    x0 = s.x0
    assert x0[s.coord_names.index("theta")] == 0.25
    assert x0[s.ncoords + s.coord_names.index("theta")] == 0.5


def test_text_and_path_give_the_same_system(models_dir):
    path = os.path.join(models_dir, "spring-pendulum.eom")
    with open(path) as f:
        text = f.read()
    a, b = autoeom.load(path), autoeom.load(text)
    x = a.x0 + 0.1
    assert np.array_equal(a.rhs(0.0, x), b.rhs(0.0, x))


def test_bad_file_names_line_and_column(tmp_path):
    bad = tmp_path / "bad.eom"
    bad.write_text("param m = 1\ncoord x = 0\nT = 1/2*m*x_dot^2 + )\n")
    with pytest.raises(autoeom.Error) as e:
        autoeom.load(bad)
    assert str(e.value).startswith(str(bad) + ":3:")
    assert e.value.status_name == "EOM_ERR_FILE"
    with pytest.raises(autoeom.Error) as e:
        autoeom.load(tmp_path / "missing.eom")
    assert e.value.status_name == "EOM_ERR_FILE"


def test_bad_arguments(spring):
    with pytest.raises(ValueError):
        spring.rhs(0.0, np.zeros(3))
    with pytest.raises(ValueError):
        spring.rhs(0.0, np.zeros((2, 5)))
    with pytest.raises(TypeError):
        spring.rhs(0.0)
    with pytest.raises(KeyError):
        spring.set(nonsense=1.0)
    with pytest.raises(KeyError):
        spring.get_param("nonsense")
    with pytest.raises(TypeError):
        spring.run(t_end=0.1, integrater="rk4")
    with pytest.raises(ValueError):
        spring.run(t_end=0.1, integrator="euler")
    with pytest.raises(ValueError):
        spring.run(t_end=-1.0)
    with pytest.raises(ValueError):
        spring.run(t_end=0.1, columns=["nonsense"])
    with pytest.raises(autoeom.Error) as e:
        spring.set_param("k", float("nan"))
    assert e.value.status_name == "EOM_ERR_NONFINITE"


def test_nan_state_raises(spring):
    x = spring.x0
    x[1] = np.nan
    for call in (lambda: spring.rhs(0.0, x), lambda: spring.energy(0.0, x),
                 lambda: spring.mass_matrix(x)):
        with pytest.raises(autoeom.Error) as e:
            call()
        assert e.value.status_name == "EOM_ERR_NONFINITE"
    batch = np.array([spring.x0, x])
    with pytest.raises(autoeom.Error) as e:
        spring.rhs(0.0, batch)
    assert "state 1 of the batch" in str(e.value)
    with pytest.raises(autoeom.Error):
        spring.run(t_end=0.1, x0=x)
