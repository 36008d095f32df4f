//! Exact statements about fitted volumes, shared by `tests/fit.rs`, `tests/fit_world.rs`
//! and the fuzz targets: points in volumes in fixed point ([`points`]), and the world
//! AABBs of volumes under maps in rationals ([`world`]). Both sit on `crate::oracle`.
#![allow(dead_code, clippy::needless_range_loop)]

pub mod points;
pub mod world;
