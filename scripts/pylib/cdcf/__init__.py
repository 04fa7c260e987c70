# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""DCF (CiA 306) to concise DCF (CiA 302 §6.2) conversion for the configuration manager."""
