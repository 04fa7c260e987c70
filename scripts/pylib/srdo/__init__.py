# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""srdo: the configuration signatures of CiA 304 SRDOs (13FFh) and scripts/srdo-sign."""

from .signature import crc16, signature, stream  # noqa: F401
