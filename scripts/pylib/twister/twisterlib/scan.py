"""Static scan of a test's sources for the ztest cases it defines.

The runner knows the expected cases before anything runs, so a case that never reports (the
image crashed or hung before it) is still listed, as "blocked". The scan is textual, like
Zephyr's: comments are removed, preprocessor conditionals are not evaluated, so a case under
`#ifdef` is expected even when compiled out (a passing run then reports it as skipped).
"""

import re
from pathlib import Path

SOURCE_SUFFIXES = (".c", ".cc", ".cpp", ".cxx")

_COMMENT_RE = re.compile(r"/\*.*?\*/|//[^\n]*", re.S)
_STRING_RE = re.compile(r'"(?:[^"\\\n]|\\.)*"')
_SUITE_RE = re.compile(r"\bZTEST_SUITE\s*\(\s*(\w+)")
_CASE_RE = re.compile(r"\b(?:ZTEST|ZTEST_F|ZTEST_USER|ZTEST_USER_F)\s*\(\s*(\w+)\s*,\s*(\w+)\s*\)")


def strip_test_prefix(name: str) -> str:
    return name[5:] if name.startswith("test_") and len(name) > 5 else name


def _clean(text: str) -> str:
    # Strings first, so that "//" or "/*" inside a string literal does not eat code.
    text = _STRING_RE.sub('""', text)
    return _COMMENT_RE.sub(" ", text)


def scan_text(text: str) -> tuple[list[str], list[tuple[str, str]]]:
    """Return (suites, [(suite, case)]) defined in one source text, in source order."""
    text = _clean(text)
    suites = _SUITE_RE.findall(text)
    cases = [(suite, strip_test_prefix(case)) for suite, case in _CASE_RE.findall(text)]
    return suites, cases


def scan_sources(test_dir: Path) -> tuple[list[str], list[str]]:
    """Scan `src/` under a test folder (recursively).

    Returns (suites, cases) where cases are "suite.case" names, without duplicates, in a stable
    order (file path, then position in the file).
    """
    src = Path(test_dir) / "src"
    suites: list[str] = []
    cases: list[str] = []
    if not src.is_dir():
        return suites, cases
    files = sorted(p for p in src.rglob("*") if p.suffix in SOURCE_SUFFIXES and p.is_file())
    for path in files:
        try:
            text = path.read_text(encoding="utf-8", errors="replace")
        except OSError:
            continue
        file_suites, file_cases = scan_text(text)
        for suite in file_suites:
            if suite not in suites:
                suites.append(suite)
        for suite, case in file_cases:
            name = f"{suite}.{case}"
            if name not in cases:
                cases.append(name)
    return suites, cases
