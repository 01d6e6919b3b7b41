#!/usr/bin/env bash
# The test command of the README: installs what the tests need (system packages, and the pinned
# Python tools in .venv/), then runs the library's tests without the desktop app (it must build
# and pass without the `gui` feature) and every test with it. It ends with every test that
# skipped, why, and how to get what it needs (a skipped test passes outside CI; under CI=true it fails).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh --test
EOTN_SKIP_LOG="$(mktemp "${TMPDIR:-/tmp}/eotn-skips.XXXXXX")"
export EOTN_SKIP_LOG
summary() {
    local status=$?
    echo
    if [ -s "$EOTN_SKIP_LOG" ]; then
        echo "== Skipped tests ($(sort -u "$EOTN_SKIP_LOG" | wc -l)): they passed without running their check =="
        sort -u "$EOTN_SKIP_LOG" | while IFS=$'\t' read -r test reason remedy; do
            echo "- $test: $reason"
            echo "    to run it: $remedy"
        done
    else
        echo "== No test skipped =="
    fi
    rm -f "$EOTN_SKIP_LOG"
    exit "$status"
}
trap summary EXIT
# Without the app: the library's unit tests (the pipeline and CLI code is the same
# in both builds; CI's clippy step already compiles every target without the app). The whole
# suite, integration tests included, runs once, with the app: running the integration binary in
# both builds cost CI about six minutes of its 55 for no code that differs.
cargo test --no-default-features --lib
cargo test
