//! The names of the runs bvkit compiles once ([`Route`]), and how each box type and each
//! transform class names itself on them ([`NamedItem`]): the one place that knows which item
//! is which. The layouts name themselves from their items (`layout::Named`), and the
//! dispatch that takes the names is `engine::route`. Here, below the layouts, because every
//! class must carry its names ([`Class`](super::Class) requires [`NamedItem`]), so that a
//! caller's generic code over `T: Transform3` can hand `&[T]` to a batch.

use super::{Rigid2, Rigid3, Similarity3, Translation2, Translation3, Trs3};
use crate::aabb::{Aabb2, Aabb3};
use crate::fields::{Block8, Fields};

/// Which run of a layout bvkit compiles once, in itself, so that a caller's call site
/// compiles a call rather than the loops. A run takes the route its boxes, poses and
/// output all name (`Engine::ROUTE`); any other runs the lane loop where it is called.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Route {
    /// None: the lane loop, instantiated at the call site.
    Generic,
    /// AoS 3D boxes (`&[Aabb3]`) with AoS or shared poses of a 3D class: the AoS loop.
    Aos,
    /// AoSoA blocks of 3D boxes (`&[Aabb3x8]`) with blocks of rigid poses
    /// (`&[Rigid3x8]`), the layout the README recommends for the update: the lane loop.
    Blocks,
    /// AoS 3D boxes with a [`Swept`](crate::Swept) pair of AoS or shared poses of 3D
    /// classes: the AoS loop at each pose, and the union of the two boxes.
    Swept,
    /// SoA columns of 3D boxes with columns of rigid poses, in a transform (the plain sink):
    /// the lane loop.
    Soa,
    /// AoS 2D boxes (`&[Aabb2]`) with AoS rigid 2D poses (`&[Rigid2]`), in a transform (the
    /// plain sink): the lane loop.
    Aos2,
}

impl Route {
    /// The route of a run whose boxes, poses and output name `a`, `b` and `c`.
    pub const fn of(a: Route, b: Route, c: Route) -> Route {
        match (a, b, c) {
            (Route::Aos, Route::Aos, Route::Aos) => Route::Aos,
            (Route::Blocks, Route::Blocks, Route::Blocks) => Route::Blocks,
            (Route::Aos, Route::Swept, Route::Aos) => Route::Swept,
            (Route::Soa, Route::Soa, Route::Soa) => Route::Soa,
            (Route::Aos2, Route::Aos2, Route::Aos2) => Route::Aos2,
            _ => Route::Generic,
        }
    }
}

/// Boxes on a [`Route`], by name.
#[derive(Clone, Copy)]
pub enum NamedBoxes<'a> {
    /// An AoS slice of 3D boxes.
    Aos(&'a [Aabb3]),
    /// AoSoA blocks.
    Blocks(&'a [Block8<Aabb3>]),
    /// SoA columns (`AabbSoaRef`'s), one per field.
    Soa([&'a [f32]; 6]),
    /// An AoS slice of 2D boxes.
    Aos2(&'a [Aabb2]),
}

/// Boxes to write on a [`Route`], by name.
pub enum NamedBoxesMut<'a> {
    /// An AoS slice of 3D boxes.
    Aos(&'a mut [Aabb3]),
    /// AoSoA blocks.
    Blocks(&'a mut [Block8<Aabb3>]),
    /// SoA columns (`AabbSoaMut`'s), one per field.
    Soa([&'a mut [f32]; 6]),
    /// An AoS slice of 2D boxes.
    Aos2(&'a mut [Aabb2]),
}

/// Poses on a [`Route`], by name: one variant per layout of a route's poses (a
/// [`Swept`](crate::Swept) pair names each end [`NamedPoses::Aos`]).
#[derive(Clone, Copy)]
pub enum NamedPoses<'a> {
    /// AoS or shared poses of a 3D class.
    Aos(AosPoses<'a>),
    /// Blocks of [`Rigid3`] poses (`Rigid3x8`).
    Blocks(&'a [Block8<Rigid3>]),
    /// Columns of [`Rigid3`] poses (`Rigid3SoaRef`'s), one per field.
    Soa([&'a [f32]; 7]),
    /// An AoS slice of [`Rigid2`] poses.
    Aos2(&'a [Rigid2]),
}

/// AoS or shared poses of a 3D class, by name: the poses of the AoS route.
#[derive(Clone, Copy)]
pub enum AosPoses<'a> {
    /// [`Translation3`] poses.
    Translation3(Maps<'a, Translation3>),
    /// [`Rigid3`] poses.
    Rigid3(Maps<'a, Rigid3>),
    /// [`Similarity3`] poses.
    Similarity3(Maps<'a, Similarity3>),
    /// [`Trs3`] poses.
    Trs3(Maps<'a, Trs3>),
    /// `Affine3A` poses.
    Affine3A(Maps<'a, glam::Affine3A>),
}

/// Poses read as AoS: one per box, or one shared.
#[derive(Clone, Copy)]
pub enum Maps<'a, T> {
    /// Pose `k` for box `k`.
    Each(&'a [T]),
    /// One pose for every box.
    Shared(&'a T),
}

impl<'a, T> Maps<'a, T> {
    /// Box `i`'s pose.
    #[inline(always)]
    pub fn at(self, i: usize) -> &'a T {
        match self {
            Maps::Each(maps) => &maps[i],
            Maps::Shared(map) => map,
        }
    }
}

/// How a box type or a transform class names its slices, blocks and columns: the routes
/// they take, and themselves by name on them. Only [`Aabb3`], [`Aabb2`], the 3D classes and
/// [`Rigid2`] have a route; the others keep the defaults.
pub trait NamedItem: Fields {
    /// The route of a slice of items (AoS), to read or to write.
    const SLICE: Route = Route::Generic;
    /// The route of one item shared by every box (a shared pose).
    const SHARED: Route = Route::Generic;
    /// The route of AoSoA blocks of items.
    const BLOCKS: Route = Route::Generic;
    /// The route of SoA columns of items.
    const COLUMNS: Route = Route::Generic;
    /// A slice of boxes by name.
    #[inline(always)]
    fn boxes(items: &[Self]) -> Option<NamedBoxes<'_>> {
        let _ = items;
        None
    }
    /// A slice of boxes to write by name.
    #[inline(always)]
    fn boxes_mut(items: &mut [Self]) -> Option<NamedBoxesMut<'_>> {
        let _ = items;
        None
    }
    /// Blocks of boxes by name.
    #[inline(always)]
    fn box_blocks(blocks: &[Block8<Self>]) -> Option<NamedBoxes<'_>> {
        let _ = blocks;
        None
    }
    /// Blocks of boxes to write by name.
    #[inline(always)]
    fn box_blocks_mut(blocks: &mut [Block8<Self>]) -> Option<NamedBoxesMut<'_>> {
        let _ = blocks;
        None
    }
    /// Columns of boxes by name.
    #[inline(always)]
    fn box_columns<C: AsRef<[f32]>>(columns: &[C]) -> Option<NamedBoxes<'_>> {
        let _ = columns;
        None
    }
    /// Columns of boxes to write by name.
    #[inline(always)]
    fn box_columns_mut<C: AsMut<[f32]>>(columns: &mut [C]) -> Option<NamedBoxesMut<'_>> {
        let _ = columns;
        None
    }
    /// AoS or shared poses by name.
    #[inline(always)]
    fn poses(poses: Maps<'_, Self>) -> Option<NamedPoses<'_>> {
        let _ = poses;
        None
    }
    /// Blocks of poses by name.
    #[inline(always)]
    fn pose_blocks(blocks: &[Block8<Self>]) -> Option<NamedPoses<'_>> {
        let _ = blocks;
        None
    }
    /// Columns of poses by name.
    #[inline(always)]
    fn pose_columns<C: AsRef<[f32]>>(columns: &[C]) -> Option<NamedPoses<'_>> {
        let _ = columns;
        None
    }
}

impl NamedItem for Aabb3 {
    const SLICE: Route = Route::Aos;
    const BLOCKS: Route = Route::Blocks;
    const COLUMNS: Route = Route::Soa;
    #[inline(always)]
    fn boxes(items: &[Self]) -> Option<NamedBoxes<'_>> {
        Some(NamedBoxes::Aos(items))
    }
    #[inline(always)]
    fn boxes_mut(items: &mut [Self]) -> Option<NamedBoxesMut<'_>> {
        Some(NamedBoxesMut::Aos(items))
    }
    #[inline(always)]
    fn box_blocks(blocks: &[Block8<Self>]) -> Option<NamedBoxes<'_>> {
        Some(NamedBoxes::Blocks(blocks))
    }
    #[inline(always)]
    fn box_blocks_mut(blocks: &mut [Block8<Self>]) -> Option<NamedBoxesMut<'_>> {
        Some(NamedBoxesMut::Blocks(blocks))
    }
    #[inline(always)]
    fn box_columns<C: AsRef<[f32]>>(columns: &[C]) -> Option<NamedBoxes<'_>> {
        let columns = <&[C; 6]>::try_from(columns).ok()?;
        Some(NamedBoxes::Soa(columns.each_ref().map(AsRef::as_ref)))
    }
    #[inline(always)]
    fn box_columns_mut<C: AsMut<[f32]>>(columns: &mut [C]) -> Option<NamedBoxesMut<'_>> {
        let columns = <&mut [C; 6]>::try_from(columns).ok()?;
        Some(NamedBoxesMut::Soa(columns.each_mut().map(AsMut::as_mut)))
    }
}

impl NamedItem for Aabb2 {
    const SLICE: Route = Route::Aos2;
    #[inline(always)]
    fn boxes(items: &[Self]) -> Option<NamedBoxes<'_>> {
        Some(NamedBoxes::Aos2(items))
    }
    #[inline(always)]
    fn boxes_mut(items: &mut [Self]) -> Option<NamedBoxesMut<'_>> {
        Some(NamedBoxesMut::Aos2(items))
    }
}

/// The 3D classes but [`Rigid3`]: AoS or shared poses on the AoS route.
macro_rules! aos_class {
    ($($class:ident: $ty:ty),*) => {$(
        impl NamedItem for $ty {
            const SLICE: Route = Route::Aos;
            const SHARED: Route = Route::Aos;
            #[inline(always)]
            fn poses(poses: Maps<'_, Self>) -> Option<NamedPoses<'_>> {
                Some(NamedPoses::Aos(AosPoses::$class(poses)))
            }
        }
    )*};
}
aos_class!(Translation3: Translation3, Similarity3: Similarity3, Trs3: Trs3,
    Affine3A: glam::Affine3A);

/// Rigid poses: the AoS route, and the blocks' and the columns'.
impl NamedItem for Rigid3 {
    const SLICE: Route = Route::Aos;
    const SHARED: Route = Route::Aos;
    const BLOCKS: Route = Route::Blocks;
    const COLUMNS: Route = Route::Soa;
    #[inline(always)]
    fn poses(poses: Maps<'_, Self>) -> Option<NamedPoses<'_>> {
        Some(NamedPoses::Aos(AosPoses::Rigid3(poses)))
    }
    #[inline(always)]
    fn pose_blocks(blocks: &[Block8<Self>]) -> Option<NamedPoses<'_>> {
        Some(NamedPoses::Blocks(blocks))
    }
    #[inline(always)]
    fn pose_columns<C: AsRef<[f32]>>(columns: &[C]) -> Option<NamedPoses<'_>> {
        let columns = <&[C; 7]>::try_from(columns).ok()?;
        Some(NamedPoses::Soa(columns.each_ref().map(AsRef::as_ref)))
    }
}

/// Rigid 2D poses: a slice of them on the 2D route (a shared one has none).
impl NamedItem for Rigid2 {
    const SLICE: Route = Route::Aos2;
    #[inline(always)]
    fn poses(poses: Maps<'_, Self>) -> Option<NamedPoses<'_>> {
        match poses {
            Maps::Each(poses) => Some(NamedPoses::Aos2(poses)),
            Maps::Shared(_) => None,
        }
    }
}

impl NamedItem for Translation2 {}
impl NamedItem for glam::Affine2 {}
