"""Status names, spelled as Zephyr's twister spells them in its reports."""

PASSED = "passed"
FAILED = "failed"
ERROR = "error"
SKIPPED = "skipped"
FILTERED = "filtered"
# Test cases only: the case never ran because its instance stopped before it (build failure,
# timeout, fault in an earlier case).
BLOCKED = "blocked"
# Test cases only: printed START but no result yet.
STARTED = "started"

# Instance statuses that make the run fail (exit code 1).
FAILING = (FAILED, ERROR)
