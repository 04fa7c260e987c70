import subprocess
import time

import fake_ztest as z

helper = subprocess.Popen(["sleep", "300"])  # must die with the image's process group
open("helper.pid", "w").write(str(helper.pid))
z.out("Running TESTSUITE hang")
z.out(z.RULE)
z.out("START - test_first")
z.out(" PASS - test_first in 0.001 seconds")
z.out(z.RULE)
z.out("START - test_forever")
while True:
    time.sleep(1)
