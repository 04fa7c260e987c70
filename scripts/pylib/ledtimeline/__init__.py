# SPDX-License-Identifier: Apache-2.0
"""scripts/led-timeline: recorded CiA 303-3 LED traces against their patterns."""
