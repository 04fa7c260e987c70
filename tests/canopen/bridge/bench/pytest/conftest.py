# SPDX-License-Identifier: Apache-2.0
"""The DDS bridge benchmark: fixtures in ../../bridge_fixtures.py (which first moves this
process into a network namespace of its own)."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

from bridge_fixtures import *  # noqa: E402,F401,F403
from bridge_fixtures import NETNS  # noqa: E402


def pytest_report_header(config):
    return f"DDS tests: {NETNS}"
