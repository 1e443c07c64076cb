//! `host-sim observability` end to end: at one toolface, ZUPT + zero
//! position leave azimuth and the horizontal accelerometer biases entangled
//! (rank 12 of 15); toolface indexing over four toolfaces makes all 15
//! states observable.
use std::process::Command;

fn run(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .arg("observability")
        .args(args)
        .output()
        .expect("host-sim runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn toolface_indexing_makes_the_biases_observable() {
    let one = run(&[]);
    assert!(one.contains("12 of 15"), "{one}");
    assert!(one.contains("unobservable direction 1"), "{one}");
    let four = run(&["--toolfaces", "0,90,180,270"]);
    assert!(four.contains("15 of 15"), "{four}");
    assert!(!four.contains("unobservable direction"), "{four}");
    let nav = run(&["--no-biases"]);
    assert!(nav.contains("9 of 9"), "{nav}");
}

#[test]
fn bad_arguments_are_refused() {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["observability", "--measurements", "gps"])
        .output()
        .expect("host-sim runs");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("zupt, zpu or both"));
}
