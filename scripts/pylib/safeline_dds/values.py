# SPDX-License-Identifier: Apache-2.0
"""CANopen values: data types of CiA 301, text to wire bytes and back, SDO abort codes."""

import struct

BOOLEAN = 0x01
INTEGER8, INTEGER16, INTEGER32 = 0x02, 0x03, 0x04
UNSIGNED8, UNSIGNED16, UNSIGNED32 = 0x05, 0x06, 0x07
REAL32 = 0x08
VISIBLE_STRING, OCTET_STRING, UNICODE_STRING = 0x09, 0x0A, 0x0B
TIME_OF_DAY, TIME_DIFFERENCE = 0x0C, 0x0D
DOMAIN = 0x0F
INTEGER24, REAL64, INTEGER40, INTEGER48, INTEGER56, INTEGER64 = 0x10, 0x11, 0x12, 0x13, 0x14, 0x15
UNSIGNED24, UNSIGNED40, UNSIGNED48, UNSIGNED56, UNSIGNED64 = 0x16, 0x18, 0x19, 0x1A, 0x1B

# code: (name, bytes, signed) for the integers
INTS = {
    UNSIGNED8: ("UNSIGNED8", 1, False), UNSIGNED16: ("UNSIGNED16", 2, False),
    UNSIGNED24: ("UNSIGNED24", 3, False), UNSIGNED32: ("UNSIGNED32", 4, False),
    UNSIGNED40: ("UNSIGNED40", 5, False), UNSIGNED48: ("UNSIGNED48", 6, False),
    UNSIGNED56: ("UNSIGNED56", 7, False), UNSIGNED64: ("UNSIGNED64", 8, False),
    INTEGER8: ("INTEGER8", 1, True), INTEGER16: ("INTEGER16", 2, True),
    INTEGER24: ("INTEGER24", 3, True), INTEGER32: ("INTEGER32", 4, True),
    INTEGER40: ("INTEGER40", 5, True), INTEGER48: ("INTEGER48", 6, True),
    INTEGER56: ("INTEGER56", 7, True), INTEGER64: ("INTEGER64", 8, True),
}

NAMES = {code: v[0] for code, v in INTS.items()}
NAMES.update({
    BOOLEAN: "BOOLEAN", REAL32: "REAL32", REAL64: "REAL64",
    VISIBLE_STRING: "VISIBLE_STRING", OCTET_STRING: "OCTET_STRING",
    UNICODE_STRING: "UNICODE_STRING", TIME_OF_DAY: "TIME_OF_DAY",
    TIME_DIFFERENCE: "TIME_DIFFERENCE", DOMAIN: "DOMAIN",
})

# --type spellings
ALIASES = {name.lower(): code for code, name in NAMES.items()}
ALIASES.update({
    "bool": BOOLEAN, "u8": UNSIGNED8, "u16": UNSIGNED16, "u24": UNSIGNED24,
    "u32": UNSIGNED32, "u64": UNSIGNED64, "i8": INTEGER8, "i16": INTEGER16, "i24": INTEGER24,
    "i32": INTEGER32, "i64": INTEGER64, "f32": REAL32, "f64": REAL64, "real": REAL32,
    "string": VISIBLE_STRING, "str": VISIBLE_STRING, "octets": OCTET_STRING,
    "bytes": OCTET_STRING, "domain": DOMAIN,
})

ACCESS = {0: "ro", 1: "wo", 2: "rw", 3: "rwr", 4: "rww", 5: "const"}

ABORTS = {
    0x05030000: "Toggle bit not alternated",
    0x05040000: "SDO protocol timed out",
    0x05040001: "Client/server command specifier not valid or unknown",
    0x05040002: "Invalid block size",
    0x05040003: "Invalid sequence number",
    0x05040004: "CRC error",
    0x05040005: "Out of memory",
    0x06010000: "Unsupported access to an object",
    0x06010001: "Attempt to read a write only object",
    0x06010002: "Attempt to write a read only object",
    0x06020000: "Object does not exist in the object dictionary",
    0x06040041: "Object cannot be mapped to the PDO",
    0x06040042: "The number and length of the objects to be mapped would exceed PDO length",
    0x06040043: "General parameter incompatibility reason",
    0x06040047: "General internal incompatibility in the device",
    0x06060000: "Access failed due to a hardware error",
    0x06070010: "Data type does not match, length of service parameter does not match",
    0x06070012: "Data type does not match, length of service parameter too high",
    0x06070013: "Data type does not match, length of service parameter too low",
    0x06090011: "Sub-index does not exist",
    0x06090030: "Invalid value for parameter",
    0x06090031: "Value of parameter written too high",
    0x06090032: "Value of parameter written too low",
    0x06090036: "Maximum value is less than minimum value",
    0x060A0023: "Resource not available: SDO connection",
    0x08000000: "General error",
    0x08000020: "Data cannot be transferred or stored to the application",
    0x08000021: "Data cannot be transferred or stored because of local control",
    0x08000022: "Data cannot be transferred or stored because of the present device state",
    0x08000023: "Object dictionary dynamic generation fails or no object dictionary is present",
    0x08000024: "No data available",
}


def abort_text(code):
    return ABORTS.get(code, "unknown abort code")


def type_name(code):
    return NAMES.get(code, f"type {code:#06x}" if code else "unknown type")


def parse_type(text):
    """A --type argument: a name (u16, UNSIGNED16, string, ...) or a number (0x0006)."""
    t = text.strip().lower()
    if t in ALIASES:
        return ALIASES[t]
    try:
        code = int(t, 0)
    except ValueError:
        raise ValueError(f"unknown data type '{text}' (u8..u64, i8..i64, bool, f32, f64, "
                         "string, octets, domain, or a CiA 301 code)")
    if code not in NAMES:
        raise ValueError(f"data type {code:#06x} is not one the client can encode")
    return code


def _int(text):
    try:
        return int(text.strip().replace("_", ""), 0)
    except ValueError:
        raise ValueError(f"'{text}' is not an integer (decimal, 0x.. hex, 0b.. binary)")


def _hex(text):
    t = text.strip()
    if t.lower().startswith("0x"):
        t = t[2:]
    t = t.replace(" ", "").replace(":", "")
    try:
        return bytes.fromhex(t)
    except ValueError:
        raise ValueError(f"'{text}' is not hex bytes (e.g. 0a1b2c or '0a 1b 2c')")


def encode(text, dtype):
    """Wire bytes (little endian) of a value typed as dtype."""
    if dtype in INTS:
        name, size, signed = INTS[dtype]
        v = _int(text)
        lo, hi = (-(1 << (8 * size - 1)), (1 << (8 * size - 1)) - 1) if signed else \
            (0, (1 << (8 * size)) - 1)
        if not lo <= v <= hi:
            raise ValueError(f"{v} does not fit {name} ({lo}..{hi})")
        return v.to_bytes(size, "little", signed=signed)
    if dtype == BOOLEAN:
        t = text.strip().lower()
        if t in ("1", "true", "on", "yes"):
            return b"\x01"
        if t in ("0", "false", "off", "no"):
            return b"\x00"
        raise ValueError(f"'{text}' is not a BOOLEAN (0/1, true/false)")
    if dtype in (REAL32, REAL64):
        try:
            f = float(text)
        except ValueError:
            raise ValueError(f"'{text}' is not a number")
        return struct.pack("<f" if dtype == REAL32 else "<d", f)
    if dtype == VISIBLE_STRING:
        try:
            return text.encode("ascii")
        except UnicodeEncodeError:
            raise ValueError("a VISIBLE_STRING holds ASCII characters only")
    if dtype == UNICODE_STRING:
        return text.encode("utf-16-le")
    if dtype in (OCTET_STRING, DOMAIN):
        return _hex(text)
    raise ValueError(f"cannot encode {type_name(dtype)}: give --type or --hex")


def decode(data, dtype):
    """(value, text) of wire bytes typed as dtype; raw hex when the type is unknown."""
    data = bytes(data)
    if dtype in INTS:
        name, size, signed = INTS[dtype]
        if len(data) == size:
            v = int.from_bytes(data, "little", signed=signed)
            return v, f"{v} (0x{v & ((1 << (8 * size)) - 1):0{2 * size}X})"
    elif dtype == BOOLEAN and len(data) == 1:
        return bool(data[0]), "true" if data[0] else "false"
    elif dtype == REAL32 and len(data) == 4:
        v = struct.unpack("<f", data)[0]
        return v, f"{v:g}"
    elif dtype == REAL64 and len(data) == 8:
        v = struct.unpack("<d", data)[0]
        return v, f"{v:g}"
    elif dtype == VISIBLE_STRING:
        v = data.split(b"\0", 1)[0].decode("ascii", "replace")
        return v, repr(v)
    elif dtype == UNICODE_STRING:
        v = data.decode("utf-16-le", "replace")
        return v, repr(v)
    return data.hex(), hex_preview(data)


def hex_preview(data, limit=32):
    data = bytes(data)
    text = data[:limit].hex(" ")
    if len(data) > limit:
        text += f" ... ({len(data)} bytes)"
    return text or "(empty)"
