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

pub use buffer::{AovFilm, AovPixel};
pub use render::render_aovs;
pub use surface::{first_surface, lobe_albedo, FirstSurface};

/// One pass. Its name in scene files and on the command line is its lowercase name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AovKind {
    Albedo,
    Normal,
    Depth,
}

impl AovKind {
    /// Every pass, in the order files list them.
    pub const ALL: [AovKind; 3] = [AovKind::Albedo, AovKind::Normal, AovKind::Depth];

    /// The EXR layer of the pass and its channels (`albedo.R`, `normal.X`, `depth.Z`):
    /// the `layer.channel` naming of OpenEXR's multi-part convention, which Nuke, Blender
    /// and OIDN's own tools read.
    pub fn layer(self) -> (&'static str, &'static [&'static str]) {
        match self {
            AovKind::Albedo => ("albedo", &["R", "G", "B"]),
            AovKind::Normal => ("normal", &["X", "Y", "Z"]),
            AovKind::Depth => ("depth", &["Z"]),
        }
    }

    /// The pass's name, as scene files and the command line spell it.
    pub fn name(self) -> &'static str {
        self.layer().0
    }

    /// The pass named `name`, if any.
    pub fn from_name(name: &str) -> Option<AovKind> {
        AovKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// A set of passes (none by default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet(u8);

impl AovSet {
    pub const NONE: AovSet = AovSet(0);

    pub fn with(self, kind: AovKind) -> AovSet {
        AovSet(self.0 | 1 << kind as u8)
    }

    pub fn union(self, o: AovSet) -> AovSet {
        AovSet(self.0 | o.0)
    }

    pub fn contains(self, kind: AovKind) -> bool {
        self.0 & 1 << kind as u8 != 0
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The passes in the set, in [`AovKind::ALL`]'s order.
    pub fn iter(self) -> impl Iterator<Item = AovKind> {
        AovKind::ALL.into_iter().filter(move |&k| self.contains(k))
    }

    /// Parses a comma-separated list such as `albedo,normal,depth`.
    pub fn parse_list(s: &str) -> Result<AovSet, String> {
        s.split(',')
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .try_fold(AovSet::NONE, |set, n| match AovKind::from_name(n) {
                Some(k) => Ok(set.with(k)),
                None => Err(format!(
                    "unknown AOV `{n}`, expected albedo, normal or depth"
                )),
            })
    }
}

impl FromIterator<AovKind> for AovSet {
    fn from_iter<I: IntoIterator<Item = AovKind>>(iter: I) -> AovSet {
        iter.into_iter().fold(AovSet::NONE, AovSet::with)
    }
}

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
