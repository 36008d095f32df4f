//! What a proxy pairs with: its body kind and its collision layers, and the tree's switches
//! for the pairs of two non-dynamic proxies.

/// The kind of body a proxy stands for, as engines have them (rapier's `RigidBodyType`,
/// avian's `RigidBody`, Box2D's `b2BodyType`).
///
/// A pair needs at least one dynamic proxy, unless the tree's [`KindPairs`] admit the pairs
/// of a kinematic proxy with a kinematic or a static one; two static proxies never pair.
/// Static proxies live in a hierarchy of their own, which a frame touches only where a
/// moving proxy's box meets theirs (see the [module docs](super)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(u8)]
pub enum BodyKind {
    /// Moved by the solver: pairs with every kind.
    #[default]
    Dynamic,
    /// Moved by the user (a platform, a door on a path): pairs with dynamic proxies, and
    /// with kinematic or static ones where [`KindPairs`] say so.
    Kinematic,
    /// Does not move (a level): pairs with dynamic proxies, and with kinematic ones where
    /// [`KindPairs::kinematic_static`] says so. It can still be moved (a teleported door):
    /// a write in its hierarchy, as any other.
    Static,
}

/// The two hierarchies of the tree: the proxies that move (dynamic and kinematic) and the
/// static ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Tier {
    Moving,
    Fixed,
}

impl BodyKind {
    /// The hierarchy that holds proxies of this kind.
    #[inline(always)]
    pub(super) fn tier(self) -> Tier {
        match self {
            BodyKind::Static => Tier::Fixed,
            BodyKind::Dynamic | BodyKind::Kinematic => Tier::Moving,
        }
    }
}

/// Collision layers, 32 of them: a proxy pairs with another only when each one's
/// memberships meet the other's filters (rapier's `InteractionGroups`, avian's
/// `CollisionLayers`, Box2D's category and mask bits). A query takes `Layers` too, and
/// finds the proxies that would pair with a proxy of those layers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Layers {
    /// The layers the proxy is in.
    pub memberships: u32,
    /// The layers the proxy pairs with.
    pub filters: u32,
}

impl Layers {
    /// In every layer, pairing with every layer: the default.
    pub const ALL: Self = Self::new(u32::MAX, u32::MAX);
    /// In no layer, pairing with none.
    pub const NONE: Self = Self::new(0, 0);

    /// Layers from their two bit sets.
    #[inline]
    #[must_use]
    pub const fn new(memberships: u32, filters: u32) -> Self {
        Self {
            memberships,
            filters,
        }
    }

    /// True when the two may pair: each one's memberships meet the other's filters.
    #[inline]
    #[must_use]
    pub const fn interacts_with(self, other: Self) -> bool {
        self.memberships & other.filters != 0 && other.memberships & self.filters != 0
    }
}

impl Default for Layers {
    fn default() -> Self {
        Self::ALL
    }
}

/// Which pairs of two non-dynamic proxies a tree reports ([`DynamicTree::set_kind_pairs`]):
/// none by default, as in rapier and avian. Two static proxies never pair.
///
/// [`DynamicTree::set_kind_pairs`]: super::DynamicTree::set_kind_pairs
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct KindPairs {
    /// Pairs of two kinematic proxies.
    pub kinematic_kinematic: bool,
    /// Pairs of a kinematic proxy and a static one.
    pub kinematic_static: bool,
}

impl KindPairs {
    /// True when a proxy of kind `a` may pair with one of kind `b`.
    #[inline(always)]
    pub(super) fn admit(self, a: BodyKind, b: BodyKind) -> bool {
        use BodyKind::{Dynamic, Kinematic, Static};
        match (a, b) {
            (Dynamic, _) | (_, Dynamic) => true,
            (Kinematic, Kinematic) => self.kinematic_kinematic,
            (Kinematic, Static) | (Static, Kinematic) => self.kinematic_static,
            (Static, Static) => false,
        }
    }
}

/// What one proxy pairs with: its kind and its layers (kept per id).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Proxy {
    pub(super) layers: Layers,
    pub(super) kind: BodyKind,
}

impl Proxy {
    /// True when the proxy's pairs take no check beyond their boxes where every proxy is
    /// so: not kinematic, and in the tree's `common` layers. (A static proxy's pairs are
    /// all with moving proxies, which are then dynamic.)
    #[inline(always)]
    pub(super) fn is_plain(self, common: Layers) -> bool {
        self.kind != BodyKind::Kinematic && self.layers == common
    }
}
