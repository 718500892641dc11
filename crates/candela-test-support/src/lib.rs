//! What the tests of several of Candela's crates share, in one place (a dev-dependency of
//! `candela-core` and `candela-scene`; it is not part of the renderer):
//!
//! - [`files`]: scene files written into a fresh temporary folder and loaded;
//! - [`mitsuba`]: a Mitsuba 3 document around a body, loaded or expected to fail;
//! - [`gltf`]: a small GLB writer, so that tests make files with exactly the features
//!   they check;
//! - [`tiles`]: two estimators' renders compared tile by tile with Welch's t-test;
//! - [`samplers`]: drawing a sampler's requests and testing their distribution and
//!   stratification;
//! - [`spectrum`]: how blue an image's error is (its radially split power spectrum);
//! - [`assert_close`].
//!
//! The statistics themselves (chi-square, Welch) live in `candela_core::chi2`, which the
//! core's own unit tests use too.

pub mod files;
pub mod gltf;
pub mod mitsuba;
pub mod samplers;
pub mod spectrum;
pub mod tiles;

use glam::Vec3;

/// Asserts that `a` and `b` differ by less than `tol` in every component.
#[track_caller]
pub fn assert_close(a: Vec3, b: Vec3, tol: f32) {
    assert!((a - b).abs().max_element() < tol, "{a} vs {b}");
}
