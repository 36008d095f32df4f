//! How each layout names itself for the runs bvkit compiles once (`Route`): from its items'
//! names ([`NamedItem`], on the box types and the transform classes), so that generic code
//! can hand a run's boxes, poses and output over to code compiled in bvkit
//! (`engine::route`). The layouts' traits otherwise only load and store.

use super::{Soa, SoaMut, SoaRef};
use crate::fields::Block8;
use crate::transform::{Maps, NamedBoxes, NamedBoxesMut, NamedItem, NamedPoses, Route};
use alloc::vec::Vec;

/// How a layout names itself: its route, and its items by name where the route is not
/// [`Route::Generic`]. Every box source, box sink and pose source has it (sealed machinery,
/// hidden); a layout holds one role, and answers `None` for the others.
pub trait Named {
    /// The run of this layout that bvkit compiles once, if any.
    #[doc(hidden)]
    const ROUTE: Route = Route::Generic;
    /// The boxes by name.
    #[doc(hidden)]
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        None
    }
    /// The boxes to write by name.
    #[doc(hidden)]
    #[inline(always)]
    fn named_boxes_mut(&mut self) -> Option<NamedBoxesMut<'_>> {
        None
    }
    /// The poses by name (a [`Swept`](crate::Swept) pair's current ones).
    #[doc(hidden)]
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        None
    }
    /// A [`Swept`](crate::Swept) pair's predicted poses by name, on [`Route::Swept`].
    #[doc(hidden)]
    #[inline(always)]
    fn named_predicted(&self) -> Option<NamedPoses<'_>> {
        None
    }
}

/// AoS items: boxes or poses, as the item is.
impl<E: NamedItem> Named for &[E] {
    const ROUTE: Route = E::SLICE;
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        E::boxes(self)
    }
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        E::poses(Maps::Each(self))
    }
}

impl<E: NamedItem> Named for &Vec<E> {
    const ROUTE: Route = E::SLICE;
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        E::boxes(self)
    }
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        E::poses(Maps::Each(self))
    }
}

impl<E: NamedItem> Named for &mut [E] {
    const ROUTE: Route = E::SLICE;
    #[inline(always)]
    fn named_boxes_mut(&mut self) -> Option<NamedBoxesMut<'_>> {
        E::boxes_mut(self)
    }
}

impl<E: NamedItem> Named for &mut Vec<E> {
    const ROUTE: Route = E::SLICE;
    #[inline(always)]
    fn named_boxes_mut(&mut self) -> Option<NamedBoxesMut<'_>> {
        E::boxes_mut(self)
    }
}

/// One pose shared by every box.
impl<E: NamedItem> Named for &E {
    const ROUTE: Route = E::SHARED;
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        E::poses(Maps::Shared(self))
    }
}

impl<E: NamedItem> Named for &[Block8<E>] {
    const ROUTE: Route = E::BLOCKS;
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        E::box_blocks(self)
    }
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        E::pose_blocks(self)
    }
}

impl<E: NamedItem> Named for &Vec<Block8<E>> {
    const ROUTE: Route = E::BLOCKS;
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        E::box_blocks(self)
    }
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        E::pose_blocks(self)
    }
}

impl<E: NamedItem> Named for &mut [Block8<E>] {
    const ROUTE: Route = E::BLOCKS;
    #[inline(always)]
    fn named_boxes_mut(&mut self) -> Option<NamedBoxesMut<'_>> {
        E::box_blocks_mut(self)
    }
}

impl<E: NamedItem> Named for &mut Vec<Block8<E>> {
    const ROUTE: Route = E::BLOCKS;
    #[inline(always)]
    fn named_boxes_mut(&mut self) -> Option<NamedBoxesMut<'_>> {
        E::box_blocks_mut(self)
    }
}

impl<E: NamedItem> Named for SoaRef<'_, E> {
    const ROUTE: Route = E::COLUMNS;
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        E::box_columns(self.columns.as_ref())
    }
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        E::pose_columns(self.columns.as_ref())
    }
}

impl<E: NamedItem> Named for SoaMut<'_, E> {
    const ROUTE: Route = E::COLUMNS;
    #[inline(always)]
    fn named_boxes_mut(&mut self) -> Option<NamedBoxesMut<'_>> {
        E::box_columns_mut(self.columns.as_mut())
    }
}

impl<E: NamedItem> Named for &Soa<E> {
    const ROUTE: Route = E::COLUMNS;
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        E::box_columns(self.columns.as_ref())
    }
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        E::pose_columns(self.columns.as_ref())
    }
}

impl<E: NamedItem> Named for &mut Soa<E> {
    const ROUTE: Route = E::COLUMNS;
    #[inline(always)]
    fn named_boxes_mut(&mut self) -> Option<NamedBoxesMut<'_>> {
        E::box_columns_mut(self.columns.as_mut())
    }
}
