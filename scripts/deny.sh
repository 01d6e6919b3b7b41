#!/usr/bin/env bash
# cargo-deny over everything eotn builds (deny.toml): licences, duplicate crates, sources; and
# the RustSec advisories where their database can be fetched (machines that reach only package
# registries cannot: then this says so and checks the rest).
set -euo pipefail
cd "$(dirname "$0")/.."
DENY_VERSION=0.20.2
if ! cargo deny --version 2>/dev/null | grep -q "$DENY_VERSION"; then
  echo "deny: installing cargo-deny $DENY_VERSION (about 3 minutes on 2 cores)" >&2
  cargo install --locked --quiet cargo-deny --version "$DENY_VERSION"
fi
cargo deny check bans licenses sources
if timeout 120 cargo deny fetch db >/dev/null 2>&1; then
  cargo deny check advisories
else
  echo "deny: advisories NOT checked: the RustSec database could not be fetched from this machine" >&2
fi
