import sys

import fake_ztest as z

z.out("Running TESTSUITE crash")
z.out(z.RULE)
z.out("START - test_oops")
z.out(">>> SAFELINE FATAL ERROR 3: Kernel oops on CPU 0")
sys.exit(134)
