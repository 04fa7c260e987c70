import fake_ztest as z

z.verdict(z.suite("misc", [("one", "PASS", None)]))
