"""The verdict of a benchmark run as a CI smoke test (--check): prints each failure and writes the
JUnit file catkin counts (--junit), one test case that fails when any check did."""
import os
import sys
from xml.sax.saxutils import quoteattr


def report(failures, junit, suite, case="smoke"):
    """Prints `failures` (messages), writes them to `junit` when given; True when there are none."""
    for message in failures:
        print("CHECK FAILED: " + message)
    if junit:
        # The first test of a clean build: the results folder may not exist yet.
        os.makedirs(os.path.dirname(os.path.abspath(junit)), exist_ok=True)
        body = "".join(f"<failure message={quoteattr(m)}/>" for m in failures)
        with open(junit, "w") as f:
            f.write(f'<?xml version="1.0"?>\n<testsuite name={quoteattr(suite)} tests="1" errors="0" '
                    f'failures="{1 if failures else 0}"><testcase name={quoteattr(case)}>{body}'
                    "</testcase></testsuite>\n")
    print("check: " + ("FAILED" if failures else "passed"))
    return not failures


def run(main, suite, case="smoke"):
    """Runs `main()`; when it raises and the command line has --check and --junit FILE, the error is
    also the smoke test's failed verdict in FILE (catkin otherwise reports only a missing file)."""
    try:
        main()
    except Exception as e:  # noqa: BLE001 - any error on the way fails the smoke test
        argv = sys.argv
        if "--check" in argv and "--junit" in argv[:-1]:
            report(["error: %r" % e], argv[argv.index("--junit") + 1], suite, case)
        raise
