import re
import sys

import fake_ztest as z

# Two lines, numbered 0 and 1, each on an interface of its own.
lines = [a for a in sys.argv[1:] if a.startswith("--can-if=")]
z.out("can lines: " + " ".join(lines))
m = [re.fullmatch(r"--can-if=(\d):(vcan\d+)", a) for a in lines]
ok = len(m) == 2 and all(m) and [x.group(1) for x in m] == ["0", "1"] and m[0].group(2) != m[1].group(2)
ok = z.suite("vcan", [("args", "PASS" if ok else "FAIL", None if ok else f"got {lines}")])
z.verdict(ok)
