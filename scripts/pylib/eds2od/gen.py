# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Object dictionary layout, C code and EDS output.

The EDS written here is the one the firmware itself writes (co_od_eds_write() in
subsys/canopen/od/od_eds.c); both follow the same rules so that a test can compare them.
"""

from __future__ import annotations

import struct

from . import dtypes
from .model import NOT_STORED, Model, Obj, Sub, cident, record_fields

ACCESS_ENUM = {"ro": 0, "wo": 1, "rw": 2, "rwr": 3, "rww": 4, "const": 5}
GROUP_ENUM = {"none": 0, "comm": 1, "app": 2, "manuf": 3}
RAM_GROUPS = ["comm", "comm_vol", "manuf", "manuf_vol", "app", "app_vol"]

# Counts checked against the Kconfig limit of the service that serves those objects: the
# generated C has `BUILD_ASSERT(NAME_OD_CNT_<key> <= <symbol>)` inside `#ifdef <symbol>`, or,
# when a guard is given, inside `#if defined(<guard>) && defined(<symbol>)` (the service's
# switch: a build without the service may carry the objects for a tool to read).
# A service that sizes its tables by Kconfig adds its entry here: key -> symbol or
# (symbol, guard).
COUNT_KCONFIG = {
    "SDO_SRV": "CONFIG_CANOPEN_SDO_SERVERS",
    "SDO_CLI": ("CONFIG_CANOPEN_SDO_CLIENTS", "CONFIG_CANOPEN_SDO_CLIENT"),
    "RPDO": ("CONFIG_CANOPEN_RPDOS", "CONFIG_CANOPEN_PDO"),
    "TPDO": ("CONFIG_CANOPEN_TPDOS", "CONFIG_CANOPEN_PDO"),
    "SRDO": ("CONFIG_CANOPEN_SRDOS", "CONFIG_CANOPEN_SRDO"),
    "EM_HIST": ("CONFIG_CANOPEN_EMCY_HISTORY", "CONFIG_CANOPEN_EMCY"),
}


def count_checks(name: str) -> str:
    """The BUILD_ASSERTs of COUNT_KCONFIG for the dictionary `name`."""
    P = name.upper()
    out = []
    for k, v in COUNT_KCONFIG.items():
        sym, guard = (v, None) if isinstance(v, str) else v
        cond = f"#ifdef {sym}" if guard is None else f"#if defined({guard}) && defined({sym})"
        out.append(f"{cond}\nBUILD_ASSERT({P}_OD_CNT_{k} <= {sym}, \"{name}: the OD has "
                   f"more {k} objects than {sym}\");\n#endif\n")
    return "".join(out)


# --------------------------------------------------------------------------------------
# Layout


def plan(model: Model):
    for o in model.objects:
        o.rom = all(s.access == "const" and not (s.default and s.default.rel)
                    for s in o.subs)
        writable = any(s.writable for s in o.subs)
        stored = (not o.rom and writable and o.index >= 0x1000 and o.index not in NOT_STORED)
        if o.store_override is not None:
            stored = o.store_override and not o.rom
        o.group = o.area if stored else "none"
        for s in o.subs:
            s.rom = o.rom
            s.store = stored and s.writable


def ram_group(o: Obj) -> str:
    return o.area if o.group != "none" else o.area + "_vol"


def elem_decl(s: Sub, name: str):
    """C declaration of one value (without ';'), or None when it has no storage."""
    t = s.dtype
    if t.cls == "VSTR":
        return f"char {name}[{s.size + 1}]"
    if t.cls == "OSTR":
        return f"uint8_t {name}[{max(s.size, 1)}]"
    if t.cls == "USTR":
        return f"uint16_t {name}[{s.size // 2 + 1}]"
    if t.cls == "DOMAIN":
        return f"CO_DOMAIN_STRUCT({s.size}) {name}" if s.size else None
    return f"{t.ctype} {name}"


def obj_field(o: Obj) -> str:
    return f"x{o.index:04X}_{cident(o.name)}"


def sub_fields(o: Obj):
    """{sub: member path below the object's field} for every sub with storage."""
    out = {}
    if o.objcode in (0x2, 0x5, 0x7):
        out[0] = ""
        return out
    if o.objcode == 0x8:
        for s in o.subs:
            out[s.sub] = ".sub0" if s.sub == 0 else f".elem[{s.sub - 1}]"
        return out
    # The reader refused names that are reserved in C or clash (model.check_identifiers).
    for sub, (n, _) in record_fields(o).items():
        out[sub] = "." + n
    return out


def obj_decl(o: Obj, ind="\t\t"):
    f = obj_field(o)
    if o.objcode in (0x2, 0x5, 0x7):
        d = elem_decl(o.subs[0], f)
        return [f"{ind}{d};"] if d else []
    lines = [f"{ind}struct {{"]
    if o.objcode == 0x8:
        lines.append(f"{ind}\tuint8_t sub0;")
        if len(o.subs) > 1:
            d = elem_decl(o.subs[1], f"elem[{max(s.sub for s in o.subs)}]")
            if d:
                lines.append(f"{ind}\t{d};")
    else:
        names = sub_fields(o)
        for s in o.subs:
            d = elem_decl(s, names[s.sub][1:])
            if d:
                lines.append(f"{ind}\t{d};")
    lines.append(f"{ind}}} {f};")
    return lines


# --------------------------------------------------------------------------------------
# Value formatting


def c_str(b: bytes) -> str:
    out = []
    for c in b:
        if c in (0x22, 0x5C):
            out.append("\\" + chr(c))
        elif 0x20 <= c < 0x7F and c != 0x3F:  # '?' escaped: no trigraphs
            out.append(chr(c))
        else:
            out.append(f"\\{c:03o}")
    return '"' + "".join(out) + '"'


def c_int(t: dtypes.DType, v: int) -> str:
    if t.cls == "INT":
        lo, _ = dtypes.int_range(t)
        big = dtypes.csize(t) == 8
        if v == lo and t.size in (4, 8):
            return f"({v + 1}{'LL' if big else ''} - 1)"
        return f"{v}{'LL' if big else ''}"
    big = dtypes.csize(t) == 8 if t.cls != "TIME" else False
    return f"0x{v:X}{'ULL' if big else 'U'}"


def c_float(t: dtypes.DType, v: float) -> str:
    r = repr(float(v))
    if "e" not in r and "." not in r:
        r += ".0"
    return r + ("f" if t.size == 4 else "")


def c_value(s: Sub, v, nid=0) -> str:
    t = s.dtype
    val = v.v + nid if v.rel else v.v
    if t.cls in ("BOOL", "INT", "UINT"):
        return c_int(t, val)
    if t.cls == "TIME":
        return f"{{.ms = 0x{val & 0xFFFFFFFF:X}U, .days = 0x{val >> 32:X}U}}"
    if t.cls == "REAL":
        return c_float(t, val)
    if t.cls == "VSTR":
        return c_str(val)
    if t.cls == "OSTR":
        return "{" + ", ".join(f"0x{c:02X}" for c in val) + "}" if val else "{0}"
    if t.cls == "USTR":
        return "{" + ", ".join(f"0x{c:04X}" for c in val) + "}" if val else "{0}"
    if t.cls == "DOMAIN":
        data = ", ".join(f"0x{c:02X}" for c in val) or "0"
        return f"{{.len = {len(val)}U, .data = {{{data}}}}}"
    raise AssertionError(t)


def eds_value(s: Sub, v) -> str:
    """A value as both writers print it."""
    t = s.dtype
    if v.rel:
        return f"$NODEID+0x{v.v:X}" if t.cls == "UINT" else f"$NODEID+{v.v}"
    if t.cls in ("BOOL", "UINT", "TIME"):
        return f"0x{v.v:X}"
    if t.cls == "INT":
        return str(v.v)
    if t.cls == "REAL":
        return ("%.9g" if t.size == 4 else "%.17g") % v.v
    if t.cls == "VSTR":
        return v.v.split(b"\0")[0].decode("utf-8", "replace")
    if t.cls in ("OSTR", "DOMAIN"):
        data = v.v
        if t.cls == "OSTR":
            data = data + bytes(s.size - len(data))
        return data.hex().upper()
    if t.cls == "USTR":
        units = list(v.v)
        if 0 in units:
            units = units[: units.index(0)]
        return b"".join(u.to_bytes(2, "little") for u in units).decode("utf-16-le", "replace")
    raise AssertionError(t)


def default_len(s: Sub) -> int:
    if s.default is None:
        return 0
    t = s.dtype
    if t.cls == "VSTR":
        return len(s.default.v.split(b"\0")[0])
    if t.cls == "USTR":
        units = list(s.default.v)
        return 2 * (units.index(0) if 0 in units else len(units))
    if t.cls == "OSTR":
        return s.size
    return len(s.default.v)


# --------------------------------------------------------------------------------------
# EDS writer


def eds_header_text(model: Model) -> str:
    out = []
    for name, keys in model.header:
        out.append(f"[{name}]\n")
        for k, v in keys:
            out.append(f"{k}={v}\n")
        out.append("\n")
    return "".join(out)


def eds_sub_lines(o: Obj, s: Sub, section: str) -> str:
    out = [f"[{section}]\n", f"ParameterName={s.name}\n"]
    code = o.objcode if section == f"{o.index:04X}" else 0x7
    out.append(f"ObjectType=0x{code:X}\n")
    out.append(f"DataType=0x{s.dtype.code:04X}\n")
    out.append(f"AccessType={s.access}\n")
    if s.default is not None:
        out.append(f"DefaultValue={eds_value(s, s.default)}\n")
    out.append(f"PDOMapping={1 if s.pdo_map else 0}\n")
    if s.low is not None:
        out.append(f"LowLimit={eds_value(s, s.low)}\n")
    if s.high is not None:
        out.append(f"HighLimit={eds_value(s, s.high)}\n")
    if s.dtype.size == 0 and s.size != default_len(s):
        out.append(f"SafeLineSize={s.size}\n")
    out.append("\n")
    return "".join(out)


def list_of(index: int) -> int:
    if index in (0x1000, 0x1001, 0x1018):
        return 0
    if 0x2000 <= index <= 0x5FFF:
        return 2
    return 1


def write_eds(model: Model) -> str:
    out = [eds_header_text(model)]
    for li, title in enumerate(("MandatoryObjects", "OptionalObjects", "ManufacturerObjects")):
        objs = [o for o in model.objects if list_of(o.index) == li]
        out.append(f"[{title}]\nSupportedObjects={len(objs)}\n")
        for n, o in enumerate(objs, start=1):
            out.append(f"{n}=0x{o.index:04X}\n")
        out.append("\n")
        for o in objs:
            if o.objcode in (0x2, 0x5, 0x7):
                out.append(eds_sub_lines(o, o.subs[0], f"{o.index:04X}"))
                continue
            out.append(f"[{o.index:04X}]\nParameterName={o.name}\n"
                       f"ObjectType=0x{o.objcode:X}\nSubNumber=0x{len(o.subs):X}\n\n")
            for s in o.subs:
                out.append(eds_sub_lines(o, s, f"{o.index:04X}sub{s.sub:X}"))
    return "".join(out)


# --------------------------------------------------------------------------------------
# C writer


def count_macros(model: Model):
    objs = model.objects

    def n_in(a, b):
        return sum(1 for o in objs if a <= o.index <= b)

    def subs_of(idx):
        o = model.obj(idx)
        return max((s.sub for s in o.subs), default=0) if o else 0

    return {
        "ENTRIES": len(objs),
        "SUBS": sum(len(o.subs) for o in objs),
        "RPDO": n_in(0x1400, 0x15FF),
        "RPDO_MAP": n_in(0x1600, 0x17FF),
        "TPDO": n_in(0x1800, 0x19FF),
        "TPDO_MAP": n_in(0x1A00, 0x1BFF),
        "SDO_SRV": n_in(0x1200, 0x127F),
        "SDO_CLI": n_in(0x1280, 0x12FF),
        # SRDO n lives at 1300h + n and the stack keeps n instances for SRDOs 1..n, so the
        # count is the highest SRDO number (the same as the number of SRDOs without gaps).
        "SRDO": max((o.index - 0x1300 for o in objs if 0x1301 <= o.index <= 0x1340), default=0),
        "HB_CONS": subs_of(0x1016),
        "EM_HIST": subs_of(0x1003),
        "EMCY_CONS": subs_of(0x1028),
        "ERR_BEHAV": subs_of(0x1029),
        "STORE_PARAM": subs_of(0x1010),
        "RESTORE_PARAM": subs_of(0x1011),
        "MPDO_SCAN": n_in(0x1FA0, 0x1FCF),
        "MPDO_DISP": n_in(0x1FD0, 0x1FFF),
        "SYNC": n_in(0x1005, 0x1005),
        "TIME": n_in(0x1012, 0x1012),
        "EMCY": n_in(0x1014, 0x1014),
        "NODEID": sum(1 for o in objs for s in o.subs if s.default is not None and
                      s.default.rel),
    }


def staged_size(s: Sub) -> int:
    return s.size if s.size > 8 and not s.rom else 0


def write_c(model: Model, name: str):
    """Return (header text, source text)."""
    plan(model)
    P = name.upper()
    p = name
    objs = model.objects
    counts = count_macros(model)
    max_staged = max([staged_size(s) for o in objs for s in o.subs] + [0])

    groups = {g: [] for g in RAM_GROUPS}
    rom = []
    for o in objs:
        if o.rom:
            rom.append(o)
        else:
            groups[ram_group(o)].append(o)
    present = [g for g in RAM_GROUPS if any(elem_or_none(o) for o in groups[g])]

    h = []
    h.append(f"/* Generated by scripts/eds2od from {model.path.split('/')[-1]}; do not edit. */\n")
    h.append(f"#ifndef {P}_OD_H_\n#define {P}_OD_H_\n\n#include <canopen/od.h>\n\n")
    h.append(f"/** Node-ID from [DeviceComissioning] (0: none given). */\n"
             f"#define {P}_OD_NODE_ID {model.node_id}U\n")
    h.append(f"/** Bit rate from [DeviceComissioning] in kbit/s (0: none given). */\n"
             f"#define {P}_OD_BITRATE_KBPS {model.bitrate}U\n")
    for k, v in counts.items():
        h.append(f"#define {P}_OD_CNT_{k} {v}U\n")
    h.append(f"/** Largest value that a chunked write stages in the scratch buffer. */\n"
             f"#define {P}_OD_MAX_STAGED {max_staged}U\n\n")

    h.append("/* Indexes; sub-indexes of records as _S_<name>. */\n")
    for o in objs:
        base = f"{P}_OD_X{o.index:04X}"
        h.append(f"#define {base} 0x{o.index:04X}U /* {c_comment(o.name)} */\n")
        if o.objcode in (0x6, 0x9):
            fields = sub_fields(o)
            for s in o.subs:
                h.append(f"#define {base}_S_{fields[s.sub][1:].upper()} {s.sub}U\n")
    h.append("\n/** RAM values of one node, grouped by storage class and reset area. */\n")
    h.append(f"struct {p}_od_ram {{\n")
    if not present:
        h.append("\tuint8_t unused;\n")
    for g in present:
        h.append("\tstruct {\n")
        for o in groups[g]:
            h.extend(line + "\n" for line in obj_decl(o))
        h.append(f"\t}} {g};\n")
    h.append("\t/* The node's first hook link of each entry (object dictionary, od_hooks.c). */\n"
             f"\tuint16_t hook_heads[{len(objs) if objs else 1}];\n")
    h.append("};\n\n")
    h.append("/** Values of const objects (flash on a target). */\n")
    h.append(f"struct {p}_od_rom {{\n")
    rom_present = [o for o in rom if elem_or_none(o)]
    if not rom_present:
        h.append("\tuint8_t unused;\n")
    for o in rom_present:
        h.extend(line + "\n" for line in obj_decl(o, "\t"))
    h.append("};\n\n")
    h.append("/* Value of an object in a node's RAM block, for reads (writes: co_od_set_*). */\n")
    for g in present:
        for o in groups[g]:
            if elem_or_none(o):
                h.append(f"#define {P}_OD_VAL_X{o.index:04X}(ram) ((ram)->{g}.{obj_field(o)})\n")
    h.append(f"\n/** The generated description. */\nextern const struct co_od_def {p}_od_def;\n")
    h.append(f"/** RAM defaults (with {P}_OD_NODE_ID for $NODEID values). */\n"
             f"extern const struct {p}_od_ram {p}_od_ram_defaults;\n")
    h.append(f"\n#endif /* {P}_OD_H_ */\n")

    # ---- source
    c = []
    c.append(f"/* Generated by scripts/eds2od from {model.path.split('/')[-1]}; do not edit. */\n")
    c.append(f'#include <stddef.h>\n\n#include "{p}_od.h"\n\n')
    c.append("#if defined(__has_include)\n#if __has_include(<zephyr/toolchain.h>)\n"
             "#include <zephyr/toolchain.h>\n#endif\n#endif\n"
             "#ifndef BUILD_ASSERT\n#define BUILD_ASSERT(expr, msg) _Static_assert(expr, msg)\n"
             "#endif\n\n")
    c.append("#ifdef CONFIG_CANOPEN_OD_SCRATCH_SIZE\n"
             f"BUILD_ASSERT({P}_OD_MAX_STAGED <= CONFIG_CANOPEN_OD_SCRATCH_SIZE,\n"
             f"\t     \"{name}: a value needs more staging than CONFIG_CANOPEN_OD_SCRATCH_SIZE\");\n"
             "#endif\n")
    c.append(count_checks(name))
    c.append(f"BUILD_ASSERT({P}_OD_CNT_SUBS < 65536, \"too many sub-indexes\");\n\n")

    # defaults
    c.append(f"const struct {p}_od_ram {p}_od_ram_defaults = {{\n")
    for g in present:
        inits = [init_of(o, model.node_id) for o in groups[g]]
        inits = [i for i in inits if i]
        if inits:
            c.append(f"\t.{g} = {{\n")
            for i in inits:
                c.append(f"\t\t{i},\n")
            c.append("\t},\n")
    c.append("};\n\n")
    c.append(f"static const struct {p}_od_rom {p}_od_rom_values = {{\n")
    for o in rom_present:
        i = init_of(o, model.node_id)
        if i:
            c.append(f"\t{i},\n")
    c.append("};\n\n")

    # names
    pool = NamePool()
    # limits, nodeid, subs, entries
    limits = []
    nodeid = []
    subs_c = []
    ents_c = []
    pos = 0
    for o in objs:
        fields = sub_fields(o)
        first = pos
        for s in o.subs:
            flags = []
            if s.pdo_map:
                flags.append("CO_OD_F_MAP")
            if s.rom:
                flags.append("CO_OD_F_ROM")
            if s.default is not None and s.default.rel:
                flags.append("CO_OD_F_NODEID")
                nodeid.append(f"\t{{{pos}U, 0x{o.index:04X}U, {s.default.v}}},\n")
            lim = "0"
            if s.low is not None or s.high is not None:
                flags.append("CO_OD_F_LIMITS")
                lim = f"{len(limits)}"
                limits.append(limit_init(s))
            if s.default is not None:
                flags.append("CO_OD_F_DEFAULT")
            if s.store:
                flags.append("CO_OD_F_STORE")
            has_storage = elem_decl(s, "x") is not None
            if has_storage:
                st = f"struct {p}_od_rom" if s.rom else f"struct {p}_od_ram"
                grp = "" if s.rom else ram_group(o) + "."
                off = f"offsetof({st}, {grp}{obj_field(o)}{fields[s.sub]})"
            else:
                off = "0"
            subs_c.append(f"\t{{.offset = {off}, .size = {s.size}U, .limit = {lim}U, "
                          f".name = {pool.add(s.name)}U, .sub = {s.sub}U, "
                          f".dtype = 0x{s.dtype.code:02X}U, .access = {ACCESS_ENUM[s.access]}U, "
                          f".flags = {' | '.join(flags) or '0U'}}},\n")
            pos += 1
        ents_c.append(f"\t{{.index = 0x{o.index:04X}U, .first = {first}U, .n_subs = {len(o.subs)}U, "
                      f".name = {pool.add(o.name)}U, .objcode = 0x{o.objcode:X}U, "
                      f".group = {GROUP_ENUM[o.group]}U}},\n")
    c.append(f"static const struct co_od_sub {p}_od_subs[] = {{\n" + "".join(subs_c) + "};\n\n")
    c.append(f"static const struct co_od_entry {p}_od_entries[] = {{\n" + "".join(ents_c) +
             "};\n\n")
    if limits:
        c.append(f"static const struct co_od_limit {p}_od_limits[] = {{\n" + "".join(limits) +
                 "};\n\n")
    if nodeid:
        c.append(f"static const struct co_od_nodeid {p}_od_nodeid[] = {{\n" + "".join(nodeid) +
                 "};\n\n")
    if pool.size() > 65535:
        raise ValueError("ParameterName pool exceeds 64 KiB")
    c.append("#ifdef CONFIG_CANOPEN_OD_NAMES\n")
    c.append(f"static const char {p}_od_names[] =\n{pool.c_text()};\n\n")
    c.append(f"static const char {p}_od_eds_header[] =\n"
             f"{c_multiline(eds_header_text(model).encode('utf-8'))};\n")
    c.append("#endif\n\n")

    comm_end = "offsetof(struct %s_od_ram, hook_heads)" % p
    for g in present:
        if not g.startswith("comm"):
            comm_end = f"offsetof(struct {p}_od_ram, {g})"
            break
    if present and not present[0].startswith("comm"):
        comm_end = "0"
    c.append(f"const struct co_od_def {p}_od_def = {{\n"
             f"\t.entries = {p}_od_entries,\n\t.subs = {p}_od_subs,\n"
             f"\t.limits = {f'{p}_od_limits' if limits else 'NULL'},\n"
             f"\t.nodeid = {f'{p}_od_nodeid' if nodeid else 'NULL'},\n"
             f"\t.ram_defaults = &{p}_od_ram_defaults,\n\t.rom = &{p}_od_rom_values,\n"
             "#ifdef CONFIG_CANOPEN_OD_NAMES\n"
             f"\t.names = {p}_od_names,\n\t.eds_header = {p}_od_eds_header,\n"
             "#endif\n"
             f"\t.ram_size = offsetof(struct {p}_od_ram, hook_heads),\n"
             f"\t.comm_end = {comm_end},\n"
             f"\t.hook_heads = offsetof(struct {p}_od_ram, hook_heads),\n"
             f"\t.n_entries = {len(objs)}U,\n\t.n_nodeid = {len(nodeid)}U,\n"
             f"\t.n_subs = {pos}U,\n\t.max_staged = {P}_OD_MAX_STAGED,\n"
             f"\t.node_id = {P}_OD_NODE_ID,\n}};\n")
    return "".join(h), "".join(c)


def elem_or_none(o: Obj) -> bool:
    return any(elem_decl(s, "x") is not None for s in o.subs)


def init_of(o: Obj, nid: int):
    f = obj_field(o)
    if o.objcode in (0x2, 0x5, 0x7):
        s = o.subs[0]
        if s.default is None or elem_decl(s, "x") is None:
            return None
        return f".{f} = {c_value(s, s.default, nid)}"
    parts = []
    fields = sub_fields(o)
    for s in o.subs:
        if s.default is None or elem_decl(s, "x") is None:
            continue
        parts.append(f"{fields[s.sub]} = {c_value(s, s.default, nid)}")
    if not parts:
        return None
    return f".{f} = {{" + ", ".join(parts) + "}"


def limit_init(s: Sub) -> str:
    t = s.dtype
    if t.cls == "REAL":
        field = ".f"
        lo_d, hi_d = -1.7976931348623157e308, 1.7976931348623157e308
    elif t.cls == "INT":
        field = ".i"
        lo_d, hi_d = dtypes.int_range(t)
    else:
        field = ".u"
        lo_d, hi_d = (0, (1 << 48) - 1) if t.cls == "TIME" else dtypes.int_range(t)
    rel = 0

    def fmtv(val, dflt):
        if val is None:
            v = dflt
        else:
            v = val.v
        if t.cls == "REAL":
            return repr(float(v))
        if t.cls == "INT":
            return f"({v + 1}LL - 1)" if v == -(1 << 63) else f"{v}LL"
        return f"0x{v:X}ULL"

    if s.low is not None:
        rel |= 4 | (1 if s.low.rel else 0)
    if s.high is not None:
        rel |= 8 | (2 if s.high.rel else 0)
    return (f"\t{{.lo = {{{field} = {fmtv(s.low, lo_d)}}}, .hi = {{{field} = "
            f"{fmtv(s.high, hi_d)}}}, .rel = {rel}U}},\n")


def c_comment(s: str) -> str:
    return s.replace("*/", "* /")


def c_multiline(b: bytes) -> str:
    lines = b.split(b"\n")
    out = []
    for i, ln in enumerate(lines):
        piece = ln + (b"\n" if i < len(lines) - 1 else b"")
        if piece:
            out.append("\t" + c_str(piece))
    return "\n".join(out) if out else '\t""'


class NamePool:
    def __init__(self):
        self.off = {}
        self.items = []
        self.n = 0

    def add(self, name: str) -> int:
        if name in self.off:
            return self.off[name]
        b = name.encode("utf-8")
        self.off[name] = self.n
        self.items.append(b)
        self.n += len(b) + 1
        return self.off[name]

    def size(self):
        return self.n

    def c_text(self):
        if not self.items:
            return '\t""'
        return "\n".join("\t" + c_str(b + b"\0") for b in self.items)


def float32(v: float) -> float:
    return struct.unpack("<f", struct.pack("<f", v))[0]
