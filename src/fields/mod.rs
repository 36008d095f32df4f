//! Plain-data types as fixed lists of `f32` fields: the unit that the AoSoA and SoA layouts
//! store and that the loaders transpose into lanes; and the AoSoA block of eight
//! (`block`), whose type the transform classes name (their blocks of poses).

mod block;

pub use block::Block8;

use crate::lane::Vector;

/// The most `f32` fields any stored type has (`Affine3A`: 12).
pub const MAX_FIELDS: usize = 12;

/// Fields `k..k + N` as a vector (an indexed loop, always inlined into the loaders).
#[inline(always)]
pub fn vector_at<L: Copy, const N: usize>(f: &[L; MAX_FIELDS], k: usize) -> Vector<L, N> {
    let mut v = [f[k]; N];
    for (i, x) in v.iter_mut().enumerate() {
        *x = f[k + i];
    }
    Vector(v)
}

/// A plain-data type stored as `FIELDS` floats: the unit of the AoSoA and SoA layouts.
pub trait Fields: Copy + Send + Sync {
    /// The number of `f32` fields.
    const FIELDS: usize;
    /// `[C; FIELDS]`: one `C` per field (a field's eight values in an AoSoA block, a
    /// column, …).
    type Array<C: Send + Sync>: AsRef<[C]> + AsMut<[C]> + Send + Sync;
    /// The array whose entry `n` is `f(n)`.
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C>;
    /// The value that pads a partial AoSoA block (the identity, or the empty box).
    const PADDING: Self;
    /// The fields, in their fixed order; entries past `FIELDS` are zero.
    fn to_fields(&self) -> [f32; MAX_FIELDS];
    /// The value from its fields.
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self;
}
