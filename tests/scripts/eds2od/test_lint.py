# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""One test per lint error: eds2od stops with `file:line: message` at the right line."""

import re

import pytest

from eds2od_testlib import run_eds2od

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


def test_valid_file_passes(tmp_path):
    p, r = lint(tmp_path, eds(var(2000), [0x2000]))
    assert r.returncode == 0, r.stderr


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
    expect(tmp_path, eds(var(2000, AccessType="ro", DefaultValue=None), [0x2000]), "[2000]",
           "missing DefaultValue")


def test_missing_default_value_sub0(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x9\nSubNumber=2\n\n"
            "[2000sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=ro\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "[2000sub0]", "missing DefaultValue")


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
    expect(tmp_path, eds(var(2000, DataType="0x000F", DefaultValue=None, PDOMapping="1"),
                         [0x2000]), "PDOMapping=1", "cannot be mapped to a PDO")


def test_pdo_mapping_of_long_string(tmp_path):
    expect(tmp_path, eds(var(2000, DataType="0x0009", DefaultValue="twelve chars",
                             PDOMapping="1"), [0x2000]), "PDOMapping=1",
           "VISIBLE_STRING of 12 bytes cannot be mapped")


def test_subnumber_mismatch(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x9\nSubNumber=3\n\n"
            "[2000sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "SubNumber=3", "SubNumber=3 but 2 sub-index sections")


def test_subnumber_and_compactsubobj(tmp_path):
    body = ("[2000]\nParameterName=Arr\nObjectType=0x8\nSubNumber=2\nCompactSubObj=2\n"
            "DataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "CompactSubObj=2", "SubNumber and CompactSubObj both")


def test_compactsubobj_with_sub_sections(tmp_path):
    body = ("[2000]\nParameterName=Arr\nObjectType=0x8\nCompactSubObj=2\n"
            "DataType=0x0005\nAccessType=rw\nDefaultValue=0\n\n"
            "[2000sub1]\nParameterName=A\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "[2000sub1]", "has sub-index sections")


def test_compactsubobj_on_record(tmp_path):
    body = ("[2000]\nParameterName=Rec\nObjectType=0x9\nCompactSubObj=2\n"
            "DataType=0x0005\nAccessType=rw\nDefaultValue=0\n")
    expect(tmp_path, eds(body, [0x2000]), "CompactSubObj=2", "only allowed on ARRAY")


def test_array_without_subnumber(tmp_path):
    expect(tmp_path, eds("[2000]\nParameterName=Arr\nObjectType=0x8\n", [0x2000]), "[2000]",
           "needs SubNumber or CompactSubObj")


@pytest.mark.parametrize("formula", ["$NODEID*2", "$NODEID-1", "0x180+$NODEID+1", "$NODEID+",
                                     "$NODEID+0x1G", "2*$NODEID", "$NODEIDX"])
def test_malformed_nodeid_formula(tmp_path, formula):
    expect(tmp_path, eds(var(2000, DataType="0x0007", DefaultValue=formula), [0x2000]),
           f"DefaultValue={formula}", "malformed $NODEID formula")


def test_nodeid_on_non_integer(tmp_path):
    expect(tmp_path, eds(var(2000, DataType="0x0008", DefaultValue="$NODEID+1"), [0x2000]),
           "DefaultValue=$NODEID+1", "only allowed for integer types")


def test_duplicate_index_section(tmp_path):
    text = eds(var(2000) + var(2000, ParameterName="Again"), [0x2000])
    expect(tmp_path, text, "[2000]", "duplicate section [2000]", nth=2)


def test_duplicate_index_in_object_lists(tmp_path):
    text = eds(var(2000), [0x2000, 0x2000])
    expect(tmp_path, text, "2=0x2000", "duplicate index 2000h in object lists")


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
    expect(tmp_path, eds(var(2000), [0x2000, 0x2001]), "2=0x2001",
           "index 2001h listed in [ManufacturerObjects] has no section")


def test_section_not_listed(tmp_path):
    expect(tmp_path, eds(var(2000) + var(2001), [0x2000]), "[2001]",
           "is not listed in any object list")


def test_supported_objects_count(tmp_path):
    text = eds(var(2000), [0x2000]).replace("SupportedObjects=1", "SupportedObjects=2")
    expect(tmp_path, text, "SupportedObjects=2", "SupportedObjects=2 but")


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
