//! Linker set-up of the board binaries only: the host build of the library
//! (and its tests) gets no linker script at all.
//!
//! The QEMU board links with its own complete script, `link-qemu.x` (with
//! its map in `memory-qemu.x`), not cortex-m-rt's `link.x`: that one
//! includes `memory.x`, which the linker finds first in its working
//! directory, the workspace root, where it is the real board's map.

use std::env;
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=memory-qemu.x");
    println!("cargo:rerun-if-changed=link-qemu.x");
    println!("cargo:rerun-if-changed=build.rs");
    let board_qemu = env::var_os("CARGO_FEATURE_BOARD_QEMU").is_some();
    let target = env::var("TARGET").unwrap_or_default();
    if !(board_qemu && target.starts_with("thumb")) {
        return;
    }
    let dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    println!("cargo:rustc-link-search={}", dir.display());
    println!("cargo:rustc-link-arg-bin=probe-qemu=-Tlink-qemu.x");
}
