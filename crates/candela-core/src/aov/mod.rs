//! Arbitrary output variables (AOVs): the passes a denoiser or a compositor reads beside
//! the beauty image.
//!
//! - **albedo**: the reflectance of the first non-specular surface a camera ray meets,
//!   seen through perfect mirrors and glass (their own reflectance or transmittance
//!   multiplies it), as Intel Open Image Denoise defines it for denoising; see
//!   [`first_surface`] for each material's value.
//! - **normal**: the world-space shading normal (after normal maps) of that same surface.
//! - **depth**: the distance along the camera's viewing axis to the first surface the
//!   ray meets (a mirror or glass included), as OpenEXR's `Z` channel is: a plane facing
//!   the camera has one depth over the whole image.
//!
//! The passes are rendered by [`render_aovs`], a pass of its own beside the path tracer's:
//! one camera ray per pixel sample through the same sample positions as the beauty's
//! (same sampler, seed, pixel and index), followed through delta lobes only. It leaves the
//! path tracer and its film untouched; it traces one ray per sample (more behind mirrors
//! and glass) and samples no light, where the beauty traces several with shadow rays:
//! 0.14 s beside the beauty's 0.86 s on the 128² Cornell box at 16 spp (shared machine).

mod buffer;
mod render;
mod surface;

pub use crate::options::{AovKind, AovSet};
pub use buffer::{AovFilm, AovPixel};
pub use render::render_aovs;
pub use surface::{first_surface, lobe_albedo, FirstSurface};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_parse_into_sets_and_unknown_names_are_refused() {
        let set = AovSet::parse_list("depth, albedo").unwrap();
        assert!(set.contains(AovKind::Albedo) && set.contains(AovKind::Depth));
        assert!(!set.contains(AovKind::Normal));
        assert_eq!(
            set.iter().collect::<Vec<_>>(),
            [AovKind::Albedo, AovKind::Depth]
        );
        assert!(AovSet::parse_list("").unwrap().is_empty());
        let err = AovSet::parse_list("albedo,uv").unwrap_err();
        assert!(err.contains("`uv`"), "{err}");
    }
}
