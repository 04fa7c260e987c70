# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Line-aware EDS/DCF reader, linter and object model.

python-canopen reads EDS/DCF well but forgets where things came from, so this module reads
the file itself, keeps the line of every section and key, and reports problems as
``file:line: message``. The generator cross-checks its model against python-canopen (see
``crosscheck``) so both readings of a file agree.
"""

from __future__ import annotations

import math
import re
import struct
from dataclasses import dataclass, field
from typing import Optional

from . import dtypes, srdo

ACCESS = ("ro", "wo", "rw", "rwr", "rww", "const")
OBJCODES = {0x2: "DOMAIN", 0x5: "DEFTYPE", 0x6: "DEFSTRUCT", 0x7: "VAR", 0x8: "ARRAY",
            0x9: "RECORD"}
LIST_SECTIONS = ("mandatoryobjects", "optionalobjects", "manufacturerobjects")
HEADER_SECTIONS = ("fileinfo", "deviceinfo", "dummyusage", "comments", "devicecomissioning")
# The objects every device has (CiA 301 §7.5.2, CiA 306 [MandatoryObjects]).
MANDATORY = {0x1000: "Device type", 0x1001: "Error register", 0x1018: "Identity object"}

# Objects written by the device or acting as commands: never part of a stored group.
NOT_STORED = {0x1001, 0x1002, 0x1003, 0x1010, 0x1011, 0x1023, 0x1024, 0x1025, 0x1026}


class LintError(Exception):
    """One or more ``file:line: message`` problems."""

    def __init__(self, messages, warnings=()):
        super().__init__("\n".join(messages))
        self.messages = list(messages)
        self.warnings = list(warnings)  # printed before the errors


# --------------------------------------------------------------------------------------
# INI reading with line numbers


@dataclass
class Key:
    name: str  # as written
    value: str
    line: int


@dataclass
class Section:
    name: str  # as written
    line: int
    keys: dict = field(default_factory=dict)  # lower-case name -> Key
    order: list = field(default_factory=list)  # Keys in file order

    def get(self, key, default=None):
        k = self.keys.get(key.lower())
        return k.value if k is not None else default

    def line_of(self, key):
        k = self.keys.get(key.lower())
        return k.line if k is not None else self.line


# SafeLine keys may also be written as a comment (";SafeLineSize=64") so that tools which
# refuse unknown keys, such as lely's dcfchk, accept the file.
DIRECTIVE_RE = re.compile(r"^[;#]\s*(SafeLine[A-Za-z]+)\s*=(.*)$")


class Reader:
    def __init__(self, path: str, text: str, strict: bool = False):
        self.path = path
        self.strict = strict
        self.errors: list[str] = []
        self.warnings: list[str] = []
        self.sections: dict[str, Section] = {}  # lower-case name -> Section
        self.order: list[Section] = []
        self._read(text)

    def err(self, line, msg):
        self.errors.append(f"{self.path}:{line}: {msg}")

    def warn(self, line, msg):
        """Something CiA 306 allows or other tools accept, but worth a look; an error with
        --strict."""
        if self.strict:
            self.errors.append(f"{self.path}:{line}: {msg} (--strict)")
        else:
            self.warnings.append(f"{self.path}:{line}: warning: {msg}")

    def _read(self, text):
        cur = None
        bad_header = False  # keys below a malformed or duplicate header: reported there
        for n, raw in enumerate(text.splitlines(), start=1):
            line = raw.strip()
            if line and line[0] in ";#":
                m = DIRECTIVE_RE.match(line)
                if m is None or cur is None:
                    continue
                line = f"{m.group(1)}={m.group(2)}"
            if not line:
                continue
            if line.startswith("["):
                if not line.endswith("]"):
                    self.err(n, f"malformed section header '{line}'")
                    cur, bad_header = None, True
                    continue
                name = line[1:-1].strip()
                low = name.lower()
                if low in self.sections:
                    prev = self.sections[low]
                    self.err(n, f"duplicate section [{name}] (first at line {prev.line})")
                    cur, bad_header = None, True
                    continue
                cur, bad_header = Section(name, n), False
                self.sections[low] = cur
                self.order.append(cur)
                continue
            if "=" not in line:
                self.err(n, f"expected key=value, got '{line}'")
                continue
            if cur is None:
                if not bad_header:
                    self.err(n, f"'{line}' is outside any section (before the first [section])")
                continue
            k, v = line.split("=", 1)
            k = k.strip()
            v = _strip_inline_comment(v).strip()
            if k.lower() in cur.keys:
                self.err(n, f"duplicate key '{k}' in [{cur.name}] "
                            f"(first at line {cur.keys[k.lower()].line})")
                continue
            key = Key(k, v, n)
            cur.keys[k.lower()] = key
            cur.order.append(key)


def _strip_inline_comment(v):
    # Same rule as configparser's inline_comment_prefixes: ';' after whitespace.
    m = re.search(r"\s;", v)
    return v[: m.start()] if m else v


# --------------------------------------------------------------------------------------
# Values


@dataclass
class Value:
    """A parsed DefaultValue/ParameterValue/LowLimit/HighLimit."""

    v: object  # int, float, bytes (OSTR/DOMAIN/VSTR utf-8), or list[int] (USTR units)
    rel: bool = False  # "$NODEID + v"


NUM_RE = r"(?:0[xX][0-9A-Fa-f]+|[0-9]+)"
NODEID_RES = [
    re.compile(r"^\$NODEID$", re.I),
    re.compile(r"^\$NODEID\+(" + NUM_RE + r")$", re.I),
    re.compile(r"^(" + NUM_RE + r")\+\$NODEID$", re.I),
]


def parse_int(s: str) -> int:
    s = s.strip()
    neg = s.startswith("-")
    if s[:1] in "+-":
        s = s[1:]
    if re.fullmatch(r"0[xX][0-9A-Fa-f]+", s):
        v = int(s, 16)
    elif re.fullmatch(r"0[0-7]+", s):
        v = int(s, 8)
    elif re.fullmatch(r"[0-9]+", s):
        v = int(s, 10)
    else:
        raise ValueError(f"'{s}' is not a number")
    return -v if neg else v


def parse_value(t: dtypes.DType, s: str, what: str) -> Value:
    """Parse a value of type t; raise ValueError with a lint message."""
    if "$" in s.upper() and "NODEID" in s.upper():
        if t.cls not in ("UINT", "INT"):
            raise ValueError(f"{what} '{s}': $NODEID is only allowed for integer types")
        compact = s.replace(" ", "").replace("\t", "")
        for i, rx in enumerate(NODEID_RES):
            m = rx.match(compact)
            if m:
                base = 0 if i == 0 else parse_int(m.group(1))
                return Value(base, rel=True)
        raise ValueError(f"{what} '{s}': malformed $NODEID formula "
                         "(expected $NODEID, $NODEID+n or n+$NODEID)")
    if t.cls in ("BOOL", "INT", "UINT", "TIME"):
        try:
            v = parse_int(s)
        except ValueError:
            raise ValueError(f"{what} '{s}' is not a valid {t.name}") from None
        lo, hi = dtypes.int_range(t) if t.cls != "TIME" else (0, (1 << 48) - 1)
        if t.cls == "INT" and v > hi and s.strip().lower().startswith("0x") and v < (1 << (8 * t.size)):
            v -= 1 << (8 * t.size)  # hex written as the two's complement pattern
        if not lo <= v <= hi:
            raise ValueError(f"{what} {s} out of range for {t.name} ({lo}..{hi})")
        return Value(v)
    if t.cls == "REAL":
        if re.fullmatch(r"0[xX][0-9A-Fa-f]+", s.strip()):
            # Hex is the IEEE 754 bit pattern, as lely's tools read and write it.
            bits = int(s.strip(), 16)
            if bits >> (8 * t.size):
                raise ValueError(f"{what} {s} has more than {8 * t.size} bits for {t.name}")
            v = struct.unpack("<f" if t.size == 4 else "<d", bits.to_bytes(t.size, "little"))[0]
            if not math.isfinite(v):
                raise ValueError(f"{what} '{s}' is not a finite {t.name}")
            return Value(v)
        try:
            v = float(s) if not re.fullmatch(r"[+-]0[xX][0-9A-Fa-f]+", s.strip()) \
                else float(parse_int(s))
        except ValueError:
            raise ValueError(f"{what} '{s}' is not a valid {t.name}") from None
        if not math.isfinite(v):
            raise ValueError(f"{what} '{s}' is not a finite {t.name}")
        if t.size == 4:
            try:
                v = struct.unpack("<f", struct.pack("<f", v))[0]
            except OverflowError:
                raise ValueError(f"{what} {s} out of range for {t.name}") from None
        return Value(v)
    if t.cls in ("OSTR", "DOMAIN"):
        h = re.sub(r"\s", "", s)
        if h.lower().startswith("0x"):
            h = h[2:]
        if len(h) % 2 or not re.fullmatch(r"[0-9A-Fa-f]*", h):
            raise ValueError(f"{what} '{s}' is not hex bytes for {t.name}")
        return Value(bytes.fromhex(h))
    if t.cls == "VSTR":
        return Value(s.encode("utf-8"))
    if t.cls == "USTR":
        b = s.encode("utf-16-le")
        return Value([int.from_bytes(b[i:i + 2], "little") for i in range(0, len(b), 2)])
    raise ValueError(f"{what}: unsupported type {t.name}")


def value_len(t: dtypes.DType, val: Optional[Value]) -> int:
    if val is None:
        return 0
    if t.cls == "USTR":
        return 2 * len(val.v)
    if t.cls in ("VSTR", "OSTR", "DOMAIN"):
        return len(val.v)
    return t.size


# --------------------------------------------------------------------------------------
# Model


@dataclass
class Sub:
    sub: int
    name: str
    dtype: dtypes.DType
    access: str
    pdo_map: bool
    default: Optional[Value]  # effective default: ParameterValue if given, else DefaultValue
    low: Optional[Value]
    high: Optional[Value]
    size: int  # wire capacity in bytes
    line: int
    # where the effective value was written (0: no value), and the section of the sub-index
    # (the object's section for a VAR or a CompactSubObj array)
    value_line: int = 0
    sec: Optional[Section] = field(default=None, repr=False, compare=False)
    # filled by the generator
    rom: bool = False
    store: bool = False

    @property
    def readable(self):
        return self.access != "wo"

    @property
    def writable(self):
        return self.access in ("wo", "rw", "rwr", "rww")

    @property
    def tpdo(self):
        return self.pdo_map and self.readable and self.access != "rww"

    @property
    def rpdo(self):
        return self.pdo_map and self.writable and self.access != "rwr"


@dataclass
class Obj:
    index: int
    name: str
    objcode: int
    subs: list
    line: int
    store_override: Optional[bool] = None
    compact: bool = False  # written with CompactSubObj
    # filled by the generator
    rom: bool = False
    group: str = "none"  # none comm app manuf

    @property
    def area(self):
        if self.index < 0x2000:
            return "comm"
        if self.index < 0x6000:
            return "manuf"
        return "app"


@dataclass
class Model:
    path: str
    objects: list  # sorted by index
    header: list  # [(section name, [(key, value)])] for FileInfo, DeviceInfo, ...
    node_id: int  # DCF NodeID or 0
    bitrate: int  # DCF Baudrate in kbit/s or 0
    node_name: str
    is_dcf: bool
    warnings: list = field(default_factory=list)

    def obj(self, index):
        for o in self.objects:
            if o.index == index:
                return o
        return None


# A value's storage beyond this is refused: the stack keeps values in RAM, and larger arrays
# make the generated C slow to compile (a DOMAIN of capacity 0 is served by a provider).
MAX_VALUE_SIZE = 65535
MAX_RAM = 1 << 20

# Record members become C struct members named after ParameterName; these cannot be used.
C_RESERVED = frozenset("""
auto break case char const continue default do double else enum extern float for goto if
inline int long register restrict return short signed sizeof static struct switch typedef
union unsigned void volatile while asm typeof bool true false linux unix i386 errno
""".split())


def cident(name: str) -> str:
    """The C identifier made from a ParameterName."""
    s = re.sub(r"[^0-9A-Za-z]+", "_", name).strip("_").lower()
    return s or "unnamed"


def record_fields(o) -> dict:
    """{sub: (member name, clash)} for a RECORD/DEFSTRUCT, clash = the sub-index that
    already has that name (or -1 for a reserved word), else None."""
    out = {}
    used = {}
    for s in o.subs:
        n = cident(s.name)
        if n[0].isdigit():
            n = f"sub{s.sub}_{n}"
        clash = None
        if n in C_RESERVED:
            clash = -1
        elif n in used:
            n = f"{n}_{s.sub}"  # repeated names ("Reserved") get the sub-index
            if n in used:
                clash = used[n]
        used.setdefault(n, s.sub)
        out[s.sub] = (n, clash)
    return out


SUB_RE = re.compile(r"^([0-9A-Fa-f]{4})sub([0-9A-Fa-f]{1,2})$", re.I)
IDX_RE = re.compile(r"^[0-9A-Fa-f]{4}$")
AUX_RE = re.compile(r"^([0-9A-Fa-f]{4})(name|value|denotation)$", re.I)


class Builder:
    def __init__(self, rd: Reader, is_dcf: bool):
        self.rd = rd
        self.is_dcf = is_dcf
        self.err = rd.err
        self.warn = rd.warn

    def num(self, sec: Section, key: str, default=None):
        v = sec.get(key)
        if v is None:
            return default
        try:
            return parse_int(v)
        except ValueError:
            self.err(sec.line_of(key), f"{key}={v} is not a number")
            return default

    def build(self) -> Model:
        rd = self.rd
        objs = {}
        subsecs = {}  # index -> {sub: Section}
        aux = {}  # (index, kind) -> Section
        for sec in rd.order:
            low = sec.name.lower()
            if IDX_RE.match(sec.name):
                objs[int(sec.name, 16)] = sec
            elif SUB_RE.match(sec.name):
                m = SUB_RE.match(sec.name)
                idx, sub = int(m.group(1), 16), int(m.group(2), 16)
                d = subsecs.setdefault(idx, {})
                if sub in d:
                    self.err(sec.line, f"duplicate sub-index {sub} of {idx:04X}h "
                                       f"(first at line {d[sub].line})")
                    continue
                d[sub] = sec
            elif AUX_RE.match(sec.name):
                m = AUX_RE.match(sec.name)
                aux[(int(m.group(1), 16), m.group(2).lower())] = sec
            elif low in LIST_SECTIONS or low in HEADER_SECTIONS:
                pass
            # Other sections (tool-specific) are ignored like python-canopen does.

        self.check_lists(objs)
        self.check_mandatory(objs)
        for idx in subsecs:
            if idx not in objs:
                s = min(subsecs[idx].values(), key=lambda s: s.line)
                self.err(s.line, f"sub-index section [{s.name}] has no object [{idx:04X}]")
        for (idx, kind), sec in aux.items():
            if idx not in objs and kind != "denotation":
                self.err(sec.line, f"[{sec.name}] has no object [{idx:04X}]")

        objects = []
        for idx in sorted(objs):
            o = self.build_obj(idx, objs[idx], subsecs.get(idx, {}), aux)
            if o is not None:
                objects.append(o)
        header = []
        for sec in rd.order:
            if sec.name.lower() in HEADER_SECTIONS:
                header.append((sec.name, [(k.name, k.value) for k in sec.order]))
        dc = rd.sections.get("devicecomissioning")
        node_id = bitrate = 0
        node_name = ""
        if dc is not None:
            node_id = self.num(dc, "NodeID", 0)
            if not 0 <= node_id <= 127:
                self.err(dc.line_of("NodeID"), f"NodeID {node_id} is not 1..127")
                node_id = 0
            bitrate = self.num(dc, "Baudrate", 0)
            node_name = dc.get("NodeName", "")
        self.check_cobids(objects, node_id)
        self.check_identifiers(objects)
        self.check_sizes(objects)
        self.check_pdo_mappings(objects)
        srdo.check(objects, objs, node_id, self.err)
        return Model(rd.path, objects, header, node_id, bitrate, node_name, self.is_dcf)

    def check_identifiers(self, objects):
        """Record members must be usable C names (the generated header names them)."""
        for o in objects:
            if o.objcode not in (0x6, 0x9):
                continue
            subs = {s.sub: s for s in o.subs}
            for sub, (n, clash) in record_fields(o).items():
                if clash is None:
                    continue
                s = subs[sub]
                line = s.sec.line_of("ParameterName") if s.sec is not None and not o.compact \
                    else s.line
                if clash < 0:
                    self.err(line, f"{o.index:04X}h:{sub}: ParameterName '{s.name}' gives the C "
                                   f"name '{n}', which is reserved in C; rename the sub-index")
                else:
                    self.err(line, f"{o.index:04X}h:{sub}: ParameterName '{s.name}' gives the C "
                                   f"name '{n}', which {o.index:04X}h:{clash} already has; "
                                   "rename one of them")

    def check_sizes(self, objects):
        total = 0
        bad = False
        for o in objects:
            for s in o.subs:
                if s.size > MAX_VALUE_SIZE:
                    line = s.sec.line_of("SafeLineSize") if s.sec is not None else s.line
                    where = f"{o.index:04X}h" if o.objcode in (0x2, 0x5, 0x7) \
                        else f"{o.index:04X}h:{s.sub}"
                    self.err(line, f"{where}: {s.dtype.name} of {s.size} bytes; "
                                   f"at most {MAX_VALUE_SIZE} bytes are held in RAM (use a "
                                   "DOMAIN of size 0 with an object provider for more)")
                    bad = True
                total += s.size
        if total > MAX_RAM and not bad:
            self.err(objects[0].line if objects else 1,
                     f"the dictionary's values take {total} bytes; at most {MAX_RAM} are allowed")

    def check_pdo_mappings(self, objects):
        """PDO mapping entries (1600h-17FFh, 1A00h-1BFFh) must name what the file has."""
        by_idx = {o.index: o for o in objects}
        for o in objects:
            if not (0x1600 <= o.index <= 0x17FF or 0x1A00 <= o.index <= 0x1BFF):
                continue
            d0 = o.subs[0].default if o.subs and o.subs[0].sub == 0 else None
            # Sub-index 0 of another type than a number (a fuzzed VISIBLE_STRING) counts as
            # "all": its own type is checked elsewhere.
            n = d0.v if d0 is not None and not d0.rel and isinstance(d0.v, int) else 0x40
            for s in o.subs[1:]:
                d = s.default
                if s.sub > n or d is None or d.rel or s.dtype.code != 0x0007 or d.v == 0:
                    continue
                idx, sub, bits = d.v >> 16, (d.v >> 8) & 0xFF, d.v & 0xFF
                if 1 <= idx <= 7:
                    continue  # dummy entry: a gap of a basic type
                line = s.value_line or s.line
                what = f"{o.index:04X}h:{s.sub}: maps {idx:04X}h:{sub}"
                tgt = by_idx.get(idx)
                if tgt is None:
                    self.err(line, f"{what}, which the {'DCF' if self.is_dcf else 'EDS'} does "
                                   "not have")
                    continue
                t = next((x for x in tgt.subs if x.sub == sub), None)
                if t is None:
                    self.err(line, f"{what}, but {idx:04X}h has no sub-index {sub}")
                    continue
                if t.dtype.size and t.dtype.size * 8 != bits and t.dtype.cls != "BOOL":
                    self.err(line, f"{what} with {bits} bits, but it is {t.dtype.name} "
                                   f"({t.dtype.size * 8} bits)")
                elif not t.pdo_map:
                    self.warn(line, f"{what}, which has PDOMapping=0")

    def check_lists(self, objs):
        seen = {}
        for name in LIST_SECTIONS:
            sec = self.rd.sections.get(name)
            if sec is None:
                continue
            count = self.num(sec, "SupportedObjects")
            if count is None:
                self.warn(sec.line, f"[{sec.name}] has no SupportedObjects")
            n = 0
            for k in sec.order:
                if k.name.lower() == "supportedobjects":
                    continue
                n += 1
                try:
                    idx = parse_int(k.value)
                except ValueError:
                    self.warn(k.line, f"object list entry '{k.value}' is not an index")
                    continue
                if idx in seen:
                    self.warn(k.line, f"duplicate index {idx:04X}h in object lists "
                                      f"(first at line {seen[idx]})")
                    continue
                seen[idx] = k.line
                if idx not in objs:
                    self.warn(k.line, f"index {idx:04X}h listed in [{sec.name}] has no "
                                      "section; the object does not exist")
                    continue
                manuf = 0x2000 <= idx <= 0x5FFF
                wrong = {"mandatoryobjects": idx not in (0x1000, 0x1001, 0x1018),
                         "optionalobjects": manuf, "manufacturerobjects": not manuf}[name]
                if wrong:
                    right = "ManufacturerObjects" if manuf else "OptionalObjects"
                    self.warn(k.line, f"index {idx:04X}h is listed in [{sec.name}]; CiA 306 "
                                      f"lists it in [{right}]")
            if count is not None and count != n:
                self.warn(sec.line_of("SupportedObjects"),
                          f"SupportedObjects={count} but [{sec.name}] lists {n} objects")
        if seen:
            for idx, sec in objs.items():
                if idx not in seen:
                    self.warn(sec.line, f"object [{sec.name}] is not listed in any object list")

    def check_mandatory(self, objs):
        """CiA 306 (and CiA 301) require 1000h, 1001h and 1018h of every device: a file
        without them describes no device, with --strict or without. The error names the
        entry of [MandatoryObjects] that lists the object, else that section, else the
        first section of the file."""
        lst = self.rd.sections.get("mandatoryobjects")
        first = self.rd.order[0].line if self.rd.order else 1
        listed = {}
        if lst is not None:
            for k in lst.order:
                try:
                    listed.setdefault(parse_int(k.value), k.line)
                except ValueError:
                    pass  # check_lists reports it
        for idx, what in MANDATORY.items():
            if idx not in objs:
                line = listed.get(idx, lst.line if lst is not None else first)
                self.err(line, f"mandatory object {idx:04X}h ({what}) is missing; CiA 306 "
                               "requires 1000h, 1001h and 1018h in every EDS/DCF")

    def build_obj(self, idx, sec, subsecs, aux):
        name = sec.get("ParameterName")
        if name is None:
            self.err(sec.line, f"[{sec.name}] has no ParameterName")
            name = f"Object {idx:04X}h"
        if idx == 0:
            self.err(sec.line, "index 0000h is not a valid object index")
            return None
        code = self.num(sec, "ObjectType", 0x7)
        if code not in OBJCODES:
            self.err(sec.line_of("ObjectType"), f"unknown object code {sec.get('ObjectType')}")
            return None
        store = sec.get("SafeLineStore")
        store_override = None
        if store is not None:
            if store not in ("0", "1"):
                self.err(sec.line_of("SafeLineStore"), "SafeLineStore must be 0 or 1")
            store_override = store == "1"

        if code == 0x2:
            # CiA 306 lets a DOMAIN object leave out its DataType; AccessType as dcfchk.
            if sec.get("DataType") is None:
                sec.keys["datatype"] = Key("DataType", "0x000F", sec.line)
            if sec.get("AccessType") is None:
                self.warn(sec.line, f"DOMAIN {idx:04X}h has no AccessType; rw is used")
                sec.keys["accesstype"] = Key("AccessType", "rw", sec.line)
        if code in (0x2, 0x5, 0x7):
            if subsecs:
                s = min(subsecs.values(), key=lambda s: s.line)
                self.err(s.line, f"{OBJCODES[code]} object {idx:04X}h cannot have sub-index "
                                 "sections")
            for k in ("SubNumber", "CompactSubObj"):
                if sec.get(k) is not None and self.num(sec, k, 0) != 0:
                    self.err(sec.line_of(k), f"{k} on a {OBJCODES[code]} object")
            sub = self.build_sub(idx, 0, sec, name)
            if sub is None:
                return None
            if code == 0x2 and sub.dtype.cls != "DOMAIN":
                self.err(sec.line_of("DataType"), "object code DOMAIN needs DataType 0x000F")
            return Obj(idx, name, code, [sub], sec.line, store_override)

        # ARRAY, RECORD, DEFSTRUCT
        subnum = sec.get("SubNumber")
        compact = sec.get("CompactSubObj")
        subs = []
        if subnum is not None and compact is not None and self.num(sec, "CompactSubObj", 0):
            self.err(sec.line_of("CompactSubObj"), "SubNumber and CompactSubObj both given")
            return None
        if compact is not None and self.num(sec, "CompactSubObj", 0):
            n = self.num(sec, "CompactSubObj", 0)
            if code not in (0x8, 0x9):
                # RECORDs too: lely's tools write PDO mapping records this way.
                self.err(sec.line_of("CompactSubObj"), "CompactSubObj is only allowed on ARRAY "
                                                       "and RECORD")
                return None
            if subsecs:
                s = min(subsecs.values(), key=lambda s: s.line)
                self.err(s.line, f"CompactSubObj={n} object {idx:04X}h has sub-index sections")
                return None
            if not 1 <= n <= 254:
                self.err(sec.line_of("CompactSubObj"), f"CompactSubObj={n} is not 1..254")
                return None
            u8 = dtypes.BY_CODE[0x0005]
            subs.append(Sub(0, "Number of entries", u8, "ro", False, Value(n), None, None, 1,
                            sec.line_of("CompactSubObj"), sec.line_of("CompactSubObj"), sec))
            names = self.compact_keys(aux.get((idx, "name")), n)
            values = self.compact_keys(aux.get((idx, "value")), n)
            proto = self.build_sub(idx, 1, sec, name, allow_param=False)
            if proto is None:
                return None
            for i in range(1, n + 1):
                s = Sub(**{**proto.__dict__})
                s.sub = i
                s.name = names[i].value if i in names and names[i].value else f"{name}{i}"
                if i in names:
                    s.line = names[i].line
                k = values.get(i)
                if k is not None and k.value == "" and s.dtype.cls in dtypes.NUMERIC:
                    self.warn(k.line, f"{idx:04X}h:{i}: empty value in [{idx:04X}Value]; "
                                      "the default stays")
                elif k is not None:
                    try:
                        s.default = parse_value(s.dtype, k.value, f"[{idx:04X}Value] {i}")
                        s.value_line = k.line
                        self.check_limits(s, k.line)
                    except ValueError as e:
                        self.err(k.line, str(e))
                subs.append(s)
            self.fix_sizes(subs, sec)
            return Obj(idx, name, code, subs, sec.line, store_override, compact=True)

        if subnum is None and not subsecs:
            self.err(sec.line, f"{OBJCODES[code]} object {idx:04X}h needs SubNumber or "
                               "CompactSubObj")
            return None
        n = len(subsecs) if subnum is None else self.num(sec, "SubNumber", 0)
        if subnum is None:
            self.warn(sec.line, f"{OBJCODES[code]} object {idx:04X}h has no SubNumber; the "
                                f"{len(subsecs)} sub-index sections are used")
        elif n != len(subsecs):
            # The sections say what exists; python-canopen and CANopenNode go by them too.
            self.warn(sec.line_of("SubNumber"), f"SubNumber={n} but {len(subsecs)} sub-index "
                                                f"sections exist for {idx:04X}h; the sections "
                                                "are used")
            n = len(subsecs)
        if n == 0:
            self.err(sec.line_of("SubNumber"), f"{OBJCODES[code]} object {idx:04X}h has no "
                                               "sub-indexes")
            return None
        for s_idx in sorted(subsecs):
            ssec = subsecs[s_idx]
            sub = self.build_sub(idx, s_idx, ssec, ssec.get("ParameterName"))
            if sub is not None:
                subs.append(sub)
        if len(subs) != len(subsecs):
            return None
        if subs[0].sub != 0:
            self.err(sec.line, f"{OBJCODES[code]} object {idx:04X}h has no sub-index 0")
            return None
        if subs[0].dtype.code != 0x0005:
            self.err(subs[0].line, f"sub-index 0 of {idx:04X}h must be UNSIGNED8")
        elif subs[0].default is None:
            hi = max(s.sub for s in subs)
            self.warn(subs[0].line, f"{idx:04X}h:0 has no DefaultValue; {hi} (the highest "
                                    "sub-index) is used")
            subs[0].default = Value(hi)
        if code == 0x8:
            types = {s.dtype.code for s in subs[1:]}
            if len(types) > 1:
                self.err(subs[1].line, f"ARRAY {idx:04X}h: sub-indexes 1.. have different "
                                       "data types")
        self.fix_sizes(subs, sec, array=(code == 0x8))
        return Obj(idx, name, code, subs, sec.line, store_override)

    def compact_keys(self, sec, n):
        """{sub: Key} of a [xxxxName]/[xxxxValue] section; keys decimal or hex."""
        out = {}
        if sec is None:
            return out
        count = None
        for k in sec.order:
            if k.name.lower() == "nrofentries":
                try:
                    count = parse_int(k.value)
                except ValueError:
                    self.err(k.line, f"NrOfEntries={k.value} is not a number")
                continue
            try:
                i = parse_int(k.name)
            except ValueError:
                self.err(k.line, f"[{sec.name}]: key '{k.name}' is not a sub-index")
                continue
            if not 1 <= i <= n:
                self.err(k.line, f"[{sec.name}]: sub-index {k.name} is not 1..{n} "
                                 f"(CompactSubObj={n})")
                continue
            if i in out:
                self.err(k.line, f"[{sec.name}]: sub-index {i} given twice (first at line "
                                 f"{out[i].line})")
                continue
            out[i] = k
        if count is not None and count != len(out):
            self.warn(sec.line_of("NrOfEntries"), f"NrOfEntries={count} but [{sec.name}] "
                                                  f"has {len(out)} entries")
        return out

    def fix_sizes(self, subs, sec, array=False):
        # ARRAY elements share one C type, so strings get the largest capacity.
        if array:
            var = [s for s in subs[1:] if s.dtype.size == 0]
            if var:
                m = max(s.size for s in var)
                for s in var:
                    s.size = m

    def build_sub(self, idx, sub, sec, name, allow_param=True):
        where = f"{idx:04X}h" if sub == 0 and not SUB_RE.match(sec.name) else f"{idx:04X}h:{sub}"
        if name is None:
            self.err(sec.line, f"[{sec.name}] has no ParameterName")
            name = f"Sub {sub}"
        dt = sec.get("DataType")
        if dt is None:
            self.err(sec.line, f"{where}: missing DataType")
            return None
        try:
            t = dtypes.BY_CODE.get(parse_int(dt))
        except ValueError:
            t = None
        if t is None:
            self.err(sec.line_of("DataType"), f"{where}: unknown data type {dt}")
            return None
        acc = sec.get("AccessType")
        if acc is None:
            self.err(sec.line, f"{where}: missing AccessType")
            return None
        if acc.lower() not in ACCESS:
            self.err(sec.line_of("AccessType"), f"{where}: unknown access type '{acc}'")
            return None
        acc = acc.lower()
        pm = sec.get("PDOMapping", "0")
        if pm not in ("0", "1", "0x0", "0x1"):
            self.err(sec.line_of("PDOMapping"), f"{where}: PDOMapping must be 0 or 1")
        pdo_map = pm in ("1", "0x1")
        default = low = high = None
        value_line = 0
        bad = False
        for key in ("DefaultValue", "LowLimit", "HighLimit") + (
                ("ParameterValue",) if allow_param else ()):
            v = sec.get(key)
            if v is None:
                continue
            if key in ("LowLimit", "HighLimit") and t.cls not in dtypes.NUMERIC:
                self.err(sec.line_of(key), f"{where}: {key} on non-numeric type {t.name}")
                bad = True
                continue
            if v == "" and t.cls not in ("VSTR", "OSTR", "USTR", "DOMAIN"):
                # CiA 306 allows an empty value; a limit that is empty is no limit.
                if key == "DefaultValue":
                    self.warn(sec.line_of(key), f"{where}: empty DefaultValue; the value starts "
                                                "at 0")
                elif key == "ParameterValue":
                    self.warn(sec.line_of(key), f"{where}: empty ParameterValue; the "
                                                "DefaultValue stays")
                continue
            try:
                val = parse_value(t, v, f"{where}: {key}")
            except ValueError as e:
                if t.cls == "DOMAIN":
                    # Tools read a DOMAIN's value their own way (a file name, text); the
                    # domain starts empty, as python-canopen has it.
                    self.warn(sec.line_of(key), f"{e}; the DOMAIN starts empty")
                    continue
                self.err(sec.line_of(key), str(e))
                bad = True
                continue
            if key in ("DefaultValue", "ParameterValue"):
                default = val  # ParameterValue comes last: a DCF's configured value wins
                value_line = sec.line_of(key)
            elif key == "LowLimit":
                low = val
            else:
                high = val
        size_key = sec.get("SafeLineSize")
        size = t.size
        if t.size == 0:
            size = value_len(t, default)
            if size_key is not None:
                try:
                    size = parse_int(size_key)
                except ValueError:
                    self.err(sec.line_of("SafeLineSize"), f"{where}: SafeLineSize is not a "
                                                          "number")
                    size = 0
                if size < value_len(t, default):
                    self.err(sec.line_of("SafeLineSize"), f"{where}: SafeLineSize={size} is "
                                                          "smaller than the DefaultValue")
                if t.cls == "USTR" and size % 2:
                    self.err(sec.line_of("SafeLineSize"), f"{where}: UNICODE_STRING size must "
                                                          "be even")
        elif size_key is not None:
            self.err(sec.line_of("SafeLineSize"), f"{where}: SafeLineSize on fixed-size type "
                                                  f"{t.name}")
        s = Sub(sub, name, t, acc, pdo_map, default, low, high, size, sec.line, value_line, sec)
        if bad:
            return s
        needs_default = acc in ("ro", "const") and t.cls in dtypes.NUMERIC and not (
            sub == 0 and SUB_RE.match(sec.name) is not None)  # sub-index 0: see build_obj
        if needs_default and default is None and sec.get("DefaultValue") is None:
            self.warn(sec.line, f"{where}: no DefaultValue for a {acc} {t.name}; the value "
                                "starts at 0")
        if pdo_map and (t.cls == "DOMAIN" or (t.size == 0 and size > 8) or size == 0):
            # Other stacks write PDOMapping=1 on such values; no PDO can carry them, so the
            # flag is dropped (a mapping entry naming one is then refused or warned about).
            self.warn(sec.line_of("PDOMapping"), f"{where}: {t.name} of {size} bytes cannot be "
                                                 "mapped to a PDO; PDOMapping=1 is ignored")
            s.pdo_map = False
        self.check_limits(s, sec.line_of("DefaultValue") if sec.get("ParameterValue") is None
                          else sec.line_of("ParameterValue"), sec)
        return s

    def check_limits(self, s: Sub, line, sec=None):
        lo, hi = s.low, s.high
        if lo is not None and hi is not None and not lo.rel and not hi.rel and lo.v > hi.v:
            self.err(sec.line_of("LowLimit") if sec else line,
                     f"{s.name}: LowLimit {fmt(lo.v)} is above HighLimit {fmt(hi.v)}")
            return
        d = s.default
        if d is None or d.rel or s.dtype.cls not in dtypes.NUMERIC:
            return
        if lo is not None and not lo.rel and d.v < lo.v:
            self.err(line, f"{s.name}: value {fmt(d.v)} below LowLimit {fmt(lo.v)}")
        if hi is not None and not hi.rel and d.v > hi.v:
            self.err(line, f"{s.name}: value {fmt(d.v)} above HighLimit {fmt(hi.v)}")

    def check_cobids(self, objects, node_id):
        """COB-ID rules (CiA 301 §7.3.5): 11-bit IDs fit, PDOs avoid restricted CAN-IDs."""
        restricted = [(0x000, 0x000), (0x001, 0x07F), (0x101, 0x180), (0x581, 0x5FF),
                      (0x601, 0x67F), (0x6E0, 0x6FF), (0x701, 0x77F), (0x780, 0x7FF)]
        for o in objects:
            pdo = 0x1400 <= o.index <= 0x15FF or 0x1800 <= o.index <= 0x19FF
            if pdo:
                subs = [s for s in o.subs if s.sub == 1]
            elif o.index in (0x1005, 0x1012, 0x1014):
                subs = o.subs[:1]
            else:
                continue
            for s in subs:
                d = s.default
                if d is None or s.dtype.code != 0x0007:
                    continue
                nids = [node_id] if (d.rel and node_id) else ([1, 127] if d.rel else [0])
                for nid in nids:
                    v = d.v + nid if d.rel else d.v
                    if v & 0x80000000 and pdo:
                        continue  # PDO not valid: the ID is not used
                    if not v & 0x20000000 and v & 0x1FFFF800:
                        self.err(s.line, f"{o.index:04X}h:{s.sub}: COB-ID {v:#x} has bits "
                                         "above 10 set in an 11-bit CAN-ID")
                        break
                    cid = v & 0x7FF
                    if pdo and not v & 0x20000000 and any(a <= cid <= b for a, b in restricted):
                        self.err(s.line, f"{o.index:04X}h:{s.sub}: COB-ID {v:#x} uses "
                                         f"restricted CAN-ID {cid:#x}")
                        break


def fmt(v):
    return f"{v:#x}" if isinstance(v, int) and v >= 0 else str(v)


def load(path: str, strict: bool = False) -> Model:
    """Read and lint an EDS/DCF; raise LintError with every problem found. The model's
    ``warnings`` list what was accepted with a remark (errors instead with ``strict``)."""
    with open(path, "rb") as f:
        raw = f.read()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    if text.startswith("\ufeff"):
        text = text[1:]
    rd = Reader(path, text, strict)
    is_dcf = path.lower().endswith(".dcf") or "devicecomissioning" in rd.sections
    model = Builder(rd, is_dcf).build()
    if rd.errors:
        raise LintError(rd.errors, rd.warnings)
    model.warnings = rd.warnings
    return model


def crosscheck(model: Model, path: str):
    """Compare the model with python-canopen's reading; return a list of disagreements."""
    import canopen

    problems = []
    try:
        od = canopen.import_od(path, node_id=model.node_id or None)
    except Exception as e:
        # python-canopen refuses some files CiA 306 allows (an empty VendorNumber, ...):
        # nothing to compare with, which is worth saying but not a disagreement.
        model.warnings.append(f"{path}: warning: python-canopen cannot read the file ({e}); "
                              "the cross-check is skipped")
        return []
    mine = {o.index: o for o in model.objects}
    for obj in od.values():
        idx = obj.index
        if idx not in mine:
            if 1 <= idx <= 7 and obj.name.startswith("Dummy"):
                continue  # python-canopen turns [DummyUsage] into objects
            problems.append(f"{path}: python-canopen sees object {idx:04X}h, eds2od does not")
            continue
        o = mine[idx]
        vars_ = [obj] if isinstance(obj, canopen.objectdictionary.ODVariable) else list(
            obj.subindices.values())
        subs = {s.sub: s for s in o.subs}
        for v in vars_:
            s = subs.get(v.subindex)
            if o.compact and v.subindex == 0:
                continue  # python-canopen makes this sub-index rw; CiA 306 says ro
            if s is None:
                problems.append(f"{path}: {idx:04X}h:{v.subindex} only seen by python-canopen")
                continue
            if v.data_type != s.dtype.code or v.access_type != s.access:
                problems.append(f"{path}: {idx:04X}h:{v.subindex} type/access differ "
                                f"(python-canopen {v.data_type:#x}/{v.access_type})")
    return problems
