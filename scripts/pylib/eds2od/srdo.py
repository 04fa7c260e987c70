# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""SRDO objects (CiA 304): what they are and the lint of their rules.

SRDO n (1..64) is described by two records: its communication parameter at 1300h + n and its
mapping at 1380h + n. 1300h is the GFC parameter, 13FEh says whether the configuration is
declared valid (A5h) and 13FFh holds one CRC signature per SRDO. ``check`` is run by the
reader (model.Builder) on every file; ``params`` gives the values that a signature covers
(used by scripts/srdo-sign).

An SRDO whose direction is 0 does not exist for the stack: it gets only the structural checks
(record layout, data types, sub-index 0, mapping count), so a disabled SRDO may hold zeros.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from . import dtypes

GFC = 0x1300
COMM = 0x1300  # + n
MAP = 0x1380  # + n
VALID = 0x13FE
SIGNATURE = 0x13FF
MAX = 64
VALID_VALUE = 0xA5
TRANSMISSION_TYPE = 254
MAX_ENTRIES = 16
# SRDO 1's default COB-IDs as the dictionary stores them: the stack adds 2 x node-ID at every
# reset communication (CiA 304: 0FFh + 2 x node-ID and 100h + 2 x node-ID, nodes 1..64).
COB1_BASE = 0xFF
COB2_BASE = 0x100
COB1_MIN, COB1_MAX = 0x101, 0x17F
DEFAULT_NODE_MAX = 64

DIRECTIONS = {0: "none", 1: "producer", 2: "consumer"}

U8, U16, U32 = (dtypes.BY_CODE[c] for c in (0x0005, 0x0006, 0x0007))
# Sub-indexes 0..6 of a communication record.
COMM_SUBS = ((U8, "highest sub-index"), (U8, "direction"), (U16, "refresh time/SCT"),
             (U8, "SRVT"), (U8, "transmission type"), (U32, "COB-ID 1"), (U32, "COB-ID 2"))


def comm_index(n: int) -> int:
    return COMM + n


def map_index(n: int) -> int:
    return MAP + n


def number_of(index: int) -> Optional[int]:
    """The SRDO number of a communication or mapping record, else None."""
    if COMM + 1 <= index <= COMM + MAX:
        return index - COMM
    if MAP + 1 <= index <= MAP + MAX:
        return index - MAP
    return None


def uses_default_cobids(cob1: int, cob2: int) -> bool:
    """Whether SRDO 1 holds the bare defaults that follow the node-ID."""
    return cob1 == COB1_BASE and cob2 == COB2_BASE


def value_of(s) -> int:
    """A sub-index's integer value as the firmware starts with it (no value: 0)."""
    if s is None or s.default is None or not isinstance(s.default.v, int):
        return 0
    return s.default.v


def value_line(s) -> int:
    return s.value_line or s.line


def type_line(s) -> int:
    return s.sec.line_of("DataType") if s.sec is not None else s.line


@dataclass
class Params:
    """What the signature of one SRDO covers, as stored in the file."""

    number: int
    direction: int
    cycle: int  # refresh time (producer) or SCT (consumer) [ms]
    srvt: int
    cob1: int  # as stored: SRDO 1 may hold the bare defaults 0xFF/0x100
    cob2: int
    entries: list  # mapping entries 1..count
    comm: object  # model.Obj
    mapping: object  # model.Obj

    @property
    def active(self):
        return self.direction != 0

    @property
    def default_cobids(self):
        return self.number == 1 and uses_default_cobids(self.cob1, self.cob2)


def params(objects) -> list:
    """Params of every SRDO with both records in a file that passed the lint, by number."""
    by = {o.index: o for o in objects}
    out = []
    for n in range(1, MAX + 1):
        comm, mapping = by.get(comm_index(n)), by.get(map_index(n))
        if comm is None or mapping is None:
            continue
        c = {s.sub: value_of(s) for s in comm.subs}
        m = {s.sub: value_of(s) for s in mapping.subs}
        count = min(m.get(0, 0), MAX_ENTRIES)
        out.append(Params(n, c.get(1, 0), c.get(2, 0), c.get(3, 0), c.get(5, 0), c.get(6, 0),
                          [m.get(k, 0) for k in range(1, count + 1)], comm, mapping))
    return out


# --------------------------------------------------------------------------------------
# Lint


def check(objects, sections, node_id, err):
    """Lint the SRDO objects; `sections` maps every index with a section to it (objects that
    failed to build are in `sections` but not in `objects`), `err(line, message)` reports."""
    Lint(objects, sections, node_id, err).run()


class Lint:
    def __init__(self, objects, sections, node_id, err):
        self.by = {o.index: o for o in objects}
        self.sections = sections
        self.node_id = node_id
        self.err = err

    def run(self):
        numbers = sorted({number_of(i) for i in self.sections if number_of(i) is not None})
        for n in numbers:
            self.srdo(n)
        self.signatures(max((n for n in numbers if comm_index(n) in self.sections),
                            default=0))
        self.var(VALID, "configuration valid")
        gfc = self.var(GFC, "GFC parameter")
        if gfc is not None and gfc.default is not None and not gfc.default.rel \
                and gfc.default.v > 1:
            self.err(value_line(gfc), f"{GFC:04X}h: GFC parameter {gfc.default.v} is not 0 "
                                      "(GFC not valid) or 1 (GFC valid)")

    def srdo(self, n):
        ci, mi = comm_index(n), map_index(n)
        if ci not in self.sections:
            self.err(self.sections[mi].line, f"{mi:04X}h: SRDO {n} has a mapping but no "
                                             f"communication parameter {ci:04X}h")
            return
        if mi not in self.sections:
            self.err(self.sections[ci].line, f"{ci:04X}h: SRDO {n} has no mapping parameter "
                                             f"{mi:04X}h")
        comm, mapping = self.by.get(ci), self.by.get(mi)
        direction = self.comm(n, comm) if comm is not None else None
        count = self.mapping_layout(n, mapping) if mapping is not None else None
        if direction:
            self.comm_values(n, comm, direction)
            if count is not None:
                self.mapping_values(n, mapping, count, direction)

    def comm(self, n, o) -> Optional[int]:
        """Structural checks of a communication record; its direction, None if unusable."""
        idx = o.index
        if o.objcode != 0x9:
            self.err(o.line, f"{idx:04X}h: SRDO {n} communication parameter must be a RECORD "
                             "(ObjectType=0x9)")
            return None
        subs = {s.sub: s for s in o.subs}
        ok = True
        for k, (t, name) in enumerate(COMM_SUBS):
            s = subs.get(k)
            if s is None:
                self.err(o.line, f"{idx:04X}h: SRDO {n} communication parameter has no "
                                 f"sub-index {k} ({name})")
                ok = False
            elif s.dtype.code != t.code:
                self.err(type_line(s), f"{idx:04X}h:{k}: {name} must be {t.name}, not "
                                       f"{s.dtype.name}")
                ok = False
        for s in o.subs:
            if s.sub >= len(COMM_SUBS):
                self.err(s.line, f"{idx:04X}h:{s.sub}: an SRDO communication parameter has "
                                 "sub-indexes 0..6 only")
                ok = False
        s0 = subs.get(0)
        if s0 is not None and s0.dtype.code == U8.code and s0.default is not None \
                and not s0.default.rel and s0.default.v != 6:
            self.err(value_line(s0), f"{idx:04X}h:0: highest sub-index is {s0.default.v}; an "
                                     "SRDO communication parameter has 6")
        if not ok:
            return None
        return value_of(subs[1])

    def comm_values(self, n, o, direction):
        idx = o.index
        subs = {s.sub: s for s in o.subs}
        v = {}
        for k in range(1, 7):
            s = subs[k]
            if s.default is not None and s.default.rel:
                self.err(value_line(s), f"{idx:04X}h:{k}: {COMM_SUBS[k][1]} cannot use "
                                        "$NODEID (SRDO 1's default COB-IDs are written as "
                                        "0xFF and 0x100; the stack adds 2 x node-ID)")
                return
            v[k] = value_of(s)
        line = {k: value_line(subs[k]) for k in range(1, 7)}
        if direction not in DIRECTIONS:
            self.err(line[1], f"{idx:04X}h:1: SRDO {n} direction {direction} is not 0 (none), "
                              "1 (producer) or 2 (consumer)")
        cycle = {1: "refresh time", 2: "SCT"}.get(direction, "refresh time/SCT")
        if v[2] < 1:
            self.err(line[2], f"{idx:04X}h:2: SRDO {n} {cycle} is 0 ms; it must be at least "
                              "1 ms")
        if v[3] < 1:
            self.err(line[3], f"{idx:04X}h:3: SRDO {n} SRVT is 0 ms; it must be at least 1 ms")
        if v[4] != TRANSMISSION_TYPE:
            self.err(line[4], f"{idx:04X}h:4: SRDO {n} transmission type {v[4]}; an SRDO has "
                              f"{TRANSMISSION_TYPE} only")
        cob1, cob2 = v[5], v[6]
        if cob1 == COB1_BASE:
            if n != 1:
                self.err(line[5], f"{idx:04X}h:5: COB-ID 1 0xff is the default of SRDO 1 "
                                  f"(0xFF + 2 x node-ID); SRDO {n} needs an odd COB-ID in "
                                  "0x101..0x17F")
            elif self.node_id > DEFAULT_NODE_MAX:
                self.err(line[5], f"{idx:04X}h:5: COB-ID 1 0xff follows the node-ID (0xFF + "
                                  f"2 x node-ID), which must be 1..{DEFAULT_NODE_MAX}; NodeID "
                                  f"is {self.node_id}")
            want2 = COB2_BASE
        else:
            if not (cob1 & 1 and COB1_MIN <= cob1 <= COB1_MAX):
                self.err(line[5], f"{idx:04X}h:5: SRDO {n} COB-ID 1 {cob1:#x} is not an odd "
                                  f"CAN-ID in 0x101..0x17F" +
                                  (" (or the default 0xFF)" if n == 1 else ""))
            want2 = cob1 + 1
        if cob2 != want2:
            how = "the default with COB-ID 1 0xFF" if cob1 == COB1_BASE else "COB-ID 1 + 1"
            self.err(line[6], f"{idx:04X}h:6: SRDO {n} COB-ID 2 {cob2:#x} must be {want2:#x} "
                              f"({how})")

    def mapping_layout(self, n, o) -> Optional[int]:
        """Structural checks of a mapping record; the number of entries, None if unusable."""
        idx = o.index
        if o.objcode not in (0x8, 0x9):
            self.err(o.line, f"{idx:04X}h: SRDO {n} mapping parameter must be a RECORD "
                             "(ObjectType=0x9) or an ARRAY")
            return None
        subs = {s.sub: s for s in o.subs}
        ok = True
        for s in o.subs[1:]:
            if s.sub > MAX_ENTRIES:
                self.err(s.line, f"{idx:04X}h:{s.sub}: an SRDO mapping has sub-indexes "
                                 f"1..{MAX_ENTRIES} only")
                ok = False
            elif s.dtype.code != U32.code:
                self.err(type_line(s), f"{idx:04X}h:{s.sub}: a mapping entry must be "
                                       f"UNSIGNED32, not {s.dtype.name}")
                ok = False
                if o.compact:
                    break
        s0 = subs[0]
        if s0.dtype.code != U8.code:
            return None  # reported by the reader
        if s0.default is not None and s0.default.rel:
            self.err(value_line(s0), f"{idx:04X}h:0: the number of entries cannot use $NODEID")
            return None
        count = value_of(s0)
        line = value_line(s0)
        if count % 2:
            self.err(line, f"{idx:04X}h:0: SRDO {n} maps {count} entries; the count must be "
                           "even (each normal entry has an inverted partner)")
            ok = False
        if count > MAX_ENTRIES:
            self.err(line, f"{idx:04X}h:0: SRDO {n} maps {count} entries; at most "
                           f"{MAX_ENTRIES}")
            ok = False
        missing = [k for k in range(1, min(count, MAX_ENTRIES) + 1) if k not in subs]
        if missing:
            self.err(line, f"{idx:04X}h:0: SRDO {n} maps {count} entries, but {idx:04X}h has "
                           f"no sub-index {', '.join(map(str, missing))}")
            ok = False
        return count if ok else None

    def mapping_values(self, n, o, count, direction):
        idx = o.index
        subs = {s.sub: s for s in o.subs}
        size = {}  # k -> bytes, for the entries that are right
        for k in range(1, count + 1):
            s = subs[k]
            line = value_line(s)
            if s.default is not None and s.default.rel:
                self.err(line, f"{idx:04X}h:{k}: a mapping entry cannot use $NODEID")
                continue
            v = value_of(s)
            ti, ts, bits = v >> 16, (v >> 8) & 0xFF, v & 0xFF
            what = f"{idx:04X}h:{k}: entry {v:#010x}"
            tgt = self.by.get(ti)
            if tgt is None:
                if ti not in self.sections:  # else the object's own errors say why
                    self.err(line, f"{what} maps {ti:04X}h:{ts}, but the file has no object "
                                   f"{ti:04X}h")
                continue
            ts_obj = next((x for x in tgt.subs if x.sub == ts), None)
            if ts_obj is None:
                self.err(line, f"{what} maps {ti:04X}h:{ts}, but {ti:04X}h has no sub-index "
                               f"{ts}")
                continue
            bad = False
            if not ts_obj.pdo_map:
                self.err(line, f"{what} maps {ti:04X}h:{ts}, which is not mappable "
                               "(PDOMapping=0)")
                bad = True
            elif direction == 1 and not ts_obj.tpdo:
                self.err(line, f"{what} maps {ti:04X}h:{ts} ({ts_obj.access}) into a "
                               "producer, which must read it")
                bad = True
            elif direction == 2 and not ts_obj.rpdo:
                self.err(line, f"{what} maps {ti:04X}h:{ts} ({ts_obj.access}) into a "
                               "consumer, which must write it")
                bad = True
            if bits == 0 or bits % 8:
                self.err(line, f"{what} maps {bits} bits of {ti:04X}h:{ts}; SRDO entries are "
                               "whole bytes")
                continue
            if bits != 8 * ts_obj.size:
                self.err(line, f"{what} maps {bits} bits of {ti:04X}h:{ts}, which has "
                               f"{8 * ts_obj.size} ({ts_obj.dtype.name}); an SRDO maps whole "
                               "objects")
                bad = True
            if not bad:
                size[k] = bits // 8
        for k in range(2, count + 1, 2):
            if k in size and k - 1 in size and size[k] != size[k - 1]:
                self.err(value_line(subs[k]), f"{idx:04X}h:{k}: the inverted entry maps "
                                              f"{8 * size[k]} bits, its normal partner "
                                              f"{idx:04X}h:{k - 1} maps {8 * size[k - 1]}")
        if len(size) != count:
            return  # the totals would repeat the entries' errors
        normal = sum(size[k] for k in range(1, count + 1, 2))
        inverted = sum(size[k] for k in range(2, count + 1, 2))
        line = value_line(subs[0])
        for total, what in ((normal, "normal"), (inverted, "inverted")):
            if not 1 <= total <= 8:
                self.err(line, f"{idx:04X}h:0: SRDO {n} maps {total} bytes of {what} data; a "
                               "frame carries 1..8")
            if normal == inverted:
                break

    def signatures(self, highest):
        sec = self.sections.get(SIGNATURE)
        o = self.by.get(SIGNATURE)
        if sec is None or o is None:
            return
        if o.objcode != 0x8:
            self.err(o.line, f"{SIGNATURE:04X}h: the SRDO signatures must be an ARRAY of "
                             "UNSIGNED16 (ObjectType=0x8)")
            return
        for s in o.subs[1:]:
            if s.dtype.code != U16.code:
                self.err(type_line(s), f"{SIGNATURE:04X}h:{s.sub}: an SRDO signature must be "
                                       f"UNSIGNED16, not {s.dtype.name}")
                break
        have = {s.sub for s in o.subs}
        missing = [k for k in range(1, highest + 1) if k not in have]
        if missing:
            self.err(o.line, f"{SIGNATURE:04X}h: SRDO {highest} exists, so the signatures need "
                             f"sub-indexes 1..{highest}; missing "
                             f"{', '.join(map(str, missing))}")

    def var(self, idx, name):
        """Checks an UNSIGNED8 VAR; returns its sub when it is one."""
        o = self.by.get(idx)
        if o is None:
            return None
        if o.objcode != 0x7 or o.subs[0].dtype.code != U8.code:
            self.err(o.line, f"{idx:04X}h: {name} must be a VAR of UNSIGNED8")
            return None
        return o.subs[0]
