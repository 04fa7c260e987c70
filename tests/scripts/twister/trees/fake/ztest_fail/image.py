import fake_ztest as z

ok = z.suite("arith", [("good", "PASS", None), ("bad", "FAIL", "1 + 1 == 3 is false: wrong sum")])
z.verdict(ok)
