//! Linker set-up of the target binaries only: the host build of the library
//! (and its tests) gets no linker script at all.
//!
//! The QEMU board links with its own complete script, `link-qemu.x` (with
//! its map in `memory-qemu.x`), not cortex-m-rt's `link.x`: that one
//! includes `memory.x`, which the linker finds first in its working
//! directory, the workspace root, where it is the real board's map.
//!
//! The filter-cycle bench (`qemu-cycle-bench`) runs on the same QEMU board
//! and links with `link-qemu-cycle-bench.x`: the same sections in a map big
//! enough for its opt-level 3 code.
//!
//! The real board (`probe-stm32`) links with cortex-m-rt's `link.x` and that
//! top-level `memory.x` on purpose (the probe's 256 KiB / 32 KiB budget): the
//! workspace root is put on the search path explicitly rather than relying
//! on the linker's working directory, and `defmt.x` places defmt's tables.

use std::env;
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=memory-qemu.x");
    println!("cargo:rerun-if-changed=link-qemu.x");
    println!("cargo:rerun-if-changed=link-qemu-cycle-bench.x");
    println!("cargo:rerun-if-changed=sections-qemu.x");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../memory.x");
    let board_qemu = env::var_os("CARGO_FEATURE_BOARD_QEMU").is_some();
    let board_stm32 = env::var_os("CARGO_FEATURE_BOARD_STM32").is_some();
    let cycle_bench = env::var_os("CARGO_FEATURE_QEMU_CYCLE_BENCH").is_some();
    let target = env::var("TARGET").unwrap_or_default();
    let dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    if board_stm32 && target.starts_with("thumb") {
        let root = dir.parent().expect("firmware/ sits in the workspace");
        println!("cargo:rustc-link-search={}", root.display());
        println!("cargo:rustc-link-arg-bin=probe-stm32=-Tlink.x");
        println!("cargo:rustc-link-arg-bin=probe-stm32=-Tdefmt.x");
    }
    if !((board_qemu || cycle_bench) && target.starts_with("thumb")) {
        return;
    }
    println!("cargo:rustc-link-search={}", dir.display());
    if board_qemu {
        println!("cargo:rustc-link-arg-bin=probe-qemu=-Tlink-qemu.x");
    }
    if cycle_bench {
        println!("cargo:rustc-link-arg-bin=qemu-cycle-bench=-Tlink-qemu-cycle-bench.x");
    }
}
