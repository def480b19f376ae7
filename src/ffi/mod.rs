//! cxx bridges to the C++ libraries. No algorithm code lives here.
#[cfg(feature = "osd")]
pub mod osd;
