#!/usr/bin/env bash
# Proves that `cargo build --release` needs only Rust and a C compiler: a fresh Debian 12
# (debootstrap, minbase) with gcc and libc6-dev and nothing else — no libclang, no -dev packages
# of the app's run-time libraries — builds eotn from a clone of this checkout, and the build tree
# names no bindgen or clang-sys. Needs root (debootstrap, chroot, bind mounts) and about 1.5 GB.
#   scripts/build-in-chroot.sh [ROOT_DIR]        (default /var/tmp/eotn-chroot)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=${1:-/var/tmp/eotn-chroot}
TOOLCHAIN=$(rustc --print sysroot)
[ -x "$ROOT/usr/bin/gcc" ] || debootstrap --variant=minbase --include=gcc,libc6-dev,ca-certificates \
  bookworm "$ROOT" http://deb.debian.org/debian
mkdir -p "$ROOT/opt/rust" "$ROOT/src"
mountpoint -q "$ROOT/opt/rust" || mount --bind -o ro "$TOOLCHAIN" "$ROOT/opt/rust"
mountpoint -q "$ROOT/proc" || mount -t proc proc "$ROOT/proc"
trap 'umount "$ROOT/opt/rust" "$ROOT/proc" 2>/dev/null || true' EXIT
cp /etc/resolv.conf "$ROOT/etc/"
# This machine's trust store (a proxy may sign the registry's certificates).
cp "${SSL_CERT_FILE:-/etc/ssl/certs/ca-certificates.crt}" "$ROOT/etc/ssl/certs/ca-certificates.crt"
rm -rf "$ROOT/src/eotn"
git clone -q . "$ROOT/src/eotn"
chroot "$ROOT" /bin/bash -c '
  set -euo pipefail
  export PATH=/opt/rust/bin:/usr/bin:/bin CARGO_HOME=/root/cargo-home
  export SSL_CERT_FILE=/etc/ssl/certs/ca-certificates.crt
  cd /src/eotn
  echo "chroot: libclang libraries here: $(/sbin/ldconfig -p | grep -c libclang || true)"
  time cargo build --release
  if cargo tree -e normal,build --prefix none | grep -E "^(bindgen|clang-sys) "; then exit 1; fi
  ls -l target/release/eotn
'
echo "chroot: built with Rust and gcc alone"
