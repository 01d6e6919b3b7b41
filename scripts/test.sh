#!/usr/bin/env bash
# The test command of the README: installs what the tests need (system packages, and the pinned
# Python tools in .venv/), then runs every test with and without the desktop app (the library and
# CLI must build and pass without the `gui` feature).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh --test
cargo test --no-default-features
cargo test
