//! Operations on voxel sets: flooding, inside classification, topology checks.

pub mod flood;
pub mod inside;
pub mod minimality;
pub mod separability;
