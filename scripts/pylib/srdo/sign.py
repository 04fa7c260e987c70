# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Sign the SRDO configuration of a DCF/EDS (see doc/srdo-sign.md).

The file is read and linted by eds2od's line-aware reader. Signing writes the signature of
every SRDO whose direction is not 0 into 13FFh:n and A5h into 13FEh by editing the lines that
hold those values (or adding one line beside them); every other line keeps its bytes.

Where a value goes: the key the firmware takes its value from. A section with a
ParameterValue has it replaced; otherwise a DCF gets a ParameterValue line right after the
DefaultValue (the device's default stays as it is) and an EDS has its DefaultValue replaced
(or added). A CompactSubObj 13FFh keeps its values in [13FFValue] (made when missing).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Optional

from eds2od import srdo as rules
from eds2od.model import Builder, LintError, Reader

from .signature import signature


@dataclass
class Target:
    """One value that signing writes: 13FFh:n or 13FEh."""

    index: int
    sub: int
    want: int
    have: Optional[int]  # the value in the file (None: none, or not a plain number)
    line: int  # where the value is, else the section
    what: str

    @property
    def name(self):
        return f"{self.index:04X}h:{self.sub}" if self.index == rules.SIGNATURE \
            else f"{self.index:04X}h"

    def fmt(self, v):
        return f"0x{v:04X}" if self.index == rules.SIGNATURE else f"0x{v:02X}"

    def problem(self):
        if self.have is None:
            return f"{self.name} has no value; it should be {self.fmt(self.want)} ({self.what})"
        return f"{self.name} holds {self.fmt(self.have)}, not {self.fmt(self.want)} ({self.what})"


def split_eol(line: str):
    body = line.splitlines()[0] if line else ""
    return body, line[len(body):]


class Document:
    """A file's text as lines with their line ends, edited line by line."""

    def __init__(self, raw: bytes):
        # The same decoding as eds2od's load(): UTF-8, else Latin-1, without a BOM.
        try:
            text, self.encoding = raw.decode("utf-8"), "utf-8"
        except UnicodeDecodeError:
            text, self.encoding = raw.decode("latin-1"), "latin-1"
        self.bom = text.startswith("\ufeff")
        self.text = text[1:] if self.bom else text
        self.lines = self.text.splitlines(keepends=True)  # numbered as the reader numbers
        ends = [split_eol(ln)[1] for ln in self.lines]
        self.eol = next((e for e in ends if e), "\n")
        self.replaced = {}  # line -> new text of that line
        self.added = {}  # line -> lines (without line end) added after it

    def set_value(self, line: int, value: str):
        """Replace the value of the key=value on `line`, keeping spacing and comment."""
        body, eol = split_eol(self.replaced.get(line, self.lines[line - 1]))
        head, _, after = body.partition("=")
        lead = after[:len(after) - len(after.lstrip())]
        rest = after[len(lead):]
        m = re.search(r"\s;", rest)  # the reader's inline comment rule
        old = rest[:m.start()] if m else rest
        tail = rest[len(old.rstrip()):]
        self.replaced[line] = f"{head}={lead}{value}{tail}{eol}"

    def add_after(self, line: int, text: str):
        self.added.setdefault(line, []).append(text)

    def data(self) -> bytes:
        out = []
        for n, ln in enumerate(self.lines, start=1):
            ln = self.replaced.get(n, ln)
            adds = self.added.get(n, [])
            body, eol = split_eol(ln)
            if adds and not eol:
                # The last line of a file without a final line end: so it stays.
                out.append(body + "".join(self.eol + a for a in adds))
                continue
            out.append(ln)
            out.extend(a + eol for a in adds)
        return (("\ufeff" if self.bom else "") + "".join(out)).encode(self.encoding)


def last_key_line(sec) -> int:
    return max((k.line for k in sec.order), default=sec.line)


class Signer:
    """Reads and lints a file, works out what signing writes, and writes it."""

    def __init__(self, path: str, node_id: Optional[int] = None, raw: Optional[bytes] = None):
        self.path = path
        if raw is None:
            with open(path, "rb") as f:
                raw = f.read()
        self.doc = Document(raw)
        self.rd = Reader(self.path, self.doc.text)
        self.is_dcf = path.lower().endswith(".dcf") or "devicecomissioning" in self.rd.sections
        self.model = Builder(self.rd, self.is_dcf).build()
        if self.rd.errors:
            raise LintError(self.rd.errors)
        self.node_id = node_id if node_id is not None else self.model.node_id
        self.errors = []
        self.srdos = rules.params(self.model.objects)
        self.targets = self.find_targets()
        if self.errors:
            raise LintError(self.errors)

    def err(self, line, msg):
        self.errors.append(f"{self.path}:{line}: {msg}")

    def find_targets(self):
        if not self.srdos:
            self.err(1, "no SRDO (1301h..1340h with its mapping 1381h..13C0h): nothing to sign")
            return []
        first = self.srdos[0]
        sig, valid = self.model.obj(rules.SIGNATURE), self.model.obj(rules.VALID)
        if sig is None:
            self.err(first.comm.line, f"SRDO {first.number} needs its signature in "
                                      f"{rules.SIGNATURE:04X}h:{first.number}, but the file has "
                                      f"no object {rules.SIGNATURE:04X}h (an ARRAY of "
                                      "UNSIGNED16, one sub-index per SRDO)")
        if valid is None:
            self.err(first.comm.line, f"the file has no object {rules.VALID:04X}h "
                                      "(configuration valid, UNSIGNED8) to declare the "
                                      f"configuration valid with 0x{rules.VALID_VALUE:02X}")
        if sig is None or valid is None:
            return []
        sig_subs = {s.sub: s for s in sig.subs}
        out = []
        for p in self.srdos:
            if not p.active:
                continue
            cob1, cob2 = p.cob1, p.cob2
            if p.default_cobids:
                line = rules.value_line(next(s for s in p.comm.subs if s.sub == 5))
                if not self.node_id:
                    self.err(line, f"SRDO {p.number} uses the default COB-IDs 0xFF/0x100, "
                                   "which follow the node-ID (0xFF + 2 x node-ID): give "
                                   "--node-id or [DeviceComissioning] NodeID")
                    continue
                if self.node_id > rules.DEFAULT_NODE_MAX:
                    self.err(line, f"SRDO {p.number} uses the default COB-IDs 0xFF/0x100 "
                                   "(+ 2 x node-ID), which need a node-ID "
                                   f"1..{rules.DEFAULT_NODE_MAX}, not {self.node_id}")
                    continue
                cob1, cob2 = cob1 + 2 * self.node_id, cob2 + 2 * self.node_id
            crc = signature(p.direction, p.cycle, p.srvt, cob1, cob2, p.entries)
            s = sig_subs[p.number]  # the lint made sure that it exists
            what = f"the signature of SRDO {p.number}, a {rules.DIRECTIONS[p.direction]}"
            out.append(self.target(s, rules.SIGNATURE, crc, what))
        out.append(self.target(valid.subs[0], rules.VALID, rules.VALID_VALUE,
                               "configuration valid"))
        return out

    @staticmethod
    def target(s, index, want, what):
        have = s.default.v if s.default is not None and not s.default.rel else None
        return Target(index, s.sub, want, have, rules.value_line(s), what)

    def mismatches(self):
        return [t for t in self.targets if t.have != t.want]

    def signed(self) -> bytes:
        """The file with every target written; LintError if the result does not check."""
        compact = []
        for t in self.mismatches():
            o = self.model.obj(t.index)
            s = next(x for x in o.subs if x.sub == t.sub)
            if o.compact and t.sub > 0:
                compact.append(t)
                continue
            sec = s.sec
            pv, dv = sec.keys.get("parametervalue"), sec.keys.get("defaultvalue")
            if pv is not None:
                self.doc.set_value(pv.line, t.fmt(t.want))
            elif self.is_dcf:
                self.doc.add_after(dv.line if dv is not None else last_key_line(sec),
                                   f"ParameterValue={t.fmt(t.want)}")
            elif dv is not None:
                self.doc.set_value(dv.line, t.fmt(t.want))
            else:
                self.doc.add_after(last_key_line(sec), f"DefaultValue={t.fmt(t.want)}")
        if compact:
            self.write_compact(compact)
        data = self.doc.data()
        try:
            left = Signer(self.path, self.node_id, raw=data).mismatches()
        except LintError as e:  # e.g. a HighLimit that keeps 13FEh from holding A5h
            raise LintError([f"{m} (in the signed file)" for m in e.messages]) from None
        if left:  # pragma: no cover - an edit that did not land is a bug of this tool
            raise LintError([f"{self.path}:{t.line}: internal error: after signing, "
                             f"{t.problem()}" for t in left])
        return data

    def write_compact(self, targets):
        """13FFh written with CompactSubObj: its values live in [13FFValue] as n=value."""
        idx = targets[0].index
        vals = self.rd.sections.get(f"{idx:04x}value")
        if vals is None:
            obj_sec = self.rd.sections[f"{idx:04x}"]
            lines = ["", f"[{idx:04X}Value]", f"NrOfEntries={len(targets)}"]
            lines += [f"{t.sub}={t.fmt(t.want)}" for t in targets]
            for ln in lines:
                self.doc.add_after(last_key_line(obj_sec), ln)
            return
        numbered = {k.name.strip() for k in vals.order if k.name.strip().isdigit()}
        for t in targets:
            k = vals.keys.get(str(t.sub))
            if k is not None:
                self.doc.set_value(k.line, t.fmt(t.want))
            else:
                self.doc.add_after(last_key_line(vals), f"{t.sub}={t.fmt(t.want)}")
                numbered.add(str(t.sub))
        nr = vals.keys.get("nrofentries")
        if nr is not None and nr.value != str(len(numbered)):
            self.doc.set_value(nr.line, str(len(numbered)))
