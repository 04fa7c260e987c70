# SPDX-License-Identifier: Apache-2.0
"""A supervisory client of the SafeLine DDS bridge: state topics and requests.

    client = BridgeClient()                  # loopback configuration, domain 42
    client.wait_bridge(5.0)                  # BridgeState, or NoBridge
    client.nodes()                           # [NodeState] (alive instances)
    reply = client.sdo_read(5, 0x1017, 0)    # SdoReply (status, abort_code, data, data_type)
    client.nmt(5, NMT_START)

Requests are keyed by this client's id (name@host:pid); replies for other clients are
dropped. A request is written only once both of its endpoints have matched the bridge's (a
VOLATILE request written before would be lost).
"""

import threading
import time

from cyclonedds.core import InstanceState, Listener, Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from . import config
from . import types as T

NMT_START, NMT_STOP, NMT_PREOP, NMT_RESET, NMT_RESET_COMM = 1, 2, 128, 129, 130
NMT_COMMANDS = {"start": NMT_START, "stop": NMT_STOP, "preop": NMT_PREOP,
                "reset": NMT_RESET, "reset-comm": NMT_RESET_COMM}

EMCY_HISTORY = 16

QOS_STATE = Qos(Policy.Reliability.Reliable(duration(seconds=1)),
                Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
QOS_EMCY = Qos(Policy.Reliability.Reliable(duration(seconds=1)),
               Policy.Durability.TransientLocal, Policy.History.KeepLast(EMCY_HISTORY))
QOS_RPC = Qos(Policy.Reliability.Reliable(duration(seconds=1)),
              Policy.Durability.Volatile, Policy.History.KeepAll)


class NoBridge(Exception):
    """No bridge answered on the domain within the time given."""


class RequestTimeout(Exception):
    """The bridge did not reply in time."""


class _Matched(Listener):
    def __init__(self):
        super().__init__()
        self.count = 0
        self.event = threading.Event()

    def _update(self, count):
        self.count = count
        if count > 0:
            self.event.set()
        else:
            self.event.clear()

    def on_publication_matched(self, writer, status):
        self._update(status.current_count)

    def on_subscription_matched(self, reader, status):
        self._update(status.current_count)


class BridgeClient:
    def __init__(self, domain_id=config.DEFAULT_DOMAIN, dds_config=None, name=None,
                 bridge=None):
        xml, self.config_desc = config.load(dds_config)
        self.domain_id = domain_id
        self._domain = config.domain(domain_id, xml, self.config_desc)
        self.dp = DomainParticipant(domain_id)
        self.client_id = config.client_id(name)
        self.bridge = bridge
        self._topics = {}
        self._readers = {}
        self._rpc = {}
        self._next_id = 1
        self._lock = threading.Lock()

    # --- state topics ---------------------------------------------------------------------

    def topic(self, name):
        if name not in self._topics:
            self._topics[name] = Topic(self.dp, name, T.TOPICS[name])
        return self._topics[name]

    def reader(self, name):
        """The reader of a state topic (created on first use; it gets the history at once)."""
        if name not in self._readers:
            qos = QOS_EMCY if name == T.TOPIC_EMCY else QOS_STATE
            self._readers[name] = DataReader(self.dp, self.topic(name), qos=qos)
        return self._readers[name]

    def open_state(self):
        """Create every state reader now, so that their history starts arriving."""
        for name in (T.TOPIC_BRIDGE, T.TOPIC_LINE, T.TOPIC_NODE, T.TOPIC_EMCY, T.TOPIC_SRDO,
                     T.TOPIC_VALUE):
            self.reader(name)

    def samples(self, name, alive_only=True):
        """[(sample, alive)] in the reader's cache: the latest per instance (EMCY: history)."""
        out = []
        for s in self.reader(name).read(N=100000):
            info = getattr(s, "sample_info", None)
            alive = info is None or info.instance_state == InstanceState.Alive
            if info is not None and not info.valid_data:
                continue
            if alive or not alive_only:
                out.append((s, alive))
        return out

    def bridges(self):
        """Alive bridges (BridgeState), filtered by the name this client was given."""
        return [s for s, _ in self.samples(T.TOPIC_BRIDGE)
                if self.bridge is None or s.bridge == self.bridge]

    def wait_bridge(self, timeout):
        """The bridge's state; NoBridge if none appears in time, or several without a name."""
        deadline = time.monotonic() + timeout
        while True:
            found = self.bridges()
            if len(found) == 1:
                return found[0]
            if len(found) > 1:
                names = ", ".join(sorted(b.bridge for b in found))
                raise NoBridge(f"several bridges on DDS domain {self.domain_id} ({names}): "
                               "choose one with --bridge NAME")
            if time.monotonic() >= deadline:
                which = f"bridge '{self.bridge}'" if self.bridge else "bridge"
                raise NoBridge(
                    f"no {which} found on DDS domain {self.domain_id} within {timeout:g} s "
                    f"({self.config_desc}; is the firmware running with --dds, on the same "
                    "domain?)")
            time.sleep(0.02)

    def _latest(self, name, key):
        best = {}
        for s, alive in self.samples(name, alive_only=False):
            if self.bridge is not None and name == T.TOPIC_BRIDGE and s.bridge != self.bridge:
                continue
            best[key(s)] = (s, alive)
        return best

    def lines(self, alive_only=True):
        items = sorted(self.line_states().items())
        return [s for _, (s, a) in items if a or not alive_only]

    def nodes(self, alive_only=True):
        items = sorted(self._latest(T.TOPIC_NODE, lambda s: (s.line, s.node_id)).items())
        return [s for _, (s, a) in items if a or not alive_only]

    def node_states(self):
        """{(line, node): (NodeState, alive)}"""
        return self._latest(T.TOPIC_NODE, lambda s: (s.line, s.node_id))

    def line_states(self):
        return self._latest(T.TOPIC_LINE, lambda s: s.line)

    def srdos(self):
        return self._latest(T.TOPIC_SRDO, lambda s: (s.line, s.node_id, s.srdo))

    def values(self):
        return self._latest(T.TOPIC_VALUE, lambda s: (s.line, s.node_id, s.index, s.subindex))

    def emcys(self, alive_only=False):
        """EMCY history (up to 16 per producer), oldest first."""
        out = [s for s, _ in self.samples(T.TOPIC_EMCY, alive_only=alive_only)]
        return sorted(out, key=lambda s: (s.time_ns, s.line, s.node_id, s.seq))

    # --- requests ---------------------------------------------------------------------------

    def _endpoints(self, kind):
        if kind not in self._rpc:
            req, rep = ((T.TOPIC_SDO_REQUEST, T.TOPIC_SDO_REPLY) if kind == "sdo"
                        else (T.TOPIC_NMT_REQUEST, T.TOPIC_NMT_REPLY))
            wl, rl = _Matched(), _Matched()
            wr = DataWriter(self.dp, self.topic(req), qos=QOS_RPC, listener=wl)
            rd = DataReader(self.dp, self.topic(rep), qos=QOS_RPC, listener=rl)
            self._rpc[kind] = (wr, wl, rd, rl)
        return self._rpc[kind]

    def _call(self, kind, make, timeout, discovery):
        wr, wl, rd, rl = self._endpoints(kind)
        bridge = self.wait_bridge(discovery)
        deadline = time.monotonic() + discovery
        for ev in (wl.event, rl.event):
            if not ev.wait(max(0.0, deadline - time.monotonic())):
                raise NoBridge(f"bridge '{bridge.bridge}' does not serve {kind.upper()} "
                               f"requests (its request topics did not match within "
                               f"{discovery:g} s)")
        with self._lock:
            rid = self._next_id
            self._next_id += 1
        wr.write(make(rid, bridge.bridge))
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for s in rd.take(N=1000):
                if getattr(s, "sample_info", None) is not None and not s.sample_info.valid_data:
                    continue
                if s.client_id == self.client_id and s.request_id == rid:
                    return s
            time.sleep(0.001)
        raise RequestTimeout(f"no reply from bridge '{bridge.bridge}' within {timeout:g} s")

    def sdo(self, op, node, index, sub, data=b"", line=0, mode=T.MODE_AUTO, timeout_ms=0,
            timeout=None, discovery=5.0):
        """One SDO request; returns the SdoReply whatever its status."""
        if timeout is None:
            timeout = (timeout_ms or 5000) / 1000.0 + 2.0

        def make(rid, bridge):
            return T.SdoRequest(client_id=self.client_id, request_id=rid, bridge=bridge, op=op,
                                line=line, node_id=node, index=index, subindex=sub, mode=mode,
                                timeout_ms=timeout_ms, data=bytes(data))
        return self._call("sdo", make, timeout, discovery)

    def sdo_read(self, node, index, sub, **kw):
        return self.sdo(T.SDO_READ, node, index, sub, **kw)

    def sdo_write(self, node, index, sub, data, **kw):
        return self.sdo(T.SDO_WRITE, node, index, sub, data=data, **kw)

    def sdo_info(self, node, index, sub, **kw):
        return self.sdo(T.SDO_INFO, node, index, sub, **kw)

    def nmt(self, node, command, line=0, timeout=5.0, discovery=5.0):
        """One NMT request (node 0: all); returns the NmtReply."""
        def make(rid, bridge):
            return T.NmtRequest(client_id=self.client_id, request_id=rid, bridge=bridge,
                                line=line, node_id=node, command=command)
        return self._call("nmt", make, timeout, discovery)

    def close(self):
        self._rpc.clear()
        self._readers.clear()
        self._topics.clear()
        self.dp = None
