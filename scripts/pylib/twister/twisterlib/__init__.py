"""twisterlib: SafeLine's twister-style test runner.

Modules, in pipeline order:
    config     load testcase.yaml/sample.yaml, validate against the schema, merge `common:`
    boards     platform descriptions from boards/*/*/<board>.yaml
    scan       static scan of ztest sources for the expected test cases
    expr       the `filter:` expression language (parser + evaluator)
    plan       discovery, scenario x platform instances, static filters
    build      CMake + Ninja, reading the built .config
    handler    running a process with a timeout and a log, killing its process group
    harness    output parsers: ztest, console, pytest
    execution  one run of one built instance (handler + harness), serialisable for the VM
    vm         the vcan fixture: a batch of instances run inside scripts/vcan-vm
    runner     the parallel pipeline, progress lines, retries
    report     twister.json, twister.xml, testplan.json, summary and counts
    cli        command line
"""
