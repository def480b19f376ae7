"""The last line of scripts/test-all.sh: passed, failed and skipped tests across cargo and pytest,
and what the skipped ones needed.

    python3 scripts/test_summary.py CARGO_LOG CARGO_STATUS PYTEST_LOG PYTEST_STATUS

Cargo counts a skipped test as passed; its loud line (`!!! NEED: detail ... SKIPPED`, from
tests/common/skip.rs) moves it to the skipped count. pytest's skips come from `-rs` lines
(`SKIPPED [n] file:line: MISSING NEED: detail`, from python/tests/conftest.py).
"""

import re
import sys
from collections import Counter

ANSI = re.compile(r"\x1b\[[0-9;]*m")


def read(path):
    try:
        with open(path, errors="replace") as f:
            return [ANSI.sub("", line.rstrip("\n")) for line in f]
    except OSError:
        return []


def cargo(lines, status):
    passed = failed = 0
    needs = Counter()
    for line in lines:
        m = re.match(r"test result: \w+\. (\d+) passed; (\d+) failed", line)
        if m:
            passed += int(m[1])
            failed += int(m[2])
        m = re.match(r"!!! (.+?): .*SKIPPED", line)
        if m:
            needs[m[1]] += 1
    skipped = sum(needs.values())
    if status != 0 and failed == 0:
        failed = 1  # It did not build, or a test binary crashed: no counts to trust.
    return passed - skipped, failed, needs


def pytest(lines, status):
    counts = Counter()
    needs = Counter()
    for line in lines:
        m = re.match(r"SKIPPED \[(\d+)\] [^:]+:\d+: (?:MISSING )?(.+?)(?::|$)", line)
        if m:
            needs[m[2]] += int(m[1])
        if re.search(r"\d+ (passed|failed|error|skipped)", line) and " in " in line:
            counts = Counter({k: int(n) for n, k in re.findall(r"(\d+) (passed|failed|errors?|skipped)", line)})
    failed = counts["failed"] + counts["error"] + counts["errors"]
    if status != 0 and failed == 0:
        failed = 1  # pytest or the module's build stopped before any count.
    return counts["passed"], failed, needs


def main(cargo_log, cargo_status, pytest_log, pytest_status):
    rust = cargo(read(cargo_log), int(cargo_status))
    python = pytest(read(pytest_log), int(pytest_status))
    needs = rust[2] + python[2]
    skipped = sum(needs.values())
    line = (f"tests: {rust[0] + python[0]} passed, {rust[1] + python[1]} failed, {skipped} skipped "
            f"(cargo {rust[0]}/{rust[1]}/{sum(rust[2].values())}, "
            f"pytest {python[0]}/{python[1]}/{sum(python[2].values())} passed/failed/skipped)")
    if needs:
        line += "; skipped for want of: " + ", ".join(f"{need} ({n})" for need, n in needs.most_common())
    print(line)


if __name__ == "__main__":
    main(*sys.argv[1:])
