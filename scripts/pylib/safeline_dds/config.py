# SPDX-License-Identifier: Apache-2.0
"""The DDS configuration of the client: the project's loopback configuration, or the user's.

Every SafeLine participant runs on the loopback configuration
(subsys/canopen/bridge/dds/config/loopback.xml: only `lo`, multicast off). The client refuses to
start without it, unless the user passes a configuration of their own (--dds-config), which is
then used as given. CYCLONEDDS_URI is never used: the configuration is always passed to the
domain explicitly, and Cyclone then ignores the variable.
"""

import os
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

BASE = Path(__file__).resolve().parents[3]
LOOPBACK = BASE / "subsys" / "canopen" / "bridge" / "dds" / "config" / "loopback.xml"
DEFAULT_DOMAIN = 42
NS = "{https://cdds.io/config}"


class ConfigError(Exception):
    """The client cannot start with this configuration."""


def loopback_problems(xml_text):
    """Why a configuration is not the loopback one (empty list: it is)."""
    try:
        root = ET.fromstring(xml_text)
    except ET.ParseError as e:
        return [f"not XML ({e})"]
    problems = []
    domains = root.findall(f"{NS}Domain")
    if not domains or any(d.get("Id") != "any" for d in domains):
        problems.append('settings must apply to every domain (<Domain Id="any">)')
    ifaces = root.findall(f".//{NS}Interfaces/{NS}NetworkInterface")
    names = [i.get("name") for i in ifaces]
    if names != ["lo"]:
        problems.append(f"interfaces {names or 'not pinned'}: must be exactly lo")
    if any(i.get("multicast", "default") not in ("false",) for i in ifaces):
        problems.append("multicast must be off on lo")
    allow = root.find(f".//{NS}General/{NS}AllowMulticast")
    if allow is None or allow.text.strip() != "false":
        problems.append("AllowMulticast must be false")
    peers = [p.get("address") for p in root.findall(f".//{NS}Peers/{NS}Peer")]
    if any(p not in ("127.0.0.1", "localhost") for p in peers):
        problems.append(f"peers {peers}: only 127.0.0.1")
    return problems


def checked_xml(text, where):
    """text, if it is a Cyclone DDS configuration; else ConfigError in one line.

    Cyclone takes text that is not XML for a list of file names, and its domain then fails
    with an exception that says nothing of the file."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise ConfigError(f"{where}: not a Cyclone DDS configuration: not XML ({e})")
    if root.tag.rpartition("}")[2] != "CycloneDDS":
        raise ConfigError(f"{where}: not a Cyclone DDS configuration: the root element is "
                          f"<{root.tag.rpartition('}')[2]}>, not <CycloneDDS>")
    if not text.isascii():
        raise ConfigError(f"{where}: not a Cyclone DDS configuration: Cyclone takes ASCII only")
    return text


def load(dds_config=None):
    """(XML text, description) of the configuration to use.

    dds_config: None for the loopback configuration, else the user's file (or XML text).
    """
    if dds_config:
        if dds_config.lstrip().startswith("<"):
            return checked_xml(dds_config, "the configuration given"), "the configuration given"
        path = Path(dds_config[7:] if dds_config.startswith("file://") else dds_config)
        if path.exists() and not path.is_file():
            # A FIFO or a device would block read_text(); a directory is no file either.
            raise ConfigError(f"cannot read the DDS configuration {path}: not a regular file")
        try:
            text = path.read_bytes().decode("utf-8")
        except OSError as e:
            raise ConfigError(f"cannot read the DDS configuration {path}: {e.strerror}")
        except UnicodeDecodeError as e:
            raise ConfigError(f"{path}: not a Cyclone DDS configuration: not UTF-8 text "
                              f"(byte {e.start})")
        return checked_xml(text, str(path)), str(path)
    try:
        text = LOOPBACK.read_text()
    except OSError:
        raise ConfigError(
            f"refusing to start: the loopback DDS configuration {LOOPBACK} is missing "
            "(pass --dds-config FILE to run on a configuration of your own)")
    problems = loopback_problems(text)
    if problems:
        raise ConfigError(f"refusing to start: {LOOPBACK} is not a loopback configuration: "
                          + "; ".join(problems))
    return text, "loopback configuration"


_domains = {}


def domain(domain_id, xml_text, where="the configuration"):
    """The process's domain object for domain_id, created once with the configuration."""
    from cyclonedds.domain import Domain

    d = _domains.get(domain_id)
    if d is None:
        d = (_create_domain(Domain, domain_id, xml_text, where), xml_text)
        _domains[domain_id] = d
    elif d[1] != xml_text:
        raise ConfigError(f"domain {domain_id} already runs with another configuration")
    return d[0]


def _create_domain(Domain, domain_id, xml_text, where):
    """Domain(); a configuration Cyclone refuses is a ConfigError carrying Cyclone's reason
    (which Cyclone prints on stderr: caught there, so the user reads one line)."""
    from cyclonedds.core import DDSException

    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as said:
        os.dup2(said.fileno(), 2)
        try:
            made = Domain(domain_id, xml_text)
            failed = False
        except DDSException:
            failed = True
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        said.seek(0)
        text = said.read().decode(errors="replace")
    if failed:
        reason = "; ".join(" ".join(ln.split()[2:]) if ln.split()[:1] and
                           ln.split()[0][:1].isdigit() else ln.strip()
                           for ln in text.splitlines() if ln.strip())
        raise ConfigError(f"{where}: Cyclone DDS refused the configuration"
                          + (f" ({reason})" if reason else ""))
    # Warnings of an accepted configuration still reach the user.
    sys.stderr.write(text)
    return made


_clients = []


def client_id(name=None):
    """`name@host:pid` (`.n` for the n-th client of a process); the allow-list matches the
    name. Requests and replies are keyed by it, so no two clients share one."""
    if not name:
        name = os.environ.get("SAFELINE_DDS_CLIENT") or os.environ.get("USER") or "client"
    _clients.append(name)
    n = len(_clients)
    suffix = f".{n}" if n > 1 else ""
    host = os.uname().nodename[:24]
    return f"{name[:32]}@{host}:{os.getpid()}{suffix}"[:64]
