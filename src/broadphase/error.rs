//! Why the tree refused an input.

use core::fmt;

/// Why the tree refused an input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BroadphaseError {
    /// A box with a NaN or infinite face, or a face below its opposite one.
    InvalidBox {
        /// The proxy.
        id: u32,
    },
    /// [`DynamicTree::insert`](super::DynamicTree::insert) of a proxy already in the tree.
    Duplicate {
        /// The proxy.
        id: u32,
    },
    /// An id of `2^31 − 2` or more (the tree packs ids in 31 bits).
    IdTooLarge {
        /// The id.
        id: u32,
    },
    /// The memory for ids up to this one could not be allocated (the tree keeps 28 bytes
    /// per id up to the largest): the tree is unchanged.
    OutOfMemory {
        /// The id.
        id: u32,
    },
    /// The moved list of [`DynamicTree::write`](super::DynamicTree::write) (or `update`) is not strictly ascending.
    Unsorted,
    /// A moved id past the end of the fat boxes.
    MissingBox {
        /// The moved id.
        id: u32,
        /// The number of fat boxes.
        len: usize,
    },
    /// The fat boxes' layout is inconsistent (its columns disagree in length).
    Layout,
    /// [`DynamicTree::set_kind`] or [`DynamicTree::set_layers`] of a proxy not in the tree.
    ///
    /// [`DynamicTree::set_kind`]: super::DynamicTree::set_kind
    /// [`DynamicTree::set_layers`]: super::DynamicTree::set_layers
    UnknownId {
        /// The id.
        id: u32,
    },
    /// A query box or point with a NaN face or coordinate, or a box with a face below its
    /// opposite one: nothing was searched.
    InvalidQuery,
    /// A cast with a NaN or infinite origin, direction or motion, a zero ray direction, a
    /// NaN or negative length, or a bad moving box: nothing was cast.
    InvalidCast,
    /// A batch of casts whose output is not as long as its rays: nothing was cast.
    OutputLength {
        /// The rays.
        rays: usize,
        /// The output's length.
        len: usize,
    },
}

impl fmt::Display for BroadphaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidBox { id } => {
                write!(
                    f,
                    "proxy {id}: the box has a NaN or infinite face, or min > max"
                )
            }
            Self::Duplicate { id } => write!(f, "proxy {id} is already in the tree"),
            Self::IdTooLarge { id } => write!(f, "proxy id {id} is not below 2^31 - 2"),
            Self::OutOfMemory { id } => {
                write!(f, "proxy id {id}: no memory for the tree's per-id tables")
            }
            Self::Unsorted => write!(f, "the moved ids are not strictly ascending"),
            Self::MissingBox { id, len } => {
                write!(f, "moved id {id} is past the {len} fat boxes")
            }
            Self::Layout => write!(f, "the fat boxes' columns disagree in length"),
            Self::UnknownId { id } => write!(f, "proxy {id} is not in the tree"),
            Self::InvalidCast => write!(
                f,
                "the cast has a NaN or infinite origin, direction or motion, a zero ray \
                 direction, a NaN or negative length, or a bad box"
            ),
            Self::OutputLength { rays, len } => {
                write!(f, "{rays} rays but an output of {len}")
            }
            Self::InvalidQuery => {
                write!(
                    f,
                    "the query has a NaN coordinate, or a face below its opposite one"
                )
            }
        }
    }
}

impl core::error::Error for BroadphaseError {}
