//! File output helpers and format bridges.
pub mod atomic;
#[cfg(feature = "vdb")]
pub mod vdb;
#[cfg(feature = "vdb")]
mod vdb_structure;
