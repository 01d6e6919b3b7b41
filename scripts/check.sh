#!/usr/bin/env bash
# What CI runs, for use before committing: formatting, the layering rule, clippy with and without
# the app, then the README's test command. One definition, in .ci/run.
set -euo pipefail
exec "$(dirname "$0")/../.ci/run"
