import sys
import time

if "CONFIG_FAKE_EXIT=1" in open("zephyr/.config").read():
    print("some output", flush=True)
    sys.exit(1)
print("Hello from native_posix", flush=True)
tick = 0
while True:
    tick += 1
    print(f"tick {tick}", flush=True)
    time.sleep(0.05)
