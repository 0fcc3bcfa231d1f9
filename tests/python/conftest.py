"""Shared fixtures of the Python package's tests (suite python): the
shipped models folder and eom-run, as meson passes them."""
import os

import pytest


@pytest.fixture(scope="session")
def models_dir():
    return os.environ["AUTOEOM_MODELS"]


@pytest.fixture(scope="session")
def eom_run():
    return os.environ["AUTOEOM_EOM_RUN"]


@pytest.fixture
def spring(models_dir):
    import autoeom
    return autoeom.load(os.path.join(models_dir, "spring-pendulum.eom"))
