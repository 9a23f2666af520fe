"""Fixtures of the Python module's tests. ctest runs them (tests/CMakeLists.txt) with
PYTHONPATH at the built module and these variables set:
MM_NORMAL_DATABASE (the Bandai normal database built by the normal_database fixture),
MM_TOOL (the `mm` program), MM_SOURCE_DIR (the source tree) and MM_SHARED_DIR (../shared)."""

import os
import pathlib

import pytest


def _required(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"{name} is not set: run these tests through ctest (ctest -R python)")
    return value


@pytest.fixture(scope="session")
def database_path():
    path = pathlib.Path(_required("MM_NORMAL_DATABASE"))
    assert path.is_file(), f"{path} does not exist: the normal_database fixture builds it"
    return path


@pytest.fixture(scope="session")
def database(database_path):
    import mm

    return mm.load_database(database_path)


@pytest.fixture(scope="session")
def mm_tool():
    return pathlib.Path(_required("MM_TOOL"))


@pytest.fixture(scope="session")
def source_dir():
    return pathlib.Path(_required("MM_SOURCE_DIR"))


@pytest.fixture(scope="session")
def shared_dir():
    return pathlib.Path(_required("MM_SHARED_DIR"))


@pytest.fixture(scope="session")
def scripts_dir(source_dir):
    return source_dir / "scripts" / "input"
