"""The filter expression language: grammar, precedence, comparisons, errors."""

import pytest
from twisterlib import expr

ENV = {
    "CONFIG_A": "y",
    "CONFIG_OFF": "n",
    "CONFIG_EMPTY": "",
    "CONFIG_NUM": "10",
    "CONFIG_HEX": "0x20",
    "CONFIG_NAME": "vcan0",
    "ARCH": "posix",
}


def ev(text, env=ENV):
    return expr.evaluate(expr.parse(text), env)


@pytest.mark.parametrize(
    "text, expected",
    [
        ("CONFIG_A", True),
        ("CONFIG_UNSET", False),
        ("CONFIG_OFF", False),
        ("CONFIG_EMPTY", False),
        ("not CONFIG_UNSET", True),
        ("not not CONFIG_A", True),
        ('CONFIG_NAME == "vcan0"', True),
        ("CONFIG_NAME == 'vcan0'", True),
        ('CONFIG_NAME != "vcan0"', False),
        ('CONFIG_UNSET == ""', True),
        ("CONFIG_NUM == 10", True),
        ("CONFIG_NUM == 0xa", True),
        ('CONFIG_NUM == "10"', True),
        ("CONFIG_HEX == 32", True),
        ("CONFIG_NAME == 0", False),
        ("CONFIG_NUM > 9", True),
        ("CONFIG_NUM > 10", False),
        ("CONFIG_NUM >= 10", True),
        ("CONFIG_NUM < 11", True),
        ("CONFIG_NUM <= 9", False),
        ("CONFIG_HEX > 0x1f", True),
        ("CONFIG_UNSET < 1", True),
        ("CONFIG_NAME > 1", False),
        ("CONFIG_NUM > -1", True),
        ('ARCH in ["posix", "arm"]', True),
        ('ARCH in ["arm"]', False),
        ("CONFIG_NUM in [1, 10]", True),
        ('CONFIG_NAME : "vcan[0-9]+"', True),
        ('CONFIG_NAME : "can"', False),  # re.match anchors at the start
        ('CONFIG_UNSET : ".*"', True),
    ],
)
def test_evaluation(text, expected):
    assert ev(text) is expected


def test_not_binds_tighter_than_and_which_binds_tighter_than_or():
    # not UNSET and OFF -> (not UNSET) and OFF -> False; "not (UNSET and OFF)" would be True
    assert ev("not CONFIG_UNSET and CONFIG_OFF") is False
    # A or B and C -> A or (B and C)
    assert ev("CONFIG_A or CONFIG_UNSET and CONFIG_OFF") is True
    assert ev("(CONFIG_A or CONFIG_UNSET) and CONFIG_OFF") is False
    assert expr.parse("CONFIG_A or CONFIG_B and CONFIG_C") == (
        "or",
        ("sym", "CONFIG_A"),
        ("and", ("sym", "CONFIG_B"), ("sym", "CONFIG_C")),
    )


def test_common_and_scenario_filters_join():
    assert ev("(CONFIG_A) and (CONFIG_NUM > 5)") is True
    assert ev("(CONFIG_A) and (CONFIG_NUM > 50)") is False


def test_symbols_lists_what_the_expression_reads():
    assert expr.symbols(expr.parse('CONFIG_A and (X == "1" or not Y)')) == {"CONFIG_A", "X", "Y"}


@pytest.mark.parametrize(
    "text, message, column",
    [
        ("", "empty expression", 1),
        ("CONFIG_A and", "expected a symbol", 13),
        ("CONFIG_A and (CONFIG_B", "expected ')'", 23),
        ("CONFIG_A CONFIG_B", "expected 'and', 'or' or the end", 10),
        ("CONFIG_A == ", "expected a string or a number", 13),
        ('CONFIG_A > "x"', "'>' needs a number", 12),
        ("CONFIG_A : 5", "needs a quoted regular expression", 12),
        ('CONFIG_A : "("', "bad regular expression", 12),
        ("CONFIG_A in [1,", "expected a string or a number", 16),
        ("CONFIG_A in 1", "expected '['", 13),
        ('dt_compat_enabled("x")', "not supported", 1),
        ("CONFIG_A && CONFIG_B", "unexpected character '&'", 10),
        ('CONFIG_A == "open', "unexpected character '\"'", 13),
    ],
)
def test_syntax_errors_say_what_and_where(text, message, column):
    with pytest.raises(expr.FilterError) as e:
        expr.parse(text)
    assert message in str(e.value)
    assert e.value.pos + 1 == column
