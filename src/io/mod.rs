//! File output helpers and format bridges.
pub mod atomic;
#[cfg(feature = "vdb")]
pub mod vdb;
