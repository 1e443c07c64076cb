#!/usr/bin/env bash
# Every test of the project, on a fresh machine: installs what the tests need,
# then runs formatting, lints, the probe's cross-builds and the test suites.
set -euo pipefail
cd "$(dirname "$0")/.."

rustup target add thumbv7em-none-eabihf
rustup component add rustfmt clippy

cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
# The probe's builds: the core alone, and the firmware crate.
cargo build -p mwd-core --release --target thumbv7em-none-eabihf
cargo build -p firmware --release --target thumbv7em-none-eabihf
cargo test --workspace
