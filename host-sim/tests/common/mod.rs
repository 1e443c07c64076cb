//! What the CLI test files share: running the binary and a scratch
//! directory per test.
#![allow(dead_code)] // each test file uses its own part of it

use std::path::{Path, PathBuf};
use std::process::Command;

/// One run of the binary: exit code and both outputs as text.
pub struct Run {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `host-sim` with `args`.
pub fn run(args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("host-sim runs");
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into(),
        stderr: String::from_utf8_lossy(&out.stderr).into(),
    }
}

/// A fresh directory for one test: `<tag>-<pid>-<name>` in the temp dir.
pub fn scratch(tag: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("{tag}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path as the `&str` an argument list takes.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The run was refused: exit 1 or 2 (argument error), `needle` in its
/// stderr, and no panic.
pub fn refused(run: &Run, needle: &str) {
    assert!(
        matches!(run.code, Some(1 | 2)),
        "exit {:?}, stderr {}",
        run.code,
        run.stderr
    );
    assert!(
        run.stderr.contains(needle),
        "`{needle}` not in stderr: {}",
        run.stderr
    );
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
}
