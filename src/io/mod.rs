//! File output helpers and format bridges.
pub mod atomic;
pub mod binvox;
#[cfg(feature = "vdb")]
mod blosc_chunk;
#[cfg(feature = "vdb")]
pub mod brick_set;
#[cfg(feature = "vdb")]
pub mod brick_splice;
mod direct_file;
mod direct_read;
#[cfg(feature = "vdb")]
pub mod grid_export;
#[cfg(feature = "vdb")]
mod grid_out;
pub mod mesh_out;
#[cfg(feature = "vdb")]
mod nvdb_writer;
pub mod preview;
pub mod references;
#[cfg(feature = "vdb")]
pub mod vdb;
#[cfg(feature = "vdb")]
mod vdb_chunks;
#[cfg(feature = "vdb")]
mod vdb_format;
#[cfg(feature = "vdb")]
mod vdb_reader;
#[cfg(feature = "vdb")]
mod vdb_structure;
#[cfg(feature = "vdb")]
mod vdb_tree_structure;
#[cfg(feature = "vdb")]
mod vdb_writer;
pub mod vox;
