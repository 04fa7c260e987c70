# SPDX-License-Identifier: Apache-2.0
import pathlib
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "common"))

import safeline_image  # noqa: E402


@pytest.fixture(scope="session")
def image(tmp_path_factory):
    return safeline_image.image_path(HERE.parent, tmp_path_factory.mktemp("build"))


@pytest.fixture(scope="session")
def output(image):
    """Console output of one complete run of the logging image."""
    result = safeline_image.run(image)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout.splitlines()
