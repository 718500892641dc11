//! A scene description's fingerprint: a 64-bit hash of everything it holds, so that
//! films rendered apart (sample ranges of one image) can be checked to come from the same
//! scene and settings before they are merged.

use std::fmt::{self, Write};

use crate::desc::SceneDesc;

/// FNV-1a (64-bit) over the description's `Debug` text, streamed, so that no copy of a
/// large scene is made. The text covers geometry, materials, lights, camera, the file
/// names items were loaded from (their spans) and every render setting (resolution,
/// seed, spp, sampler, filter, the compiled copy of the loop …); it is the same on every
/// machine and run for the same loaded scene. Not a cryptographic hash: it guards
/// against mistakes, not against forgery.
pub fn fingerprint(desc: &SceneDesc) -> u64 {
    let mut h = Fnv1a(0xcbf2_9ce4_8422_2325);
    write!(h, "{desc:?}").expect("hashing cannot fail");
    h.0
}

struct Fnv1a(u64);

impl Write for Fnv1a {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for &b in s.as_bytes() {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_change_the_fingerprint_and_equal_scenes_share_it() {
        let a = SceneDesc::default();
        assert_eq!(fingerprint(&a), fingerprint(&SceneDesc::default()));
        let mut b = SceneDesc::default();
        b.render.seed += 1;
        assert_ne!(fingerprint(&a), fingerprint(&b));
        let mut c = SceneDesc::default();
        c.render.width += 1;
        assert_ne!(fingerprint(&a), fingerprint(&c));
    }

    #[test]
    fn fnv1a_matches_its_reference_value() {
        // FNV-1a 64 of "a" (from the algorithm's published test vectors).
        let mut h = Fnv1a(0xcbf2_9ce4_8422_2325);
        h.write_str("a").unwrap();
        assert_eq!(h.0, 0xaf63_dc4c_8601_ec8c);
    }
}
