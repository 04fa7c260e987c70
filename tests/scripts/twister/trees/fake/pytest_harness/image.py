import sys

print("image args:", " ".join(sys.argv[1:]), flush=True)
