# SPDX-License-Identifier: Apache-2.0
"""SafeLine's supervisory client for the Cyclone DDS bridge (doc/dds-bridge.md).

scripts/safeline-dds is the command; this package is its library: the topic types (types),
the loopback configuration (config), CANopen values (values), the client (client) and the
command line (cli).
"""

__version__ = "1.0"
