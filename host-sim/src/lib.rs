//! Library side of the host tool: simulation, file formats, analysis. The
//! CLI in `main.rs` is a thin layer over it, and the system tests use it.
