//! cxx bridges to the C++ libraries. No algorithm code lives here.
#[cfg(feature = "vdb")]
pub mod vdb;
