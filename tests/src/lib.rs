//! System tests across crates live in `tests/tests/`; this library only
//! holds helpers they share.
