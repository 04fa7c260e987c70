# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""One test per lint error: eds2od stops with `file:line: message` at the right line."""

import re

import pytest

from eds2od_testlib import (app_array, run_eds2od, section, srdo_comm, srdo_map,
                            srdo_signatures, srdo_valid)

HEAD = """[FileInfo]
FileName=lint.eds
EDSVersion=4.0

[DeviceInfo]
VendorName=SafeLine
ProductName=Lint

[MandatoryObjects]
SupportedObjects=3
1=0x1000
2=0x1001
3=0x1018

[1000]
ParameterName=Device type
DataType=0x0007
AccessType=ro
DefaultValue=0
PDOMapping=0

[1001]
ParameterName=Error register
DataType=0x0005
AccessType=ro
DefaultValue=0
PDOMapping=0

[1018]
ParameterName=Identity object
ObjectType=0x9
SubNumber=2

[1018sub0]
ParameterName=Highest sub-index supported
DataType=0x0005
AccessType=const
DefaultValue=1

[1018sub1]
ParameterName=Vendor-ID
DataType=0x0007
AccessType=ro
DefaultValue=0
"""


def eds(body, listed, optional=()):
    text = HEAD
    if optional:
        text += "\n[OptionalObjects]\nSupportedObjects=%d\n" % len(optional)
        text += "".join(f"{n}=0x{i:04X}\n" for n, i in enumerate(optional, 1))
    text += "\n[ManufacturerObjects]\nSupportedObjects=%d\n" % len(listed)
    text += "".join(f"{n}=0x{i:04X}\n" for n, i in enumerate(listed, 1))
    return text + "\n" + body


def var(idx, **keys):
    keys.setdefault("ParameterName", "Value")
    keys.setdefault("DataType", "0x0006")
    keys.setdefault("AccessType", "rw")
    keys.setdefault("DefaultValue", "0")
    return f"[{idx}]\n" + "".join(f"{k}={v}\n" for k, v in keys.items() if v is not None) + "\n"


def line_of(text, needle, nth=1):
    """1-based line of the nth line that equals or contains needle."""
    hits = [n for n, ln in enumerate(text.splitlines(), 1) if needle in ln]
    return hits[nth - 1]


def lint(tmp_path, text):
    p = tmp_path / "lint.eds"
    p.write_text(text)
    r = run_eds2od(p)
    return p, r


def expect(tmp_path, text, needle, message, nth=1):
    p, r = lint(tmp_path, text)
    assert r.returncode == 1, r.stderr
    line = line_of(text, needle, nth)
    pat = re.escape(f"{p}:{line}: ") + r".*" + re.escape(message)
    assert re.search(pat, r.stderr), f"want line {line} '{message}', got:\n{r.stderr}"


def expect_warning(tmp_path, text, needle, message, nth=1):
    """Accepted with `file:line: warning: message`; refused with --strict."""
    p, r = lint(tmp_path, text)
    assert r.returncode == 0, r.stderr
    line = line_of(text, needle, nth)
    pat = re.escape(f"{p}:{line}: warning: ") + r".*" + re.escape(message)
    assert re.search(pat, r.stderr), f"want line {line} '{message}', got:\n{r.stderr}"
    r = run_eds2od(p, extra=["--strict"])
    assert r.returncode == 1, r.stderr
    pat = re.escape(f"{p}:{line}: ") + r".*" + re.escape(message) + r".*\(--strict\)"
    assert re.search(pat, r.stderr), f"want line {line} '{message}', got:\n{r.stderr}"


def test_valid_file_passes(tmp_path):
    p, r = lint(tmp_path, eds(var(2000), [0x2000]))
    assert r.returncode == 0, r.stderr


def test_missing_mandatory_object_named_at_its_list_entry(tmp_path):
    text = eds(var(2000), [0x2000])
    start = text.index("[1000]")
    text = text[:start] + text[text.index("[1001]"):]
    expect(tmp_path, text, "1=0x1000", "mandatory object 1000h (Device type) is missing")
    p, r = lint(tmp_path, text)
    assert "1001h" not in r.stderr.replace("1000h, 1001h and 1018h", ""), r.stderr


def test_missing_mandatory_objects_refused_with_strict_or_without(tmp_path):
    text = eds(var(2000), [0x2000])
    text = text[:text.index("[1018]")] + text[text.index("[ManufacturerObjects]"):]
    text = text.replace("SupportedObjects=3\n1=0x1000\n2=0x1001\n3=0x1018\n",
                        "SupportedObjects=2\n1=0x1000\n2=0x1001\n")
    expect(tmp_path, text, "[MandatoryObjects]", "mandatory object 1018h (Identity object)")
    p, r = lint(tmp_path, text)
    s = run_eds2od(p, extra=["--strict"])
    assert s.returncode == 1 and "mandatory object 1018h" in s.stderr, s.stderr


def test_unknown_data_type(tmp_path):
    expect(tmp_path, eds(var(2000, DataType="0x0017"), [0x2000]), "DataType=0x0017",
           "unknown data type")


def test_unknown_access_type(tmp_path):
    expect(tmp_path, eds(var(2000, AccessType="rx"), [0x2000]), "AccessType=rx",
           "unknown access type 'rx'")


def test_unknown_object_code(tmp_path):
    expect(tmp_path, eds(var(2000, ObjectType="0x4"), [0x2000]), "ObjectType=0x4",
           "unknown object code 0x4")


def test_missing_default_value_ro(tmp_path):
    expect_warning(tmp_path, eds(var(2000, AccessType="ro", DefaultValue=None), [0x2000]),
                   "[2000]", "no DefaultValue for a ro UNSIGNED16; the value starts at 0")


def test_missing_default_value_sub0(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x9\nSubNumber=2\n\n"
            "[2000sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=ro\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect_warning(tmp_path, eds(body, [0x2000]), "[2000sub0]",
                   "2000h:0 has no DefaultValue; 1 (the highest sub-index) is used")


def test_value_above_high_limit(tmp_path):
    expect(tmp_path, eds(var(2000, DefaultValue="300", HighLimit="200"), [0x2000]),
           "DefaultValue=300", "above HighLimit")


def test_value_below_low_limit(tmp_path):
    expect(tmp_path, eds(var(2000, DefaultValue="5", LowLimit="10"), [0x2000]),
           "DefaultValue=5", "below LowLimit")


def test_dcf_parameter_value_outside_limits(tmp_path):
    expect(tmp_path, eds(var(2000, DefaultValue="5", ParameterValue="500", HighLimit="100"),
                         [0x2000]), "ParameterValue=500", "above HighLimit")


def test_low_limit_above_high_limit(tmp_path):
    expect(tmp_path, eds(var(2000, LowLimit="10", HighLimit="5", DefaultValue="7"), [0x2000]),
           "LowLimit=10", "is above HighLimit")


def test_value_out_of_type_range(tmp_path):
    expect(tmp_path, eds(var(2000, DataType="0x0005", DefaultValue="256"), [0x2000]),
           "DefaultValue=256", "out of range for UNSIGNED8")


def test_pdo_mapping_of_domain(tmp_path):
    expect_warning(tmp_path, eds(var(2000, DataType="0x000F", DefaultValue=None,
                                     PDOMapping="1"), [0x2000]), "PDOMapping=1",
                   "cannot be mapped to a PDO; PDOMapping=1 is ignored")


def test_pdo_mapping_of_long_string(tmp_path):
    expect_warning(tmp_path, eds(var(2000, DataType="0x0009", DefaultValue="twelve chars",
                                     PDOMapping="1"), [0x2000]), "PDOMapping=1",
                   "VISIBLE_STRING of 12 bytes cannot be mapped")


def test_subnumber_mismatch(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x9\nSubNumber=3\n\n"
            "[2000sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect_warning(tmp_path, eds(body, [0x2000]), "SubNumber=3",
                   "SubNumber=3 but 2 sub-index sections")


def test_subnumber_and_compactsubobj(tmp_path):
    body = ("[2000]\nParameterName=Arr\nObjectType=0x8\nSubNumber=2\nCompactSubObj=2\n"
            "DataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "CompactSubObj=2", "SubNumber and CompactSubObj both")


def test_compactsubobj_with_sub_sections(tmp_path):
    body = ("[2000]\nParameterName=Arr\nObjectType=0x8\nCompactSubObj=2\n"
            "DataType=0x0005\nAccessType=rw\nDefaultValue=0\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "[2000sub1]", "has sub-index sections")


def test_compactsubobj_on_defstruct(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x6\nCompactSubObj=2\n"
            "DataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "CompactSubObj=2", "only allowed on ARRAY and RECORD")


def test_array_without_subnumber(tmp_path):
    expect(tmp_path, eds("[2000]\nParameterName=Arr\nObjectType=0x8\n", [0x2000]), "[2000]",
           "needs SubNumber or CompactSubObj")


@pytest.mark.parametrize("formula", ["$NODEID*2", "$NODEID-1", "0x180+$NODEID+1", "$NODEID+",
                                     "$NODEID+0x1G", "2*$NODEID", "$NODEIDX"])
def test_malformed_nodeid_formula(tmp_path, formula):
    expect(tmp_path, eds(var(2000, DataType="0x0007", DefaultValue=formula), [0x2000]),
           f"DefaultValue={formula}", "malformed $NODEID formula")


@pytest.mark.parametrize("formula", ["0x180+$NODEID", "$NODEID+0x180", "$NODEID + 384",
                                     "384 + $nodeid"])
def test_nodeid_formula_either_order(tmp_path, formula):
    """CiA 306 writes $NODEID+n; files also say n+$NODEID (dcfchk takes only the first)."""
    p, r = lint(tmp_path, eds(var(2000, DataType="0x0007", DefaultValue=formula), [0x2000]))
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr
    r = run_eds2od(p, tmp_path / "gen", "nid")
    assert r.returncode == 0, r.stderr
    assert "DefaultValue=$NODEID+0x180\n" in (tmp_path / "gen" / "nid.eds").read_text()


def test_nodeid_on_non_integer(tmp_path):
    expect(tmp_path, eds(var(2000, DataType="0x0008", DefaultValue="$NODEID+1"), [0x2000]),
           "DefaultValue=$NODEID+1", "only allowed for integer types")


def test_duplicate_index_section(tmp_path):
    text = eds(var(2000) + var(2000, ParameterName="Again"), [0x2000])
    expect(tmp_path, text, "[2000]", "duplicate section [2000]", nth=2)


def test_duplicate_index_in_object_lists(tmp_path):
    text = eds(var(2000), [0x2000, 0x2000])
    expect_warning(tmp_path, text, "2=0x2000", "duplicate index 2000h in object lists")


def test_duplicate_sub_index(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x9\nSubNumber=2\n\n"
            "[2000sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n\n"
            "[2000sub01]\nParameterName=B\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "[2000sub01]", "duplicate sub-index 1 of 2000h")


def test_duplicate_key(tmp_path):
    expect(tmp_path, eds(var(2000, PDOMapping="0") + "", [0x2000]).replace(
        "PDOMapping=0\n\n", "PDOMapping=0\nPDOMapping=1\n\n", 1), "PDOMapping=1",
        "duplicate key 'PDOMapping'")


def test_listed_object_without_section(tmp_path):
    expect_warning(tmp_path, eds(var(2000), [0x2000, 0x2001]), "2=0x2001",
                   "index 2001h listed in [ManufacturerObjects] has no section")


def test_section_not_listed(tmp_path):
    expect_warning(tmp_path, eds(var(2000) + var(2001), [0x2000]), "[2001]",
                   "is not listed in any object list")


def test_list_without_supported_objects(tmp_path):
    text = eds(var(2000), [0x2000]).replace("[ManufacturerObjects]\nSupportedObjects=1\n",
                                            "[ManufacturerObjects]\n")
    expect_warning(tmp_path, text, "[ManufacturerObjects]",
                   "[ManufacturerObjects] has no SupportedObjects")


def test_supported_objects_count(tmp_path):
    text = eds(var(2000), [0x2000]).replace("SupportedObjects=1", "SupportedObjects=2")
    expect_warning(tmp_path, text, "SupportedObjects=2", "SupportedObjects=2 but")


def test_array_types_differ(tmp_path):
    body = ("[2000]\nParameterName=Arr\nObjectType=0x8\nSubNumber=3\n\n"
            "[2000sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=ro\nDefaultValue=2\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n\n"
            "[2000sub2]\nParameterName=B\nDataType=0x0006\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "[2000sub1]", "have different data types")


def test_sub0_must_be_unsigned8(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x9\nSubNumber=2\n\n"
            "[2000sub0]\nParameterName=Highest\nDataType=0x0006\nAccessType=ro\nDefaultValue=1\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "[2000sub0]", "must be UNSIGNED8")


def tpdo(cobid):
    return ("[1800]\nParameterName=TPDO\nObjectType=0x9\nSubNumber=2\n\n"
            "[1800sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=const\nDefaultValue=1\n\n"
            f"[1800sub1]\nParameterName=COB-ID\nDataType=0x0007\nAccessType=rw\nDefaultValue={cobid}\n\n")


def test_pdo_cobid_restricted(tmp_path):
    expect(tmp_path, eds(tpdo("0x601"), [], optional=[0x1800]), "[1800sub1]",
           "restricted CAN-ID 0x601")


def test_cobid_11bit_overflow(tmp_path):
    expect(tmp_path, eds(tpdo("0x00000801"), [], optional=[0x1800]), "[1800sub1]",
           "bits above 10 set")


def test_invalid_pdo_cobid_is_not_checked(tmp_path):
    p, r = lint(tmp_path, eds(tpdo("0x80000601"), [], optional=[0x1800]))
    assert r.returncode == 0, r.stderr


def test_invalid_number(tmp_path):
    expect(tmp_path, eds(var(2000, DefaultValue="12abc"), [0x2000]), "DefaultValue=12abc",
           "is not a valid UNSIGNED16")


def test_all_errors_reported_at_once(tmp_path):
    text = eds(var(2000, AccessType="rx") + var(2001, DataType="0x0099"), [0x2000, 0x2001])
    p, r = lint(tmp_path, text)
    assert r.returncode == 1
    assert "2 error(s)" in r.stderr


# --------------------------------------------------------------------------------------
# SRDO objects (CiA 304): 1300h, 1301h-1340h, 1381h-13C0h, 13FEh, 13FFh

GFC = section("1300", {"ParameterName": "GFC parameter", "ObjectType": "0x7",
                       "DataType": "0x0005", "AccessType": "rw", "DefaultValue": "1",
                       "PDOMapping": "0"})
MAP1 = [0x62000108, 0x62010108]  # producer: 6200h:1 and its inverted copy 6201h:1, 8 bits
MAP2 = [0x64010110, 0x64020110]  # consumer: 6401h:1 and 6402h:1, 16 bits
APP = (app_array(0x6200, 2) + app_array(0x6201, 2) + app_array(0x6401, 2, "0x0006") +
       app_array(0x6402, 2, "0x0006"))


def srdo_body(comm1=None, map1=None, comm2=None, map2=None, sig=None, valid=None, gfc=None,
              app=None):
    """Two valid SRDOs: 1 a producer on 101h/102h, 2 a consumer of 103h/104h; each part can
    be replaced (an empty string leaves it out)."""
    parts = [comm1, srdo_comm(1)], [map1, srdo_map(1, MAP1)], \
        [comm2, srdo_comm(2, 2, 50, 20, 254, 0x103, 0x104)], [map2, srdo_map(2, MAP2)], \
        [sig, srdo_signatures(2)], [valid, srdo_valid()], [gfc, GFC], [app, APP]
    return "".join(given if given is not None else default for given, default in parts)


def srdo_eds(body, dcf_node_id=None):
    """A whole file around body, every object listed where it belongs."""
    idxs = sorted(int(h, 16) for h in re.findall(r"^\[([0-9A-F]{4})\]$", body, re.M))
    text = eds(body, [i for i in idxs if 0x2000 <= i < 0x6000],
               optional=[i for i in idxs if not 0x2000 <= i < 0x6000])
    if dcf_node_id is not None:
        text = text.replace("[MandatoryObjects]",
                            f"[DeviceComissioning]\nNodeID={dcf_node_id}\n\n[MandatoryObjects]")
    return text


def key_line(text, sec, key):
    """1-based line of key= in [sec]."""
    rows = text.splitlines()
    at = rows.index(f"[{sec}]")
    for n in range(at + 1, len(rows)):
        if rows[n].startswith("["):
            break
        if rows[n].startswith(key + "="):
            return n + 1
    raise AssertionError(f"no {key} in [{sec}]")


def expect_key(tmp_path, text, sec, key, message):
    p, r = lint(tmp_path, text)
    assert r.returncode == 1, r.stderr
    line = key_line(text, sec, key)
    pat = re.escape(f"{p}:{line}: ") + r".*" + re.escape(message)
    assert re.search(pat, r.stderr), f"want line {line} '{message}', got:\n{r.stderr}"


def test_srdo_valid_file_passes(tmp_path):
    p, r = lint(tmp_path, srdo_eds(srdo_body()))
    assert r.returncode == 0, r.stderr


def test_srdo_default_cobids_pass(tmp_path):
    """SRDO 1 may hold the bare defaults 0xFF/0x100 (the stack adds 2 x node-ID)."""
    p, r = lint(tmp_path, srdo_eds(srdo_body(comm1=srdo_comm(1, cob1=0xFF, cob2=0x100)),
                                   dcf_node_id=64))
    assert r.returncode == 0, r.stderr


def test_srdo_disabled_gets_structural_checks_only(tmp_path):
    """Direction 0: zeros everywhere and a mapping of nothing are fine."""
    body = srdo_body(comm2=srdo_comm(2, 0, 0, 0, 0, 0, 0), map2=srdo_map(2, [0, 0], count=0))
    p, r = lint(tmp_path, srdo_eds(body))
    assert r.returncode == 0, r.stderr


def test_srdo_disabled_odd_count(tmp_path):
    body = srdo_body(comm2=srdo_comm(2, 0, 0, 0, 0, 0, 0), map2=srdo_map(2, MAP2, count=1))
    expect_key(tmp_path, srdo_eds(body), "1382sub0", "DefaultValue",
               "SRDO 2 maps 1 entries; the count must be even")


def test_srdo_disabled_wrong_type(tmp_path):
    body = srdo_body(comm2=srdo_comm(2, 0, 0, 0, 0, 0, 0, types={3: "0x0006"}))
    expect_key(tmp_path, srdo_eds(body), "1302sub3", "DataType",
               "1302h:3: SRVT must be UNSIGNED8, not UNSIGNED16")


def test_srdo_entries_beyond_count_not_checked(tmp_path):
    body = srdo_body(map1=srdo_map(1, MAP1 + [0x7FFF0108, 0x12345678], count=2))
    p, r = lint(tmp_path, srdo_eds(body))
    assert r.returncode == 0, r.stderr


def test_srdo_comm_not_record(tmp_path):
    body = srdo_body(comm1=srdo_comm(1).replace("ObjectType=0x9", "ObjectType=0x8", 1)
                     .replace("DataType=0x0006", "DataType=0x0005")
                     .replace("DataType=0x0007", "DataType=0x0005")
                     .replace("DefaultValue=0x101", "DefaultValue=0x1")
                     .replace("DefaultValue=0x102", "DefaultValue=0x2"))
    expect(tmp_path, srdo_eds(body), "[1301]", "SRDO 1 communication parameter must be a RECORD")


def test_srdo_comm_missing_sub(tmp_path):
    comm = srdo_comm(1)
    comm = comm[:comm.index("[1301sub5]")] + comm[comm.index("[1301sub6]"):]
    comm = comm.replace("SubNumber=0x7", "SubNumber=0x6")
    expect(tmp_path, srdo_eds(srdo_body(comm1=comm)), "[1301]",
           "SRDO 1 communication parameter has no sub-index 5 (COB-ID 1)")


def test_srdo_comm_extra_sub(tmp_path):
    comm = srdo_comm(1).replace("SubNumber=0x7", "SubNumber=0x8") + section(
        "1301sub7", {"ParameterName": "Extra", "DataType": "0x0005", "AccessType": "rw",
                     "DefaultValue": "0"})
    expect(tmp_path, srdo_eds(srdo_body(comm1=comm)), "[1301sub7]",
           "1301h:7: an SRDO communication parameter has sub-indexes 0..6 only")


def test_srdo_comm_wrong_type(tmp_path):
    body = srdo_body(comm1=srdo_comm(1, types={5: "0x0006"}))
    expect_key(tmp_path, srdo_eds(body), "1301sub5", "DataType",
               "1301h:5: COB-ID 1 must be UNSIGNED32, not UNSIGNED16")


def test_srdo_comm_sub0_not_6(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(comm1=srdo_comm(1, sub0=5))), "1301sub0",
               "DefaultValue", "1301h:0: highest sub-index is 5; an SRDO communication "
                               "parameter has 6")


def test_srdo_direction(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(comm1=srdo_comm(1, direction=3))), "1301sub1",
               "DefaultValue", "SRDO 1 direction 3 is not 0 (none), 1 (producer) or 2")


def test_srdo_refresh_time_zero(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(comm1=srdo_comm(1, cycle=0))), "1301sub2",
               "DefaultValue", "SRDO 1 refresh time is 0 ms; it must be at least 1 ms")


def test_srdo_sct_zero(tmp_path):
    body = srdo_body(comm2=srdo_comm(2, 2, 0, 20, 254, 0x103, 0x104))
    expect_key(tmp_path, srdo_eds(body), "1302sub2", "DefaultValue",
               "SRDO 2 SCT is 0 ms; it must be at least 1 ms")


def test_srdo_srvt_zero(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(comm1=srdo_comm(1, srvt=0))), "1301sub3",
               "DefaultValue", "SRDO 1 SRVT is 0 ms; it must be at least 1 ms")


def test_srdo_transmission_type(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(comm1=srdo_comm(1, tt=253))), "1301sub4",
               "DefaultValue", "SRDO 1 transmission type 253; an SRDO has 254 only")


@pytest.mark.parametrize("cob1", [0x100, 0x181, 0x1FF, 0x80000101])
def test_srdo_cobid1(tmp_path, cob1):
    body = srdo_body(comm2=srdo_comm(2, 2, 50, 20, 254, cob1, cob1 + 1))
    expect_key(tmp_path, srdo_eds(body), "1302sub5", "DefaultValue",
               f"SRDO 2 COB-ID 1 {cob1:#x} is not an odd CAN-ID in 0x101..0x17F")


def test_srdo_cobid2(tmp_path):
    body = srdo_body(comm2=srdo_comm(2, 2, 50, 20, 254, 0x103, 0x106))
    expect_key(tmp_path, srdo_eds(body), "1302sub6", "DefaultValue",
               "SRDO 2 COB-ID 2 0x106 must be 0x104 (COB-ID 1 + 1)")


def test_srdo_cobid2_with_default_cobid1(tmp_path):
    body = srdo_body(comm1=srdo_comm(1, cob1=0xFF, cob2=0x102))
    expect_key(tmp_path, srdo_eds(body), "1301sub6", "DefaultValue",
               "SRDO 1 COB-ID 2 0x102 must be 0x100 (the default with COB-ID 1 0xFF)")


def test_srdo_default_cobids_only_for_srdo_1(tmp_path):
    body = srdo_body(comm2=srdo_comm(2, 2, 50, 20, 254, 0xFF, 0x100))
    expect_key(tmp_path, srdo_eds(body), "1302sub5", "DefaultValue",
               "COB-ID 1 0xff is the default of SRDO 1 (0xFF + 2 x node-ID); SRDO 2 needs")


def test_srdo_default_cobids_need_node_id_up_to_64(tmp_path):
    body = srdo_body(comm1=srdo_comm(1, cob1=0xFF, cob2=0x100))
    expect_key(tmp_path, srdo_eds(body, dcf_node_id=65), "1301sub5", "DefaultValue",
               "must be 1..64; NodeID is 65")


def test_srdo_cobid_with_nodeid_formula(tmp_path):
    body = srdo_body(comm1=srdo_comm(1, cob1="$NODEID+0xFF", cob2="$NODEID+0x100"))
    expect_key(tmp_path, srdo_eds(body), "1301sub5", "DefaultValue",
               "1301h:5: COB-ID 1 cannot use $NODEID")


def test_srdo_parameter_value_line_reported(tmp_path):
    """In a DCF the configured value is the one checked, at its own line."""
    body = srdo_body(comm1=srdo_comm(1, tt=253, key="ParameterValue"))
    expect_key(tmp_path, srdo_eds(body, dcf_node_id=1), "1301sub4", "ParameterValue",
               "SRDO 1 transmission type 253")


def test_srdo_comm_without_mapping(tmp_path):
    expect(tmp_path, srdo_eds(srdo_body(map2="")), "[1302]",
           "1302h: SRDO 2 has no mapping parameter 1382h")


def test_srdo_mapping_without_comm(tmp_path):
    expect(tmp_path, srdo_eds(srdo_body(comm2="", sig=srdo_signatures(1))), "[1382]",
           "1382h: SRDO 2 has a mapping but no communication parameter 1302h")


def test_srdo_mapping_not_a_record(tmp_path):
    mp = section("1381", {"ParameterName": "Map", "ObjectType": "0x7", "DataType": "0x0005",
                          "AccessType": "rw", "DefaultValue": "0", "PDOMapping": "0"})
    expect(tmp_path, srdo_eds(srdo_body(map1=mp)), "[1381]",
           "1381h: SRDO 1 mapping parameter must be a RECORD")


def test_srdo_mapping_entry_type(tmp_path):
    mp = srdo_map(1, MAP1).replace("[1381sub2]\nParameterName=Mapping entry 2\nObjectType=0x7\n"
                                   "DataType=0x0007", "[1381sub2]\nParameterName=Mapping entry "
                                   "2\nObjectType=0x7\nDataType=0x0006")
    mp = mp.replace("DefaultValue=0x62010108", "DefaultValue=0x0108")
    expect_key(tmp_path, srdo_eds(srdo_body(map1=mp)), "1381sub2", "DataType",
               "1381h:2: a mapping entry must be UNSIGNED32, not UNSIGNED16")


def test_srdo_mapping_above_16(tmp_path):
    mp = srdo_map(1, MAP1, size=17)
    expect(tmp_path, srdo_eds(srdo_body(map1=mp)), "[1381sub11]",
           "1381h:17: an SRDO mapping has sub-indexes 1..16 only")


def test_srdo_mapping_count_odd(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(map1=srdo_map(1, MAP1 + [0x62000208], count=3))),
               "1381sub0", "DefaultValue", "SRDO 1 maps 3 entries; the count must be even")


def test_srdo_mapping_count_above_16(tmp_path):
    mp = srdo_map(1, MAP1, count=18, size=16)
    expect_key(tmp_path, srdo_eds(srdo_body(map1=mp)), "1381sub0", "DefaultValue",
               "SRDO 1 maps 18 entries; at most 16")


def test_srdo_mapping_count_above_entries(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(map1=srdo_map(1, MAP1, count=4))), "1381sub0",
               "DefaultValue", "SRDO 1 maps 4 entries, but 1381h has no sub-index 3, 4")


def test_srdo_mapping_missing_object(tmp_path):
    body = srdo_body(map1=srdo_map(1, [0x62000108, 0x62050108]))
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x62050108",
           "1381h:2: entry 0x62050108 maps 6205h:1, but the file has no object 6205h")


def test_srdo_mapping_missing_sub_index(tmp_path):
    """An entry naming a sub-index its object does not have (here a VAR's sub 1)."""
    var6100 = section("6100", {"ParameterName": "Safe input", "ObjectType": "0x7",
                               "DataType": "0x0005", "AccessType": "rw", "DefaultValue": "0",
                               "PDOMapping": "1"})
    body = srdo_body(map1=srdo_map(1, [0x61000108, 0x62010108]), app=APP + var6100)
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x61000108",
           "1381h:1: entry 0x61000108 maps 6100h:1, but 6100h has no sub-index 1")


def test_srdo_mapping_not_mappable(tmp_path):
    body = srdo_body(app=app_array(0x6200, 2, pdo="0") + app_array(0x6201, 2) +
                     app_array(0x6401, 2, "0x0006") + app_array(0x6402, 2, "0x0006"))
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x62000108",
           "maps 6200h:1, which is not mappable (PDOMapping=0)")


def test_srdo_mapping_not_whole_bytes(tmp_path):
    body = srdo_body(map2=srdo_map(2, [0x6401010C, 0x6402010C]))
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x6401010C",
           "maps 12 bits of 6401h:1; SRDO entries are whole bytes")


def test_srdo_mapping_longer_than_object(tmp_path):
    body = srdo_body(map1=srdo_map(1, [0x62000110, 0x62010110]))
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x62000110",
           "maps 16 bits of 6200h:1, which has 8 (UNSIGNED8); an SRDO maps whole objects")


def test_srdo_mapping_partner_length(tmp_path):
    body = srdo_body(map2=srdo_map(2, [0x64010110, 0x62000108]))
    expect_key(tmp_path, srdo_eds(body), "1382sub2", "DefaultValue",
               "1382h:2: the inverted entry maps 8 bits, its normal partner 1382h:1 maps 16")


def test_srdo_mapping_part_of_an_object(tmp_path):
    # The stack maps whole objects only (a consumer writes, a producer reads whole values).
    body = srdo_body(map2=srdo_map(2, [0x64010108, 0x64020108]))
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x64010108",
           "maps 8 bits of 6401h:1, which has 16 (UNSIGNED16); an SRDO maps whole objects")


def test_srdo_consumer_maps_read_only_object(tmp_path):
    body = srdo_body(app=app_array(0x6200, 2) + app_array(0x6201, 2) +
                     app_array(0x6401, 2, "0x0006", access="ro") +
                     app_array(0x6402, 2, "0x0006"))
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x64010110",
           "maps 6401h:1 (ro) into a consumer, which must write it")


def test_srdo_producer_maps_write_only_object(tmp_path):
    body = srdo_body(app=app_array(0x6200, 2, access="wo") + app_array(0x6201, 2) +
                     app_array(0x6401, 2, "0x0006") + app_array(0x6402, 2, "0x0006"))
    expect(tmp_path, srdo_eds(body), "DefaultValue=0x62000108",
           "maps 6200h:1 (wo) into a producer, which must read it")


def test_srdo_mapping_more_than_8_bytes(tmp_path):
    entries = [0x64010110, 0x64020110, 0x64010210, 0x64020210] * 2 + [0x62000108, 0x62010108]
    expect_key(tmp_path, srdo_eds(srdo_body(map2=srdo_map(2, entries))), "1382sub0",
               "DefaultValue", "SRDO 2 maps 9 bytes of normal data; a frame carries 1..8")


def test_srdo_mapping_empty(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(map1=srdo_map(1, [], count=0))), "1381sub0",
               "DefaultValue", "SRDO 1 maps 0 bytes of normal data; a frame carries 1..8")


def test_srdo_signatures_not_array(tmp_path):
    sig = srdo_signatures(2).replace("ObjectType=0x8", "ObjectType=0x9", 1)
    expect(tmp_path, srdo_eds(srdo_body(sig=sig)), "[13FF]",
           "13FFh: the SRDO signatures must be an ARRAY of UNSIGNED16")


def test_srdo_signatures_type(tmp_path):
    sig = srdo_signatures(2).replace("DataType=0x0006", "DataType=0x0007")
    expect_key(tmp_path, srdo_eds(srdo_body(sig=sig)), "13FFsub1", "DataType",
               "13FFh:1: an SRDO signature must be UNSIGNED16, not UNSIGNED32")


def test_srdo_signatures_too_few(tmp_path):
    expect(tmp_path, srdo_eds(srdo_body(sig=srdo_signatures(1))), "[13FF]",
           "13FFh: SRDO 2 exists, so the signatures need sub-indexes 1..2; missing 2")


def test_srdo_valid_type(tmp_path):
    expect(tmp_path, srdo_eds(srdo_body(valid=srdo_valid(dtype="0x0006"))), "[13FE]",
           "13FEh: configuration valid must be a VAR of UNSIGNED8")


def test_gfc_value(tmp_path):
    expect_key(tmp_path, srdo_eds(srdo_body(gfc=GFC.replace("DefaultValue=1", "DefaultValue=2"))),
               "1300", "DefaultValue", "1300h: GFC parameter 2 is not 0 (GFC not valid) or 1")


def test_gfc_type(tmp_path):
    expect(tmp_path, srdo_eds(srdo_body(gfc=GFC.replace("DataType=0x0005", "DataType=0x0006"))),
           "[1300]", "1300h: GFC parameter must be a VAR of UNSIGNED8")
