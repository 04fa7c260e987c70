# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Makes srdo_sign_testlib importable from the tests of this folder."""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
