#!/usr/bin/env bash
# Everything CI checks, in the order it fails fastest: formatting, layering, lints with and
# without the app, then the README's test command.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo fmt --check

# Layering: only src/app/ (and the binary's entry) may name egui/eframe, so the pipeline and CLI
# never depend on the UI.
if grep -rnE '\b(egui|eframe|egui_plot|egui_kittest|rfd)::' src --include='*.rs' | grep -v '^src/app/' | grep -v '^src/main.rs'; then
  echo "layering: the lines above use the UI outside src/app/" >&2
  exit 1
fi

cargo clippy --all-targets --no-default-features -- -D warnings
cargo clippy --all-targets -- -D warnings
scripts/test.sh
