//! One 8x8x8 leaf: a 512-bit occupancy mask plus optional per-voxel channels, laid out
//! exactly like an OpenVDB LeafNode (`n = x*64 + y*8 + z`; mask word `x`, bit `y*8+z`) so
//! leaves cross the bridge as plain arrays.

use super::bits;
use super::channel_pool::ChannelBox;
use super::coord::{Coord, CoordBox, LEAF_VOXELS, offset_coord};

/// Which optional per-voxel channels a grid carries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Channels {
    /// One `f32` per voxel (the separating voxelizer stores the distance to the surface).
    pub value: bool,
    /// A unit normal per voxel.
    pub normal: bool,
    /// A linear RGB colour per voxel (written as the `Cd` grid).
    pub color: bool,
}

impl Channels {
    pub const NONE: Channels = Channels {
        value: false,
        normal: false,
        color: false,
    };
    pub const VALUE: Channels = Channels {
        value: true,
        ..Channels::NONE
    };
}

#[derive(Clone, Debug)]
pub struct Leaf {
    /// Index of the leaf's (0,0,0) voxel; every component a multiple of 8.
    pub origin: Coord,
    pub mask: [u64; 8],
    pub value: Option<ChannelBox<[f32; LEAF_VOXELS]>>,
    pub normal: Option<ChannelBox<[[f32; 3]; LEAF_VOXELS]>>,
    pub color: Option<ChannelBox<[[f32; 3]; LEAF_VOXELS]>>,
}

impl Leaf {
    /// An empty leaf with storage for `channels`.
    pub fn new(origin: Coord, channels: Channels) -> Self {
        Leaf {
            origin,
            mask: [0; 8],
            value: channels.value.then(ChannelBox::zeroed),
            normal: channels.normal.then(ChannelBox::zeroed),
            color: channels.color.then(ChannelBox::zeroed),
        }
    }

    /// A leaf without channels whose active voxels are `mask`'s.
    pub fn with_mask(origin: Coord, mask: [u64; 8]) -> Self {
        Leaf {
            mask,
            ..Leaf::new(origin, Channels::NONE)
        }
    }

    #[inline]
    pub fn is_on(&self, n: usize) -> bool {
        bits::get(&self.mask, n)
    }

    #[inline]
    pub fn set_on(&mut self, n: usize) {
        bits::set(&mut self.mask, n);
    }

    /// Number of active voxels.
    pub fn count(&self) -> u32 {
        self.mask.iter().map(|w| w.count_ones()).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.mask.iter().all(|&w| w == 0)
    }

    /// In-leaf offsets of the active voxels, ascending.
    pub fn offsets(&self) -> impl Iterator<Item = usize> + '_ {
        bits::ones(&self.mask)
    }

    /// Coordinates of the active voxels.
    pub fn coords(&self) -> impl Iterator<Item = Coord> + '_ {
        self.offsets().map(|n| offset_coord(self.origin, n))
    }

    /// Copies the channels of voxel `n` from `other` (same channel set or a subset).
    pub fn copy_channels_from(&mut self, other: &Leaf, n: usize) {
        if let (Some(d), Some(s)) = (self.value.as_mut(), other.value.as_ref()) {
            d[n] = s[n];
        }
        if let (Some(d), Some(s)) = (self.normal.as_mut(), other.normal.as_ref()) {
            d[n] = s[n];
        }
        if let (Some(d), Some(s)) = (self.color.as_mut(), other.color.as_ref()) {
            d[n] = s[n];
        }
    }
}

/// The box of the active voxels of a leaf at `origin` with `mask`, if any: x by the non-empty
/// words, y by the non-empty bytes of their union, z by the union of those bytes.
pub fn mask_box(origin: Coord, mask: &[u64; 8]) -> Option<CoordBox> {
    let x0 = mask.iter().position(|&w| w != 0)?;
    let x1 = mask.iter().rposition(|&w| w != 0)?;
    let rows = mask.iter().fold(0u64, |a, &w| a | w);
    let bytes = (0..8).map(|y| rows >> (8 * y) & 0xff);
    let ys = bytes
        .clone()
        .enumerate()
        .fold(0u64, |a, (y, r)| a | u64::from(r != 0) << y);
    let zs = bytes.fold(0u64, |a, r| a | r);
    let o = origin;
    Some(CoordBox {
        min: [
            o[0] + x0 as i64,
            o[1] + ys.trailing_zeros() as i64,
            o[2] + zs.trailing_zeros() as i64,
        ],
        max: [
            o[0] + x1 as i64,
            o[1] + 63 - ys.leading_zeros() as i64,
            o[2] + 63 - zs.leading_zeros() as i64,
        ],
    })
}
