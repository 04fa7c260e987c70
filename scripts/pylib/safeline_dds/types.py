# SPDX-License-Identifier: Apache-2.0
"""The bridge's topic types, written with the binding's IDL classes.

They mirror subsys/canopen/bridge/dds/idl/safeline_canopen.idl member by member (same order,
same types, same keys): the bridge's types carry no type information (idlc -t), so samples
match by type name and a difference would misread every sample. tests/scripts/safeline_dds
compares the two.
"""

from dataclasses import dataclass, field

import cyclonedds.idl as idl
import cyclonedds.idl.annotations as annotate
import cyclonedds.idl.types as types

MODULE = "safeline.canopen.v1"

TOPIC_BRIDGE = "canopen/bridge_state"
TOPIC_LINE = "canopen/line_state"
TOPIC_NODE = "canopen/node_state"
TOPIC_EMCY = "canopen/emcy"
TOPIC_SRDO = "canopen/srdo_state"
TOPIC_VALUE = "canopen/od_value"
TOPIC_SDO_REQUEST = "canopen/sdo/request"
TOPIC_SDO_REPLY = "canopen/sdo/reply"
TOPIC_NMT_REQUEST = "canopen/nmt/request"
TOPIC_NMT_REPLY = "canopen/nmt/reply"

STATUS_OK = 0
STATUS_REFUSED = 1
STATUS_MALFORMED = 2
STATUS_UNKNOWN_LINE = 3
STATUS_UNKNOWN_NODE = 4
STATUS_ABORTED = 5
STATUS_TIMEOUT = 6
STATUS_FAILED = 7
STATUS_NOT_FOUND = 8

STATUS_NAMES = {
    STATUS_OK: "ok",
    STATUS_REFUSED: "refused",
    STATUS_MALFORMED: "malformed",
    STATUS_UNKNOWN_LINE: "unknown line",
    STATUS_UNKNOWN_NODE: "unknown node",
    STATUS_ABORTED: "aborted",
    STATUS_TIMEOUT: "timeout",
    STATUS_FAILED: "failed",
    STATUS_NOT_FOUND: "not found",
}

SDO_READ = 0
SDO_WRITE = 1
SDO_INFO = 2

MODE_AUTO = 0
MODE_SEGMENTED = 1
MODE_BLOCK = 2

NMT_UNKNOWN = 255
BOOT_NONE = 255
HB_NONE, HB_WAITING, HB_ACTIVE, HB_LOST = 0, 1, 2, 3


@dataclass
@annotate.final
class BridgeState(idl.IdlStruct, typename=f"{MODULE}.BridgeState"):
    bridge: types.bounded_str[32]
    annotate.key("bridge")
    version: types.bounded_str[32] = ""
    domain_id: types.uint32 = 0
    started_ns: types.uint64 = 0
    time_ns: types.uint64 = 0
    lines: types.uint32 = 0
    nodes: types.uint32 = 0
    read_only: bool = False
    events: types.uint32 = 0
    events_lost: types.uint32 = 0
    queue_max: types.uint32 = 0
    queue_size: types.uint32 = 0
    samples: types.uint32 = 0
    requests: types.uint32 = 0
    refused: types.uint32 = 0
    malformed: types.uint32 = 0
    replies_deferred: types.uint32 = 0
    replies_lost: types.uint32 = 0


@dataclass
@annotate.final
class LineState(idl.IdlStruct, typename=f"{MODULE}.LineState"):
    line: types.uint8
    annotate.key("line")
    name: types.bounded_str[32] = ""
    can_state: types.uint8 = 255
    tx_err_cnt: types.uint8 = 0
    rx_err_cnt: types.uint8 = 0
    active_line: types.uint8 = 0
    rx_frames: types.uint32 = 0
    tx_frames: types.uint32 = 0
    rx_overruns: types.uint32 = 0
    rx_unhandled: types.uint32 = 0
    tx_dropped: types.uint32 = 0
    tx_errors: types.uint32 = 0
    events_lost: types.uint32 = 0
    nodes: types.uint32 = 0
    time_ns: types.uint64 = 0


@dataclass
@annotate.final
class NodeState(idl.IdlStruct, typename=f"{MODULE}.NodeState"):
    line: types.uint8
    annotate.key("line")
    node_id: types.uint8
    annotate.key("node_id")
    name: types.bounded_str[32] = ""
    local: bool = False
    nmt_state: types.uint8 = NMT_UNKNOWN
    heartbeat: types.uint8 = 0
    heartbeat_ns: types.uint64 = 0
    guarding: types.uint8 = 0
    boot_status: types.uint8 = BOOT_NONE
    boot_ns: types.uint64 = 0
    identity_mask: types.uint8 = 0
    device_type: types.uint32 = 0
    vendor_id: types.uint32 = 0
    product_code: types.uint32 = 0
    revision: types.uint32 = 0
    serial: types.uint32 = 0
    error_register: types.uint8 = 0
    emcy_count: types.uint32 = 0
    time_ns: types.uint64 = 0


@dataclass
@annotate.final
class Emcy(idl.IdlStruct, typename=f"{MODULE}.Emcy"):
    line: types.uint8
    annotate.key("line")
    node_id: types.uint8
    annotate.key("node_id")
    code: types.uint16 = 0
    error_register: types.uint8 = 0
    msef: types.array[types.uint8, 5] = field(default_factory=lambda: [0] * 5)
    own: bool = False
    cob_id: types.uint16 = 0
    seq: types.uint32 = 0
    time_ns: types.uint64 = 0


@dataclass
@annotate.final
class SrdoState(idl.IdlStruct, typename=f"{MODULE}.SrdoState"):
    line: types.uint8
    annotate.key("line")
    node_id: types.uint8
    annotate.key("node_id")
    srdo: types.uint8
    annotate.key("srdo")
    safe: bool = False
    reason: types.uint8 = 0
    reason_text: types.bounded_str[32] = ""
    transitions: types.uint32 = 0
    time_ns: types.uint64 = 0


@dataclass
@annotate.final
class OdValue(idl.IdlStruct, typename=f"{MODULE}.OdValue"):
    line: types.uint8
    annotate.key("line")
    node_id: types.uint8
    annotate.key("node_id")
    index: types.uint16
    annotate.key("index")
    subindex: types.uint8
    annotate.key("subindex")
    data_type: types.uint16 = 0
    abort_code: types.uint32 = 0
    size: types.uint32 = 0
    data: types.sequence[types.uint8, 256] = field(default_factory=list)
    changes: types.uint32 = 0
    time_ns: types.uint64 = 0


@dataclass
@annotate.final
class SdoRequest(idl.IdlStruct, typename=f"{MODULE}.SdoRequest"):
    client_id: types.bounded_str[64]
    annotate.key("client_id")
    request_id: types.uint32 = 0
    bridge: types.bounded_str[32] = ""
    op: types.uint8 = SDO_READ
    line: types.uint8 = 0
    node_id: types.uint8 = 0
    index: types.uint16 = 0
    subindex: types.uint8 = 0
    mode: types.uint8 = MODE_AUTO
    timeout_ms: types.uint32 = 0
    data: types.sequence[types.uint8] = field(default_factory=list)


@dataclass
@annotate.final
class SdoReply(idl.IdlStruct, typename=f"{MODULE}.SdoReply"):
    client_id: types.bounded_str[64]
    annotate.key("client_id")
    request_id: types.uint32 = 0
    status: types.uint8 = 0
    abort_code: types.uint32 = 0
    message: types.bounded_str[160] = ""
    data_type: types.uint16 = 0
    access: types.uint8 = 255
    name: types.bounded_str[64] = ""
    data: types.sequence[types.uint8] = field(default_factory=list)


@dataclass
@annotate.final
class NmtRequest(idl.IdlStruct, typename=f"{MODULE}.NmtRequest"):
    client_id: types.bounded_str[64]
    annotate.key("client_id")
    request_id: types.uint32 = 0
    bridge: types.bounded_str[32] = ""
    line: types.uint8 = 0
    node_id: types.uint8 = 0
    command: types.uint8 = 0


@dataclass
@annotate.final
class NmtReply(idl.IdlStruct, typename=f"{MODULE}.NmtReply"):
    client_id: types.bounded_str[64]
    annotate.key("client_id")
    request_id: types.uint32 = 0
    status: types.uint8 = 0
    message: types.bounded_str[160] = ""


# Topic name -> type, in the order of the IDL.
TOPICS = {
    TOPIC_BRIDGE: BridgeState,
    TOPIC_LINE: LineState,
    TOPIC_NODE: NodeState,
    TOPIC_EMCY: Emcy,
    TOPIC_SRDO: SrdoState,
    TOPIC_VALUE: OdValue,
    TOPIC_SDO_REQUEST: SdoRequest,
    TOPIC_SDO_REPLY: SdoReply,
    TOPIC_NMT_REQUEST: NmtRequest,
    TOPIC_NMT_REPLY: NmtReply,
}
