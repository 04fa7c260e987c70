# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""eds2od: CiA 306 EDS/DCF -> SafeLine object dictionary (C sources and a regenerated EDS)."""

from .model import LintError, load  # noqa: F401
