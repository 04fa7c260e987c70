# SPDX-License-Identifier: Apache-2.0
import os
import pathlib
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[3] / "kernel" / "common"))

import safeline_image  # noqa: E402


@pytest.fixture(scope="session")
def image(tmp_path_factory):
    # Run by hand, the folder is built against this tree.
    os.environ.setdefault("SAFELINE_BASE", str(HERE.parents[4]))
    return safeline_image.image_path(HERE.parent, tmp_path_factory.mktemp("build"))


@pytest.fixture
def run(image):
    def _run(*args, timeout=60):
        return safeline_image.run(image, "--testargs", *args, timeout=timeout)

    return _run
