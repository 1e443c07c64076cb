//! Prints the worked example frames of `docs/protocol.md` in hex, before
//! and after COBS framing, and the bandwidth figures.
use mwd_core::protocol::{encode_body, encode_frame, example, frame, wire_len, FrameKind};

fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn main() {
    let seq = example::EXAMPLE_SEQ;
    for (name, payload) in [
        ("raw sample", example::raw_sample()),
        ("navigation solution", example::nav_solution()),
        ("boot event", example::boot_event()),
        ("station survey", example::station_survey()),
    ] {
        let mut body = [0u8; frame::MAX_BODY_LEN];
        let mut wire = [0u8; mwd_core::protocol::MAX_WIRE_LEN];
        let b = encode_body(seq, &payload, &mut body).expect("fits");
        let w = encode_frame(seq, &payload, &mut wire).expect("fits");
        println!(
            "{name} (seq {seq:#06x}), body {b} bytes:\n{}",
            hex(&body[..b])
        );
        println!("on the wire, {w} bytes:\n{}\n", hex(&wire[..w]));
    }
    print_uplink_examples();
    let raw = wire_len(FrameKind::RawSample.body_len());
    let nav = wire_len(FrameKind::NavSolution.body_len());
    let per_s = mwd_core::protocol::cyclic_bytes_per_s();
    println!(
        "raw {raw} B + nav {nav} B per cycle, {per_s} B/s at 20 Hz = {:.1} % of {} B/s",
        100.0 * f64::from(per_s) / f64::from(mwd_core::protocol::UART_BYTES_PER_S),
        mwd_core::protocol::UART_BYTES_PER_S
    );
}

/// The uplink's worked examples: a command and the probe's two answers.
fn print_uplink_examples() {
    use mwd_core::protocol::uplink::{self, reply};
    let seq = example::EXAMPLE_COMMAND_SEQ;
    let mut body = [0u8; uplink::MAX_COMMAND_BODY_LEN];
    let mut wire = [0u8; uplink::MAX_COMMAND_WIRE_LEN];
    let b =
        uplink::encode_command_body(seq, &example::set_site_command(), &mut body).expect("fits");
    let w = uplink::encode_command(seq, &example::set_site_command(), &mut wire).expect("fits");
    println!(
        "set site (command {seq}), body {b} bytes:\n{}",
        hex(&body[..b])
    );
    println!("on the wire, {w} bytes:\n{}\n", hex(&wire[..w]));
    for (name, r) in [("ACK", example::ack_reply()), ("NAK", example::nak_reply())] {
        let b = reply::encode_reply_body(example::EXAMPLE_SEQ, &r, &mut body).expect("fits");
        let w = reply::encode_reply(example::EXAMPLE_SEQ, &r, &mut wire).expect("fits");
        println!("{name} reply, body {b} bytes:\n{}", hex(&body[..b]));
        println!("on the wire, {w} bytes:\n{}\n", hex(&wire[..w]));
    }
}
