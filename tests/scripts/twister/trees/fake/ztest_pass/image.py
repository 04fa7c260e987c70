import sys

import fake_ztest as z

z.out("argv: " + " ".join(sys.argv[1:]))
ok = z.suite("demo", [("adds", "PASS", None), ("skips", "SKIP", None)])
z.verdict(ok)
