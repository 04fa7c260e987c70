"""The `filter:` expression language of testcase.yaml, evaluated against a built `.config`.

Grammar (Zephyr's, without the devicetree functions), lowest precedence first:

    expr    := and_expr ("or" and_expr)*
    and_expr:= not_expr ("and" not_expr)*
    not_expr:= "not" not_expr | primary
    primary := "(" expr ")"
             | SYM                          true when SYM is set and not "n" or ""
             | SYM ("=="|"!=") const
             | SYM ("<"|">"|"<="|">=") number
             | SYM "in" "[" const ("," const)* "]"
             | SYM ":" string               re.match of the regex on SYM's value
    const   := string | number              "text" or 'text'; 12, 0x1F, -3

Values come from `.config` with string quotes removed; an unset symbol reads as "" (and as 0 in
numeric comparisons). A number compares numerically with a symbol whose value is a number, a
string compares as text.

    >>> evaluate(parse('CONFIG_A and not (CONFIG_B == "x")'), {"CONFIG_A": "y"})
    True
"""

import re
from dataclasses import dataclass

__all__ = ["FilterError", "parse", "evaluate", "symbols"]


class FilterError(ValueError):
    """A syntax or evaluation error, with the column where it was found."""

    def __init__(self, message: str, expression: str = "", pos: int | None = None):
        self.message = message
        self.expression = expression
        self.pos = pos
        where = f" at column {pos + 1}" if pos is not None else ""
        super().__init__(f"{message}{where}")


@dataclass(frozen=True)
class _Tok:
    kind: str  # SYM STR NUM OP KW EOF
    value: object
    pos: int


_KEYWORDS = {"and", "or", "not", "in"}
_TOKEN_RE = re.compile(
    r"""
    (?P<ws>\s+)
  | (?P<num>-?(?:0[xX][0-9a-fA-F]+|\d+))(?![A-Za-z0-9_])
  | (?P<sym>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<str>"(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*')
  | (?P<op>==|!=|<=|>=|<|>|:|\(|\)|\[|\]|,)
    """,
    re.VERBOSE,
)


def _unescape(quoted: str) -> str:
    return re.sub(r"\\(.)", r"\1", quoted[1:-1])


def _tokenize(text: str) -> list[_Tok]:
    tokens = []
    pos = 0
    while pos < len(text):
        m = _TOKEN_RE.match(text, pos)
        if not m:
            raise FilterError(f"unexpected character {text[pos]!r}", text, pos)
        kind = m.lastgroup
        value = m.group()
        if kind == "num":
            tokens.append(_Tok("NUM", int(value, 0), pos))
        elif kind == "sym":
            tokens.append(_Tok("KW" if value in _KEYWORDS else "SYM", value, pos))
        elif kind == "str":
            tokens.append(_Tok("STR", _unescape(value), pos))
        elif kind == "op":
            tokens.append(_Tok("OP", value, pos))
        pos = m.end()
    tokens.append(_Tok("EOF", None, len(text)))
    return tokens


class _Parser:
    def __init__(self, text: str):
        self.text = text
        self.toks = _tokenize(text)
        self.i = 0

    def peek(self) -> _Tok:
        return self.toks[self.i]

    def take(self) -> _Tok:
        tok = self.toks[self.i]
        self.i += 1
        return tok

    def accept(self, kind: str, value=None) -> _Tok | None:
        tok = self.peek()
        if tok.kind == kind and (value is None or tok.value == value):
            self.i += 1
            return tok
        return None

    def expect(self, kind: str, value=None, what: str = "") -> _Tok:
        tok = self.accept(kind, value)
        if tok is None:
            self.fail(f"expected {what or value or kind}")
        return tok

    def fail(self, message: str):
        tok = self.peek()
        found = "end of expression" if tok.kind == "EOF" else repr(str(tok.value))
        raise FilterError(f"{message}, found {found}", self.text, tok.pos)

    def parse(self):
        if self.peek().kind == "EOF":
            raise FilterError("empty expression", self.text, 0)
        tree = self.expr()
        if self.peek().kind != "EOF":
            self.fail("expected 'and', 'or' or the end")
        return tree

    def expr(self):
        node = self.and_expr()
        while self.accept("KW", "or"):
            node = ("or", node, self.and_expr())
        return node

    def and_expr(self):
        node = self.not_expr()
        while self.accept("KW", "and"):
            node = ("and", node, self.not_expr())
        return node

    def not_expr(self):
        if self.accept("KW", "not"):
            return ("not", self.not_expr())
        return self.primary()

    def const(self):
        tok = self.peek()
        if tok.kind in ("STR", "NUM"):
            self.i += 1
            return tok.value
        self.fail("expected a string or a number")

    def primary(self):
        if self.accept("OP", "("):
            node = self.expr()
            self.expect("OP", ")", "')'")
            return node
        tok = self.peek()
        if tok.kind != "SYM":
            self.fail("expected a symbol, 'not' or '('")
        self.i += 1
        sym = tok.value
        if self.peek().kind == "OP" and self.peek().value == "(":
            raise FilterError(
                f"function {sym}() is not supported (no devicetree in SafeLine filters)",
                self.text,
                tok.pos,
            )
        op = self.peek()
        if op.kind == "OP" and op.value in ("==", "!="):
            self.i += 1
            return (op.value, sym, self.const())
        if op.kind == "OP" and op.value in ("<", ">", "<=", ">="):
            self.i += 1
            num = self.peek()
            if num.kind != "NUM":
                self.fail(f"'{op.value}' needs a number")
            self.i += 1
            return (op.value, sym, num.value)
        if op.kind == "OP" and op.value == ":":
            self.i += 1
            rx = self.peek()
            if rx.kind != "STR":
                self.fail("':' needs a quoted regular expression")
            self.i += 1
            try:
                re.compile(rx.value)
            except re.error as e:
                raise FilterError(f"bad regular expression: {e}", self.text, rx.pos) from None
            return (":", sym, rx.value)
        if op.kind == "KW" and op.value == "in":
            self.i += 1
            self.expect("OP", "[", "'['")
            values = [self.const()]
            while self.accept("OP", ","):
                values.append(self.const())
            self.expect("OP", "]", "']' or ','")
            return ("in", sym, tuple(values))
        return ("sym", sym)


def parse(text: str):
    """Parse a filter expression into a tuple tree; raise FilterError on bad syntax."""
    return _Parser(text).parse()


def symbols(tree) -> set[str]:
    """The symbols an expression reads (for messages)."""
    if tree[0] in ("and", "or"):
        return symbols(tree[1]) | symbols(tree[2])
    if tree[0] == "not":
        return symbols(tree[1])
    return {tree[1]}


def _as_int(value: str) -> int | None:
    try:
        return int(value, 0)
    except (TypeError, ValueError):
        return None


def _equal(value: str, const) -> bool:
    if isinstance(const, int):
        return _as_int(value) == const
    return value == const


def evaluate(tree, env: dict[str, str]) -> bool:
    """Evaluate a parsed expression. `env` maps symbols to their (unquoted) string values."""
    op = tree[0]
    if op == "or":
        return evaluate(tree[1], env) or evaluate(tree[2], env)
    if op == "and":
        return evaluate(tree[1], env) and evaluate(tree[2], env)
    if op == "not":
        return not evaluate(tree[1], env)
    value = env.get(tree[1], "")
    if op == "sym":
        return value not in ("", "n")
    if op == "==":
        return _equal(value, tree[2])
    if op == "!=":
        return not _equal(value, tree[2])
    if op == "in":
        return any(_equal(value, c) for c in tree[2])
    if op == ":":
        return re.match(tree[2], value) is not None
    num = _as_int(value) if value != "" else 0
    if num is None:
        return False
    if op == "<":
        return num < tree[2]
    if op == ">":
        return num > tree[2]
    if op == "<=":
        return num <= tree[2]
    if op == ">=":
        return num >= tree[2]
    raise FilterError(f"unknown operator {op}")
